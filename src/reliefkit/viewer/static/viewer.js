// web/src/camera.js
var rad = (deg) => deg * Math.PI / 180;
var sub = (a, b) => a.map((x, i) => x - b[i]);
var norm = (a) => Math.hypot(...a);
var scale = (a, s) => a.map((x) => x * s);
var cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
function parseView(text) {
  const parts = text.split(",").map(Number);
  if (![2, 3].includes(parts.length) || !parts.every(Number.isFinite) || Math.abs(parts[1]) >= 90 || parts.length === 3 && !(parts[2] > 0)) {
    throw new Error(`view must be AZ,EL or AZ,EL,DIST with |EL| < 90 (e.g. 30,25,2.6), got '${text}'`);
  }
  return [parts[0], parts[1], parts.length === 3 ? parts[2] : null];
}
function parseSize(text) {
  const m = /^(\d{1,5})x(\d{1,5})$/.exec(text);
  if (!m || +m[1] < 1 || +m[2] < 1 || +m[1] > 8192 || +m[2] > 8192) {
    throw new Error(`size must be WxH within 1..8192 (e.g. 512x512), got '${text}'`);
  }
  return [+m[1], +m[2]];
}
function lookAt(eye, target, up = [0, 1, 0]) {
  const forward = sub(target, eye);
  const f = scale(forward, 1 / norm(forward));
  let side = cross(f, up);
  if (norm(side) < 1e-9) side = cross(f, Math.abs(f[1]) > 0.5 ? [0, 0, -1] : [0, 1, 0]);
  const s = scale(side, 1 / norm(side));
  const u = cross(s, f);
  const rows = [s, u, scale(f, -1)];
  const view = identity();
  for (let r = 0; r < 3; r++) {
    for (let c = 0; c < 3; c++) view[r * 4 + c] = rows[r][c];
    view[r * 4 + 3] = -(rows[r][0] * eye[0] + rows[r][1] * eye[1] + rows[r][2] * eye[2]);
  }
  return view;
}
function perspective(fovDeg, aspect, near, far) {
  const f = 1 / Math.tan(rad(fovDeg) / 2);
  const p = new Array(16).fill(0);
  p[0] = f / aspect;
  p[5] = f;
  p[10] = (far + near) / (near - far);
  p[11] = 2 * far * near / (near - far);
  p[14] = -1;
  return p;
}
function orthographic(halfHeight, aspect, near, far) {
  const p = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1];
  p[0] = 1 / (halfHeight * aspect);
  p[5] = 1 / halfHeight;
  p[10] = -2 / (far - near);
  p[11] = -(far + near) / (far - near);
  return p;
}
function lightCamera(bounds, direction, size) {
  const [lo, hi] = bounds;
  const centre = [0, 1, 2].map((i) => (lo[i] + hi[i]) / 2);
  const radius = norm(sub(hi, lo)) / 2 || 1;
  const towards = scale(direction, 1 / norm(direction));
  const up = Math.abs(towards[1]) > 0.99 ? [1, 0, 0] : [0, 1, 0];
  const eye = centre.map((c, i) => c + 2 * radius * towards[i]);
  const [near, far] = [0.5 * radius, 3.5 * radius];
  return {
    eye,
    target: centre,
    up,
    fov_deg: 40,
    size: [size, size],
    near,
    far,
    ortho_height: radius,
    origin: centre,
    view: lookAt(eye, centre, up),
    proj: orthographic(radius, 1, near, far)
  };
}
function orbitBounds(bounds, az, el, dist, size, frame) {
  const [w, h] = size;
  if (dist === null) {
    const halfV = rad(frame.fov) / 2;
    const halfH = Math.atan(Math.tan(halfV) * w / h);
    dist = frame.fit_margin / Math.sin(Math.min(halfV, halfH));
  }
  const diag = norm(sub(bounds[1], bounds[0])) / 2;
  const radius = diag > 0 ? diag : 1;
  const d = dist * radius;
  const near = Math.max(d - 1.05 * radius, 5e-3 * d);
  const far = d + 1.05 * radius;
  const target = [0, 1, 2].map((i) => (bounds[0][i] + bounds[1][i]) / 2);
  const [a, e] = [rad(az), rad(el)];
  const eye = [0, 1, 2].map((i) => target[i] + d * [Math.cos(e) * Math.sin(a), Math.sin(e), Math.cos(e) * Math.cos(a)][i]);
  return {
    eye,
    target,
    up: [0, 1, 0],
    fov_deg: frame.fov,
    size,
    near,
    far,
    ortho_height: null,
    origin: target,
    view: lookAt(eye, target),
    proj: perspective(frame.fov, w / h, near, far),
    distance: dist
  };
}
function cameraUniforms(camera) {
  const origin = camera.origin;
  const view = multiply(camera.view, translation(origin));
  const toEye = sub(camera.eye, camera.target);
  return {
    u_view: matrix(view),
    u_proj: matrix(camera.proj),
    u_inv_view_proj: matrix(invert(multiply(camera.proj, view))),
    u_eye: sub(camera.eye, origin),
    u_orthographic: camera.ortho_height != null,
    u_view_dir: scale(toEye, 1 / norm(toEye)),
    u_viewport: camera.size
  };
}
function modelOffset(camera, origin) {
  return { u_model_offset: sub(origin || [0, 0, 0], camera.origin) };
}
function lightFrom(fields, az, el) {
  const [a, e] = [rad(az), rad(el)];
  const direction = [Math.cos(e) * Math.sin(a), Math.sin(e), Math.cos(e) * Math.cos(a)];
  return { direction, uniforms: { ...fields.uniforms, u_light_dir: direction } };
}
function matrix(rows) {
  return { shape: [4, 4], dtype: "float64", data: rows };
}
function identity() {
  return [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1];
}
function translation(t) {
  const m = identity();
  [m[3], m[7], m[11]] = t;
  return m;
}
function multiply(a, b) {
  const out = new Array(16).fill(0);
  for (let r = 0; r < 4; r++) for (let c = 0; c < 4; c++) for (let k = 0; k < 4; k++) out[r * 4 + c] += a[r * 4 + k] * b[k * 4 + c];
  return out;
}
function invert(m) {
  const a = [0, 1, 2, 3].map((r) => [...m.slice(r * 4, r * 4 + 4), ...identity().slice(r * 4, r * 4 + 4)]);
  for (let c = 0; c < 4; c++) {
    let p = c;
    for (let r = c + 1; r < 4; r++) if (Math.abs(a[r][c]) > Math.abs(a[p][c])) p = r;
    [a[c], a[p]] = [a[p], a[c]];
    const pivot = a[c][c];
    for (let k = 0; k < 8; k++) a[c][k] /= pivot;
    for (let r = 0; r < 4; r++) {
      if (r === c) continue;
      const f = a[r][c];
      for (let k = 0; k < 8; k++) a[r][k] -= f * a[c][k];
    }
  }
  return a.flatMap((row) => row.slice(4));
}

// web/src/plans.js
function decode(value, arrays) {
  if (Array.isArray(value)) return value.map((v) => decode(v, arrays));
  if (value === null || typeof value !== "object") return value;
  if ("array" in value) return arrays[value.array];
  if ("scalar" in value) return value.value;
  if ("tuple" in value) return value.tuple.map((v) => decode(v, arrays));
  if ("encoded" in value) return { encoded: decodeFields(value.encoded, arrays) };
  return decodeFields(value.dict, arrays);
}
function decodeFields(object, arrays) {
  return Object.fromEntries(Object.entries(object).map(([k, v]) => [k, decode(v, arrays)]));
}
function decodePlans(draw, arrays) {
  const geometries = {};
  for (const [key, g] of Object.entries(draw.geometries)) {
    const { attributes, ...rest } = g;
    const attrs = Object.fromEntries(Object.entries(attributes).map(([name, a]) => {
      const [array, perInstance] = decode(a, arrays);
      return [name, { array, per_instance: perInstance }];
    }));
    geometries[key] = { key, attributes: attrs, ...decodeFields(rest, arrays) };
  }
  const textures = {};
  for (const [key, t] of Object.entries(draw.textures)) textures[key] = { key, ...decodeFields(t, arrays) };
  return draw.plans.map((entry) => {
    const [name, defines] = decode(entry.program, arrays);
    const multipass = decode(entry.multipass, arrays);
    const hook = decode(entry.per_view, arrays);
    return {
      name: entry.name,
      program: { name, defines },
      geometry: geometries[entry.geometry],
      textures: Object.fromEntries(Object.entries(entry.textures).map(([s, k]) => [s, textures[k]])),
      uniforms: decode(entry.uniforms, arrays),
      raster: decode(entry.raster, arrays),
      render_pass: entry.render_pass,
      origin: decode(entry.origin, arrays),
      first: entry.first,
      count: entry.count,
      per_view: hook && { function: hook[0], data: hook[1] },
      multipass: multipass && { kind: multipass[0], programs: multipass[1], params: multipass[2] }
    };
  });
}
function programKey(name, defines) {
  const sorted = Object.keys(defines || {}).sort().map((k) => [k, defines[k]]);
  return `${name} ${JSON.stringify(sorted)}`;
}
function withView(plan, update) {
  let geometry = plan.geometry;
  const { attributes = {}, indices, vertices, instances } = update;
  if (Object.keys(attributes).length || indices != null || vertices != null || instances != null) {
    geometry = {
      ...geometry,
      attributes: Object.fromEntries(Object.entries(geometry.attributes).map(
        ([name, attr]) => [name, { ...attr, array: attributes[name] || attr.array }]
      )),
      indices: indices != null ? indices : geometry.indices,
      vertices: vertices != null ? vertices : geometry.vertices,
      instances: instances != null ? instances : geometry.instances
    };
  }
  const params = update.params && Object.keys(update.params).length ? update.params : null;
  return {
    ...plan,
    geometry,
    raster: update.cull != null ? { ...plan.raster, cull: update.cull } : plan.raster,
    count: update.count != null ? update.count : plan.count,
    multipass: params ? { ...plan.multipass, params: { ...plan.multipass.params, ...params } } : plan.multipass,
    uniforms: { ...plan.uniforms, ...update.uniforms || {} }
  };
}

// web/src/shadow_map.js
function drawShadowMapped(executor, plan, camera, light, outer, extra = {}) {
  const [uniforms, textures] = shadowInputs(executor, plan, light, outer);
  executor.drawViewed(plan, camera, light, { uniforms: { ...extra.uniforms, ...uniforms }, textures });
}
function shadowInputs(executor, plan, light, outer, params = plan.multipass.params) {
  const key = `shadow-map ${plan.geometry.key} ${light.direction.join(",")}`;
  if (!executor.cache.has(key)) {
    const gl = executor.gl;
    const size = Number(params.size);
    const bounds = nested(params.bounds);
    const cam = lightCamera(bounds, light.direction, size);
    const depth = gl.createTexture();
    gl.bindTexture(gl.TEXTURE_2D, depth);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.DEPTH_COMPONENT32F, size, size, 0, gl.DEPTH_COMPONENT, gl.FLOAT, null);
    const fbo = gl.createFramebuffer();
    gl.bindFramebuffer(gl.FRAMEBUFFER, fbo);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.DEPTH_ATTACHMENT, gl.TEXTURE_2D, depth, 0);
    gl.drawBuffers([gl.NONE]);
    gl.viewport(0, 0, size, size);
    gl.depthMask(true);
    gl.clearBufferfv(gl.DEPTH, 0, [1]);
    const raster = { depth_test: true, depth_write: true, cull: params.cull || "none", blend: "none" };
    for (const caster of executor.groups.get(plan.geometry.key) || [plan]) {
      const viewed = params.caster_hooks === false ? caster : executor.view(caster, cam, light);
      executor.drawViewed(viewed, cam, light, { program: caster.multipass.programs.caster, raster });
    }
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    gl.deleteFramebuffer(fbo);
    outer();
    gl.bindTexture(gl.TEXTURE_2D, depth);
    const compare = (params.sampler || "compare") === "compare";
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_COMPARE_MODE, compare ? gl.COMPARE_REF_TO_TEXTURE : gl.NONE);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_COMPARE_FUNC, gl.LEQUAL);
    for (const p of [gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER]) gl.texParameteri(gl.TEXTURE_2D, p, compare ? gl.LINEAR : gl.NEAREST);
    for (const p of [gl.TEXTURE_WRAP_S, gl.TEXTURE_WRAP_T]) gl.texParameteri(gl.TEXTURE_2D, p, gl.CLAMP_TO_EDGE);
    const texel = 2 * cam.ortho_height / size;
    const uniforms = {
      u_light_matrix: matrix(multiply(multiply(cam.proj, cam.view), translation(plan.origin || [0, 0, 0]))),
      u_shadow_texel: texel,
      u_shadow_bias: "bias" in params ? Number(params.bias) : texel / (cam.far - cam.near)
    };
    executor.cache.set(key, [uniforms, { u_shadow_map: { tex: depth, target: gl.TEXTURE_2D } }]);
  }
  return executor.cache.get(key);
}
function nested(box) {
  if (box && box.data) return [Array.from(box.data.slice(0, 3), Number), Array.from(box.data.slice(3, 6), Number)];
  return box;
}

// web/src/opaque_depth.js
function drawWithOpaqueDepth(executor, plan, camera, light, outer, extra) {
  const [uniforms, textures] = opaqueDepthInputs(executor, plan, light, outer, extra.targets);
  executor.drawViewed(plan, camera, light, { uniforms: { ...extra.uniforms, ...uniforms }, textures });
}
function opaqueDepthInputs(executor, plan, light, outer, targets) {
  const gl = executor.gl;
  const [w, h] = targets.size;
  let [uniforms, textures] = [{}, {}];
  if (plan.multipass.params.shadow_map) {
    [uniforms, textures] = shadowInputs(executor, plan, light, outer, plan.multipass.params.shadow_map);
  }
  gl.bindFramebuffer(gl.FRAMEBUFFER, targets.depthCopyFbo);
  gl.viewport(0, 0, w, h);
  executor.drawFullScreen(executor.copyDepth, { u_depth: targets.depth });
  const depth = new Float32Array(w * h * 4);
  gl.readPixels(0, 0, w, h, gl.RGBA, gl.FLOAT, depth);
  outer();
  return [{ ...uniforms, u_clip_opaque: depth.some((z) => z < 1) }, { ...textures, u_opaque_depth: targets.depthCopy }];
}

// web/src/depth_peel.js
var BEYOND = 2;
var COMPOSITE = { depth_test: false, depth_write: false, cull: "none", blend: "under" };
function drawDepthPeeled(executor, plan, camera, light, outer, extra) {
  const gl = executor.gl;
  const [uniforms, textures] = opaqueDepthInputs(executor, plan, light, outer, extra.targets);
  const [w, h] = extra.targets.size;
  const peel = peelTargets(executor, w, h);
  const raster = { ...plan.raster, depth_write: true, blend: "none" };
  const layer = executor.program({ name: plan.multipass.programs.layer[0], defines: plan.multipass.programs.layer[1] });
  gl.bindFramebuffer(gl.FRAMEBUFFER, peel.fbos[1]);
  gl.clearBufferfv(gl.COLOR, 1, [-1, -1, -1, -1]);
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
      uniforms: { ...extra.uniforms, ...uniforms },
      textures: { ...textures, u_peel_depth: before },
      raster
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

// web/src/stencil_count.js
var COUNT = { depth_test: false, depth_write: true, depth_func: "<", cull: "none", blend: "none" };
var COPY = { depth_test: true, depth_write: true, depth_func: "<", cull: "none", blend: "none" };
var FULL_SCREEN = { key: "full-screen triangle", attributes: {}, vertices: 3, primitive: "triangles" };
var SOURCES = ["u_src_color", "u_src_position", "u_src_normal"];
function drawStencilCounted(executor, plan, camera, light, outer, extra) {
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
  gl.stencilMask(255);
  for (let i = 0; i < SOURCES.length; i++) gl.clearBufferfv(gl.COLOR, i, [0, 0, 0, 0]);
  gl.clearBufferfi(gl.DEPTH_STENCIL, 0, 1, 0);
  const stencil = (func, ref, op, color) => {
    gl.enable(gl.STENCIL_TEST);
    gl.stencilFunc(func, ref, 255);
    gl.stencilOp(gl.KEEP, gl.KEEP, op);
    gl.colorMask(color, color, color, color);
  };
  try {
    for (let g = 0; g < ranges.length; g += 2) {
      const span = { ...plan, first: ranges[g], count: ranges[g + 1] };
      values.forEach((value, i) => {
        stencil(gl.EQUAL, i, gl.INCR, false);
        executor.drawViewed(span, camera, light, { ...role("test"), uniforms: { ...extra.uniforms, [params.uniform]: value } });
      });
      stencil(gl.EQUAL, values.length, gl.INCR, true);
      executor.drawViewed(span, camera, light, { ...role("color"), uniforms: extra.uniforms });
      stencil(gl.GREATER, values.length, gl.ZERO, false);
      executor.drawViewed(span, camera, light, { ...role("color"), uniforms: extra.uniforms });
    }
  } finally {
    gl.disable(gl.STENCIL_TEST);
    gl.colorMask(true, true, true, true);
  }
  outer();
  const copy = {
    name: `${plan.name}: copy`,
    program: { name: programs.copy[0], defines: programs.copy[1] },
    geometry: FULL_SCREEN,
    textures: {},
    uniforms: {},
    raster: COPY,
    origin: plan.origin,
    first: 0,
    count: null
  };
  executor.drawViewed(copy, camera, light, { textures: Object.fromEntries(SOURCES.map((s, i) => [s, target.textures[i]])) });
}
function numbers(value) {
  if (value && value.data) return Array.from(value.data, Number);
  return Array.isArray(value) ? value.flat(Infinity).map(Number) : [Number(value)];
}
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
    executor.cache.set(key, { fbo, textures });
  }
  return executor.cache.get(key);
}

// web/src/textures.js
var FORMATS = {
  // dtype -> [internal formats by channel count, format by channel count, type]
  uint8: ["R8 RG8 RGB8 RGBA8", "RED RG RGB RGBA", "UNSIGNED_BYTE"],
  float32: ["R32F RG32F RGB32F RGBA32F", "RED RG RGB RGBA", "FLOAT"],
  float16: ["R16F RG16F RGB16F RGBA16F", "RED RG RGB RGBA", "HALF_FLOAT"],
  uint16: ["R16UI RG16UI RGB16UI RGBA16UI", "RED_INTEGER RG_INTEGER RGB_INTEGER RGBA_INTEGER", "UNSIGNED_SHORT"]
};
var TARGETS = { "2d": "TEXTURE_2D", "3d": "TEXTURE_3D", "2d_array": "TEXTURE_2D_ARRAY" };
function uploadTexture(gl, t) {
  if (t.encoded || t.array.encoding) throw new Error(`${t.what}: block-compressed textures are not drawn by the viewer yet`);
  const target = gl[TARGETS[t.target]];
  const levels = t.levels || [t.array];
  const { shape, dtype } = levels[0];
  const planar = t.target === "2d";
  const dims = planar ? 2 : 3;
  const channels = shape.length > dims ? shape[dims] : 1;
  const format = FORMATS[dtype];
  if (!format || channels < 1 || channels > 4) throw new Error(`${t.what}: a ${dtype} texture of ${channels} channels is not supported`);
  let internal = gl[format[0].split(" ")[channels - 1]];
  if (t.srgb) {
    if (dtype !== "uint8" || channels !== 4) throw new Error(`${t.what}: sRGB textures must be RGBA uint8`);
    internal = gl.SRGB8_ALPHA8;
  }
  const fmt = gl[format[1].split(" ")[channels - 1]];
  const type = gl[format[2]];
  const tex = gl.createTexture();
  gl.bindTexture(target, tex);
  gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
  levels.forEach((level, k) => {
    const [d, h, w] = planar ? [1, ...level.shape.slice(0, 2)] : level.shape.slice(0, 3);
    const data = level.dtype === "float64" ? new Float32Array(level.data) : level.data;
    if (planar) gl.texImage2D(target, k, internal, w, h, 0, fmt, type, data);
    else gl.texImage3D(target, k, internal, w, h, d, 0, fmt, type, data);
  });
  const integer = dtype === "uint16";
  const nearest = t.filter === "nearest" || integer;
  let minify = nearest ? gl.NEAREST : gl.LINEAR;
  if (t.levels) {
    gl.texParameteri(target, gl.TEXTURE_MAX_LEVEL, t.levels.length - 1);
    minify = gl.NEAREST_MIPMAP_NEAREST;
  } else if (t.mipmaps && !nearest) {
    gl.generateMipmap(target);
    minify = gl.LINEAR_MIPMAP_LINEAR;
  }
  gl.texParameteri(target, gl.TEXTURE_MIN_FILTER, minify);
  gl.texParameteri(target, gl.TEXTURE_MAG_FILTER, nearest ? gl.NEAREST : gl.LINEAR);
  const wraps = [gl.TEXTURE_WRAP_S, gl.TEXTURE_WRAP_T, gl.TEXTURE_WRAP_R];
  (t.wrap || []).slice(0, planar ? 2 : 3).forEach((w, i) => {
    gl.texParameteri(target, wraps[i], w === "repeat" ? gl.REPEAT : gl.CLAMP_TO_EDGE);
  });
  return { tex, target };
}

// web/src/copy_depth.glsl
var copy_depth_default = "#version 300 es\n// The opaque pass's depth as a float colour (render/multipass/opaque_depth.py: a transparent\n// plan samples it while the depth attachment itself is being tested). VERTEX_SHADER /\n// FRAGMENT_SHADER pick the stage.\nprecision highp float;\n#ifdef VERTEX_SHADER\nvoid main() {  // one full-screen triangle\n    vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));\n    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);\n}\n#else\nuniform highp sampler2D u_depth;\nout vec4 f_out;\n\nvoid main() {\n    f_out = vec4(texelFetch(u_depth, ivec2(gl_FragCoord.xy), 0).r);\n}\n#endif\n";

// web/src/present.glsl
var present_default = "#version 300 es\n// The picture `reliefkit render` writes (render/frame.py frame_from_passes, Frame.rgba8,\n// colorspace.to_rgba8): the opaque pass's colour where it covered a pixel (position.w > 0.5),\n// under the transparent pass's premultiplied colour, straight again and sRGB-encoded;\n// transparent where neither drew. VERTEX_SHADER / FRAGMENT_SHADER pick the stage.\nprecision highp float;\n#ifdef VERTEX_SHADER\nvoid main() {  // one full-screen triangle\n    vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));\n    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);\n}\n#else\nuniform sampler2D u_color;\nuniform sampler2D u_position;\nuniform sampler2D u_transparent;  // premultiplied, accumulated front to back\nout vec4 f_out;\n\nvec3 srgb_encode(vec3 x) {\n    x = clamp(x, 0.0, 1.0);\n    return mix(1.055 * pow(x, vec3(1.0 / 2.4)) - 0.055, 12.92 * x, lessThanEqual(x, vec3(0.0031308)));\n}\n\nvoid main() {\n    ivec2 p = ivec2(gl_FragCoord.xy);\n    bool covered = texelFetch(u_position, p, 0).w > 0.5;\n    vec4 opaque = covered ? texelFetch(u_color, p, 0) : vec4(0.0);\n    vec4 front = texelFetch(u_transparent, p, 0);\n    float alpha = front.a + (1.0 - front.a) * opaque.a;\n    vec3 rgb = front.rgb + (1.0 - front.a) * opaque.rgb * opaque.a;\n    vec3 straight = alpha > 0.0 ? rgb / alpha : vec3(0.0);\n    f_out = covered || front.a > 0.0 ? vec4(srgb_encode(straight), clamp(alpha, 0.0, 1.0))\n                                     : vec4(0.0);\n}\n#endif\n";

// web/src/executor.js
var FRAME_ATTACHMENTS = 3;
var MODES = { triangles: "TRIANGLES", points: "POINTS", lines: "LINES", triangle_strip: "TRIANGLE_STRIP" };
var BLEND = { under: ["ONE_MINUS_DST_ALPHA", "ONE"], add: ["ONE", "ONE"] };
var MULTIPASS = {
  "shadow-map": drawShadowMapped,
  "opaque-depth": drawWithOpaqueDepth,
  // its extra passes only place the position and normal AOVs at the half-opacity point,
  // which the page does not show: its colour and coverage are the opaque-depth kind's
  "half-opacity-search": drawWithOpaqueDepth,
  "depth-peel": drawDepthPeeled,
  "stencil-count": drawStencilCounted
};
var FRONT_OPACITY_UNIT = 15;
var Unsupported = class extends Error {
};
function createContext(canvas) {
  const gl = canvas.getContext("webgl2", { alpha: true, premultipliedAlpha: false, antialias: false, preserveDrawingBuffer: true });
  if (!gl) throw new Error("this browser has no WebGL2: the viewer needs it");
  if (!gl.getExtension("EXT_color_buffer_float")) throw new Error("this browser cannot render to float textures (EXT_color_buffer_float)");
  gl.getExtension("OES_texture_float_linear");
  return gl;
}
var Executor = class {
  /** ``hooks``: the view hooks' ports by the Python function's "module:name" (web/src/hooks/). */
  constructor(gl, draw, name, hooks = {}) {
    this.gl = gl;
    this.name = name;
    this.hooks = hooks;
    this.sources = new Map(draw.programs.map((p) => [programKey(p.program, p.defines), p]));
    this.programs = /* @__PURE__ */ new Map();
    this.buffers = /* @__PURE__ */ new Map();
    this.vaos = /* @__PURE__ */ new Map();
    this.textures = /* @__PURE__ */ new Map();
    this.groups = /* @__PURE__ */ new Map();
    this.cache = /* @__PURE__ */ new Map();
    this.depthClamp = gl.getExtension("EXT_depth_clamp");
    this.timer = gl.getExtension("EXT_disjoint_timer_query_webgl2");
    this.query = null;
    this.gpuMs = null;
    this.present = this.link("present.glsl", sourcePair(present_default));
    this.copyDepth = this.link("copy_depth.glsl", sourcePair(copy_depth_default));
  }
  /** Take ``plan`` to draw (its programs compiled); throws `Unsupported` for one it cannot
   *  draw yet, or an Error (a shader that does not compile). */
  add(plan) {
    this.check(plan);
    this.program(plan.program);
    if (plan.multipass) {
      for (const role of Object.values(plan.multipass.programs)) this.program({ name: role[0], defines: role[1] });
      if (!this.groups.has(plan.geometry.key)) this.groups.set(plan.geometry.key, []);
      this.groups.get(plan.geometry.key).push(plan);
    }
  }
  check(plan) {
    if (plan.per_view && !this.hooks[plan.per_view.function]) throw new Unsupported(`${plan.name}: its view hook ${plan.per_view.function} is not supported by the viewer yet`);
    if (plan.multipass && !MULTIPASS[plan.multipass.kind]) throw new Unsupported(`${plan.name}: the multi-pass kind ${plan.multipass.kind} is not supported by the viewer yet`);
    const encoded = Object.values(plan.textures).find((t) => t.encoded || (t.levels || [t.array]).some((a) => a.encoding));
    if (encoded) throw new Unsupported(`${plan.name}: ${encoded.what} is block-compressed, which the viewer does not draw yet`);
    if (plan.raster.depth_clamp && !this.depthClamp) throw new Unsupported(`${plan.name}: needs depth clamping, which this browser lacks (EXT_depth_clamp)`);
  }
  program(program) {
    const key = programKey(program.name, program.defines);
    if (!this.programs.has(key)) {
      const sources = this.sources.get(key);
      if (!sources) throw new Error(`${this.name}: no embedded shader for ${key}`);
      this.programs.set(key, this.link(program.name, { vertex: sources.vertex, fragment: sources.fragment }));
    }
    return this.programs.get(key);
  }
  link(name, { vertex, fragment }) {
    const gl = this.gl;
    const prog = gl.createProgram();
    for (const [type, source, stage] of [[gl.VERTEX_SHADER, vertex, "vertex"], [gl.FRAGMENT_SHADER, fragment, "fragment"]]) {
      const shader = gl.createShader(type);
      gl.shaderSource(shader, source);
      gl.compileShader(shader);
      if (!gl.getShaderParameter(shader, gl.COMPILE_STATUS)) {
        throw new Error(`the ${stage} shader of ${name} does not compile in this browser: ${gl.getShaderInfoLog(shader).trim()}`);
      }
      gl.attachShader(prog, shader);
    }
    gl.linkProgram(prog);
    if (!gl.getProgramParameter(prog, gl.LINK_STATUS)) {
      throw new Error(`${name} does not link in this browser: ${gl.getProgramInfoLog(prog).trim()}`);
    }
    const uniforms = /* @__PURE__ */ new Map();
    for (let i = 0; i < gl.getProgramParameter(prog, gl.ACTIVE_UNIFORMS); i++) {
      const info = gl.getActiveUniform(prog, i);
      uniforms.set(info.name.replace(/\[0\]$/, ""), { location: gl.getUniformLocation(prog, info.name), type: info.type, size: info.size });
    }
    return { prog, uniforms, name };
  }
  /** The buffer of a geometry's attribute (or 'indices') holding ``array``: written when the
   *  array is not the one it holds (a view hook's new array; render/executor.py _write). */
  buffer(geometry, name, array, target) {
    const gl = this.gl;
    if (!this.buffers.has(geometry.key)) this.buffers.set(geometry.key, {});
    const made = this.buffers.get(geometry.key);
    if (!made[name]) made[name] = { buffer: gl.createBuffer(), source: null };
    const entry = made[name];
    if (entry.source !== array) {
      gl.bindBuffer(target, entry.buffer);
      gl.bufferData(target, array.dtype === "uint32" || target === gl.ARRAY_BUFFER ? array.data : new Uint32Array(array.data), gl.DYNAMIC_DRAW);
      entry.source = array;
    }
    return entry.buffer;
  }
  vertexArray(linked, geometry) {
    const gl = this.gl;
    const key = `${linked.name} ${geometry.key}`;
    if (!this.vaos.has(key)) {
      const vao = gl.createVertexArray();
      gl.bindVertexArray(vao);
      for (const [name, attr] of Object.entries(geometry.attributes)) {
        const loc = gl.getAttribLocation(linked.prog, name);
        if (loc < 0) continue;
        const { shape, dtype } = attr.array;
        const comps = shape.length === 2 ? shape[1] : 1;
        gl.bindBuffer(gl.ARRAY_BUFFER, this.buffer(geometry, name, attr.array, gl.ARRAY_BUFFER));
        gl.enableVertexAttribArray(loc);
        if (dtype === "int32") gl.vertexAttribIPointer(loc, comps, gl.INT, 0, 0);
        else if (dtype === "float32") gl.vertexAttribPointer(loc, comps, gl.FLOAT, false, 0, 0);
        else throw new Error(`${geometry.key}: vertex array ${name} is ${dtype}, not float32 or int32`);
        gl.vertexAttribDivisor(loc, attr.per_instance ? 1 : 0);
      }
      if (geometry.indices) gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, this.buffer(geometry, "indices", geometry.indices, gl.ELEMENT_ARRAY_BUFFER));
      gl.bindVertexArray(null);
      this.vaos.set(key, vao);
    }
    return this.vaos.get(key);
  }
  texture(t) {
    if (!this.textures.has(t)) this.textures.set(t, uploadTexture(this.gl, t));
    return this.textures.get(t);
  }
  /** Draw ``plans`` from ``camera`` into ``targets`` and present them on the canvas: the
   *  opaque pass, then the transparent plans front to back (gl/targets.py draw_passes). */
  frame(plans, camera, light, targets) {
    const gl = this.gl;
    const [w, h] = camera.size;
    const pass = (fbo) => () => {
      gl.bindFramebuffer(gl.FRAMEBUFFER, fbo);
      gl.viewport(0, 0, w, h);
    };
    const opaque = pass(targets.fbo);
    const transparent = pass(targets.transparentFbo);
    const timing = this.timer && !this.query;
    if (timing) {
      this.query = gl.createQuery();
      gl.beginQuery(this.timer.TIME_ELAPSED_EXT, this.query);
    }
    opaque();
    gl.depthMask(true);
    for (let i = 0; i < FRAME_ATTACHMENTS; i++) gl.clearBufferfv(gl.COLOR, i, [0, 0, 0, 0]);
    gl.clearBufferfv(gl.DEPTH, 0, [1]);
    for (const plan of plans.filter((p) => p.render_pass === "opaque")) this.draw(plan, camera, light, opaque);
    transparent();
    for (let i = 0; i < FRAME_ATTACHMENTS; i++) gl.clearBufferfv(gl.COLOR, i, [0, 0, 0, 0]);
    const front = { u_front_opacity: FRONT_OPACITY_UNIT };
    gl.activeTexture(gl.TEXTURE0 + FRONT_OPACITY_UNIT);
    gl.bindTexture(gl.TEXTURE_2D, targets.frontOpacity.tex);
    for (const plan of plans.filter((p) => p.render_pass === "transparent")) {
      this.draw(plan, camera, light, transparent, { uniforms: front, targets });
    }
    if (timing) gl.endQuery(this.timer.TIME_ELAPSED_EXT);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    gl.viewport(0, 0, w, h);
    this.setRaster({ depth_test: false, cull: "none", blend: "none", depth_write: false });
    gl.useProgram(this.present.prog);
    const samplers = this.bindTextures({ u_color: targets.color, u_position: targets.position, u_transparent: targets.transparent });
    for (const [name, value] of Object.entries(samplers)) setUniform(gl, this.present, name, value);
    gl.bindVertexArray(null);
    gl.drawArrays(gl.TRIANGLES, 0, 3);
  }
  /** The GPU time of the latest timed frame's draws in ms (null until one is known): a timer
   *  query's result becomes available only after the page has returned to the browser. */
  gpuTime() {
    const gl = this.gl;
    if (this.query && gl.getQueryParameter(this.query, gl.QUERY_RESULT_AVAILABLE)) {
      if (!gl.getParameter(this.timer.GPU_DISJOINT_EXT)) this.gpuMs = gl.getQueryParameter(this.query, gl.QUERY_RESULT) / 1e6;
      gl.deleteQuery(this.query);
      this.query = null;
    }
    return this.gpuMs;
  }
  /** Wait until the frame is drawn: a one-pixel read back (Chromium's gl.finish() returns
   *  before the GPU process has drawn). */
  finish() {
    const gl = this.gl;
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));
  }
  /** ``plan`` as seen from ``camera`` (its hook's update applied), its new arrays written into
   *  the geometry's buffers (render/executor.py Executor.view). */
  view(plan, camera, light) {
    if (!plan.per_view) return plan;
    const hook = this.hooks[plan.per_view.function];
    const viewed = withView(plan, hook(plan, camera, light, plan.per_view.data) || {});
    const gl = this.gl;
    for (const [name, attr] of Object.entries(viewed.geometry.attributes)) this.buffer(plan.geometry, name, attr.array, gl.ARRAY_BUFFER);
    if (viewed.geometry.indices) {
      gl.bindVertexArray(null);
      this.buffer(plan.geometry, "indices", viewed.geometry.indices, gl.ELEMENT_ARRAY_BUFFER);
    }
    return viewed;
  }
  /** Draw ``source`` from ``camera``: its view, then one draw or its multi-pass kind;
   *  ``extra`` (uniforms, the frame's targets) goes to both. */
  draw(source, camera, light, outer, extra = {}) {
    const plan = this.view(source, camera, light);
    if (plan.count === 0) return;
    if (plan.multipass) MULTIPASS[plan.multipass.kind](this, plan, camera, light, outer, extra);
    else this.drawViewed(plan, camera, light, extra);
  }
  /** A full-screen triangle drawn with ``linked`` and ``textures`` under ``raster`` (a pass
   *  of a multi-pass kind). */
  drawFullScreen(linked, textures, raster = { depth_test: false, cull: "none", blend: "none", depth_write: false }) {
    const gl = this.gl;
    this.setRaster(raster);
    gl.useProgram(linked.prog);
    for (const [name, value] of Object.entries(this.bindTextures(textures))) setUniform(gl, linked, name, value);
    gl.bindVertexArray(null);
    gl.drawArrays(gl.TRIANGLES, 0, 3);
  }
  /** One draw of a plan already seen from ``camera``; ``program`` (a [name, defines] role),
   *  ``raster``, ``uniforms`` and ``textures`` replace or add to the plan's. */
  drawViewed(plan, camera, light, { program, raster, uniforms = {}, textures = {} } = {}) {
    const gl = this.gl;
    const linked = this.program(program ? { name: program[0], defines: program[1] } : plan.program);
    const vao = this.vertexArray(linked, plan.geometry);
    gl.useProgram(linked.prog);
    const samplers = this.bindTextures({ ...plan.textures, ...textures });
    const values = { ...cameraUniforms(camera), ...modelOffset(camera, plan.origin), ...light.uniforms, ...plan.uniforms, ...uniforms, ...samplers };
    for (const [name, value] of Object.entries(values)) setUniform(gl, linked, name, value);
    this.setRaster(raster || plan.raster);
    gl.bindVertexArray(vao);
    const { mode, count, first, instances, indexed } = counts(gl, plan);
    if (indexed && instances != null) gl.drawElementsInstanced(mode, count, gl.UNSIGNED_INT, first * 4, instances);
    else if (indexed) gl.drawElements(mode, count, gl.UNSIGNED_INT, first * 4);
    else if (instances != null) gl.drawArraysInstanced(mode, first, count, instances);
    else gl.drawArrays(mode, first, count);
    gl.bindVertexArray(null);
  }
  /** Bind textures (sampler name -> plan texture or {tex, target}) to units 0, 1, ...;
   *  the sampler uniforms and each one's `<sampler>_decode` (1, 0: no encoding). */
  bindTextures(textures) {
    const gl = this.gl;
    const out = {};
    const units = /* @__PURE__ */ new Map();
    const uploaded = Object.entries(textures).map(([name, t]) => [name, t.tex ? t : this.texture(t)]);
    for (const [name, made] of uploaded) {
      if (!units.has(made)) {
        units.set(made, units.size);
        gl.activeTexture(gl.TEXTURE0 + units.get(made));
        gl.bindTexture(made.target, made.tex);
      }
      out[name] = units.get(made);
      out[`${name}_decode`] = [1, 0];
    }
    return out;
  }
  setRaster(r) {
    const gl = this.gl;
    (r.depth_test ? gl.enable : gl.disable).call(gl, gl.DEPTH_TEST);
    gl.depthFunc(r.depth_func === "<=" ? gl.LEQUAL : gl.LESS);
    gl.depthMask(!!r.depth_write);
    if (this.depthClamp) (r.depth_clamp ? gl.enable : gl.disable).call(gl, this.depthClamp.DEPTH_CLAMP_EXT);
    if (r.cull && r.cull !== "none") {
      gl.enable(gl.CULL_FACE);
      gl.cullFace(r.cull === "front" ? gl.FRONT : gl.BACK);
    } else gl.disable(gl.CULL_FACE);
    gl.frontFace(r.front_face === "cw" ? gl.CW : gl.CCW);
    if (r.blend && r.blend !== "none") {
      gl.enable(gl.BLEND);
      gl.blendFunc(gl[BLEND[r.blend][0]], gl[BLEND[r.blend][1]]);
    } else gl.disable(gl.BLEND);
  }
};
var MAX_TARGET_BYTES = 1 << 30;
function createTargets(gl, [w, h]) {
  const side = gl.getParameter(gl.MAX_TEXTURE_SIZE);
  const bytes = w * h * ((2 * FRAME_ATTACHMENTS + 2) * 16 + 4);
  if (w > side || h > side || bytes > MAX_TARGET_BYTES) {
    throw new Error(`a ${w}x${h} frame needs ${Math.ceil(bytes / 2 ** 20)} MiB of float render targets (limits: ${side} texels a side, ${MAX_TARGET_BYTES / 2 ** 20} MiB): ask for a smaller size`);
  }
  const make = (internal, format, type, attachment) => {
    const tex = gl.createTexture();
    gl.bindTexture(gl.TEXTURE_2D, tex);
    gl.texImage2D(gl.TEXTURE_2D, 0, internal, w, h, 0, format, type, null);
    for (const p of [gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER]) gl.texParameteri(gl.TEXTURE_2D, p, gl.NEAREST);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, attachment, gl.TEXTURE_2D, tex, 0);
    return { tex, target: gl.TEXTURE_2D };
  };
  const attachments = [...Array(FRAME_ATTACHMENTS).keys()].map((i) => gl.COLOR_ATTACHMENT0 + i);
  const framebuffer = (colors, depth2) => {
    const fbo2 = gl.createFramebuffer();
    gl.bindFramebuffer(gl.FRAMEBUFFER, fbo2);
    const made = colors.map((a) => make(gl.RGBA32F, gl.RGBA, gl.FLOAT, a));
    if (depth2) gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.DEPTH_ATTACHMENT, gl.TEXTURE_2D, depth2.tex, 0);
    gl.drawBuffers(colors);
    const status = gl.checkFramebufferStatus(gl.FRAMEBUFFER);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    if (status !== gl.FRAMEBUFFER_COMPLETE) throw new Error(`the ${w}x${h} float render targets are incomplete (status 0x${status.toString(16)})`);
    return [fbo2, made];
  };
  const depth = (() => {
    const tex = gl.createTexture();
    gl.bindTexture(gl.TEXTURE_2D, tex);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.DEPTH_COMPONENT32F, w, h, 0, gl.DEPTH_COMPONENT, gl.FLOAT, null);
    for (const p of [gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER]) gl.texParameteri(gl.TEXTURE_2D, p, gl.NEAREST);
    return { tex, target: gl.TEXTURE_2D };
  })();
  const [fbo, [color, position]] = framebuffer(attachments, depth);
  const [transparentFbo, [transparent]] = framebuffer(attachments, depth);
  const [depthCopyFbo, [depthCopy]] = framebuffer([gl.COLOR_ATTACHMENT0], null);
  const [frontFbo, [frontOpacity]] = framebuffer([gl.COLOR_ATTACHMENT0], null);
  gl.bindFramebuffer(gl.FRAMEBUFFER, frontFbo);
  gl.clearBufferfv(gl.COLOR, 0, [0, 0, 0, 0]);
  gl.bindFramebuffer(gl.FRAMEBUFFER, null);
  return { fbo, color, position, depth, transparentFbo, transparent, depthCopyFbo, depthCopy, frontOpacity, size: [w, h] };
}
function counts(gl, plan) {
  const g = plan.geometry;
  let count = plan.count;
  if (count == null) {
    if (g.indices) count = g.indices.data.length;
    else if (g.vertices != null) count = g.vertices;
    else count = Math.min(...Object.values(g.attributes).filter((a) => !a.per_instance).map((a) => a.array.shape[0]));
  }
  return { mode: gl[MODES[g.primitive]], count, first: plan.first || 0, instances: g.instances, indexed: !!g.indices };
}
function sourcePair(text) {
  const [version, ...rest] = text.split("\n");
  const body = rest.join("\n");
  return { vertex: `${version}
#define VERTEX_SHADER
${body}`, fragment: `${version}
#define FRAGMENT_SHADER
${body}` };
}
function flat(value) {
  if (value && value.data && value.shape) return Array.from(value.data, Number);
  if (Array.isArray(value)) return value.flatMap(flat);
  return [typeof value === "boolean" ? Number(value) : value];
}
function setUniform(gl, linked, name, value) {
  const u = linked.uniforms.get(name);
  if (!u) return;
  const T = gl;
  const rowMajor = !!(value && value.shape && value.shape.length === 2);
  if (Array.isArray(value) && u.size === 1 && Array.isArray(value[0]) && ![T.FLOAT_MAT3, T.FLOAT_MAT4].includes(u.type)) value = value[0];
  const v = flat(value);
  const n = {
    [T.FLOAT_MAT4]: 16,
    [T.FLOAT_MAT3]: 9,
    [T.FLOAT_VEC2]: 2,
    [T.FLOAT_VEC3]: 3,
    [T.FLOAT_VEC4]: 4,
    [T.INT_VEC2]: 2,
    [T.INT_VEC3]: 3,
    [T.INT_VEC4]: 4,
    [T.BOOL_VEC2]: 2,
    [T.BOOL_VEC3]: 3,
    [T.BOOL_VEC4]: 4
  }[u.type] || 1;
  const data = v.slice(0, n * u.size);
  switch (u.type) {
    case T.FLOAT:
      return gl.uniform1fv(u.location, data);
    case T.FLOAT_VEC2:
      return gl.uniform2fv(u.location, data);
    case T.FLOAT_VEC3:
      return gl.uniform3fv(u.location, data);
    case T.FLOAT_VEC4:
      return gl.uniform4fv(u.location, data);
    case T.FLOAT_MAT3:
      return gl.uniformMatrix3fv(u.location, rowMajor, data);
    case T.FLOAT_MAT4:
      return gl.uniformMatrix4fv(u.location, rowMajor, data);
    case T.UNSIGNED_INT:
      return gl.uniform1uiv(u.location, data);
    case T.INT_VEC2:
    case T.BOOL_VEC2:
      return gl.uniform2iv(u.location, data);
    case T.INT_VEC3:
    case T.BOOL_VEC3:
      return gl.uniform3iv(u.location, data);
    case T.INT_VEC4:
    case T.BOOL_VEC4:
      return gl.uniform4iv(u.location, data);
    default:
      return gl.uniform1iv(u.location, data);
  }
}

// web/src/glb.js
var MAGIC = 1179937895;
var JSON_CHUNK = 1313821514;
var BIN_CHUNK = 5130562;
var TYPED = {
  bool: Uint8Array,
  int8: Int8Array,
  uint8: Uint8Array,
  int16: Int16Array,
  uint16: Uint16Array,
  int32: Int32Array,
  uint32: Uint32Array,
  float16: Uint16Array,
  float32: Float32Array,
  float64: Float64Array,
  int64: BigInt64Array,
  uint64: BigUint64Array
};
function parseGlb(buffer, name) {
  const data = new DataView(buffer);
  if (buffer.byteLength < 20 || data.getUint32(0, true) !== MAGIC) {
    throw new Error(`${name} is not a GLB file`);
  }
  if (data.getUint32(4, true) !== 2 || data.getUint32(8, true) > buffer.byteLength) {
    throw new Error(`${name}: not a glTF 2.0 GLB, or truncated`);
  }
  let json = null;
  let bin = new ArrayBuffer(0);
  for (let at = 12; at + 8 <= buffer.byteLength; ) {
    const length = data.getUint32(at, true);
    const type = data.getUint32(at + 4, true);
    if (at + 8 + length > buffer.byteLength) throw new Error(`${name}: a chunk runs past the end`);
    const body = buffer.slice(at + 8, at + 8 + length);
    if (type === JSON_CHUNK) json = parseJson(body, name);
    else if (type === BIN_CHUNK) bin = body;
    at += 8 + length;
  }
  if (json === null) throw new Error(`${name}: no JSON chunk`);
  return { json, bin, name };
}
function parseJson(bytes, name) {
  try {
    return JSON.parse(new TextDecoder("utf-8", { fatal: true }).decode(bytes));
  } catch (e) {
    throw new Error(`${name}: its JSON chunk does not parse (${e.message})`);
  }
}
function drawOf(glb) {
  for (const node of glb.json.nodes || []) {
    for (const [ext, value] of Object.entries(node.extensions || {})) {
      if (!ext.startsWith("RELIEFKIT_")) continue;
      if (!value.draw) throw new Error(`${glb.name}: ${ext} holds no draw plans`);
      if (!Array.isArray(value.draw.programs)) {
        throw new Error(`${glb.name}: its draw plans carry no shaders (export with --embed-shaders)`);
      }
      return value.draw;
    }
  }
  throw new Error(`${glb.name}: no RELIEFKIT_ extension (not exported by reliefkit)`);
}
async function readArrays(gl, glb, draw) {
  const out = {};
  for (const [name, ref] of Object.entries(draw.arrays)) {
    const Typed = TYPED[ref.dtype];
    if (!Typed || !Array.isArray(ref.shape)) throw new Error(`${glb.name}: array ${name} has no known dtype`);
    const count = ref.shape.reduce((a, b) => a * b, 1);
    let data;
    if ("image" in ref) data = await pngValues(gl, glb, ref.image, ref.shape);
    else if ("bufferView" in ref) data = new Typed(viewBytes(glb, ref.bufferView, count * Typed.BYTES_PER_ELEMENT, name));
    else data = new Typed(count);
    out[name] = ref.encoding ? { dtype: ref.dtype, shape: ref.shape, data, encoding: ref.encoding } : { dtype: ref.dtype, shape: ref.shape, data };
  }
  return out;
}
function viewBytes(glb, index, length, name) {
  const view = (glb.json.bufferViews || [])[index];
  if (!view || view.byteLength !== length || (view.byteOffset || 0) + length > glb.bin.byteLength) {
    throw new Error(`${glb.name}: array ${name}'s bufferView does not hold it (truncated or forged)`);
  }
  const start = view.byteOffset || 0;
  return glb.bin.slice(start, start + length);
}
async function pngValues(gl, glb, index, shape) {
  const image = (glb.json.images || [])[index];
  if (!image) throw new Error(`${glb.name}: image ${index} is missing`);
  const view = (glb.json.bufferViews || [])[image.bufferView];
  if (!view || (view.byteOffset || 0) + view.byteLength > glb.bin.byteLength) {
    throw new Error(`${glb.name}: image ${index}'s bufferView lies outside the file (truncated or forged)`);
  }
  const bytes = glb.bin.slice(view.byteOffset || 0, (view.byteOffset || 0) + view.byteLength);
  let bitmap;
  try {
    bitmap = await createImageBitmap(
      new Blob([bytes], { type: "image/png" }),
      { premultiplyAlpha: "none", colorSpaceConversion: "none" }
    );
  } catch {
    throw new Error(`${glb.name}: image ${index} is not a PNG this browser decodes`);
  }
  const rows = shape.length === 2 ? shape[0] : shape.slice(0, -2).reduce((a, b) => a * b, 1);
  const width = shape.length === 2 ? shape[1] : shape[shape.length - 2];
  if (bitmap.width !== width || bitmap.height !== rows) {
    bitmap.close();
    throw new Error(`${glb.name}: image ${index} is ${bitmap.width}x${bitmap.height}, its array needs ${width}x${rows}`);
  }
  const rgba = readBitmap(gl, bitmap);
  const channels = shape.length === 2 ? 1 : shape[shape.length - 1];
  if (channels === 4) return rgba;
  const pick = { 1: [0], 2: [0, 3], 3: [0, 1, 2] }[channels];
  const out = new Uint8Array(rgba.length / 4 * channels);
  for (let p = 0, q = 0; p < rgba.length; p += 4) for (const c of pick) out[q++] = rgba[p + c];
  return out;
}
function readBitmap(gl, bitmap) {
  const tex = gl.createTexture();
  const fbo = gl.createFramebuffer();
  try {
    gl.bindTexture(gl.TEXTURE_2D, tex);
    gl.pixelStorei(gl.UNPACK_FLIP_Y_WEBGL, false);
    gl.pixelStorei(gl.UNPACK_PREMULTIPLY_ALPHA_WEBGL, false);
    gl.pixelStorei(gl.UNPACK_COLORSPACE_CONVERSION_WEBGL, gl.NONE);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, gl.RGBA, gl.UNSIGNED_BYTE, bitmap);
    gl.bindFramebuffer(gl.FRAMEBUFFER, fbo);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, tex, 0);
    const out = new Uint8Array(bitmap.width * bitmap.height * 4);
    gl.readPixels(0, 0, bitmap.width, bitmap.height, gl.RGBA, gl.UNSIGNED_BYTE, out);
    return out;
  } finally {
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    gl.deleteFramebuffer(fbo);
    gl.deleteTexture(tex);
    bitmap.close();
  }
}

// web/src/main.js
var state = window.reliefkit = { ready: false, errors: [], frames: 0 };
var HOOKS = {};
function report(message) {
  state.errors.push(message);
  const box = document.getElementById("messages");
  const line = document.createElement("p");
  line.className = "error";
  line.textContent = message;
  box.appendChild(line);
  fetch("log", { method: "POST", body: message }).catch(() => {
  });
}
window.addEventListener("error", (e) => report(`error: ${e.message}`));
window.addEventListener("unhandledrejection", (e) => report(`error: ${e.reason && e.reason.message ? e.reason.message : e.reason}`));
async function fetchOk(url) {
  const response = await fetch(url);
  if (!response.ok) throw new Error(`cannot load ${url} (${response.status} ${response.statusText})`);
  return response;
}
async function openInput(input, size) {
  const panel = document.createElement("figure");
  const canvas = document.createElement("canvas");
  [canvas.width, canvas.height] = size;
  canvas.style.width = `${size[0]}px`;
  canvas.style.height = `${size[1]}px`;
  const caption = document.createElement("figcaption");
  caption.textContent = `${input.name} (${input.kind})`;
  panel.append(canvas, caption);
  document.getElementById("panels").appendChild(panel);
  try {
    const gl = createContext(canvas);
    canvas.addEventListener("webglcontextlost", () => report(`${input.name}: the browser lost the WebGL context (reload the page)`));
    const glb = parseGlb(await (await fetchOk(input.file)).arrayBuffer(), input.name);
    const draw = drawOf(glb);
    const plans = decodePlans(draw, await readArrays(gl, glb, draw));
    const executor = new Executor(gl, draw, input.name, HOOKS);
    const drawn = [];
    for (const plan of plans) {
      try {
        executor.add(plan);
        drawn.push(plan);
      } catch (e) {
        if (!(e instanceof Unsupported)) throw e;
        report(`${input.name}: ${e.message}`);
      }
    }
    return { canvas, executor, plans: drawn, targets: createTargets(gl, size) };
  } catch (e) {
    report(`${input.name}: ${e.message}`);
    return null;
  }
}
function union(boxes) {
  return [0, 1].map((k) => [0, 1, 2].map((i) => (k ? Math.max : Math.min)(...boxes.map((b) => b[k][i]))));
}
async function main() {
  const params = new URLSearchParams(location.search);
  const manifest = await (await fetchOk("inputs.json")).json();
  const frame = manifest.camera;
  let [az, el, dist] = parseView(params.get("view") || frame.default_view);
  const size = parseSize(params.get("size") || frame.default_size);
  const [lightAz, lightEl] = parseView(params.get("light") || manifest.light.angles);
  const light = lightFrom(manifest.light, lightAz, lightEl);
  const bounds = union(manifest.inputs.map((i) => i.bounds));
  const panels = (await Promise.all(manifest.inputs.map((i) => openInput(i, size)))).filter(Boolean);
  const readout = document.getElementById("stats");
  const render = () => {
    const start = performance.now();
    const camera = orbitBounds(bounds, az, el, dist, size, frame);
    dist = camera.distance;
    for (const p of panels) p.executor.frame(p.plans, camera, light, p.targets);
    for (const p of panels) p.executor.finish();
    state.frameMs = performance.now() - start;
    const shown = () => {
      const gpu = panels.map((p) => p.executor.gpuTime());
      state.gpuMs = gpu.every((t) => t !== null) ? gpu.reduce((a, b) => a + b, 0) : null;
      readout.textContent = `view ${az.toFixed(1)},${el.toFixed(1)},${dist.toFixed(3)}  ${size[0]}x${size[1]}  frame ${state.frameMs.toFixed(1)} ms` + (state.gpuMs === null ? "" : `, GPU ${state.gpuMs.toFixed(2)} ms`);
    };
    shown();
    setTimeout(shown, 50);
    state.view = [az, el, dist];
    params.set("view", `${+az.toFixed(3)},${+el.toFixed(3)},${+dist.toFixed(4)}`);
    history.replaceState(null, "", `?${params}`);
    state.frames += 1;
    state.ready = true;
  };
  let pending = false;
  const redraw = () => {
    if (!pending) {
      pending = true;
      requestAnimationFrame(() => {
        pending = false;
        render();
      });
    }
  };
  for (const p of panels) {
    p.canvas.addEventListener("pointerdown", (e) => p.canvas.setPointerCapture(e.pointerId));
    p.canvas.addEventListener("pointermove", (e) => {
      if (!p.canvas.hasPointerCapture(e.pointerId)) return;
      az -= e.movementX * 0.4;
      el = Math.max(-89, Math.min(89, el + e.movementY * 0.4));
      redraw();
    });
    p.canvas.tabIndex = 0;
    p.canvas.addEventListener("keydown", (e) => {
      const step = {
        ArrowLeft: [5, 0, 1],
        ArrowRight: [-5, 0, 1],
        ArrowUp: [0, 5, 1],
        ArrowDown: [0, -5, 1],
        "+": [0, 0, 1 / 1.1],
        "=": [0, 0, 1 / 1.1],
        "-": [0, 0, 1.1]
      }[e.key];
      if (!step) return;
      e.preventDefault();
      az += step[0];
      el = Math.max(-89, Math.min(89, el + step[1]));
      dist = Math.max(0.01, Math.min(1e4, dist * step[2]));
      redraw();
    });
    p.canvas.addEventListener("wheel", (e) => {
      e.preventDefault();
      dist = Math.max(0.01, Math.min(1e4, dist * Math.exp(e.deltaY * 1e-3)));
      redraw();
    }, { passive: false });
  }
  render();
}
main().catch((e) => report(`error: ${e.message}`)).finally(() => {
  state.loaded = true;
});
