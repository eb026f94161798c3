// slicing/render.py:slices_view: the depth object's slice stack for this camera as vertex
// and index arrays, nearest slice first; for the stencil passes each slice's index range.

import { ndarray } from "./ndarray.js";
import { mat4, norm } from "./linalg.js";
import { autoSliceCount, projectedArea, sliceBox, viewDirection } from "./slices.js";
import { boxUniforms } from "./view.js";

const VISIBLE_TEXELS = 1.5; // depth_images.VISIBLE_TEXELS
const FINEST_TEXELS = 0.5; // render.FINEST_TEXELS

/** The cube's slices for `camera` (`render.slice_stack`). */
function sliceStack(cubeToWorld, resolution, slicing, slices, camera) {
  const m = mat4(cubeToWorld);
  const side = norm([m[0], m[4], m[8]]);
  const centre = [m[3] + 0.5 * side, m[7] + 0.5 * side, m[11] + 0.5 * side];
  let thickness = side;
  if (slicing !== "orthogonal") {
    const f = viewDirection(camera, centre);
    thickness = side * (Math.abs(f[0]) + Math.abs(f[1]) + Math.abs(f[2]));
  }
  const count = slices || autoSliceCount(thickness, camera, centre,
    side / resolution * FINEST_TEXELS);
  return [sliceBox(m, camera, slicing, count), side];
}

export function slicesView(plan, camera, light, {
  cube_to_world: cubeToWorld, resolution, slicing, slices, passes, alpha_test: alphaTest,
  texturing,
}) {
  const [stack, side] = sliceStack(cubeToWorld, resolution, slicing, slices, camera);
  const slack = alphaTest === "point" ? stack.spacing / side : 0;
  const sizes = stack.front.map((k) => stack.first[k + 1] - stack.first[k]);
  const corners = stack.triangles.flat().flatMap((v) => stack.positions[v]);
  const stats = {
    slicing, slices: stack.offsets.length, passes, texturing, alpha_test: alphaTest,
    slice_polygons: sizes.filter((n) => n > 0).length,
    fill_pixels: projectedArea(corners, camera),
  };
  const update = {};
  if (passes === "stencil") {
    const ranges = [];
    let start = 0;
    for (const n of sizes) {
      if (n > 0) ranges.push(3 * start, 3 * n);
      start += n;
    }
    update.params = { ranges: ndarray("int32", [ranges.length / 2, 2], ranges) };
  } else {
    stats.draws = 1;
  }
  const ordered = stack.front.flatMap(
    (k) => stack.triangles.slice(stack.first[k], stack.first[k + 1]).flat());
  const origin = plan.origin;
  const n = stack.positions.length;
  return {
    ...update,
    uniforms: {
      ...boxUniforms(camera, cubeToWorld),
      u_visible_depth: VISIBLE_TEXELS / resolution + slack,
      u_slice_normal: [...stack.normal],
      u_slice_spacing: stack.spacing || side,
    },
    attributes: {
      in_position: ndarray("float32", [n, 3],
        stack.positions.flatMap((p) => [p[0] - origin[0], p[1] - origin[1], p[2] - origin[2]])),
      in_cube: ndarray("float32", [n, 3], stack.box.flat()),
    },
    indices: ndarray("uint32", [ordered.length / 3, 3], ordered),
    stats,
  };
}
