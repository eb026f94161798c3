// slicing/render.py:ray_cast_view: the box's uniforms and the proxy's faces to cull.

import { boxUniforms, cullFace } from "./view.js";

export function rayCastView(plan, camera, light, { cube_to_world: cubeToWorld, texturing }) {
  return {
    uniforms: boxUniforms(camera, cubeToWorld),
    cull: cullFace(plan.geometry.attributes.in_position.array, plan.origin, camera),
    stats: { slicing: "raycast", slices: 0, passes: "single", texturing },
  };
}
