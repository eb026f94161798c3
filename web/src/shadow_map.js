// The "shadow-map" multi-pass kind (render/multipass/shadow_map.py): a depth map of every plan
// that shares the plan's geometry (all the materials of a mesh cast), drawn from the light's
// orthographic camera with each plan's ``caster`` program, again when the light moves; then the
// plan is drawn with the map and the uniforms of shaders/include/shadow_map.glsl.

import { lightCamera, matrix, multiply, translation } from './camera.js';
import { releaseAll } from './gl_objects.js';

/** Draw ``plan`` shadow-mapped; ``outer`` rebinds the frame's target after the depth pass. */
export function drawShadowMapped(executor, plan, camera, light, outer, extra = {}) {
  const [uniforms, textures] = shadowInputs(executor, plan, light, outer);
  executor.drawViewed(plan, camera, light, { uniforms: { ...extra.uniforms, ...uniforms }, textures });
}

/** The uniforms and the texture (``u_shadow_map``) of ``light``'s shadow map for ``plan``'s
 *  group, drawn on first use with ``params`` (the Python module's; other kinds pass theirs). */
export function shadowInputs(executor, plan, light, outer, params = plan.multipass.params) {
  const key = `shadow-map ${plan.geometry.key}`;
  const direction = light.direction.join(',');
  const made = executor.cache.get(key);
  if (made && made.direction !== direction) { // the light moved (the page's sliders): drawn again
    releaseAll(executor.gl, made);
    executor.cache.delete(key);
  }
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
    const raster = { depth_test: true, depth_write: true, cull: params.cull || 'none', blend: 'none' };
    for (const caster of executor.groups.get(plan.geometry.key) || [plan]) {
      const viewed = params.caster_hooks === false ? caster : executor.view(caster, cam, light);
      executor.drawViewed(viewed, cam, light, { program: caster.multipass.programs.caster, raster });
    }
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    gl.deleteFramebuffer(fbo);
    outer();
    gl.bindTexture(gl.TEXTURE_2D, depth);
    const compare = (params.sampler || 'compare') === 'compare';
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_COMPARE_MODE, compare ? gl.COMPARE_REF_TO_TEXTURE : gl.NONE);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_COMPARE_FUNC, gl.LEQUAL);
    for (const p of [gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER]) gl.texParameteri(gl.TEXTURE_2D, p, compare ? gl.LINEAR : gl.NEAREST);
    for (const p of [gl.TEXTURE_WRAP_S, gl.TEXTURE_WRAP_T]) gl.texParameteri(gl.TEXTURE_2D, p, gl.CLAMP_TO_EDGE);
    const texel = (2 * cam.ortho_height) / size;
    const uniforms = {
      u_light_matrix: matrix(multiply(multiply(cam.proj, cam.view), translation(plan.origin || [0, 0, 0]))),
      u_shadow_texel: texel,
      u_shadow_bias: 'bias' in params ? Number(params.bias) : texel / (cam.far - cam.near),
    };
    executor.cache.set(key, { direction, inputs: [uniforms, { u_shadow_map: { tex: depth, target: gl.TEXTURE_2D } }] });
  }
  return executor.cache.get(key).inputs;
}

/** A (2, 3) box given as a plan's array or as nested lists. */
function nested(box) {
  if (box && box.data) return [Array.from(box.data.slice(0, 3), Number), Array.from(box.data.slice(3, 6), Number)];
  return box;
}
