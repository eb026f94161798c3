// The "depth-peel" kind (render/multipass/depth_peel.py): a transparent plan composited
// exactly whatever its order, one pass per depth layer. Pass k draws the whole plan, keeping
// what lies behind layer k - 1 (``u_peel_depth``: its depth and cell per pixel), into its own
// colour and a float copy of the nearest fragment's depth; the ``layer`` program then adds
// that colour under the layers in front. Python stops when an occlusion query counts no
// sample; WebGL2 gives a query's result only after the frame, so here a pass whose depth copy
// holds no fragment (read back) ends it, or ``max_layers``.

import { opaqueDepthInputs } from './opaque_depth.js';

const BEYOND = 2.0; // a pixel no fragment reaches keeps "beyond everything"
const COMPOSITE = { depth_test: false, depth_write: false, cull: 'none', blend: 'under' };

export function drawDepthPeeled(executor, plan, camera, light, outer, extra) {
  const gl = executor.gl;
  const [uniforms, textures] = opaqueDepthInputs(executor, plan, light, outer, extra.targets);
  const [w, h] = extra.targets.size;
  const peel = peelTargets(executor, w, h);
  const raster = { ...plan.raster, depth_write: true, blend: 'none' };
  const layer = executor.program({ name: plan.multipass.programs.layer[0], defines: plan.multipass.programs.layer[1] });
  gl.bindFramebuffer(gl.FRAMEBUFFER, peel.fbos[1]);
  gl.clearBufferfv(gl.COLOR, 1, [-1, -1, -1, -1]); // nothing peeled yet
  const depth = new Float32Array(w * h * 4);
  let layers = 0;
  for (let k = 0; k < Number(plan.multipass.params.max_layers); k++) {
    const [fbo, before] = [peel.fbos[k % 2], peel.peeled[(k + 1) % 2]];
    gl.bindFramebuffer(gl.FRAMEBUFFER, fbo);
    gl.viewport(0, 0, w, h);
    gl.depthMask(true);
    gl.clearBufferfv(gl.COLOR, 0, [0, 0, 0, 0]);
    gl.clearBufferfv(gl.COLOR, 1, [BEYOND, BEYOND, BEYOND, BEYOND]);
    gl.clearBufferfv(gl.DEPTH, 0, [1]);
    executor.drawViewed(plan, camera, light, {
      uniforms: { ...extra.uniforms, ...uniforms }, textures: { ...textures, u_peel_depth: before }, raster,
    });
    gl.readBuffer(gl.COLOR_ATTACHMENT1);
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.FLOAT, depth);
    gl.readBuffer(gl.COLOR_ATTACHMENT0);
    if (!depth.some((z, i) => i % 4 === 0 && z !== BEYOND)) break;
    layers += 1;
    outer();
    executor.drawFullScreen(layer, { u_layer: peel.color }, COMPOSITE);
  }
  outer();
  return layers;
}

/** The passes' colour, two float depth copies (each pass reads the other's) and a depth
 *  buffer, made once per executor and size. */
function peelTargets(executor, w, h) {
  const key = `depth-peel ${w}x${h}`;
  if (!executor.cache.has(key)) {
    const gl = executor.gl;
    const texture = (internal, format, type) => {
      const tex = gl.createTexture();
      gl.bindTexture(gl.TEXTURE_2D, tex);
      gl.texImage2D(gl.TEXTURE_2D, 0, internal, w, h, 0, format, type, null);
      for (const p of [gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER]) gl.texParameteri(gl.TEXTURE_2D, p, gl.NEAREST);
      return { tex, target: gl.TEXTURE_2D };
    };
    const color = texture(gl.RGBA32F, gl.RGBA, gl.FLOAT);
    const peeled = [0, 1].map(() => texture(gl.RGBA32F, gl.RGBA, gl.FLOAT));
    const depth = texture(gl.DEPTH_COMPONENT32F, gl.DEPTH_COMPONENT, gl.FLOAT);
    const fbos = peeled.map((z) => {
      const fbo = gl.createFramebuffer();
      gl.bindFramebuffer(gl.FRAMEBUFFER, fbo);
      gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, color.tex, 0);
      gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT1, gl.TEXTURE_2D, z.tex, 0);
      gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.DEPTH_ATTACHMENT, gl.TEXTURE_2D, depth.tex, 0);
      gl.drawBuffers([gl.COLOR_ATTACHMENT0, gl.COLOR_ATTACHMENT1]);
      return fbo;
    });
    executor.cache.set(key, { color, peeled, fbos });
  }
  return executor.cache.get(key);
}
