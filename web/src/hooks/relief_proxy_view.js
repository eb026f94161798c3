// relief/render.py:proxy_view: the proxy's faces to cull and the box matrices relative to
// the camera.

import { boxUniforms, cullFace } from "./view.js";

export function proxyView(plan, camera, light, { box_to_world: boxToWorld }) {
  return {
    uniforms: boxUniforms(camera, boxToWorld),
    cull: cullFace(plan.geometry.attributes.in_position.array, plan.origin, camera),
  };
}
