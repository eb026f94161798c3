// The "opaque-depth" kind (render/multipass/opaque_depth.py): a transparent plan drawn once,
// sampling a copy of the opaque depth (``u_opaque_depth``; ``u_clip_opaque``: whether any
// opaque surface was drawn), lit by the light's shadow map when its params ask for one.
// `opaqueDepthInputs` gives the same to the kinds that draw such plans in several passes.

import { shadowInputs } from './shadow_map.js';

export function drawWithOpaqueDepth(executor, plan, camera, light, outer, extra) {
  const [uniforms, textures] = opaqueDepthInputs(executor, plan, light, outer, extra.targets);
  executor.drawViewed(plan, camera, light, { uniforms: { ...extra.uniforms, ...uniforms }, textures });
}

/** The uniforms and textures above; the frame's transparent target bound again (``outer``). */
export function opaqueDepthInputs(executor, plan, light, outer, targets) {
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
