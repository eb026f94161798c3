// reliefkit's viewer page: every input of `reliefkit view` (inputs.json: its GLB, kind and
// framing bounds) drawn side by side from one camera by the WebGL2 executor. The view is in
// the URL (?view=AZ,EL,DIST&size=WxH&light=AZ,EL, kept up to date); a drag (mouse or touch)
// or the arrow keys orbit, the wheel or + and - zoom.
// window.reliefkit.ready turns true after the first complete frame (frameMs, gpuMs and each
// panel's counts are the latest frame's; setView(az, el, dist) draws a view: the bench's
// orbit); errors show in the page and are posted to the server's log.

import { lightFrom, orbitBounds, parseSize, parseView } from './camera.js';
import { createContext, createTargets, Executor, Unsupported } from './executor.js';
import { drawOf, parseGlb, readArrays } from './glb.js';
import { HOOKS } from './hooks/index.js';
import { decodePlans } from './plans.js';

const state = window.reliefkit = { ready: false, errors: [], frames: 0 };

function report(message) {
  state.errors.push(message);
  const box = document.getElementById('messages');
  const line = document.createElement('p');
  line.className = 'error';
  line.textContent = message;
  box.appendChild(line);
  fetch('log', { method: 'POST', body: message }).catch(() => {}); // a static server has none
}

window.addEventListener('error', (e) => report(`error: ${e.message}`));
window.addEventListener('unhandledrejection', (e) => report(`error: ${e.reason && e.reason.message ? e.reason.message : e.reason}`));

async function fetchOk(url) {
  const response = await fetch(url);
  if (!response.ok) throw new Error(`cannot load ${url} (${response.status} ${response.statusText})`);
  return response;
}

/** One input's panel: its canvas, executor, plans and targets, or its error. */
async function openInput(input, size, programs) {
  const panel = document.createElement('figure');
  const canvas = document.createElement('canvas');
  [canvas.width, canvas.height] = size;
  canvas.style.width = `${size[0]}px`;
  canvas.style.height = `${size[1]}px`;
  const caption = document.createElement('figcaption');
  caption.textContent = `${input.name} (${input.kind})`;
  panel.append(canvas, caption);
  document.getElementById('panels').appendChild(panel);
  try {
    const gl = createContext(canvas);
    canvas.addEventListener('webglcontextlost', () => report(`${input.name}: the browser lost the WebGL context (reload the page)`));
    const glb = parseGlb(await (await fetchOk(input.file)).arrayBuffer(), input.name);
    const draw = drawOf(glb);
    const plans = decodePlans(draw, await readArrays(gl, glb, draw));
    const executor = new Executor(gl, draw, input.name, HOOKS, programs);
    const drawn = [];
    for (const plan of plans) {
      try {
        executor.add(plan);
        drawn.push(plan);
      } catch (e) {
        if (!(e instanceof Unsupported)) throw e;
        report(`${input.name}: ${e.message}`);
      }
    }
    return { canvas, executor, plans: drawn, targets: createTargets(gl, size) };
  } catch (e) {
    report(`${input.name}: ${e.message}`);
    return null;
  }
}

function union(boxes) {
  return [0, 1].map((k) => [0, 1, 2].map((i) => (k ? Math.max : Math.min)(...boxes.map((b) => b[k][i]))));
}

async function main() {
  const params = new URLSearchParams(location.search);
  const manifest = await (await fetchOk('inputs.json')).json();
  const frame = manifest.camera;
  let [az, el, dist] = parseView(params.get('view') || frame.default_view);
  const size = parseSize(params.get('size') || frame.default_size);
  const [lightAz, lightEl] = parseView(params.get('light') || manifest.light.angles);
  const light = lightFrom(manifest.light, lightAz, lightEl);
  const bounds = union(manifest.inputs.map((i) => i.bounds));
  const panels = (await Promise.all(manifest.inputs.map((i) => openInput(i, size, manifest.programs)))).filter(Boolean);

  const readout = document.getElementById('stats');
  const render = () => {
    const start = performance.now();
    const camera = orbitBounds(bounds, az, el, dist, size, frame);
    dist = camera.distance;
    for (const p of panels) p.executor.frame(p.plans, camera, light, p.targets);
    for (const p of panels) p.executor.finish();
    state.frameMs = performance.now() - start; // the CPU's clock around the draws and a read back
    state.counts = panels.map((p) => ({ ...p.executor.counts }));
    const shown = () => {
      const gpu = panels.map((p) => p.executor.gpuTime());
      state.gpuMs = gpu.every((t) => t !== null) ? gpu.reduce((a, b) => a + b, 0) : null;
      readout.textContent = `view ${az.toFixed(1)},${el.toFixed(1)},${dist.toFixed(3)}  ${size[0]}x${size[1]}  `
        + `frame ${state.frameMs.toFixed(1)} ms` + (state.gpuMs === null ? '' : `, GPU ${state.gpuMs.toFixed(2)} ms`);
    };
    shown();
    setTimeout(shown, 50); // the timer query's result, once the browser has it
    state.view = [az, el, dist];
    params.set('view', `${+az.toFixed(3)},${+el.toFixed(3)},${+dist.toFixed(4)}`);
    history.replaceState(null, '', `?${params}`); // the view stays in the URL
    state.frames += 1;
    state.ready = true;
  };
  let pending = false;
  const redraw = () => {
    if (!pending) {
      pending = true;
      requestAnimationFrame(() => { pending = false; render(); });
    }
  };
  for (const p of panels) {
    p.canvas.addEventListener('pointerdown', (e) => p.canvas.setPointerCapture(e.pointerId));
    p.canvas.addEventListener('pointermove', (e) => {
      if (!p.canvas.hasPointerCapture(e.pointerId)) return;
      az -= e.movementX * 0.4;
      el = Math.max(-89, Math.min(89, el + e.movementY * 0.4));
      redraw();
    });
    p.canvas.tabIndex = 0; // arrows orbit, + and - zoom
    p.canvas.addEventListener('keydown', (e) => {
      const step = { ArrowLeft: [5, 0, 1], ArrowRight: [-5, 0, 1], ArrowUp: [0, 5, 1], ArrowDown: [0, -5, 1],
        '+': [0, 0, 1 / 1.1], '=': [0, 0, 1 / 1.1], '-': [0, 0, 1.1] }[e.key];
      if (!step) return;
      e.preventDefault();
      az += step[0];
      el = Math.max(-89, Math.min(89, el + step[1]));
      dist = Math.max(0.01, Math.min(1e4, dist * step[2]));
      redraw();
    });
    p.canvas.addEventListener('wheel', (e) => {
      e.preventDefault();
      dist = Math.max(0.01, Math.min(1e4, dist * Math.exp(e.deltaY * 0.001)));
      redraw();
    }, { passive: false });
  }
  // reliefkit bench viewer's orbit: draw AZ,EL,DIST (DIST null: framed) now; resolves after
  // the browser has had the frame, with the timer query's result where it has one
  state.setView = (a, e, d = null) => {
    [az, el, dist] = [a, e, d];
    render();
    return new Promise((resolve) => setTimeout(() => resolve({ frameMs: state.frameMs, gpuMs: state.gpuMs }), 60));
  };
  render();
}

main().catch((e) => report(`error: ${e.message}`)).finally(() => { state.loaded = true; });
