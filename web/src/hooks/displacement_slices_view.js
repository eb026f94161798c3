// slicing/displacement_render.py:slices_view: a displacement map's slice polygons for this
// camera (slicing/displacement_slices.py): offset surfaces (§3.1), per prism the direction
// most perpendicular to the view cutting its tetrahedra (§3.2), or planes facing the viewer
// cut through every tetrahedron (§3.3); K h slices as given or automatic from the size on
// screen, halved while a frame would need more than MAX_POLYGONS.

import { float64, int32, ndarray } from "./ndarray.js";
import { cross, dot, norm, sub } from "./linalg.js";
import { autoSliceCount, pixelWorldSize, projectedArea, viewDirection } from "./slices.js";
import { isOrthographic } from "./view.js";

const AUTO_MIN = 2, AUTO_MAX = 512; // displacement_render
const MAX_PLANES = 8192, MAX_POLYGONS = 2000000; // displacement_slices
const TET_EDGES = [[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]];

class TooManyPolygons extends Error {}

/** Per pattern of tetrahedron vertices above the plane: the crossed edges in cyclic order. */
const CUTS = Array.from({ length: 16 }, (_, m) => {
  const edge = (a, b) => TET_EDGES.findIndex(([i, j]) => i === Math.min(a, b) && j === Math.max(a, b));
  const up = [0, 1, 2, 3].filter((i) => (m >> i) & 1);
  const down = [0, 1, 2, 3].filter((i) => !((m >> i) & 1));
  if (up.length === 1 || up.length === 3) {
    const [lone, rest] = up.length === 1 ? [up[0], down] : [down[0], up];
    return rest.map((r) => edge(lone, r));
  }
  if (up.length === 2) {
    const [a, b] = up, [c, d] = down;
    return [edge(a, c), edge(a, d), edge(b, d), edge(b, c)];
  }
  return [];
});

/** The map as the hook's data holds it, its base in world space, float64. */
function baseOf(d) {
  const rel = float64(d.positions), n = rel.length / 3;
  const world = new Float64Array(3 * n);
  for (let i = 0; i < 3 * n; i++) world[i] = rel[i] + d.origin[i % 3];
  return {
    world, normals: float64(d.normals), uvs: float64(d.uvs), tris: int32(d.indices),
    scale: d.scale, tile: d.tile, height: d.height,
  };
}

const vec = (a, i) => [a[3 * i], a[3 * i + 1], a[3 * i + 2]];

function bounds(base) {
  const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  for (let i = 0; i < base.world.length / 3; i++) {
    for (let k = 0; k < 3; k++) {
      const p = base.world[3 * i + k], top = p + base.scale * base.normals[3 * i + k];
      lo[k] = Math.min(lo[k], p, top);
      hi[k] = Math.max(hi[k], p, top);
    }
  }
  return [lo, hi];
}

/** World size of one height texel on the base (`displacement_render.texel_world_size`). */
function texelWorldSize(base) {
  let area = 0, uvArea = 0;
  const { tris, world, uvs } = base;
  for (let f = 0; f < tris.length / 3; f++) {
    const [a, b, c] = [tris[3 * f], tris[3 * f + 1], tris[3 * f + 2]];
    area += 0.5 * norm(cross(sub(vec(world, b), vec(world, a)), sub(vec(world, c), vec(world, a))));
    const d1 = [uvs[2 * b] - uvs[2 * a], uvs[2 * b + 1] - uvs[2 * a + 1]];
    const d2 = [uvs[2 * c] - uvs[2 * a], uvs[2 * c + 1] - uvs[2 * a + 1]];
    uvArea += 0.5 * Math.abs(d1[0] * d2[1] - d1[1] * d2[0]);
  }
  const perUv = uvArea > 0 ? Math.sqrt(area / uvArea) : Math.sqrt(area);
  const [h, w] = base.height.shape;
  return perUv / Math.max(w * base.tile[0], h * base.tile[1]);
}

/** A part of the slices: flat positions, box (u, v, h) and jacobian (9 a vertex, row-major
 * d(world)/d(u, v, h)) per vertex, the base triangle per vertex, polygons and levels. */
const part = () => ({ positions: [], box: [], jacobian: [], triangle: [], polygons: 0, levels: 0 });

/** The base moved by h * scale along its normals (`_offset_surface`). */
function offsetSurface(base, h) {
  const out = part();
  const { tris, world, normals, uvs, scale } = base;
  const F = tris.length / 3;
  for (let f = 0; f < F; f++) {
    const v = [tris[3 * f], tris[3 * f + 1], tris[3 * f + 2]];
    const uv = v.map((i) => [uvs[2 * i], uvs[2 * i + 1]]);
    const du = [uv[1][0] - uv[0][0], uv[2][0] - uv[0][0]];
    const dv = [uv[1][1] - uv[0][1], uv[2][1] - uv[0][1]];
    const det = du[0] * dv[1] - du[1] * dv[0];
    const inv = Math.abs(det) > 1e-14 ? [[dv[1] / det, -du[1] / det], [-dv[0] / det, du[0] / det]]
      : [[0, 0], [0, 0]];
    const tp = v.map((i) => [0, 1, 2].map((k) => world[3 * i + k] + (h * scale) * normals[3 * i + k]));
    const e1 = sub(tp[1], tp[0]), e2 = sub(tp[2], tp[0]);
    const ju = [0, 1, 2].map((k) => e1[k] * inv[0][0] + e2[k] * inv[1][0]);
    const jv = [0, 1, 2].map((k) => e1[k] * inv[0][1] + e2[k] * inv[1][1]);
    for (let c = 0; c < 3; c++) {
      out.positions.push(...tp[c]);
      out.box.push(uv[c][0], uv[c][1], h);
      const n = [0, 1, 2].map((k) => scale * normals[3 * v[c] + k]);
      for (let k = 0; k < 3; k++) out.jacobian.push(ju[k], jv[k], n[k]);
      out.triangle.push(f);
    }
  }
  out.polygons = F;
  out.levels = 1;
  return out;
}

/** (F, 2, 3) world gradients of u and v in each base triangle's plane, flat. */
function uvGradients(base) {
  const { tris, world, uvs } = base;
  const F = tris.length / 3;
  const out = new Float64Array(6 * F);
  for (let f = 0; f < F; f++) {
    const [a, b, c] = [tris[3 * f], tris[3 * f + 1], tris[3 * f + 2]];
    const e1 = sub(vec(world, b), vec(world, a)), e2 = sub(vec(world, c), vec(world, a));
    const g00 = dot(e1, e1), g01 = dot(e1, e2), g11 = dot(e2, e2);
    const det = g00 * g11 - g01 * g01;
    if (!(Math.abs(det) > 1e-30)) continue;
    const inv = [[g11 / det, -g01 / det], [-g01 / det, g00 / det]];
    for (let k = 0; k < 2; k++) {
      const r = [uvs[2 * b + k] - uvs[2 * a + k], uvs[2 * c + k] - uvs[2 * a + k]];
      const c0 = inv[0][0] * r[0] + inv[0][1] * r[1], c1 = inv[1][0] * r[0] + inv[1][1] * r[1];
      for (let x = 0; x < 3; x++) out[6 * f + 3 * k + x] = c0 * e1[x] + c1 * e2[x];
    }
  }
  return out;
}

function median(values) {
  const s = Float64Array.from(values).sort();
  const m = s.length >> 1;
  return s.length % 2 ? s[m] : (s[m - 1] + s[m]) / 2;
}

/** The h, u and v levels of orthogonal slicing (`orthogonal_levels`). */
function orthogonalLevels(base, count, minSpacing) {
  const out = [Array.from({ length: count }, (_, i) => (i + 0.5) / count)];
  const spacing = Math.max(base.scale / count, minSpacing);
  const grads = uvGradients(base);
  const F = grads.length / 6;
  for (let k = 0; k < 2; k++) {
    const g = [];
    for (let f = 0; f < F; f++) {
      const n = norm([grads[6 * f + 3 * k], grads[6 * f + 3 * k + 1], grads[6 * f + 3 * k + 2]]);
      if (n > 0) g.push(n);
    }
    let lo = Infinity, hi = -Infinity;
    for (let i = k; i < base.uvs.length; i += 2) {
      lo = Math.min(lo, base.uvs[i]);
      hi = Math.max(hi, base.uvs[i]);
    }
    if (!g.length || hi <= lo) {
      out.push([]);
      continue;
    }
    const step = spacing * median(g);
    const n = Math.min(Math.max(1, Math.ceil((hi - lo) / step - 1e-9)), MAX_PLANES);
    out.push(Array.from({ length: n }, (_, i) => lo + (hi - lo) * (i + 0.5) / n));
  }
  return out;
}

/** Per base triangle the slicing direction most perpendicular to the view: 0 (h), 1 (u),
 * 2 (v); ties go to h (`orthogonal_choice`). */
function orthogonalChoice(base, camera) {
  const { tris, world } = base;
  const F = tris.length / 3;
  const grads = uvGradients(base);
  const centroids = [];
  for (let f = 0; f < F; f++) {
    const p = [0, 1, 2].map((c) => vec(world, tris[3 * f + c]));
    centroids.push([0, 1, 2].map((k) => (p[0][k] + p[1][k] + p[2][k]) / 3));
  }
  let ortho = null;
  if (isOrthographic(camera)) {
    const mean = [0, 1, 2].map((k) => centroids.reduce((s, c) => s + c[k], 0) / F);
    ortho = viewDirection(camera, mean);
  }
  const choice = new Int32Array(F);
  for (let f = 0; f < F; f++) {
    const p = [0, 1, 2].map((c) => vec(world, tris[3 * f + c]));
    const dirs = [cross(sub(p[1], p[0]), sub(p[2], p[0])),
      [grads[6 * f], grads[6 * f + 1], grads[6 * f + 2]],
      [grads[6 * f + 3], grads[6 * f + 4], grads[6 * f + 5]]];
    let v = ortho;
    if (!v) {
      const d = sub(centroids[f], camera.eye);
      const n = Math.max(norm(d), 1e-300);
      v = d.map((x) => x / n);
    }
    const score = dirs.map((d) => {
      const n = norm(d);
      return n > 0 ? Math.abs(dot(d.map((x) => x / n), v)) : -1;
    });
    const top = Math.max(...score);
    choice[f] = score[0] >= top - 1e-9 ? 0 : score.indexOf(top);
  }
  return choice;
}

/** Count of sorted `levels` below (`right`: at or below) x, as np.searchsorted. */
function searchSorted(levels, x, right) {
  let lo = 0, hi = levels.length;
  while (lo < hi) {
    const mid = (lo + hi) >> 1;
    if (right ? levels[mid] <= x : levels[mid] < x) lo = mid + 1;
    else hi = mid;
  }
  return lo;
}

/** Polygons where `levels` of `values` (per volume vertex) cut the tetrahedra `which` of
 * the volume, first triangles of every polygon then the quads' second ones, as
 * `cut_tetrahedra`; refused past MAX_POLYGONS with the `reserved` ones. */
function cutTetrahedra(vol, which, values, levels, reserved) {
  const spans = which.map((t) => {
    const s = [0, 1, 2, 3].map((c) => values[vol.tets[4 * t + c]]);
    return [s, searchSorted(levels, Math.min(...s), true), searchSorted(levels, Math.max(...s), false)];
  });
  const total = spans.reduce((n, [, lo, hi]) => n + Math.max(hi - lo, 0), 0);
  if (total + reserved > MAX_POLYGONS) {
    throw new TooManyPolygons(`${total + reserved} slice polygons would be needed (at most ${MAX_POLYGONS})`);
  }
  const out = part();
  const quads = part();
  const used = new Set();
  which.forEach((t, w) => {
    const [s, lo, hi] = spans[w];
    for (let li = lo; li < hi; li++) {
      const level = levels[li];
      let pattern = 0;
      for (let c = 0; c < 4; c++) if (s[c] > level) pattern |= 1 << c;
      const edges = CUTS[pattern];
      if (!edges.length) continue;
      used.add(li);
      out.polygons += 1;
      const corners = edges.map((e) => {
        const [i, j] = TET_EDGES[e];
        const ia = vol.tets[4 * t + i], ib = vol.tets[4 * t + j];
        const sa = s[i], sb = s[j];
        let u = sb !== sa ? (level - sa) / (sb - sa) : 0;
        u = Math.min(1, Math.max(0, u));
        return [[0, 1, 2].map((k) => vol.positions[3 * ia + k] + u * (vol.positions[3 * ib + k] - vol.positions[3 * ia + k])),
          [0, 1, 2].map((k) => vol.box[3 * ia + k] + u * (vol.box[3 * ib + k] - vol.box[3 * ia + k]))];
      });
      const jac = Array.from(vol.jacobian.subarray(9 * t, 9 * t + 9));
      const emit = (into, idx) => idx.forEach((c) => {
        into.positions.push(...corners[c][0]);
        into.box.push(...corners[c][1]);
        into.jacobian.push(...jac);
        into.triangle.push(vol.prism_of[t]);
      });
      emit(out, [0, 1, 2]);
      if (edges.length === 4) emit(quads, [0, 2, 3]);
    }
  });
  out.levels = used.size;
  for (const key of ["positions", "box", "jacobian", "triangle"]) {
    for (const x of quads[key]) out[key].push(x);
  }
  return out;
}

function joined(parts, spacing, mode, directions) {
  const out = part();
  for (const p of parts) {
    for (const key of ["positions", "box", "jacobian", "triangle"]) {
      for (const x of p[key]) out[key].push(x);
    }
    out.polygons += p.polygons;
    out.levels += p.levels;
  }
  return { ...out, spacing, mode, directions };
}

function volumeOf(v) {
  return { positions: float64(v.positions), box: float64(v.box), tets: int32(v.tets),
    jacobian: float64(v.jacobian), prism_of: int32(v.prism_of) };
}

/** The slice triangles of `mode` with `count` h slices (`slice_triangles`). */
function sliceTriangles(base, vol, camera, mode, count, minSpacing) {
  const F = base.tris.length / 3;
  if (mode === "surface") {
    if (count * F > MAX_POLYGONS) throw new TooManyPolygons(`${count * F} slice polygons`);
    const levels = count > 1 ? Array.from({ length: count }, (_, i) => i * (1 / (count - 1)))
      : [0];
    if (count > 1) levels[count - 1] = 1;
    return joined(levels.map((h) => offsetSurface(base, h)),
      count > 1 ? base.scale / (count - 1) : base.scale, "surface", { a: F });
  }
  const baseSurface = offsetSurface(base, 0);
  const T = vol.tets.length / 4;
  if (mode === "orthogonal") {
    const choice = orthogonalChoice(base, camera);
    const levels = orthogonalLevels(base, count, minSpacing);
    const parts = [baseSurface];
    const directions = {};
    [[0, "a", 2], [1, "b", 0], [2, "c", 1]].forEach(([k, name, axis]) => {
      const which = [];
      for (let t = 0; t < T; t++) if (choice[vol.prism_of[t]] === k) which.push(t);
      directions[name] = choice.filter((c) => c === k).length;
      if (!which.length || !levels[k].length) return;
      const values = new Float64Array(vol.box.length / 3);
      for (let i = 0; i < values.length; i++) values[i] = vol.box[3 * i + axis];
      parts.push(cutTetrahedra(vol, which, values, levels[k],
        parts.reduce((n, p) => n + p.polygons, 0)));
    });
    return joined(parts, base.scale / count, "orthogonal", directions);
  }
  const spacing = Math.max(base.scale / count, minSpacing);
  const n = vol.positions.length / 3;
  const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  for (let i = 0; i < n; i++) {
    for (let k = 0; k < 3; k++) {
      lo[k] = Math.min(lo[k], vol.positions[3 * i + k]);
      hi[k] = Math.max(hi[k], vol.positions[3 * i + k]);
    }
  }
  const f = viewDirection(camera, [0, 1, 2].map((k) => 0.5 * (lo[k] + hi[k])));
  const depth = new Float64Array(n);
  for (let i = 0; i < n; i++) depth[i] = dot(vec(vol.positions, i), f);
  const near = depth.reduce((a, b) => Math.min(a, b)), far = depth.reduce((a, b) => Math.max(a, b));
  const planes = Math.min(Math.max(1, Math.ceil((far - near) / spacing - 1e-9)), MAX_PLANES);
  const levels = Array.from({ length: planes }, (_, i) => near + (far - near) * (i + 0.5) / planes);
  const cut = cutTetrahedra(vol, Array.from({ length: T }, (_, t) => t), depth, levels,
    baseSurface.polygons);
  return joined([baseSurface, cut], (far - near) / planes, "screen", { planes });
}

export function displacementSlicesView(plan, camera, light, {
  displacement, layers, volume, slicing, slices, alpha_test: alphaTest,
}) {
  const base = baseOf(displacement);
  const vol = volume && volumeOf(volume);
  const [lo, hi] = bounds(base);
  const centre = [0, 1, 2].map((k) => 0.5 * (lo[k] + hi[k]));
  const texel = texelWorldSize(base);
  let count = slices ?? autoSliceCount(base.scale, camera, centre, texel, AUTO_MAX);
  const finest = slices == null ? Math.max(pixelWorldSize(camera, centre), texel) : 0;
  let tris;
  for (;;) {
    try {
      tris = sliceTriangles(base, vol, camera, slicing, count, finest);
      break;
    } catch (error) {
      if (!(error instanceof TooManyPolygons) || slices != null || count <= AUTO_MIN) throw error;
      count = Math.max(AUTO_MIN, Math.floor(count / 2));
    }
  }
  const m = tris.positions.length / 3;
  const stats = {
    slices: count, slicing, alpha_test: alphaTest, slice_planes: tris.levels,
    slice_polygons: tris.polygons, slice_triangles: Math.floor(m / 3),
    slice_spacing: tris.spacing, fill_pixels: projectedArea(tris.positions, camera),
  };
  for (const [k, v] of Object.entries(tris.directions)) stats[`direction_${k}`] = v;
  const origin = plan.origin;
  const column = (c) => ndarray("float32", [m, 3], Array.from({ length: 3 * m },
    (_, i) => tris.jacobian[9 * Math.floor(i / 3) + 3 * (i % 3) + c]));
  const layer = float64(layers);
  return {
    uniforms: { u_bound: count > 1 ? 1 / (count - 1) : 1 },
    attributes: {
      in_position: ndarray("float32", [m, 3], tris.positions.map((x, i) => x - origin[i % 3])),
      in_uvh: ndarray("float32", [m, 3], tris.box),
      in_ju: column(0), in_jv: column(1), in_jh: column(2),
      in_layer: ndarray("float32", [m], tris.triangle.map((f) => layer[f])),
    },
    stats,
  };
}
