// What several hooks compute from the camera: the proxy's faces to cull and a box's
// matrices in the camera's relative world space (render/proxy.py, gl/uniforms.py).

import { at } from "./ndarray.js";
import { invertBox, mat4, multiply, translation } from "./linalg.js";

/** A 4x4 row-major float64 matrix as a hook returns one: {dtype, shape, data}. */
export function matrixArray(m) {
  return { dtype: "float64", shape: [4, 4], data: Float64Array.from(m) };
}

/** `u_box_to_world` and `u_world_to_box` relative to `camera.origin` (`box_uniforms`). */
export function boxUniforms(camera, boxToWorld) {
  const origin = camera.origin;
  const relative = multiply(translation([-origin[0], -origin[1], -origin[2]]), mat4(boxToWorld));
  return { u_box_to_world: matrixArray(relative), u_world_to_box: matrixArray(invertBox(relative)) };
}

/** "front" when the proxy (vertices `positions` relative to `origin`) reaches in front of
 * the near plane, else "back" (`render.proxy.cull_face`). */
export function cullFace(positions, origin, camera) {
  const v = camera.view;
  let most = -Infinity;
  for (let i = 0; i < positions.data.length; i += 3) {
    const x = at(positions, i) + origin[0];
    const y = at(positions, i + 1) + origin[1];
    const z = at(positions, i + 2) + origin[2];
    most = Math.max(most, v[8] * x + v[9] * y + v[10] * z + v[11]);
  }
  return most > -camera.near * 1.001 ? "front" : "back";
}

/** Whether the camera is orthographic (it has an `ortho_height`). */
export const isOrthographic = (camera) => camera.ortho_height !== null &&
  camera.ortho_height !== undefined;
