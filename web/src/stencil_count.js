// The "stencil-count" kind (render/multipass/stencil_count.py): a fragment is kept where every
// one of several tests passes, counted in a stencil buffer one pass per test, group after
// group of the plan's triangles (the first complete group wins, no depth test), then copied
// into the frame's target by the ``copy`` program, which writes the depth. Params:
// ``uniform`` and ``values`` (the tests), ``ranges`` ((G, 2) first index and count per group).

const COUNT = { depth_test: false, depth_write: true, depth_func: '<', cull: 'none', blend: 'none' };
const COPY = { depth_test: true, depth_write: true, depth_func: '<', cull: 'none', blend: 'none' };
const FULL_SCREEN = { key: 'full-screen triangle', attributes: {}, vertices: 3, primitive: 'triangles' };
const SOURCES = ['u_src_color', 'u_src_position', 'u_src_normal'];

export function drawStencilCounted(executor, plan, camera, light, outer, extra) {
  const gl = executor.gl;
  const { programs, params } = plan.multipass;
  const values = numbers(params.values);
  const ranges = numbers(params.ranges);
  const [w, h] = camera.size;
  const target = stencilTarget(executor, w, h);
  const role = (name) => ({ program: programs[name], raster: COUNT });
  gl.bindFramebuffer(gl.FRAMEBUFFER, target.fbo);
  gl.viewport(0, 0, w, h);
  gl.colorMask(true, true, true, true);
  gl.depthMask(true);
  gl.stencilMask(0xff);
  for (let i = 0; i < SOURCES.length; i++) gl.clearBufferfv(gl.COLOR, i, [0, 0, 0, 0]);
  gl.clearBufferfi(gl.DEPTH_STENCIL, 0, 1, 0);
  const stencil = (func, ref, op, color) => {
    gl.enable(gl.STENCIL_TEST);
    gl.stencilFunc(func, ref, 0xff);
    gl.stencilOp(gl.KEEP, gl.KEEP, op);
    gl.colorMask(color, color, color, color);
  };
  try {
    for (let g = 0; g < ranges.length; g += 2) {
      const span = { ...plan, first: ranges[g], count: ranges[g + 1] };
      values.forEach((value, i) => {
        stencil(gl.EQUAL, i, gl.INCR, false);
        executor.drawViewed(span, camera, light, { ...role('test'), uniforms: { ...extra.uniforms, [params.uniform]: value } });
      });
      stencil(gl.EQUAL, values.length, gl.INCR, true);
      executor.drawViewed(span, camera, light, { ...role('color'), uniforms: extra.uniforms });
      stencil(gl.GREATER, values.length, gl.ZERO, false);
      executor.drawViewed(span, camera, light, { ...role('color'), uniforms: extra.uniforms });
    }
  } finally {
    gl.disable(gl.STENCIL_TEST);
    gl.colorMask(true, true, true, true);
  }
  outer();
  const copy = { name: `${plan.name}: copy`, program: { name: programs.copy[0], defines: programs.copy[1] },
    geometry: FULL_SCREEN, textures: {}, uniforms: {}, raster: COPY, origin: plan.origin, first: 0, count: null };
  executor.drawViewed(copy, camera, light, { textures: Object.fromEntries(SOURCES.map((s, i) => [s, target.textures[i]])) });
}

function numbers(value) {
  if (value && value.data) return Array.from(value.data, Number);
  return Array.isArray(value) ? value.flat(Infinity).map(Number) : [Number(value)];
}

/** RGBA32F outputs and a depth + stencil buffer (gl/stencil.py StencilTarget), once per size. */
function stencilTarget(executor, w, h) {
  const key = `stencil-count ${w}x${h}`;
  if (!executor.cache.has(key)) {
    const gl = executor.gl;
    const fbo = gl.createFramebuffer();
    gl.bindFramebuffer(gl.FRAMEBUFFER, fbo);
    const textures = SOURCES.map((_, i) => {
      const tex = gl.createTexture();
      gl.bindTexture(gl.TEXTURE_2D, tex);
      gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, w, h, 0, gl.RGBA, gl.FLOAT, null);
      for (const p of [gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER]) gl.texParameteri(gl.TEXTURE_2D, p, gl.NEAREST);
      gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0 + i, gl.TEXTURE_2D, tex, 0);
      return { tex, target: gl.TEXTURE_2D };
    });
    const rbo = gl.createRenderbuffer();
    gl.bindRenderbuffer(gl.RENDERBUFFER, rbo);
    gl.renderbufferStorage(gl.RENDERBUFFER, gl.DEPTH24_STENCIL8, w, h);
    gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.DEPTH_STENCIL_ATTACHMENT, gl.RENDERBUFFER, rbo);
    gl.drawBuffers(SOURCES.map((_, i) => gl.COLOR_ATTACHMENT0 + i));
    const status = gl.checkFramebufferStatus(gl.FRAMEBUFFER);
    if (status !== gl.FRAMEBUFFER_COMPLETE) throw new Error(`a ${w}x${h} framebuffer with a stencil buffer is incomplete (0x${status.toString(16)})`);
    executor.cache.set(key, { fbo, textures, rbo });
  }
  return executor.cache.get(key);
}
