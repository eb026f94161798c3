// reliefkit's viewer page: every input of `reliefkit view` (inputs.json: its GLB, kind and
// framing bounds) drawn side by side from one camera by the WebGL2 executor. The view is in
// the URL (?view=AZ,EL,DIST&size=WxH&light=AZ,EL and the render options that differ from
// their defaults, kept up to date; target=X,Y,Z once panned); navigation.js orbits, pans and
// zooms by mouse, touch and keys; controls.js switches render options and moves the light;
// ?debug=normals|depth|iterations|mask shows a debug view instead (debug_views.js).
// window.reliefkit.ready turns true after the first complete frame (frameMs, gpuMs and each
// panel's counts are the latest frame's; setView(az, el, dist) draws a view: the bench's
// orbit); errors show in the page and are posted to the server's log.

import { lightFrom, parseLight, parseSize, parseView } from './camera.js';
import { lightControls, optionControls } from './controls.js';
import { DebugViews } from './debug_views.js';
import { makeDrawable } from './drawable.js';
import { createContext, createTargets } from './executor.js';
import { drawOf, parseGlb } from './glb.js';
import { Navigation, parseTarget } from './navigation.js';

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
  if (response.status === 400 && (response.headers.get('Content-Type') || '').startsWith('text/plain')) {
    throw new Error(await response.text()); // the server's one-line message (a bad render option)
  }
  if (!response.ok) throw new Error(`cannot load ${url} (${response.status} ${response.statusText})`);
  return response;
}

/** The GLB at ``url`` (the panel's `glb` and `draw`, which the debug views read too) with its
 *  executor and plans; a plan it cannot draw is said and left out. */
async function loadPlans(gl, url, input, programs) {
  const glb = parseGlb(await (await fetchOk(url)).arrayBuffer(), input.name);
  const draw = drawOf(glb);
  return { glb, draw, ...await makeDrawable(gl, glb, draw, input.name, programs, report) };
}

/** ``panel``'s plans made again with the render options of ``query``: {swap, discard}. */
async function reloadPanel(panel, query, programs) {
  const loaded = await loadPlans(panel.executor.gl, `${panel.input.file}?${query}`, panel.input, programs);
  return {
    swap() {
      panel.executor.dispose();
      DebugViews.forget(panel);
      Object.assign(panel, loaded);
    },
    discard() { loaded.executor.dispose(); },
  };
}

/** One input's panel: its canvas, executor, plans and targets, or its error. */
async function openInput(input, index, size, programs) {
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
    const loaded = await loadPlans(gl, input.file, input, programs);
    return { canvas, input, index, targets: createTargets(gl, size), gl, panel, ...loaded };
  } catch (e) {
    report(`${input.name}: ${e.message}`);
    return null;
  }
}

/** The page's own URL parameters (render options are the inputs' flags). */
const PAGE_PARAMETERS = ['view', 'size', 'light', 'target', 'debug'];

/** The URL's ``name`` parsed, or where it does not parse, ``fallback``'s, said (the page opens
 *  on the default rather than not at all) and dropped from the URL. */
function fromUrl(params, name, parse, fallback) {
  if (params.has(name)) {
    try {
      return parse(params.get(name));
    } catch (e) {
      report(`error: ${e.message}; showing the default`);
      params.delete(name);
    }
  }
  return fallback === null ? null : parse(fallback);
}

/** URL parameters that are neither the page's nor a render option of an input: said, and
 *  dropped (the CLI refuses such flags too). */
function unknownParameters(params, inputs) {
  const flags = new Set(inputs.flatMap((i) => (i.options || []).map((o) => o.flag)));
  for (const name of [...params.keys()]) {
    if (PAGE_PARAMETERS.includes(name) || flags.has(name)) continue;
    report(`error: the URL's ${name}=${params.get(name)} is no parameter of this page (${PAGE_PARAMETERS.join(', ')}) `
      + `and no render option of its inputs${flags.size ? ` (${[...flags].join(', ')})` : ''}: ignored`);
    params.delete(name);
  }
}

function union(boxes) {
  return [0, 1].map((k) => [0, 1, 2].map((i) => (k ? Math.max : Math.min)(...boxes.map((b) => b[k][i]))));
}

async function main() {
  if (location.protocol === 'file:') {
    throw new Error('this page was opened as a file: browsers let no page read the files beside it. '
      + 'Serve its folder and open the address printed: python -m http.server -d FOLDER');
  }
  const params = new URLSearchParams(location.search);
  const manifest = await (await fetchOk('inputs.json')).json();
  const frame = manifest.camera;
  unknownParameters(params, manifest.inputs);
  const size = fromUrl(params, 'size', parseSize, frame.default_size);
  const [lightAz, lightEl] = fromUrl(params, 'light', parseLight, manifest.light.angles);
  let light = lightFrom(manifest.light, lightAz, lightEl);
  const opening = { view: fromUrl(params, 'view', parseView, frame.default_view),
    target: fromUrl(params, 'target', parseTarget, null) };
  const nav = new Navigation(opening, union(manifest.inputs.map((i) => i.bounds)), size, frame);
  const panels = (await Promise.all(manifest.inputs.map((i, k) => openInput(i, k, size, manifest.programs)))).filter(Boolean);
  if (!panels.length) return; // each said why; nothing is drawn, so never ready
  const debug = new DebugViews(params, manifest, panels, report);

  const readout = document.getElementById('stats');
  const render = () => {
    const start = performance.now();
    const camera = nav.camera();
    for (const p of debug.order(panels)) debug.draw(p, camera, light);
    for (const p of panels) p.executor.finish();
    state.frameMs = performance.now() - start; // the CPU's clock around the draws and a read back
    state.counts = panels.map((p) => ({ ...p.executor.counts }));
    const shown = () => {
      const gpu = panels.map((p) => debug.executor(p).gpuTime());
      state.gpuMs = gpu.every((t) => t !== null) ? gpu.reduce((a, b) => a + b, 0) : null;
      readout.textContent = `view ${nav.az.toFixed(1)},${nav.el.toFixed(1)},${nav.dist.toFixed(3)}  ${size[0]}x${size[1]}  `
        + `frame ${state.frameMs.toFixed(1)} ms` + (state.gpuMs === null ? '' : `, GPU ${state.gpuMs.toFixed(2)} ms`)
        + (loads ? '  (making the plans with the new render options...)' : '');
    };
    shown();
    setTimeout(shown, 50); // the timer query's result, once the browser has it
    state.view = [nav.az, nav.el, nav.dist];
    state.target = camera.target;
    nav.toUrl(params);
    history.replaceState(null, '', `?${params}`); // the view stays in the URL
    state.frames += 1;
    state.ready = loads === 0;
  };
  let loads = 0; // option switches under way: not ready until they end and a frame is drawn
  let pending = false;
  const redraw = () => {
    if (!pending) {
      pending = true;
      requestAnimationFrame(() => { pending = false; render(); });
    }
  };
  debug.onChange = redraw;
  nav.onChange = redraw;
  for (const p of panels) nav.attach(p.canvas);
  await debug.ready;
  lightControls({
    form: document.getElementById('light'), angles: [lightAz, lightEl],
    onChange: (a, e) => {
      light = lightFrom(manifest.light, a, e);
      params.set('light', `${a},${e}`);
      redraw();
    },
  });
  await optionControls({
    form: document.getElementById('options'), manifest, params, panels, report,
    reload: (panel, query) => reloadPanel(panel, query, manifest.programs),
    loading: (promise) => {
      loads += 1;
      state.ready = false;
      readout.textContent += '  (making the plans with the new render options...)';
      promise.catch(() => {}).finally(async () => {
        await debug.refresh(); // a debug view's plans come from the new GLBs too
        loads -= 1;
        redraw();
      });
    },
  });
  // reliefkit bench viewer's orbit: draw AZ,EL,DIST (DIST null: framed) now; resolves after
  // the browser has had the frame, with the timer query's result where it has one
  state.setView = (a, e, d = null) => {
    nav.set(a, e, d);
    render();
    return new Promise((resolve) => setTimeout(() => resolve({ frameMs: state.frameMs, gpuMs: state.gpuMs }), 60));
  };
  render();
}

main().catch((e) => report(`error: ${e.message}`)).finally(() => { state.loaded = true; });
