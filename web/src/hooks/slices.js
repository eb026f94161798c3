// Slice stacks through a box (slicing/slices.py): planes along the box axis most
// perpendicular to the view (§3.2) or facing the viewer cut exactly to the box (§3.3), and
// how many slices a view needs. Boxes are 4x4 row-major box_to_world matrices.

import { cross, dot, inverse3, mat4, multiply, norm, transformPoint } from "./linalg.js";
import { isOrthographic } from "./view.js";

const CORNERS = Array.from({ length: 8 }, (_, i) => [i & 1, (i >> 1) & 1, (i >> 2) & 1]);
const EDGES = [];
for (let i = 0; i < 8; i++) {
  for (let a = 0; a < 3; a++) if (!(i & (1 << a))) EDGES.push([i, i | (1 << a)]);
}
const ON_PLANE = 1e-12;
const AXIS_PREFERENCE = [2, 0, 1];
const TIE = 1e-9;
export const AUTO_MIN = 2;
export const AUTO_MAX = 2048;

/** Unit world direction from the viewer into the scene at `centre` (`view_direction`). */
export function viewDirection(camera, centre) {
  const f = isOrthographic(camera)
    ? [0, 1, 2].map((k) => camera.target[k] - camera.eye[k])
    : [0, 1, 2].map((k) => centre[k] - camera.eye[k]);
  const n = norm(f);
  if (!Number.isFinite(n) || n === 0) {
    throw new Error("no view direction: the eye is at the box centre");
  }
  return f.map((x) => x / n);
}

/** [A rows (3x3: columns the u, v, h edges), origin corner] of a box matrix. */
function boxParts(boxToWorld) {
  const m = mat4(boxToWorld);
  return [[0, 1, 2].map((r) => [m[4 * r], m[4 * r + 1], m[4 * r + 2]]),
    [m[3], m[7], m[11]]];
}

const applyA = (a, q) => [0, 1, 2].map((k) => a[k][0] * q[0] + a[k][1] * q[1] + a[k][2] * q[2]);
const det3 = (a) => dot(a[0], cross(a[1], a[2]));

/** Box-coordinate points where m . q = c meets the unit cube's edges, deduplicated. */
function cutUnitCube(m, c) {
  const tol = ON_PLANE * Math.max(Math.abs(m[0]) + Math.abs(m[1]) + Math.abs(m[2]) + Math.abs(c),
    1e-300);
  const s = CORNERS.map((q) => {
    const v = dot(q, m) - c;
    return Math.abs(v) <= tol ? 0 : v;
  });
  const points = CORNERS.filter((_, i) => s[i] === 0);
  for (const [i, j] of EDGES) {
    if (s[i] * s[j] < 0) {
      const t = s[i] / (s[i] - s[j]);
      points.push([0, 1, 2].map((k) => CORNERS[i][k] + t * (CORNERS[j][k] - CORNERS[i][k])));
    }
  }
  const keep = [];
  for (const p of points) {
    const q = p.map((x) => Math.min(1, Math.max(0, x)));
    if (keep.every((r) => Math.max(...q.map((x, k) => Math.abs(x - r[k]))) > 1e-12)) keep.push(q);
  }
  return keep;
}

/** The convex polygon of the box and the plane normal . x = d, CCW about `normal`:
 * [box coords, world points] (empty where the plane misses the box). */
function polygon(a, o, normal, d) {
  const m = [0, 1, 2].map((j) => a[0][j] * normal[0] + a[1][j] * normal[1] + a[2][j] * normal[2]);
  let q = cutUnitCube(m, d - dot(normal, o));
  if (q.length < 3) return [[], []];
  let x = q.map((p) => applyA(a, p).map((v, k) => v + o[k]));
  const centre = [0, 1, 2].map((k) => x.reduce((s, p) => s + p[k], 0) / x.length);
  let e1 = cross(normal, [1, 0, 0]);
  if (norm(e1) < 0.5) e1 = cross(normal, [0, 1, 0]);
  const n1 = norm(e1);
  e1 = e1.map((v) => v / n1);
  const e2 = cross(normal, e1);
  const angle = x.map((p) => {
    const rel = [0, 1, 2].map((k) => p[k] - centre[k]);
    return Math.atan2(dot(rel, e2), dot(rel, e1));
  });
  const order = angle.map((_, i) => i).sort((i, j) => angle[i] - angle[j] || i - j);
  q = order.map((i) => q[i]);
  x = order.map((i) => x[i]);
  const rel = x.map((p) => [0, 1, 2].map((k) => p[k] - x[0][k]));
  const sum = [0, 0, 0];
  for (let k = 1; k < rel.length - 1; k++) {
    const c = cross(rel[k], rel[k + 1]);
    for (let i = 0; i < 3; i++) sum[i] += c[i];
  }
  const largest = Math.max(...rel.flat().map(Math.abs));
  if (dot(sum, normal) <= 1e-14 * largest * largest) return [[], []];
  return [q, x];
}

/** The polygons as one indexed triangle list of fans, grouped by slice (`_assemble`). */
function assemble(polygons, normal, offsets, axis, spacing, front) {
  const box = [], positions = [], triangles = [], first = [0];
  for (const [q, x] of polygons) {
    const n = q.length;
    if (n >= 3) {
      const base = positions.length;
      for (let k = 1; k < n - 1; k++) triangles.push([base, base + k, base + k + 1]);
      box.push(...q);
      positions.push(...x);
    }
    first.push(first[first.length - 1] + Math.max(n - 2, 0));
  }
  return { positions, box, triangles, first, normal, offsets, axis, spacing, front };
}

function screenSlices(boxToWorld, camera, count) {
  const [a, o] = boxParts(boxToWorld);
  const corners = CORNERS.map((q) => applyA(a, q).map((v, k) => v + o[k]));
  const mean = [0, 1, 2].map((k) => corners.reduce((s, p) => s + p[k], 0) / 8);
  const f = viewDirection(camera, mean);
  const depth = corners.map((p) => dot(p, f));
  const near = Math.min(...depth), far = Math.max(...depth);
  const spacing = (far - near) / count;
  const depths = Array.from({ length: count },
    (_, i) => near + ((count - 1 - i + 0.5) / count) * (far - near));
  const normal = f.map((v) => -v);
  const polygons = depths.map((t) => polygon(a, o, normal, -t));
  const front = Array.from({ length: count }, (_, i) => count - 1 - i);
  return assemble(polygons, normal, depths.map((t) => -t), null, spacing, front);
}

function bestAxis(a, o, camera) {
  const centre = [0, 1, 2].map((k) => o[k] + 0.5 * (a[k][0] + a[k][1] + a[k][2]));
  const f = viewDirection(camera, centre);
  const g = inverse3(a);
  const score = g.map((row) => Math.abs(dot(row, f)) / norm(row));
  const top = Math.max(...score);
  return AXIS_PREFERENCE.find((ax) => score[ax] >= top - TIE);
}

function orthogonalSlices(boxToWorld, camera, count) {
  const [a, o] = boxParts(boxToWorld);
  const axis = bestAxis(a, o, camera);
  const centre = [0, 1, 2].map((k) => o[k] + 0.5 * (a[k][0] + a[k][1] + a[k][2]));
  const f = viewDirection(camera, centre);
  const g = inverse3(a)[axis];
  const sign = dot(g, f) >= 0 ? -1 : 1;
  const gn = norm(g);
  const normal = g.map((v) => sign * v / gn);
  let levels = Array.from({ length: count }, (_, i) => (i + 0.5) / count);
  let offsets = levels.map((l) => sign * (l - dot(g, o)) / gn);
  const order = offsets.map((_, i) => i).sort((i, j) => offsets[i] - offsets[j] || i - j);
  levels = order.map((i) => levels[i]);
  offsets = order.map((i) => offsets[i]);
  const b = (axis + 1) % 3, c = (axis + 2) % 3;
  let quad = [[0, 0], [1, 0], [1, 1], [0, 1]].map(([vb, vc]) => {
    const q = [0, 0, 0];
    q[b] = vb;
    q[c] = vc;
    return q;
  });
  if ((sign < 0) !== (det3(a) < 0)) quad = quad.reverse();
  const polygons = levels.map((level) => {
    const q = quad.map((p) => p.map((v, k) => (k === axis ? level : v)));
    return [q, q.map((p) => applyA(a, p).map((v, k) => v + o[k]))];
  });
  const spacing = levels.length > 1 ? Math.abs((levels[1] - levels[0]) / gn) : 0;
  const front = Array.from({ length: count }, (_, i) => count - 1 - i);
  return assemble(polygons, normal, offsets, axis, spacing, front);
}

/** `count` slices of the box for `camera` ("orthogonal" or "screen"): {positions, box
 * (per vertex), triangles, first (per slice its first triangle, K + 1), normal, offsets,
 * axis, spacing, front (slice indices nearest first)}. */
export function sliceBox(boxToWorld, camera, slicing, count) {
  return slicing === "orthogonal" ? orthogonalSlices(boxToWorld, camera, count)
    : screenSlices(boxToWorld, camera, count);
}

/** World length one pixel spans at `point` (`slices.pixel_world_size`). */
export function pixelWorldSize(camera, point) {
  const eye = transformPoint(camera.view, point);
  const p = camera.proj;
  const ndcY = (e) => (p[4] * e[0] + p[5] * e[1] + p[6] * e[2] + p[7])
    / (p[12] * e[0] + p[13] * e[1] + p[14] * e[2] + p[15]);
  const step = Math.max(Math.abs(eye[2]), 1e-6) * 1e-3;
  const up = [eye[0], eye[1] + step, eye[2]];
  const pixels = Math.abs(ndcY(up) - ndcY(eye)) * 0.5 * camera.size[1];
  return pixels > 0 ? step / pixels : Infinity;
}

/** Slices one pixel apart at `centre`, no closer than `finest`, within [AUTO_MIN, maximum]
 * (`slices.auto_slice_count`). */
export function autoSliceCount(thickness, camera, centre, finest, maximum = AUTO_MAX) {
  const spacing = Math.max(pixelWorldSize(camera, centre), finest);
  if (!Number.isFinite(spacing) || spacing <= 0) return AUTO_MIN;
  return Math.min(maximum, Math.max(AUTO_MIN, Math.ceil(thickness / spacing - 1e-9)));
}

/** Projected area in pixels of triangles given as a flat list of world corners (3 numbers
 * each, 3 corners a triangle), unclipped (`slices.projected_area`). */
export function projectedArea(corners, camera) {
  const m = multiply(camera.proj, camera.view);
  const [w0, h0] = camera.size;
  let total = 0;
  const pix = [[0, 0], [0, 0], [0, 0]];
  for (let t = 0; t < corners.length; t += 9) {
    for (let k = 0; k < 3; k++) {
      const x = corners[t + 3 * k], y = corners[t + 3 * k + 1], z = corners[t + 3 * k + 2];
      const cx = m[0] * x + m[1] * y + m[2] * z + m[3];
      const cy = m[4] * x + m[5] * y + m[6] * z + m[7];
      let w = m[12] * x + m[13] * y + m[14] * z + m[15];
      if (!(Math.abs(w) > 1e-12)) w = 1e-12;
      pix[k][0] = (cx / w + 1) * 0.5 * w0;
      pix[k][1] = (cy / w + 1) * 0.5 * h0;
    }
    const d1 = [pix[1][0] - pix[0][0], pix[1][1] - pix[0][1]];
    const d2 = [pix[2][0] - pix[0][0], pix[2][1] - pix[0][1]];
    total += Math.abs(0.5 * (d1[0] * d2[1] - d1[1] * d2[0]));
  }
  return total;
}
