// 4x4 matrices as 16 numbers, row-major (numpy's layout), and 3-vectors as arrays: float64
// throughout, as the Python hooks compute.

export const identity = () => [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1];

/** A 4x4 matrix from an {dtype, shape, data} array, nested rows or 16 numbers. */
export function mat4(m) {
  const flat = m.data ? Array.from(m.data, Number) : (Array.isArray(m[0]) ? m.flat() : [...m]);
  if (flat.length !== 16) throw new Error(`a 4x4 matrix needs 16 numbers, got ${flat.length}`);
  return flat;
}

export function multiply(a, b) {
  const out = new Array(16);
  for (let r = 0; r < 4; r++) {
    for (let c = 0; c < 4; c++) {
      let s = 0;
      for (let k = 0; k < 4; k++) s += a[r * 4 + k] * b[k * 4 + c];
      out[r * 4 + c] = s;
    }
  }
  return out;
}

/** The inverse by Gauss-Jordan elimination with partial pivoting (throws when singular). */
export function inverse(m) {
  const a = [...m];
  const inv = identity();
  for (let col = 0; col < 4; col++) {
    let pivot = col;
    for (let r = col + 1; r < 4; r++) {
      if (Math.abs(a[r * 4 + col]) > Math.abs(a[pivot * 4 + col])) pivot = r;
    }
    if (a[pivot * 4 + col] === 0) throw new Error("singular matrix");
    for (let c = 0; c < 4; c++) {
      [a[col * 4 + c], a[pivot * 4 + c]] = [a[pivot * 4 + c], a[col * 4 + c]];
      [inv[col * 4 + c], inv[pivot * 4 + c]] = [inv[pivot * 4 + c], inv[col * 4 + c]];
    }
    const p = a[col * 4 + col];
    for (let c = 0; c < 4; c++) {
      a[col * 4 + c] /= p;
      inv[col * 4 + c] /= p;
    }
    for (let r = 0; r < 4; r++) {
      if (r === col) continue;
      const f = a[r * 4 + col];
      if (f === 0) continue;
      for (let c = 0; c < 4; c++) {
        a[r * 4 + c] -= f * a[col * 4 + c];
        inv[r * 4 + c] -= f * inv[col * 4 + c];
      }
    }
  }
  return inv;
}

export function translation(offset) {
  const m = identity();
  m[3] = offset[0];
  m[7] = offset[1];
  m[11] = offset[2];
  return m;
}

/** m @ (x, y, z, w) as 4 numbers. */
export function apply4(m, x, y, z, w = 1) {
  const out = [0, 0, 0, 0];
  for (let r = 0; r < 4; r++) {
    out[r] = m[r * 4] * x + m[r * 4 + 1] * y + m[r * 4 + 2] * z + m[r * 4 + 3] * w;
  }
  return out;
}

/** A point through a (possibly projective) matrix, divided by w (`transform_points`). */
export function transformPoint(m, p) {
  const h = apply4(m, p[0], p[1], p[2], 1);
  return [h[0] / h[3], h[1] / h[3], h[2] / h[3]];
}

/** world_to_box of a box far from the world origin, inverted about its centre
 * (`core.transforms.invert_box`). */
export function invertBox(boxToWorld) {
  const centre = transformPoint(boxToWorld, [0.5, 0.5, 0.5]);
  const relative = multiply(translation(centre.map((x) => -x)), boxToWorld);
  return multiply(inverse(relative), translation(centre.map((x) => -x)));
}

/** The 3x3 inverse of rows [[a, b, c], ...] (throws when singular). */
export function inverse3(m) {
  const [[a, b, c], [d, e, f], [g, h, i]] = m;
  const A = e * i - f * h, B = -(d * i - f * g), C = d * h - e * g;
  const det = a * A + b * B + c * C;
  if (det === 0) throw new Error("singular matrix");
  return [
    [A / det, -(b * i - c * h) / det, (b * f - c * e) / det],
    [B / det, (a * i - c * g) / det, -(a * f - c * d) / det],
    [C / det, -(a * h - b * g) / det, (a * e - b * d) / det],
  ];
}

export const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
export const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
export const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
export const scale = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
export const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
  a[0] * b[1] - a[1] * b[0]];
export const norm = (a) => Math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
