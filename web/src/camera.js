// The camera of `reliefkit render --view AZ,EL,DIST --size WxH`, computed as scene/camera.py
// and scene/views.py compute it (doubles, as numpy's float64), and the uniforms that
// gl/uniforms.py sets from it (world space relative to the camera's origin, its target).
// Matrices are row-major arrays of 16, as numpy holds them.

const rad = (deg) => (deg * Math.PI) / 180;
const sub = (a, b) => a.map((x, i) => x - b[i]);
const norm = (a) => Math.hypot(...a);
const scale = (a, s) => a.map((x) => x * s);
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];

/** 'AZ,EL[,DIST]' -> [az, el, dist or null]; throws in the words of `--view`. */
export function parseView(text) {
  const parts = text.split(',').map(Number);
  if (![2, 3].includes(parts.length) || !parts.every(Number.isFinite) || Math.abs(parts[1]) >= 90
      || (parts.length === 3 && !(parts[2] > 0))) {
    throw new Error(`view must be AZ,EL or AZ,EL,DIST with |EL| < 90 (e.g. 30,25,2.6), got '${text}'`);
  }
  return [parts[0], parts[1], parts.length === 3 ? parts[2] : null];
}

/** 'AZ,EL' -> the light's [az, el] in degrees; throws in the words of `--light`. */
export function parseLight(text) {
  const parts = text.split(',').map(Number);
  if (parts.length !== 2 || !parts.every(Number.isFinite) || Math.abs(parts[1]) > 90) {
    throw new Error(`light must be AZ,EL in degrees with an elevation within [-90, 90] (e.g. -60,30), got '${text}'`);
  }
  return parts;
}

/** 'WxH' -> [W, H]. */
export function parseSize(text) {
  const m = /^(\d{1,5})x(\d{1,5})$/.exec(text);
  if (!m || +m[1] < 1 || +m[2] < 1 || +m[1] > 8192 || +m[2] > 8192) {
    throw new Error(`size must be WxH within 1..8192 (e.g. 512x512), got '${text}'`);
  }
  return [+m[1], +m[2]];
}

export function lookAt(eye, target, up = [0, 1, 0]) {
  const forward = sub(target, eye);
  const f = scale(forward, 1 / norm(forward));
  let side = cross(f, up);
  if (norm(side) < 1e-9) side = cross(f, Math.abs(f[1]) > 0.5 ? [0, 0, -1] : [0, 1, 0]);
  const s = scale(side, 1 / norm(side));
  const u = cross(s, f);
  const rows = [s, u, scale(f, -1)];
  const view = identity();
  for (let r = 0; r < 3; r++) {
    for (let c = 0; c < 3; c++) view[r * 4 + c] = rows[r][c];
    view[r * 4 + 3] = -(rows[r][0] * eye[0] + rows[r][1] * eye[1] + rows[r][2] * eye[2]);
  }
  return view;
}

export function perspective(fovDeg, aspect, near, far) {
  const f = 1 / Math.tan(rad(fovDeg) / 2);
  const p = new Array(16).fill(0);
  p[0] = f / aspect;
  p[5] = f;
  p[10] = (far + near) / (near - far);
  p[11] = (2 * far * near) / (near - far);
  p[14] = -1;
  return p;
}

export function orthographic(halfHeight, aspect, near, far) {
  const p = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1];
  p[0] = 1 / (halfHeight * aspect);
  p[5] = 1 / halfHeight;
  p[10] = -2 / (far - near);
  p[11] = -(far + near) / (far - near);
  return p;
}

/** The light's orthographic camera over ``bounds`` (render/shadows.py light_camera). */
export function lightCamera(bounds, direction, size) {
  const [lo, hi] = bounds;
  const centre = [0, 1, 2].map((i) => (lo[i] + hi[i]) / 2);
  const radius = norm(sub(hi, lo)) / 2 || 1;
  const towards = scale(direction, 1 / norm(direction));
  const up = Math.abs(towards[1]) > 0.99 ? [1, 0, 0] : [0, 1, 0];
  const eye = centre.map((c, i) => c + 2 * radius * towards[i]);
  const [near, far] = [0.5 * radius, 3.5 * radius];
  return {
    eye, target: centre, up, fov_deg: 40, size: [size, size], near, far, ortho_height: radius, origin: centre,
    view: lookAt(eye, centre, up), proj: orthographic(radius, 1, near, far),
  };
}

/** The camera orbiting ``bounds``' centre (scene.views.orbit_bounds); ``frame`` holds the
 *  page's copies of the Python constants (fov, fit margin). */
export function orbitBounds(bounds, az, el, dist, size, frame, target = null) {
  const [w, h] = size;
  if (dist === null) {
    const halfV = rad(frame.fov) / 2;
    const halfH = Math.atan((Math.tan(halfV) * w) / h);
    dist = frame.fit_margin / Math.sin(Math.min(halfV, halfH));
  }
  const diag = norm(sub(bounds[1], bounds[0])) / 2;
  const radius = diag > 0 ? diag : 1;
  const d = dist * radius;
  const centre = [0, 1, 2].map((i) => (bounds[0][i] + bounds[1][i]) / 2);
  const orbited = target || centre; // a panned view orbits another point
  const [a, e] = [rad(az), rad(el)];
  const eye = [0, 1, 2].map((i) => orbited[i] + d * [Math.cos(e) * Math.sin(a), Math.sin(e), Math.cos(e) * Math.cos(a)][i]);
  const toCentre = target ? norm(sub(centre, eye)) : d; // near and far hug the box wherever the camera looks
  const near = Math.max(toCentre - 1.05 * radius, 0.005 * d);
  const far = toCentre + 1.05 * radius;
  return {
    eye, target: orbited, up: [0, 1, 0], fov_deg: frame.fov, size, near, far, ortho_height: null, origin: orbited,
    view: lookAt(eye, orbited), proj: perspective(frame.fov, w / h, near, far), distance: dist,
  };
}

/** gl/uniforms.py camera_uniforms. */
export function cameraUniforms(camera) {
  const origin = camera.origin;
  const view = multiply(camera.view, translation(origin));
  const toEye = sub(camera.eye, camera.target);
  return {
    u_view: matrix(view), u_proj: matrix(camera.proj),
    u_inv_view_proj: matrix(invert(multiply(camera.proj, view))),
    u_eye: sub(camera.eye, origin), u_orthographic: camera.ortho_height != null,
    u_view_dir: scale(toEye, 1 / norm(toEye)), u_viewport: camera.size,
  };
}

/** gl/uniforms.py model_offset: a plan's origin relative to the camera's. */
export function modelOffset(camera, origin) {
  return { u_model_offset: sub(origin || [0, 0, 0], camera.origin) };
}

/** The light from its angles: its unit ``direction`` (towards the light) and its uniforms
 *  (scene/light.py DirectionalLight.uniforms; ``fields`` holds the others from Python). */
export function lightFrom(fields, az, el) {
  const [a, e] = [rad(az), rad(el)];
  const direction = [Math.cos(e) * Math.sin(a), Math.sin(e), Math.cos(e) * Math.cos(a)];
  return { direction, uniforms: { ...fields.uniforms, u_light_dir: direction } };
}

/** A row-major 4x4 as a plan's (4, 4) array: uniforms transpose it, as gl/uniforms.py does. */
export function matrix(rows) {
  return { shape: [4, 4], dtype: 'float64', data: rows };
}

function identity() {
  return [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1];
}

export function translation(t) {
  const m = identity();
  [m[3], m[7], m[11]] = t;
  return m;
}

export function multiply(a, b) {
  const out = new Array(16).fill(0);
  for (let r = 0; r < 4; r++) for (let c = 0; c < 4; c++) for (let k = 0; k < 4; k++) out[r * 4 + c] += a[r * 4 + k] * b[k * 4 + c];
  return out;
}

/** The inverse of a 4x4 matrix by Gauss-Jordan elimination with partial pivoting. */
export function invert(m) {
  const a = [0, 1, 2, 3].map((r) => [...m.slice(r * 4, r * 4 + 4), ...identity().slice(r * 4, r * 4 + 4)]);
  for (let c = 0; c < 4; c++) {
    let p = c;
    for (let r = c + 1; r < 4; r++) if (Math.abs(a[r][c]) > Math.abs(a[p][c])) p = r;
    [a[c], a[p]] = [a[p], a[c]];
    const pivot = a[c][c];
    for (let k = 0; k < 8; k++) a[c][k] /= pivot;
    for (let r = 0; r < 4; r++) {
      if (r === c) continue;
      const f = a[r][c];
      for (let k = 0; k < 8; k++) a[r][k] -= f * a[c][k];
    }
  }
  return a.flatMap((row) => row.slice(4));
}
