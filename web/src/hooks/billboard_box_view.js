// billboard/box_render.py:box_view and cloud_view: each box flattened with distance (lod
// auto, §3.4.2) and drawn in the camera's relative world space, and the flat cloud drawn
// instead beyond the switch distance (billboard/lod.py).

import { boxUniforms, cullFace, isOrthographic } from "./view.js";
import { mat4, multiply, norm, sub } from "./linalg.js";

/** `box_render.MIN_FLATTEN`: a box of zero depth has no inside to rasterize. */
const MIN_FLATTEN = 1e-3;

function pixelSize(camera, distance) {
  if (isOrthographic(camera)) return 2 * camera.ortho_height / camera.size[1];
  return 2 * distance * Math.tan(camera.fov_deg * Math.PI / 180 / 2) / camera.size[1];
}

function switchDistance(camera, epsilon) {
  if (isOrthographic(camera)) return epsilon >= pixelSize(camera, 1) ? Infinity : 0;
  return epsilon * camera.size[1] / (2 * Math.tan(camera.fov_deg * Math.PI / 180 / 2));
}

/** The boxes' depth scale at this camera (`lod.flatten_factor`). */
export function flattenFactor(camera, epsilon, center, transition) {
  const s = switchDistance(camera, epsilon);
  if (!Number.isFinite(s) || s <= 0) return s > 0 ? 1 : 0;
  const distance = norm(sub(camera.eye, center));
  const start = transition * s;
  if (distance <= start) return 1;
  return Math.max(0, (s - distance) / (s - start));
}

/** What the boxes draw from `camera` (`box_render.view_lod`). */
export function viewLod(camera, flatten, lod) {
  if (lod) flatten = flattenFactor(camera, lod.epsilon, lod.center, lod.transition);
  const cloud = Boolean(lod) && flatten <= 0;
  return { lod: cloud ? "billboard cloud" : "boxes", flatten };
}

function scaleW(factor) {
  return [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, factor, 0.5 * (1 - factor), 0, 0, 0, 1];
}

export function boxView(plan, camera, light, { box_to_world: boxToWorld, flatten, lod }) {
  const drawn = viewLod(camera, flatten, lod);
  if (drawn.lod !== "boxes") return { count: 0, stats: drawn };
  const handoff = lod ? 1 - drawn.flatten : 0;
  const box = multiply(mat4(boxToWorld), scaleW(Math.max(drawn.flatten, MIN_FLATTEN)));
  return {
    uniforms: { u_handoff: handoff, ...boxUniforms(camera, box) },
    cull: cullFace(plan.geometry.attributes.in_position.array, plan.origin, camera),
    stats: drawn,
  };
}

export function cloudView(plan, camera, light, { flatten, lod }) {
  const drawn = viewLod(camera, flatten, lod);
  return drawn.lod === "billboard cloud" ? { stats: drawn } : { count: 0, stats: drawn };
}
