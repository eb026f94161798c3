// The page's debug views (docs/viewer.md): ?debug=normals|depth|iterations|mask, or the
// selector above the pictures, shows in every panel one of its frame's AOVs instead of the
// picture, coloured by present.glsl (shaders/viewer/include/debug_views.glsl):
//   normals     the world normal as n * 0.5 + 0.5
//   depth       the view distance as grey, white at the near side of the bounding sphere the
//               camera frames, black at its far side
//   iterations  the loop count that `render --stats` averages as iterations_mean (the
//               instrumented plans' primary count, over the pixels a counting fragment ran
//               on) on metrics.heat_ramp from 0 to the frame's max
//   mask        metrics.error_image(this, the mesh, "mask"): the coverage against the first
//               mesh input's, read back from its panel (each panel has its own context)
// A panel that cannot show one says why in its caption.

import { makeDrawable } from './drawable.js';
import { createTargets } from './executor.js';
import { releaseAll } from './gl_objects.js';

/** The views by name, present.glsl's u_debug; absent (picture) is 0. */
const MODES = { picture: 0, normals: 1, depth: 2, iterations: 3, mask: 4 };
const ITERATIONS_ATTACHMENT = 3; // RK_FRAME_ATTACHMENTS: iterations.glsl's f_iterations

export class DebugViews {
  /** ``params``: the page's URL parameters (``debug`` read, and kept up to date);
   *  ``report``: the page's error line. */
  constructor(params, manifest, panels, report) {
    this.params = params;
    this.panels = panels;
    this.report = report;
    this.ramp = manifest.heat_ramp;
    this.programs = manifest.programs;
    this.reference = panels.find((p) => p.input.kind === 'mesh') || null;
    this.onChange = () => {};
    this.state = window.reliefkit.debug = { mode: 'picture', notes: [], iterations: [] };
    for (const p of panels) {
      p.note = document.createElement('p');
      p.note.className = 'note';
      p.panel.appendChild(p.note);
    }
    let mode = params.get('debug') || 'picture';
    if (!(mode in MODES)) {
      report(`error: debug must be one of ${Object.keys(MODES).join(', ')}, got '${mode}'`);
      mode = 'picture';
    }
    this.makeSelector(mode);
    this.ready = this.select(mode);
  }

  /** The selector above the pictures, showing ``mode``. */
  makeSelector(mode) {
    const label = document.createElement('label');
    label.id = 'debug-views';
    label.textContent = 'show ';
    const select = document.createElement('select');
    for (const name of Object.keys(MODES)) select.add(new Option(name, name, false, name === mode));
    select.addEventListener('change', () => this.select(select.value).then(() => this.onChange()));
    label.appendChild(select);
    document.getElementById('panels').before(label);
  }

  /** Switch to ``mode``: the URL follows; the instrumented plans are made when first needed. */
  async select(mode) {
    this.mode = mode;
    this.state.mode = mode;
    if (mode === 'picture') this.params.delete('debug');
    else this.params.set('debug', mode);
    if (mode === 'iterations') {
      await Promise.all(this.panels.map((p) => this.counting(p)));
      if (this.mode !== mode) return; // another view was picked meanwhile
    }
    for (const p of this.panels) {
      const reference = mode === 'mask' && p === this.reference ? 'the reference of the mask difference' : '';
      this.setNote(p, this.unavailable(p) || reference);
    }
  }

  /** Free ``p``'s iteration-counting plans and targets (its render options changed: they are
   *  made again from its new GLB when next needed). */
  static forget(p) {
    if (p.counting) {
      p.counting.executor.dispose();
      releaseAll(p.gl, p.counting.targets);
    }
    delete p.counting;
  }

  /** The current view again, after panels' plans were replaced. */
  refresh() {
    return this.select(this.mode);
  }

  /** The panel's iteration-counting plans and their targets (one more attachment), made
   *  once; null for a kind whose export has none. */
  async counting(p) {
    if (p.counting === undefined) {
      p.counting = null;
      if (p.draw.instrumented) {
        try {
          const made = await makeDrawable(p.gl, p.glb, p.draw.instrumented, p.input.name, this.programs, this.report);
          p.counting = { ...made, targets: createTargets(p.gl, p.targets.size, 1) };
        } catch (e) {
          this.report(`${p.input.name}: ${e.message}`);
        }
      }
    }
    return p.counting;
  }

  /** Why ``p`` cannot show the current view (it shows the picture then), or null. */
  unavailable(p) {
    if (this.mode === 'iterations' && !p.counting) return `no iteration counts for ${p.input.kind}`;
    if (this.mode === 'mask' && !this.reference) return `mask difference needs the mesh as another input: reliefkit view ${p.input.name} MESH`;
    return null;
  }

  setNote(p, text) {
    p.note.textContent = text;
    this.state.notes[this.panels.indexOf(p)] = text;
  }

  /** The panels in the order they draw: the mask's reference first. */
  order(panels) {
    if (this.mode !== 'mask' || !this.reference) return panels;
    return [this.reference, ...panels.filter((p) => p !== this.reference)];
  }

  /** The view ``p`` shows now: the current one, or the picture where it cannot. */
  shown(p) {
    return this.unavailable(p) ? 'picture' : this.mode;
  }

  /** The executor that draws ``p`` now (its GPU time is the panel's). */
  executor(p) {
    return this.shown(p) === 'iterations' ? p.counting.executor : p.executor;
  }

  /** Draw panel ``p`` from ``camera`` and show the current view. */
  draw(p, camera, light) {
    const mode = this.shown(p);
    const { plans, targets } = mode === 'iterations' ? p.counting : p;
    const executor = this.executor(p);
    executor.frame(plans, camera, light, targets, (drawn) => this.presenting(p, mode, drawn, camera));
  }

  /** present.glsl's uniforms and textures of ``mode`` for the panel's drawn ``targets``. */
  presenting(p, mode, targets, camera) {
    if (mode === 'picture') return {};
    const uniforms = { u_debug: MODES[mode], u_heat_ramp: this.ramp };
    const textures = { u_normal: targets.normal };
    if (mode === 'depth') {
      const toEye = camera.eye.map((x, i) => x - camera.target[i]);
      const distance = Math.hypot(...toEye);
      const radius = distance / camera.distance; // orbitBounds: the distance in radii
      uniforms.u_eye = camera.eye.map((x, i) => x - camera.origin[i]);
      uniforms.u_depth_range = [distance - radius, distance + radius];
    } else if (mode === 'iterations') {
      const counts = this.iterations(p, readAttachment(p.gl, targets, ITERATIONS_ATTACHMENT));
      uniforms.u_iteration_scale = counts.max > 0 ? counts.max : 1;
      textures.u_iterations = targets.iterations;
    } else if (mode === 'mask') {
      if (p === this.reference) this.referenceMask = coverage(readAttachment(p.gl, targets, 1));
      textures.u_reference = uploadMask(p, this.referenceMask, targets.size);
    }
    return { uniforms, textures };
  }

  /** render/draw.py _iteration_stats' iterations_mean and iterations_max of the counts,
   *  shown in the panel's caption and kept in window.reliefkit.debug.iterations. */
  iterations(p, counts) {
    let fragments = 0, sum = 0, max = 0;
    for (let i = 0; i < counts.length; i += 4) {
      if (counts[i + 2] <= 0.5) continue; // no counting fragment ran here
      fragments += 1;
      sum += counts[i];
      max = Math.max(max, counts[i]);
    }
    const seen = { fragments, mean: fragments ? sum / fragments : 0, max };
    this.state.iterations[this.panels.indexOf(p)] = seen;
    this.setNote(p, `iterations: mean ${seen.mean.toFixed(2)}, max ${seen.max} (heat ramp 0..${seen.max})`);
    return seen;
  }
}

/** One RGBA32F attachment of the opaque pass's framebuffer, bottom row first. */
function readAttachment(gl, targets, index) {
  const [w, h] = targets.size;
  const out = new Float32Array(w * h * 4);
  gl.bindFramebuffer(gl.READ_FRAMEBUFFER, targets.fbo);
  gl.readBuffer(gl.COLOR_ATTACHMENT0 + index);
  gl.readPixels(0, 0, w, h, gl.RGBA, gl.FLOAT, out);
  gl.readBuffer(gl.COLOR_ATTACHMENT0);
  gl.bindFramebuffer(gl.READ_FRAMEBUFFER, null);
  return out;
}

/** The coverage (position.w > 0.5) of a read-back position target, one byte a pixel. */
function coverage(position) {
  const out = new Uint8Array(position.length / 4);
  for (let i = 0; i < out.length; i++) out[i] = position[4 * i + 3] > 0.5 ? 255 : 0;
  return out;
}

/** The reference's coverage as an R8 texture of the panel's own context. */
function uploadMask(p, mask, [w, h]) {
  const gl = p.gl;
  if (!p.referenceTexture) {
    p.referenceTexture = { tex: gl.createTexture(), target: gl.TEXTURE_2D };
    gl.bindTexture(gl.TEXTURE_2D, p.referenceTexture.tex);
    for (const param of [gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER]) gl.texParameteri(gl.TEXTURE_2D, param, gl.NEAREST);
  }
  gl.bindTexture(gl.TEXTURE_2D, p.referenceTexture.tex);
  gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
  gl.texImage2D(gl.TEXTURE_2D, 0, gl.R8, w, h, 0, gl.RED, gl.UNSIGNED_BYTE, mask);
  gl.pixelStorei(gl.UNPACK_ALIGNMENT, 4);
  return p.referenceTexture;
}
