// The page's camera as a user moves it: orbit (azimuth, elevation), zoom (distance in
// bounding-sphere radii, as `reliefkit render --view AZ,EL,DIST`) and pan (the point orbited,
// moved in the picture's plane; `target=X,Y,Z` in the URL, world coordinates, only once
// panned). Mouse: drag orbits, right- or shift-drag pans, the wheel zooms; touch: one finger
// orbits, two pan and pinch-zoom; keys: arrows orbit, shift+arrows pan, + and - zoom, 0 goes
// back to the opening view.

import { orbitBounds } from './camera.js';

const ORBIT_DEG_PER_PIXEL = 0.4;
const KEY_ORBIT_DEG = 5;
const KEY_PAN_PIXELS = 20;
const KEY_ZOOM = 1.1;
const clampEl = (e) => Math.max(-89, Math.min(89, e));
const clampDist = (d) => Math.max(0.01, Math.min(1e4, d));

/** 'X,Y,Z' -> [x, y, z]; throws in the URL's words. */
export function parseTarget(text) {
  const parts = text.split(',').map(Number);
  if (parts.length !== 3 || !parts.every(Number.isFinite)) {
    throw new Error(`target must be X,Y,Z (world coordinates, e.g. 0,0.5,0), got '${text}'`);
  }
  return parts;
}

export class Navigation {
  /** ``opening``: the view the page opens on ({view: [az, el, dist or null], target or
   *  null}, from the URL); ``bounds`` the union of the inputs' framing boxes; ``frame``:
   *  inputs.json's camera defaults. */
  constructor(opening, bounds, size, frame) {
    this.bounds = bounds;
    this.size = size;
    this.frame = frame;
    this.opening = opening;
    this.reset();
    this.onChange = () => {};
  }

  reset() {
    this.set(...this.opening.view);
    this.target = this.opening.target;
  }

  /** The camera of the current view (its distance fitted the first time when not given). */
  camera() {
    const camera = orbitBounds(this.bounds, this.az, this.el, this.dist, this.size, this.frame, this.target);
    this.dist = camera.distance;
    return camera;
  }

  set(az, el, dist = null) {
    [this.az, this.el, this.dist] = [az, el, dist];
    this.fitted = dist === null; // the distance that fits the view: left out of the URL
  }

  orbit(dx, dy) {
    this.az -= dx * ORBIT_DEG_PER_PIXEL;
    this.el = clampEl(this.el + dy * ORBIT_DEG_PER_PIXEL);
  }

  zoom(factor) {
    this.dist = clampDist(this.dist * factor);
    this.fitted = false;
  }

  /** Move the orbited point by ``dx``, ``dy`` pixels of the picture, so what is under the
   *  pointer stays under it at the target's depth. */
  pan(dx, dy) {
    const camera = this.camera();
    const toEye = camera.eye.map((x, i) => x - camera.target[i]);
    const d = Math.hypot(...toEye);
    const perPixel = (2 * d * Math.tan((camera.fov_deg * Math.PI) / 360)) / this.size[1];
    const [right, up] = [camera.view.slice(0, 3), camera.view.slice(4, 7)]; // lookAt's rows
    this.target = camera.target.map((t, i) => t - (dx * right[i] - dy * up[i]) * perPixel);
  }

  /** The view in ``params``: view always (its distance once zoomed, to 10 digits: a copied
   *  URL draws the same picture), target once panned. */
  toUrl(params) {
    const angles = `${+this.az.toFixed(3)},${+this.el.toFixed(3)}`;
    params.set('view', this.fitted ? angles : `${angles},${+this.dist.toPrecision(10)}`);
    if (this.target) params.set('target', this.target.map((x) => +x.toPrecision(7)).join(','));
    else params.delete('target');
  }

  /** Mouse, touch and keyboard on ``canvas``. */
  attach(canvas) {
    const pointers = new Map(); // pointer id -> its last position
    const changed = () => this.onChange();
    canvas.addEventListener('contextmenu', (e) => e.preventDefault()); // right-drag pans
    canvas.addEventListener('pointerdown', (e) => {
      canvas.setPointerCapture(e.pointerId);
      pointers.set(e.pointerId, [e.clientX, e.clientY]);
    });
    const lift = (e) => pointers.delete(e.pointerId);
    canvas.addEventListener('pointerup', lift);
    canvas.addEventListener('pointercancel', lift);
    canvas.addEventListener('pointermove', (e) => {
      const last = pointers.get(e.pointerId);
      if (!last) return;
      const [dx, dy] = [e.clientX - last[0], e.clientY - last[1]];
      if (pointers.size === 2) { // two fingers: pan by half the move, pinch zooms
        const other = [...pointers].find(([id]) => id !== e.pointerId)[1];
        const apart = (a) => Math.hypot(a[0] - other[0], a[1] - other[1]);
        const before = apart(last);
        const after = apart([e.clientX, e.clientY]);
        if (before > 0 && after > 0) this.zoom(before / after);
        this.pan(dx / 2, dy / 2);
      } else if (pointers.size === 1) {
        if (e.buttons & 2 || e.buttons & 4 || e.shiftKey) this.pan(dx, dy);
        else this.orbit(dx, dy);
      }
      pointers.set(e.pointerId, [e.clientX, e.clientY]);
      changed();
    });
    canvas.tabIndex = 0;
    canvas.addEventListener('keydown', (e) => {
      const arrow = { ArrowLeft: [-1, 0], ArrowRight: [1, 0], ArrowUp: [0, -1], ArrowDown: [0, 1] }[e.key];
      if (arrow && e.shiftKey) this.pan(arrow[0] * KEY_PAN_PIXELS, arrow[1] * KEY_PAN_PIXELS);
      else if (arrow) {
        this.az -= arrow[0] * KEY_ORBIT_DEG;
        this.el = clampEl(this.el - arrow[1] * KEY_ORBIT_DEG);
      } else if (e.key === '+' || e.key === '=') this.zoom(1 / KEY_ZOOM);
      else if (e.key === '-') this.zoom(KEY_ZOOM);
      else if (e.key === '0') this.reset();
      else return;
      e.preventDefault();
      changed();
    });
    canvas.addEventListener('wheel', (e) => {
      e.preventDefault();
      this.zoom(Math.exp(e.deltaY * 0.001));
      changed();
    }, { passive: false });
  }
}
