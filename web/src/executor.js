// The page's executor: render/executor.py in WebGL2. Each plan's program (the GLSL ES sources
// the export embedded), geometry and textures are made once; a frame draws the opaque plans
// into the AOV targets that gl/targets.py makes (colour, position + coverage, normal; a float
// depth texture) with the uniforms the Python executor sets, then presents the picture
// `reliefkit render` writes (shaders/viewer/present.glsl, served in inputs.json).

import { cameraUniforms, modelOffset } from './camera.js';
import { programKey, withView } from './plans.js';
import { drawDepthPeeled } from './depth_peel.js';
import { drawWithOpaqueDepth } from './opaque_depth.js';
import { drawShadowMapped } from './shadow_map.js';
import { releaseAll } from './gl_objects.js';
import { drawStencilCounted } from './stencil_count.js';
import { uploadTexture } from './textures.js';

const FRAME_ATTACHMENTS = 3;
const MODES = { triangles: 'TRIANGLES', points: 'POINTS', lines: 'LINES', triangle_strip: 'TRIANGLE_STRIP' };
const BLEND = { under: ['ONE_MINUS_DST_ALPHA', 'ONE'], add: ['ONE', 'ONE'] };

/** Multi-pass kinds (render/executor.py MULTIPASS): ``kind(executor, viewed plan, camera,
 *  light, outer)``, where ``outer()`` binds the frame's target again after a pass of its own. */
const MULTIPASS = {
  'shadow-map': drawShadowMapped,
  'opaque-depth': drawWithOpaqueDepth,
  // its extra passes only place the position and normal AOVs at the half-opacity point,
  // which the page does not show: its colour and coverage are the opaque-depth kind's
  'half-opacity-search': drawWithOpaqueDepth,
  'depth-peel': drawDepthPeeled,
  'stencil-count': drawStencilCounted,
};
const FRONT_OPACITY_UNIT = 15; // gl/targets.py: drawables use the low units

/** A plan this executor cannot draw yet, named in a user's words. */
export class Unsupported extends Error {}

export function createContext(canvas) {
  const gl = canvas.getContext('webgl2', { alpha: true, premultipliedAlpha: false, antialias: false, preserveDrawingBuffer: true });
  if (!gl) throw new Error('this browser has no WebGL2: the viewer needs it');
  if (!gl.getExtension('EXT_color_buffer_float')) throw new Error('this browser cannot render to float textures (EXT_color_buffer_float)');
  gl.getExtension('OES_texture_float_linear');
  return gl;
}

export class Executor {
  /** ``hooks``: the view hooks' ports by the Python function's "module:name" (web/src/hooks/);
   *  ``programs``: the page's own programs (inputs.json: present, copy_depth). */
  constructor(gl, draw, name, hooks, programs) {
    this.gl = gl;
    this.name = name;
    this.hooks = hooks;
    this.sources = new Map(draw.programs.map((p) => [programKey(p.program, p.defines), p]));
    this.programs = new Map();
    this.buffers = new Map(); // geometry key -> {attribute name or 'indices': {buffer, source}}
    this.vaos = new Map();
    this.textures = new Map();
    this.groups = new Map(); // geometry key -> its multi-pass plans (a shadow map's casters)
    this.cache = new Map();  // a multi-pass kind's per-light products
    this.depthClamp = gl.getExtension('EXT_depth_clamp');
    this.timer = gl.getExtension('EXT_disjoint_timer_query_webgl2'); // GPU time, where the browser has it
    this.query = null;
    this.gpuMs = null;
    // what explains a frame's cost, whatever the device (reliefkit bench viewer): the plans
    // taken, the texture bytes uploaded (as given: no built mipmaps), the last frame's draw
    // calls and vertices (instances included: a slice stack's many quads)
    this.counts = { plans: 0, textureBytes: 0, drawCalls: 0, vertices: 0 };
    // the page's own programs, built by reliefkit's shader loader (inputs.json `programs`)
    this.present = this.link(programs.present.name, programs.present);
    this.copyDepth = this.link(programs.copy_depth.name, programs.copy_depth);
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
    this.counts.plans += 1;
  }

  check(plan) {
    if (plan.per_view && !this.hooks[plan.per_view.function]) throw new Unsupported(`${plan.name}: its view hook ${plan.per_view.function} is not supported by the viewer yet`);
    if (plan.multipass && !MULTIPASS[plan.multipass.kind]) throw new Unsupported(`${plan.name}: the multi-pass kind ${plan.multipass.kind} is not supported by the viewer yet`);
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
    for (const [type, source, stage] of [[gl.VERTEX_SHADER, vertex, 'vertex'], [gl.FRAGMENT_SHADER, fragment, 'fragment']]) {
      const shader = gl.createShader(type);
      gl.shaderSource(shader, source);
      gl.compileShader(shader);
      if (!gl.getShaderParameter(shader, gl.COMPILE_STATUS)) {
        throw new Error(`the ${stage} shader of ${name} does not compile in this browser: ${gl.getShaderInfoLog(shader).trim()}`);
      }
      gl.attachShader(prog, shader);
    }
    gl.linkProgram(prog);
    for (const shader of gl.getAttachedShaders(prog)) gl.deleteShader(shader); // freed with the program
    if (!gl.getProgramParameter(prog, gl.LINK_STATUS)) {
      throw new Error(`${name} does not link in this browser: ${gl.getProgramInfoLog(prog).trim()}`);
    }
    const uniforms = new Map();
    for (let i = 0; i < gl.getProgramParameter(prog, gl.ACTIVE_UNIFORMS); i++) {
      const info = gl.getActiveUniform(prog, i);
      uniforms.set(info.name.replace(/\[0\]$/, ''), { location: gl.getUniformLocation(prog, info.name), type: info.type, size: info.size });
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
      gl.bufferData(target, array.dtype === 'uint32' || target === gl.ARRAY_BUFFER ? array.data : new Uint32Array(array.data), gl.DYNAMIC_DRAW);
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
        if (dtype === 'int32') gl.vertexAttribIPointer(loc, comps, gl.INT, 0, 0);
        else if (dtype === 'float32') gl.vertexAttribPointer(loc, comps, gl.FLOAT, false, 0, 0);
        else throw new Error(`${geometry.key}: vertex array ${name} is ${dtype}, not float32 or int32`);
        gl.vertexAttribDivisor(loc, attr.per_instance ? 1 : 0);
      }
      if (geometry.indices) gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, this.buffer(geometry, 'indices', geometry.indices, gl.ELEMENT_ARRAY_BUFFER));
      gl.bindVertexArray(null);
      this.vaos.set(key, vao);
    }
    return this.vaos.get(key);
  }

  texture(t) {
    if (!this.textures.has(t)) {
      const made = uploadTexture(this.gl, t);
      this.counts.textureBytes += made.bytes;
      this.textures.set(t, made);
    }
    return this.textures.get(t);
  }

  /** Draw ``plans`` from ``camera`` into ``targets`` and present them on the canvas: the
   *  opaque pass, then the transparent plans front to back (gl/targets.py draw_passes).
   *  ``presenting(targets)``, called once they are drawn, gives present.glsl's further
   *  uniforms and textures (a debug view's: web/src/debug_views.js). */
  frame(plans, camera, light, targets, presenting = () => ({})) {
    const gl = this.gl;
    const [w, h] = camera.size;
    const pass = (fbo) => () => {
      gl.bindFramebuffer(gl.FRAMEBUFFER, fbo);
      gl.viewport(0, 0, w, h);
    };
    const opaque = pass(targets.fbo);
    const transparent = pass(targets.transparentFbo);
    Object.assign(this.counts, { drawCalls: 1, vertices: 3 }); // the picture's presentation, below
    const timing = this.timer && !this.query;
    if (timing) {
      this.gpuMs = null; // this frame's, once known: never an older frame's
      this.query = gl.createQuery();
      gl.beginQuery(this.timer.TIME_ELAPSED_EXT, this.query);
    }
    opaque();
    gl.depthMask(true);
    for (let i = 0; i < targets.attachments; i++) gl.clearBufferfv(gl.COLOR, i, [0, 0, 0, 0]);
    gl.clearBufferfv(gl.DEPTH, 0, [1]);
    for (const plan of plans.filter((p) => p.render_pass === 'opaque')) this.draw(plan, camera, light, opaque);
    transparent();
    for (let i = 0; i < FRAME_ATTACHMENTS; i++) gl.clearBufferfv(gl.COLOR, i, [0, 0, 0, 0]);
    // one drawable per canvas: nothing is in front of it (u_front_opacity stays zero)
    const front = { u_front_opacity: FRONT_OPACITY_UNIT };
    gl.activeTexture(gl.TEXTURE0 + FRONT_OPACITY_UNIT);
    gl.bindTexture(gl.TEXTURE_2D, targets.frontOpacity.tex);
    for (const plan of plans.filter((p) => p.render_pass === 'transparent')) {
      this.draw(plan, camera, light, transparent, { uniforms: front, targets });
    }
    if (timing) gl.endQuery(this.timer.TIME_ELAPSED_EXT);
    const { uniforms = {}, textures = {} } = presenting(targets);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    gl.viewport(0, 0, w, h);
    this.setRaster({ depth_test: false, cull: 'none', blend: 'none', depth_write: false });
    gl.useProgram(this.present.prog);
    const samplers = this.bindTextures({ u_color: targets.color, u_position: targets.position, u_transparent: targets.transparent, ...textures });
    for (const [name, value] of Object.entries({ u_debug: 0, ...uniforms, ...samplers })) setUniform(gl, this.present, name, value);
    gl.bindVertexArray(null);
    gl.drawArrays(gl.TRIANGLES, 0, 3);
  }

  /** Free every GL object this executor made (programs, buffers, vertex arrays, textures,
   *  a multi-pass kind's targets): its plans are replaced (the page's option controls). */
  dispose() {
    const gl = this.gl;
    for (const { prog } of [...this.programs.values(), this.present, this.copyDepth]) gl.deleteProgram(prog);
    for (const made of this.buffers.values()) for (const { buffer } of Object.values(made)) gl.deleteBuffer(buffer);
    for (const vao of this.vaos.values()) gl.deleteVertexArray(vao);
    for (const { tex } of this.textures.values()) gl.deleteTexture(tex);
    for (const entry of this.cache.values()) releaseAll(gl, entry);
    if (this.query) gl.deleteQuery(this.query);
    for (const map of [this.programs, this.buffers, this.vaos, this.textures, this.cache, this.groups]) map.clear();
    this.query = null;
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
      gl.bindVertexArray(null); // an element buffer binds to the bound vertex array
      this.buffer(plan.geometry, 'indices', viewed.geometry.indices, gl.ELEMENT_ARRAY_BUFFER);
    }
    return viewed;
  }

  /** Draw ``source`` from ``camera``: its view, then one draw or its multi-pass kind;
   *  ``extra`` (uniforms, the frame's targets) goes to both. */
  draw(source, camera, light, outer, extra = {}) {
    const plan = this.view(source, camera, light);
    if (plan.count === 0) return; // switched off from this view
    if (plan.multipass) MULTIPASS[plan.multipass.kind](this, plan, camera, light, outer, extra);
    else this.drawViewed(plan, camera, light, extra);
  }

  /** A full-screen triangle drawn with ``linked`` and ``textures`` under ``raster`` (a pass
   *  of a multi-pass kind). */
  drawFullScreen(linked, textures, raster = { depth_test: false, cull: 'none', blend: 'none', depth_write: false }) {
    const gl = this.gl;
    this.setRaster(raster);
    gl.useProgram(linked.prog);
    for (const [name, value] of Object.entries(this.bindTextures(textures))) setUniform(gl, linked, name, value);
    gl.bindVertexArray(null);
    gl.drawArrays(gl.TRIANGLES, 0, 3);
    this.counts.drawCalls += 1;
    this.counts.vertices += 3;
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
    this.counts.drawCalls += 1;
    this.counts.vertices += count * (instances ?? 1);
    gl.bindVertexArray(null);
  }

  /** Bind textures (sampler name -> plan texture or {tex, target}) to units 0, 1, ...;
   *  the sampler uniforms and each one's `<sampler>_decode` (1, 0: no encoding). */
  bindTextures(textures) {
    const gl = this.gl;
    const out = {};
    const units = new Map();
    // uploaded first: an upload binds its texture to the active unit
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
    gl.depthFunc(r.depth_func === '<=' ? gl.LEQUAL : gl.LESS);
    gl.depthMask(!!r.depth_write);
    if (this.depthClamp) (r.depth_clamp ? gl.enable : gl.disable).call(gl, this.depthClamp.DEPTH_CLAMP_EXT);
    if (r.cull && r.cull !== 'none') {
      gl.enable(gl.CULL_FACE);
      gl.cullFace(r.cull === 'front' ? gl.FRONT : gl.BACK);
    } else gl.disable(gl.CULL_FACE);
    gl.frontFace(r.front_face === 'cw' ? gl.CW : gl.CCW);
    if (r.blend && r.blend !== 'none') {
      gl.enable(gl.BLEND);
      gl.blendFunc(gl[BLEND[r.blend][0]], gl[BLEND[r.blend][1]]);
    } else gl.disable(gl.BLEND);
  }
}

const MAX_TARGET_BYTES = 1 << 30; // the float AOV targets of one canvas

/** The AOV targets of a WxH frame (gl/targets.py render_target), sizes checked first;
 *  ``extra`` more RGBA32F attachments in the opaque pass (1: the iteration counts of the
 *  instrumented plans, `iterations`). */
export function createTargets(gl, [w, h], extra = 0) {
  const side = gl.getParameter(gl.MAX_TEXTURE_SIZE);
  // RGBA32F: both passes' attachments, the depth copy and the front opacity; float depth
  const bytes = w * h * ((2 * FRAME_ATTACHMENTS + extra + 2) * 16 + 4);
  if (w > side || h > side || bytes > MAX_TARGET_BYTES) {
    throw new Error(`a ${w}x${h} frame needs ${Math.ceil(bytes / 2 ** 20)} MiB of float render targets `
      + `(limits: ${side} texels a side, ${MAX_TARGET_BYTES / 2 ** 20} MiB): ask for a smaller size`);
  }
  const make = (internal, format, type, attachment) => {
    const tex = gl.createTexture();
    gl.bindTexture(gl.TEXTURE_2D, tex);
    gl.texImage2D(gl.TEXTURE_2D, 0, internal, w, h, 0, format, type, null);
    for (const p of [gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER]) gl.texParameteri(gl.TEXTURE_2D, p, gl.NEAREST);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, attachment, gl.TEXTURE_2D, tex, 0);
    return { tex, target: gl.TEXTURE_2D };
  };
  const attachments = (n) => [...Array(n).keys()].map((i) => gl.COLOR_ATTACHMENT0 + i);
  const framebuffer = (colors, depth) => {
    const fbo = gl.createFramebuffer();
    gl.bindFramebuffer(gl.FRAMEBUFFER, fbo);
    const made = colors.map((a) => make(gl.RGBA32F, gl.RGBA, gl.FLOAT, a));
    if (depth) gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.DEPTH_ATTACHMENT, gl.TEXTURE_2D, depth.tex, 0);
    gl.drawBuffers(colors);
    const status = gl.checkFramebufferStatus(gl.FRAMEBUFFER);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    if (status !== gl.FRAMEBUFFER_COMPLETE) throw new Error(`the ${w}x${h} float render targets are incomplete (status 0x${status.toString(16)})`);
    return [fbo, made];
  };
  const depth = (() => {
    const tex = gl.createTexture();
    gl.bindTexture(gl.TEXTURE_2D, tex);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.DEPTH_COMPONENT32F, w, h, 0, gl.DEPTH_COMPONENT, gl.FLOAT, null);
    for (const p of [gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER]) gl.texParameteri(gl.TEXTURE_2D, p, gl.NEAREST);
    return { tex, target: gl.TEXTURE_2D };
  })();
  const [fbo, [color, position, normal, iterations]] = framebuffer(attachments(FRAME_ATTACHMENTS + extra), depth);
  // the transparent pass shares the opaque depth (tested, never written)
  const [transparentFbo, [transparent]] = framebuffer(attachments(FRAME_ATTACHMENTS), depth);
  const [depthCopyFbo, [depthCopy]] = framebuffer([gl.COLOR_ATTACHMENT0], null);
  const [frontFbo, [frontOpacity]] = framebuffer([gl.COLOR_ATTACHMENT0], null);
  gl.bindFramebuffer(gl.FRAMEBUFFER, frontFbo);
  gl.clearBufferfv(gl.COLOR, 0, [0, 0, 0, 0]);
  gl.bindFramebuffer(gl.FRAMEBUFFER, null);
  return { fbo, color, position, normal, iterations, depth, transparentFbo, transparent, depthCopyFbo, depthCopy, frontFbo, frontOpacity, size: [w, h], attachments: FRAME_ATTACHMENTS + extra };
}

/** render/executor.py _counts. */
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

function flat(value) {
  if (value && value.data && value.shape) return Array.from(value.data, Number);
  if (Array.isArray(value)) return value.flatMap(flat);
  return [typeof value === 'boolean' ? Number(value) : value];
}

/** gl/uniforms.py set_uniforms: unused names skipped, lists cut to the array's length; a
 *  matrix given as an (n, n) array is row-major (numpy's), as a flat tuple column-major
 *  (what moderngl hands GL as it is). */
function setUniform(gl, linked, name, value) {
  const u = linked.uniforms.get(name);
  if (!u) return;
  const T = gl;
  const rowMajor = !!(value && value.shape && value.shape.length === 2);
  if (Array.isArray(value) && u.size === 1 && Array.isArray(value[0]) && ![T.FLOAT_MAT3, T.FLOAT_MAT4].includes(u.type)) value = value[0];
  const v = flat(value);
  const n = { [T.FLOAT_MAT4]: 16, [T.FLOAT_MAT3]: 9, [T.FLOAT_VEC2]: 2, [T.FLOAT_VEC3]: 3, [T.FLOAT_VEC4]: 4,
    [T.INT_VEC2]: 2, [T.INT_VEC3]: 3, [T.INT_VEC4]: 4, [T.BOOL_VEC2]: 2, [T.BOOL_VEC3]: 3, [T.BOOL_VEC4]: 4 }[u.type] || 1;
  const data = v.slice(0, n * u.size);
  switch (u.type) {
    case T.FLOAT: return gl.uniform1fv(u.location, data);
    case T.FLOAT_VEC2: return gl.uniform2fv(u.location, data);
    case T.FLOAT_VEC3: return gl.uniform3fv(u.location, data);
    case T.FLOAT_VEC4: return gl.uniform4fv(u.location, data);
    case T.FLOAT_MAT3: return gl.uniformMatrix3fv(u.location, rowMajor, data);
    case T.FLOAT_MAT4: return gl.uniformMatrix4fv(u.location, rowMajor, data);
    case T.UNSIGNED_INT: return gl.uniform1uiv(u.location, data);
    case T.INT_VEC2: case T.BOOL_VEC2: return gl.uniform2iv(u.location, data);
    case T.INT_VEC3: case T.BOOL_VEC3: return gl.uniform3iv(u.location, data);
    case T.INT_VEC4: case T.BOOL_VEC4: return gl.uniform4iv(u.location, data);
    default: return gl.uniform1iv(u.location, data); // int, bool, samplers
  }
}
