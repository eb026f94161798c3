// shellvolume/render.py:visibility_hook: the shell's tetrahedra front to back from the
// camera, by SXMPVO (shellvolume/order.py, step by step the same arithmetic in float64, so
// the same order) or by centroid depth. order.py's module docstring explains the steps:
// 1. face neighbours ordered by their shared face's orientation, 2. an A-buffer of the
// boundary faces relating consecutive faces along each sample ray, 3. a depth-first
// topological sort, cycles broken deterministically.

import { float64, int32 } from "./ndarray.js";
import { inverse, multiply, norm, sub } from "./linalg.js";
import { isOrthographic } from "./view.js";

const RESOLUTION_TIE = 1e-9; // order.TIE
const RECENT = 4096; // order._RECENT

/** Python's round(): halves to even (`order.abuffer_size` rounds so). */
function roundHalfEven(x) {
  const r = Math.round(x);
  return Math.abs(x % 1) === 0.5 && r % 2 !== 0 ? r - 1 : r;
}

function forward(camera) {
  const d = sub(camera.target, camera.eye);
  const n = norm(d);
  return [d[0] / n, d[1] / n, d[2] / n];
}

/** (T,) centroid depths: distance from the eye, or along the view direction (ortho). */
export function centroidDepths(positions, tets, camera) {
  const ortho = isOrthographic(camera);
  const point = ortho ? forward(camera) : camera.eye;
  const count = tets.length / 4;
  const out = new Float64Array(count);
  const c = [0, 0, 0];
  for (let i = 0; i < count; i++) {
    for (let k = 0; k < 3; k++) {
      c[k] = (positions[tets[4 * i] * 3 + k] + positions[tets[4 * i + 1] * 3 + k]
        + positions[tets[4 * i + 2] * 3 + k] + positions[tets[4 * i + 3] * 3 + k]) / 4;
    }
    if (ortho) {
      out[i] = c[0] * point[0] + c[1] * point[1] + c[2] * point[2];
    } else {
      const d0 = c[0] - point[0], d1 = c[1] - point[1], d2 = c[2] - point[2];
      out[i] = Math.sqrt(d0 * d0 + d1 * d1 + d2 * d2);
    }
  }
  return out;
}

/** Indices by increasing depth, ties by index, NaNs last (a stable argsort). */
function byDepth(depth) {
  const order = Int32Array.from({ length: depth.length }, (_, i) => i);
  return order.sort((a, b) => {
    const da = depth[a], db = depth[b];
    if (da !== da || db !== db) return (da !== da) - (db !== db) || a - b;
    return da - db || a - b;
  });
}

/** Step 1: each face pair's relation (src in front of dst). */
function adjacentRelations(cells, camera) {
  const ortho = isOrthographic(camera);
  const point = ortho ? forward(camera) : camera.eye;
  const tol = ortho ? 1e-12 : 1e-12 * cells.scale;
  const tet = int32(cells.pair_tet), other = int32(cells.pair_other);
  const plane = float64(cells.pair_plane);
  const src = [], dst = [];
  for (let k = 0; k < tet.length; k++) {
    const p = 4 * k;
    const facing = ortho
      ? -(plane[p] * point[0] + plane[p + 1] * point[1] + plane[p + 2] * point[2])
      : plane[p] * point[0] + plane[p + 1] * point[1] + plane[p + 2] * point[2] + plane[p + 3];
    if (facing < -tol) {
      src.push(tet[k]);
      dst.push(other[k]);
    } else if (facing > tol) {
      src.push(other[k]);
      dst.push(tet[k]);
    }
  }
  return [src, dst];
}

function project(positions, m, width, height) {
  const n = positions.length / 3;
  const screen = new Float64Array(2 * n);
  const front = new Uint8Array(n);
  for (let i = 0; i < n; i++) {
    const x = positions[3 * i], y = positions[3 * i + 1], z = positions[3 * i + 2];
    const cx = m[0] * x + m[1] * y + m[2] * z + m[3];
    const cy = m[4] * x + m[5] * y + m[6] * z + m[7];
    let w = m[12] * x + m[13] * y + m[14] * z + m[15];
    front[i] = w > 0 ? 1 : 0;
    if (!(w > 0)) w = 1;
    screen[2 * i] = (cx / w + 1) * 0.5 * width;
    screen[2 * i + 1] = (1 - cy / w) * 0.5 * height;
  }
  return [screen, front];
}

function pixelRays(inv, width, height) {
  const origins = new Float64Array(3 * width * height);
  const dirs = new Float64Array(3 * width * height);
  let shortest = Infinity;
  const ends = [[0, 0, 0], [0, 0, 0]];
  for (let r = 0; r < height; r++) {
    const ny = 1 - 2 * (r + 0.5) / height;
    for (let c = 0; c < width; c++) {
      const nx = 2 * (c + 0.5) / width - 1;
      for (let e = 0; e < 2; e++) {
        const nz = e === 0 ? -1 : 1;
        const hw = inv[12] * nx + inv[13] * ny + inv[14] * nz + inv[15];
        for (let k = 0; k < 3; k++) {
          ends[e][k] = (inv[4 * k] * nx + inv[4 * k + 1] * ny + inv[4 * k + 2] * nz
            + inv[4 * k + 3]) / hw;
        }
      }
      let length = 0;
      const p = r * width + c;
      for (let k = 0; k < 3; k++) {
        origins[3 * p + k] = ends[0][k];
        dirs[3 * p + k] = ends[1][k] - ends[0][k];
        length += dirs[3 * p + k] * dirs[3 * p + k];
      }
      shortest = Math.min(shortest, Math.sqrt(length));
    }
  }
  return [origins, dirs, shortest];
}

/** Per boundary face its screen triangle, the pixel box it may cover and its doubled
 * signed area (`order._covered`). */
function covered(screen, front, corners, h, w) {
  const n = corners.length / 3;
  const tri = new Float64Array(6 * n);
  const box = new Int32Array(4 * n);
  const area = new Float64Array(n);
  for (let i = 0; i < n; i++) {
    for (let k = 0; k < 3; k++) {
      tri[6 * i + 2 * k] = screen[2 * corners[3 * i + k]];
      tri[6 * i + 2 * k + 1] = screen[2 * corners[3 * i + k] + 1];
    }
    box[4 * i + 1] = -1;
    if (!(front[corners[3 * i]] && front[corners[3 * i + 1]] && front[corners[3 * i + 2]])) {
      continue;
    }
    const [x0, y0, x1, y1, x2, y2] = tri.subarray(6 * i, 6 * i + 6);
    const a = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0);
    if (Math.abs(a) < 1e-12) continue;
    area[i] = a;
    box[4 * i] = Math.max(0, Math.ceil(Math.min(x0, x1, x2) - 0.5));
    box[4 * i + 1] = Math.min(w - 1, Math.floor(Math.max(x0, x1, x2) - 0.5));
    box[4 * i + 2] = Math.max(0, Math.ceil(Math.min(y0, y1, y2) - 0.5));
    box[4 * i + 3] = Math.min(h - 1, Math.floor(Math.max(y0, y1, y2) - 0.5));
  }
  return [tri, box, area];
}

function edge(tri, i, a, b, x, y) {
  return (tri[6 * i + 2 * a] - x) * (tri[6 * i + 2 * b + 1] - y)
    - (tri[6 * i + 2 * b] - x) * (tri[6 * i + 2 * a + 1] - y);
}

function inside(tri, i, area, x, y) {
  const e0 = edge(tri, i, 1, 2, x, y), e1 = edge(tri, i, 2, 0, x, y);
  const e2 = edge(tri, i, 0, 1, x, y);
  if (area > 0) return e0 >= 0 && e1 >= 0 && e2 >= 0;
  return e0 <= 0 && e1 <= 0 && e2 <= 0;
}

/** The A-buffer: per pixel the boundary faces covering its sample, by ray parameter (ties
 * by face): [starts, faces, t] (`order._rasterize`). */
function rasterize(screen, front, corners, planes, origins, dirs, w, h) {
  const [tri, box, area] = covered(screen, front, corners, h, w);
  const pixelsOf = [];
  const counts = new Float64Array(h * w + 1);
  const n = corners.length / 3;
  for (let i = 0; i < n; i++) {
    const mine = [];
    for (let r = box[4 * i + 2]; r <= box[4 * i + 3]; r++) {
      for (let c = box[4 * i]; c <= box[4 * i + 1]; c++) {
        if (inside(tri, i, area[i], c + 0.5, r + 0.5)) {
          mine.push(r * w + c);
          counts[r * w + c + 1] += 1;
        }
      }
    }
    pixelsOf.push(mine);
  }
  const starts = counts;
  for (let p = 0; p < h * w; p++) starts[p + 1] += starts[p];
  const cursor = starts.slice(0, h * w);
  const faces = new Int32Array(starts[h * w]);
  const t = new Float64Array(starts[h * w]);
  for (let i = 0; i < n; i++) {
    for (const p of pixelsOf[i]) {
      const den = planes[4 * i] * dirs[3 * p] + planes[4 * i + 1] * dirs[3 * p + 1]
        + planes[4 * i + 2] * dirs[3 * p + 2];
      const num = planes[4 * i] * origins[3 * p] + planes[4 * i + 1] * origins[3 * p + 1]
        + planes[4 * i + 2] * origins[3 * p + 2] + planes[4 * i + 3];
      faces[cursor[p]] = i;
      t[cursor[p]] = den !== 0 ? -num / den : Infinity;
      cursor[p] += 1;
    }
  }
  for (let p = 0; p < h * w; p++) {
    for (let k = starts[p] + 1; k < starts[p + 1]; k++) { // insertion sort by (t, face)
      const tk = t[k], fk = faces[k];
      let j = k - 1;
      while (j >= starts[p] && (t[j] > tk || (t[j] === tk && faces[j] > fk))) {
        t[j + 1] = t[j];
        faces[j + 1] = faces[j];
        j--;
      }
      t[j + 1] = tk;
      faces[j + 1] = fk;
    }
  }
  return [starts, faces, t];
}

/** Relations between consecutive depth layers of each pixel's list, a relation seen in
 * the table of recent ones not repeated (`order._layer_pairs`). */
function rayEdges(starts, faces, t, tets, tie) {
  const src = [], dst = [];
  const recent = new Float64Array(RECENT).fill(-1);
  for (let p = 0; p < starts.length - 1; p++) {
    if (starts[p + 1] - starts[p] < 2) continue;
    let prevLo = -1, prevHi = -1;
    let k = starts[p];
    while (k < starts[p + 1]) {
      let hi = k + 1;
      while (hi < starts[p + 1] && t[hi] - t[hi - 1] <= tie) hi++;
      if (prevLo >= 0) {
        for (let a = prevLo; a < prevHi; a++) {
          for (let b = k; b < hi; b++) {
            const ta = tets[faces[a]], tb = tets[faces[b]];
            const key = ta * 4294967296 + tb;
            const slot = (ta * 40503 + tb) & (RECENT - 1);
            if (ta !== tb && recent[slot] !== key) {
              recent[slot] = key;
              src.push(ta);
              dst.push(tb);
            }
          }
        }
      }
      prevLo = k;
      prevHi = hi;
      k = hi;
    }
  }
  return [src, dst];
}

/** Step 2: relations along the A-buffer's sample rays across the shell's gaps. */
function abufferRelations(cells, positions, camera, resolution) {
  const [w0, h0] = camera.size;
  const s = resolution / Math.max(w0, h0);
  const width = Math.max(1, roundHalfEven(w0 * s)), height = Math.max(1, roundHalfEven(h0 * s));
  const mvp = multiply(camera.proj, camera.view);
  const [screen, front] = project(positions, mvp, width, height);
  const [origins, dirs, shortest] = pixelRays(inverse(mvp), width, height);
  const [starts, faces, t] = rasterize(screen, front, int32(cells.face_vertices),
    float64(cells.face_plane), origins, dirs, width, height);
  const tie = RESOLUTION_TIE * cells.scale / Math.max(shortest, 1e-300);
  return rayEdges(starts, faces, t, int32(cells.face_tet), tie);
}

/** Step 3: a topological order of the relations by a depth-first traversal over ranks
 * (nodes numbered by centroid depth), cycles counted and broken (`order.topological_order`):
 * [order, cycles]. */
export function topologicalOrder(order, relations) {
  const count = order.length;
  const rank = new Int32Array(count);
  for (let r = 0; r < count; r++) rank[order[r]] = r;
  const successors = Array.from({ length: count }, () => []);
  for (const [src, dst] of relations) {
    for (let k = 0; k < src.length; k++) {
      if (src[k] !== dst[k]) successors[rank[src[k]]].push(rank[dst[k]]);
    }
  }
  for (let v = 0; v < count; v++) { // by decreasing rank, once each
    successors[v] = [...new Set(successors[v])].sort((a, b) => b - a);
  }
  const state = new Int8Array(count);
  const next = new Int32Array(count);
  const stack = new Int32Array(count);
  const post = new Int32Array(count);
  let nPost = 0, broken = 0;
  for (let root = count - 1; root >= 0; root--) {
    if (state[root] !== 0) continue;
    let top = 0;
    stack[0] = root;
    state[root] = 1;
    while (top >= 0) {
      const v = stack[top];
      if (next[v] < successors[v].length) {
        const u = successors[v][next[v]++];
        if (state[u] === 0) {
          state[u] = 1;
          stack[++top] = u;
        } else if (state[u] === 1) {
          broken++;
        }
      } else {
        state[v] = 2;
        post[nPost++] = v;
        top--;
      }
    }
  }
  const out = new Int32Array(count);
  for (let k = 0; k < count; k++) out[k] = order[post[count - 1 - k]];
  return [out, broken];
}

/** The front-to-back order ({order, cycles, method}) of `cells` (`order.OrderCells` as
 * plain arrays) from `camera`: "sxmpvo" or "centroid" (`order.visibility_order`). */
export function visibilityOrder(cells, camera, method, resolution) {
  const positions = float64(cells.positions);
  const tets = int32(cells.tets);
  const depthOrder = byDepth(centroidDepths(positions, tets, camera));
  if (method === "centroid") return { order: depthOrder, cycles: 0, method };
  if (method !== "sxmpvo") throw new Error(`no visibility sort ${method}`);
  const gaps = abufferRelations(cells, positions, camera, resolution);
  const [order, cycles] = topologicalOrder(depthOrder,
    [adjacentRelations(cells, camera), gaps]);
  return { order, cycles, method };
}

export function visibilityHook(plan, camera, light, { cells, method }) {
  const start = performance.now();
  const sorted = visibilityOrder(cells, camera, method, Math.max(...camera.size));
  return {
    attributes: { in_tet: { dtype: "int32", shape: [sorted.order.length], data: sorted.order } },
    stats: { sort: sorted.method, sort_seconds: (performance.now() - start) / 1000,
      cycles: sorted.cycles },
  };
}


