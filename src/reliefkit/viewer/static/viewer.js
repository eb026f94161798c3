(() => {
  // web/src/camera.js
  var rad = (deg) => deg * Math.PI / 180;
  var sub = (a, b) => a.map((x, i) => x - b[i]);
  var norm = (a) => Math.hypot(...a);
  var scale = (a, s) => a.map((x) => x * s);
  var cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  function parseView(text) {
    const parts = text.split(",").map(Number);
    if (![2, 3].includes(parts.length) || !parts.every(Number.isFinite) || Math.abs(parts[1]) >= 90 || parts.length === 3 && !(parts[2] > 0)) {
      throw new Error(`view must be AZ,EL or AZ,EL,DIST with |EL| < 90 (e.g. 30,25,2.6), got '${text}'`);
    }
    return [parts[0], parts[1], parts.length === 3 ? parts[2] : null];
  }
  function parseLight(text) {
    const parts = text.split(",").map(Number);
    if (parts.length !== 2 || !parts.every(Number.isFinite) || Math.abs(parts[1]) > 90) {
      throw new Error(`light must be AZ,EL in degrees with an elevation within [-90, 90] (e.g. -60,30), got '${text}'`);
    }
    return parts;
  }
  function parseSize(text) {
    const m = /^(\d{1,5})x(\d{1,5})$/.exec(text);
    if (!m || +m[1] < 1 || +m[2] < 1 || +m[1] > 8192 || +m[2] > 8192) {
      throw new Error(`size must be WxH within 1..8192 (e.g. 512x512), got '${text}'`);
    }
    return [+m[1], +m[2]];
  }
  function lookAt(eye, target, up = [0, 1, 0]) {
    const forward2 = sub(target, eye);
    const f = scale(forward2, 1 / norm(forward2));
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
  function perspective(fovDeg, aspect, near, far) {
    const f = 1 / Math.tan(rad(fovDeg) / 2);
    const p = new Array(16).fill(0);
    p[0] = f / aspect;
    p[5] = f;
    p[10] = (far + near) / (near - far);
    p[11] = 2 * far * near / (near - far);
    p[14] = -1;
    return p;
  }
  function orthographic(halfHeight, aspect, near, far) {
    const p = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1];
    p[0] = 1 / (halfHeight * aspect);
    p[5] = 1 / halfHeight;
    p[10] = -2 / (far - near);
    p[11] = -(far + near) / (far - near);
    return p;
  }
  function lightCamera(bounds2, direction, size) {
    const [lo, hi] = bounds2;
    const centre = [0, 1, 2].map((i) => (lo[i] + hi[i]) / 2);
    const radius = norm(sub(hi, lo)) / 2 || 1;
    const towards = scale(direction, 1 / norm(direction));
    const up = Math.abs(towards[1]) > 0.99 ? [1, 0, 0] : [0, 1, 0];
    const eye = centre.map((c, i) => c + 2 * radius * towards[i]);
    const [near, far] = [0.5 * radius, 3.5 * radius];
    return {
      eye,
      target: centre,
      up,
      fov_deg: 40,
      size: [size, size],
      near,
      far,
      ortho_height: radius,
      origin: centre,
      view: lookAt(eye, centre, up),
      proj: orthographic(radius, 1, near, far)
    };
  }
  function orbitBounds(bounds2, az, el, dist, size, frame, target = null) {
    const [w, h] = size;
    if (dist === null) {
      const halfV = rad(frame.fov) / 2;
      const halfH = Math.atan(Math.tan(halfV) * w / h);
      dist = frame.fit_margin / Math.sin(Math.min(halfV, halfH));
    }
    const diag = norm(sub(bounds2[1], bounds2[0])) / 2;
    const radius = diag > 0 ? diag : 1;
    const d = dist * radius;
    const centre = [0, 1, 2].map((i) => (bounds2[0][i] + bounds2[1][i]) / 2);
    const orbited = target || centre;
    const [a, e] = [rad(az), rad(el)];
    const eye = [0, 1, 2].map((i) => orbited[i] + d * [Math.cos(e) * Math.sin(a), Math.sin(e), Math.cos(e) * Math.cos(a)][i]);
    const toCentre = target ? norm(sub(centre, eye)) : d;
    const near = Math.max(toCentre - 1.05 * radius, 5e-3 * d);
    const far = toCentre + 1.05 * radius;
    return {
      eye,
      target: orbited,
      up: [0, 1, 0],
      fov_deg: frame.fov,
      size,
      near,
      far,
      ortho_height: null,
      origin: orbited,
      view: lookAt(eye, orbited),
      proj: perspective(frame.fov, w / h, near, far),
      distance: dist
    };
  }
  function cameraUniforms(camera) {
    const origin = camera.origin;
    const view = multiply(camera.view, translation(origin));
    const toEye = sub(camera.eye, camera.target);
    return {
      u_view: matrix(view),
      u_proj: matrix(camera.proj),
      u_inv_view_proj: matrix(invert(multiply(camera.proj, view))),
      u_eye: sub(camera.eye, origin),
      u_orthographic: camera.ortho_height != null,
      u_view_dir: scale(toEye, 1 / norm(toEye)),
      u_viewport: camera.size
    };
  }
  function modelOffset(camera, origin) {
    return { u_model_offset: sub(origin || [0, 0, 0], camera.origin) };
  }
  function lightFrom(fields, az, el) {
    const [a, e] = [rad(az), rad(el)];
    const direction = [Math.cos(e) * Math.sin(a), Math.sin(e), Math.cos(e) * Math.cos(a)];
    return { direction, uniforms: { ...fields.uniforms, u_light_dir: direction } };
  }
  function matrix(rows) {
    return { shape: [4, 4], dtype: "float64", data: rows };
  }
  function identity() {
    return [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1];
  }
  function translation(t) {
    const m = identity();
    [m[3], m[7], m[11]] = t;
    return m;
  }
  function multiply(a, b) {
    const out = new Array(16).fill(0);
    for (let r = 0; r < 4; r++) for (let c = 0; c < 4; c++) for (let k = 0; k < 4; k++) out[r * 4 + c] += a[r * 4 + k] * b[k * 4 + c];
    return out;
  }
  function invert(m) {
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

  // web/src/controls.js
  function asText(value) {
    if (value === null || value === void 0) return "";
    if (Array.isArray(value)) return value.map(String).join(",");
    return String(value);
  }
  function sameValue(opt, a, b) {
    if (["int", "float", "floats"].includes(opt.kind) && a !== "" && b !== "") {
      const [x, y] = [a, b].map((t) => t.split(",").map(Number));
      return x.length === y.length && x.every((v, i) => v === y[i]);
    }
    return a === b;
  }
  function optionUnion(inputs) {
    const union2 = /* @__PURE__ */ new Map();
    inputs.forEach((input, index) => {
      for (const opt of input.options || []) {
        if (!union2.has(opt.flag)) union2.set(opt.flag, { opt, owners: [] });
        union2.get(opt.flag).owners.push(index);
      }
    });
    return union2;
  }
  function optionQuery(input, values) {
    const query = new URLSearchParams();
    for (const opt of input.options) query.set(opt.flag, values[opt.flag]);
    return query.toString();
  }
  function optionControls({ form, manifest, params, panels, reload, loading, report: report2 }) {
    const inputs = manifest.inputs;
    const union2 = optionUnion(inputs);
    const current = inputs.map((input) => Object.fromEntries(
      (input.options || []).map((o) => [o.flag, asText(o.value)])
    ));
    const shown = (flag) => current[union2.get(flag).owners[0]][flag];
    const defaultOf = (k, flag) => asText(inputs[k].options.find((o) => o.flag === flag).default);
    const syncUrl = () => {
      for (const [flag, { opt, owners }] of union2) {
        const differs = owners.some((k) => !sameValue(opt, current[k][flag], defaultOf(k, flag)));
        if (differs) params.set(flag, shown(flag));
        else params.delete(flag);
      }
      history.replaceState(null, "", `?${params}`);
    };
    let queue = Promise.resolve();
    const apply = (flag, text) => {
      const { owners } = union2.get(flag);
      queue = queue.then(async () => {
        const targets = panels.filter((p) => owners.includes(p.index) && current[p.index][flag] !== text);
        const wanted = new Map(targets.map((p) => [p, { ...current[p.index], [flag]: text }]));
        const loads = await Promise.allSettled(targets.map((p) => reload(p, optionQuery(inputs[p.index], wanted.get(p)))));
        const failed = loads.filter((r) => r.status === "rejected");
        if (failed.length) {
          for (const r of loads) if (r.status === "fulfilled") r.value.discard();
          for (const r of failed) report2(r.reason.message);
        } else {
          for (const r of loads) r.value.swap();
          for (const [p, values] of wanted) current[p.index] = values;
        }
        setControl(flag, shown(flag));
        syncUrl();
      });
      loading(queue);
      return queue;
    };
    const controls = /* @__PURE__ */ new Map();
    const setControl = (flag, text) => {
      const input = controls.get(flag);
      if (input.type === "checkbox") input.checked = text === "true";
      else input.value = text;
    };
    form.replaceChildren();
    form.addEventListener("submit", (e) => e.preventDefault());
    for (const [flag, { opt, owners }] of union2) {
      const label = document.createElement("label");
      const kinds = [...new Set(owners.map((k) => inputs[k].kind))].join(", ");
      label.title = `${opt.help} (applies to: ${kinds})`;
      const name = document.createElement("span");
      name.textContent = `--${flag}`;
      const input = control(opt);
      input.id = `option-${flag}`;
      input.name = flag;
      input.disabled = !manifest.live;
      const small = document.createElement("small");
      small.textContent = kinds;
      label.append(name, input, small);
      form.appendChild(label);
      controls.set(flag, input);
      setControl(flag, shown(flag));
      input.addEventListener("change", () => apply(flag, input.type === "checkbox" ? String(input.checked) : input.value));
    }
    if (!union2.size) return Promise.resolve();
    if (!manifest.live) {
      const why = document.createElement("p");
      why.className = "why";
      why.textContent = "This static export holds the plans made with these options: run `reliefkit view` on its inputs with other render options (or export again with them) to change them.";
      form.appendChild(why);
    }
    const asked = [...union2].filter(([flag]) => params.has(flag));
    for (const [flag, { opt, owners }] of asked) {
      const text = params.get(flag);
      const differing = owners.filter((k) => !sameValue(opt, current[k][flag], text));
      if (!differing.length) continue;
      if (manifest.live) apply(flag, text);
      else {
        report2(`the URL asks for ${flag}=${text}, but this static export holds the plans made with ${flag}=${current[differing[0]][flag]} (export again with --${flag} ${text} to see them)`);
      }
    }
    return queue.then(syncUrl);
  }
  function control(opt) {
    if (opt.choices) {
      const select = document.createElement("select");
      const choices = (opt.default === null ? [""] : []).concat(opt.choices.map(String));
      for (const choice of choices) {
        const option = document.createElement("option");
        option.value = choice;
        option.textContent = choice === "" ? "(none)" : choice;
        select.appendChild(option);
      }
      return select;
    }
    const input = document.createElement("input");
    if (opt.kind === "bool") {
      input.type = "checkbox";
      return input;
    }
    if (opt.kind === "int" || opt.kind === "float") {
      input.type = "number";
      input.step = opt.kind === "int" ? "1" : "any";
      if (opt.lo !== null) input.min = String(opt.lo);
      if (opt.hi !== null) input.max = String(opt.hi);
    } else input.type = "text";
    if (opt.default === null) input.placeholder = "none";
    return input;
  }
  function lightControls({ form, angles, onChange }) {
    form.addEventListener("submit", (e) => e.preventDefault());
    const sliders = [["azimuth", -180, 180, angles[0]], ["elevation", -90, 90, angles[1]]].map(([what, lo, hi, value]) => {
      const label = document.createElement("label");
      label.title = `the light's ${what} in degrees (render --light AZ,EL)`;
      const name = document.createElement("span");
      name.textContent = `light ${what}`;
      const input = document.createElement("input");
      Object.assign(input, { type: "range", min: String(lo), max: String(hi), step: "1", value: String(value), id: `light-${what}` });
      const readout = document.createElement("output");
      readout.textContent = String(value);
      label.append(name, input, readout);
      form.appendChild(label);
      return [input, readout];
    });
    for (const [input, readout] of sliders) {
      input.addEventListener("input", () => {
        readout.textContent = input.value;
        onChange(Number(sliders[0][0].value), Number(sliders[1][0].value));
      });
    }
  }

  // web/src/plans.js
  function decode(value, arrays) {
    if (Array.isArray(value)) return value.map((v) => decode(v, arrays));
    if (value === null || typeof value !== "object") return value;
    if ("array" in value) return arrays[value.array];
    if ("scalar" in value) return value.value;
    if ("tuple" in value) return value.tuple.map((v) => decode(v, arrays));
    if ("encoded" in value) return { encoded: decodeFields(value.encoded, arrays) };
    return decodeFields(value.dict, arrays);
  }
  function decodeFields(object, arrays) {
    return Object.fromEntries(Object.entries(object).map(([k, v]) => [k, decode(v, arrays)]));
  }
  function decodePlans(draw, arrays) {
    const geometries = {};
    for (const [key, g] of Object.entries(draw.geometries)) {
      const { attributes, ...rest } = g;
      const attrs = Object.fromEntries(Object.entries(attributes).map(([name, a]) => {
        const [array, perInstance] = decode(a, arrays);
        return [name, { array, per_instance: perInstance }];
      }));
      geometries[key] = { key, attributes: attrs, ...decodeFields(rest, arrays) };
    }
    const textures = {};
    for (const [key, t] of Object.entries(draw.textures)) textures[key] = { key, ...decodeFields(t, arrays) };
    return draw.plans.map((entry) => {
      const [name, defines] = decode(entry.program, arrays);
      const multipass = decode(entry.multipass, arrays);
      const hook = decode(entry.per_view, arrays);
      return {
        name: entry.name,
        program: { name, defines },
        geometry: geometries[entry.geometry],
        textures: Object.fromEntries(Object.entries(entry.textures).map(([s, k]) => [s, textures[k]])),
        uniforms: decode(entry.uniforms, arrays),
        raster: decode(entry.raster, arrays),
        render_pass: entry.render_pass,
        origin: decode(entry.origin, arrays),
        first: entry.first,
        count: entry.count,
        per_view: hook && { function: hook[0], data: hook[1] },
        multipass: multipass && { kind: multipass[0], programs: multipass[1], params: multipass[2] }
      };
    });
  }
  function programKey(name, defines) {
    const sorted = Object.keys(defines || {}).sort().map((k) => [k, defines[k]]);
    return `${name} ${JSON.stringify(sorted)}`;
  }
  function withView(plan, update) {
    let geometry = plan.geometry;
    const { attributes = {}, indices, vertices, instances } = update;
    if (Object.keys(attributes).length || indices != null || vertices != null || instances != null) {
      geometry = {
        ...geometry,
        attributes: Object.fromEntries(Object.entries(geometry.attributes).map(
          ([name, attr]) => [name, { ...attr, array: attributes[name] || attr.array }]
        )),
        indices: indices != null ? indices : geometry.indices,
        vertices: vertices != null ? vertices : geometry.vertices,
        instances: instances != null ? instances : geometry.instances
      };
    }
    const params = update.params && Object.keys(update.params).length ? update.params : null;
    return {
      ...plan,
      geometry,
      raster: update.cull != null ? { ...plan.raster, cull: update.cull } : plan.raster,
      count: update.count != null ? update.count : plan.count,
      multipass: params ? { ...plan.multipass, params: { ...plan.multipass.params, ...params } } : plan.multipass,
      uniforms: { ...plan.uniforms, ...update.uniforms || {} }
    };
  }

  // web/src/gl_objects.js
  function releaseAll(gl, value) {
    if (value instanceof WebGLTexture) gl.deleteTexture(value);
    else if (value instanceof WebGLFramebuffer) gl.deleteFramebuffer(value);
    else if (value instanceof WebGLRenderbuffer) gl.deleteRenderbuffer(value);
    else if (Array.isArray(value)) for (const v of value) releaseAll(gl, v);
    else if (value && typeof value === "object" && Object.getPrototypeOf(value) === Object.prototype) {
      for (const v of Object.values(value)) releaseAll(gl, v);
    }
  }

  // web/src/shadow_map.js
  function drawShadowMapped(executor, plan, camera, light, outer, extra = {}) {
    const [uniforms, textures] = shadowInputs(executor, plan, light, outer);
    executor.drawViewed(plan, camera, light, { uniforms: { ...extra.uniforms, ...uniforms }, textures });
  }
  function shadowInputs(executor, plan, light, outer, params = plan.multipass.params) {
    const key = `shadow-map ${plan.geometry.key}`;
    const direction = light.direction.join(",");
    const made = executor.cache.get(key);
    if (made && made.direction !== direction) {
      releaseAll(executor.gl, made);
      executor.cache.delete(key);
    }
    if (!executor.cache.has(key)) {
      const gl = executor.gl;
      const size = Number(params.size);
      const bounds2 = nested(params.bounds);
      const cam = lightCamera(bounds2, light.direction, size);
      const depth = gl.createTexture();
      gl.bindTexture(gl.TEXTURE_2D, depth);
      gl.texImage2D(gl.TEXTURE_2D, 0, gl.DEPTH_COMPONENT32F, size, size, 0, gl.DEPTH_COMPONENT, gl.FLOAT, null);
      const fbo = gl.createFramebuffer();
      gl.bindFramebuffer(gl.FRAMEBUFFER, fbo);
      gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.DEPTH_ATTACHMENT, gl.TEXTURE_2D, depth, 0);
      gl.drawBuffers([gl.NONE]);
      gl.viewport(0, 0, size, size);
      gl.depthMask(true);
      gl.clearBufferfv(gl.DEPTH, 0, [1]);
      const raster = { depth_test: true, depth_write: true, cull: params.cull || "none", blend: "none" };
      for (const caster of executor.groups.get(plan.geometry.key) || [plan]) {
        const viewed = params.caster_hooks === false ? caster : executor.view(caster, cam, light);
        executor.drawViewed(viewed, cam, light, { program: caster.multipass.programs.caster, raster });
      }
      gl.bindFramebuffer(gl.FRAMEBUFFER, null);
      gl.deleteFramebuffer(fbo);
      outer();
      gl.bindTexture(gl.TEXTURE_2D, depth);
      const compare = (params.sampler || "compare") === "compare";
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_COMPARE_MODE, compare ? gl.COMPARE_REF_TO_TEXTURE : gl.NONE);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_COMPARE_FUNC, gl.LEQUAL);
      for (const p of [gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER]) gl.texParameteri(gl.TEXTURE_2D, p, compare ? gl.LINEAR : gl.NEAREST);
      for (const p of [gl.TEXTURE_WRAP_S, gl.TEXTURE_WRAP_T]) gl.texParameteri(gl.TEXTURE_2D, p, gl.CLAMP_TO_EDGE);
      const texel = 2 * cam.ortho_height / size;
      const uniforms = {
        u_light_matrix: matrix(multiply(multiply(cam.proj, cam.view), translation(plan.origin || [0, 0, 0]))),
        u_shadow_texel: texel,
        u_shadow_bias: "bias" in params ? Number(params.bias) : texel / (cam.far - cam.near)
      };
      executor.cache.set(key, { direction, inputs: [uniforms, { u_shadow_map: { tex: depth, target: gl.TEXTURE_2D } }] });
    }
    return executor.cache.get(key).inputs;
  }
  function nested(box) {
    if (box && box.data) return [Array.from(box.data.slice(0, 3), Number), Array.from(box.data.slice(3, 6), Number)];
    return box;
  }

  // web/src/opaque_depth.js
  function drawWithOpaqueDepth(executor, plan, camera, light, outer, extra) {
    const [uniforms, textures] = opaqueDepthInputs(executor, plan, light, outer, extra.targets);
    executor.drawViewed(plan, camera, light, { uniforms: { ...extra.uniforms, ...uniforms }, textures });
  }
  function opaqueDepthInputs(executor, plan, light, outer, targets) {
    const gl = executor.gl;
    const [w, h] = targets.size;
    let [uniforms, textures] = [{}, {}];
    if (plan.multipass.params.shadow_map) {
      [uniforms, textures] = shadowInputs(executor, plan, light, outer, plan.multipass.params.shadow_map);
    }
    gl.bindFramebuffer(gl.FRAMEBUFFER, targets.depthCopyFbo);
    gl.viewport(0, 0, w, h);
    executor.drawFullScreen(executor.copyDepth, { u_depth: targets.depth });
    const depth = new Float32Array(w * h * 4);
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.FLOAT, depth);
    outer();
    return [{ ...uniforms, u_clip_opaque: depth.some((z) => z < 1) }, { ...textures, u_opaque_depth: targets.depthCopy }];
  }

  // web/src/depth_peel.js
  var BEYOND = 2;
  var COMPOSITE = { depth_test: false, depth_write: false, cull: "none", blend: "under" };
  function drawDepthPeeled(executor, plan, camera, light, outer, extra) {
    const gl = executor.gl;
    const [uniforms, textures] = opaqueDepthInputs(executor, plan, light, outer, extra.targets);
    const [w, h] = extra.targets.size;
    const peel = peelTargets(executor, w, h);
    const raster = { ...plan.raster, depth_write: true, blend: "none" };
    const layer = executor.program({ name: plan.multipass.programs.layer[0], defines: plan.multipass.programs.layer[1] });
    gl.bindFramebuffer(gl.FRAMEBUFFER, peel.fbos[1]);
    gl.clearBufferfv(gl.COLOR, 1, [-1, -1, -1, -1]);
    const depth = new Float32Array(w * h * 4);
    let layers = 0;
    for (let k = 0; k < Number(plan.multipass.params.max_layers); k++) {
      const [fbo, before] = [peel.fbos[k % 2], peel.peeled[(k + 1) % 2]];
      gl.bindFramebuffer(gl.FRAMEBUFFER, fbo);
      gl.viewport(0, 0, w, h);
      gl.depthMask(true);
      gl.clearBufferfv(gl.COLOR, 0, [0, 0, 0, 0]);
      gl.clearBufferfv(gl.COLOR, 1, [BEYOND, BEYOND, BEYOND, BEYOND]);
      gl.clearBufferfv(gl.DEPTH, 0, [1]);
      executor.drawViewed(plan, camera, light, {
        uniforms: { ...extra.uniforms, ...uniforms },
        textures: { ...textures, u_peel_depth: before },
        raster
      });
      gl.readBuffer(gl.COLOR_ATTACHMENT1);
      gl.readPixels(0, 0, w, h, gl.RGBA, gl.FLOAT, depth);
      gl.readBuffer(gl.COLOR_ATTACHMENT0);
      if (!depth.some((z, i) => i % 4 === 0 && z !== BEYOND)) break;
      layers += 1;
      outer();
      executor.drawFullScreen(layer, { u_layer: peel.color }, COMPOSITE);
    }
    outer();
    return layers;
  }
  function peelTargets(executor, w, h) {
    const key = `depth-peel ${w}x${h}`;
    if (!executor.cache.has(key)) {
      const gl = executor.gl;
      const texture = (internal, format, type) => {
        const tex = gl.createTexture();
        gl.bindTexture(gl.TEXTURE_2D, tex);
        gl.texImage2D(gl.TEXTURE_2D, 0, internal, w, h, 0, format, type, null);
        for (const p of [gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER]) gl.texParameteri(gl.TEXTURE_2D, p, gl.NEAREST);
        return { tex, target: gl.TEXTURE_2D };
      };
      const color = texture(gl.RGBA32F, gl.RGBA, gl.FLOAT);
      const peeled = [0, 1].map(() => texture(gl.RGBA32F, gl.RGBA, gl.FLOAT));
      const depth = texture(gl.DEPTH_COMPONENT32F, gl.DEPTH_COMPONENT, gl.FLOAT);
      const fbos = peeled.map((z) => {
        const fbo = gl.createFramebuffer();
        gl.bindFramebuffer(gl.FRAMEBUFFER, fbo);
        gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, color.tex, 0);
        gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT1, gl.TEXTURE_2D, z.tex, 0);
        gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.DEPTH_ATTACHMENT, gl.TEXTURE_2D, depth.tex, 0);
        gl.drawBuffers([gl.COLOR_ATTACHMENT0, gl.COLOR_ATTACHMENT1]);
        return fbo;
      });
      executor.cache.set(key, { color, peeled, fbos });
    }
    return executor.cache.get(key);
  }

  // web/src/stencil_count.js
  var COUNT = { depth_test: false, depth_write: true, depth_func: "<", cull: "none", blend: "none" };
  var COPY = { depth_test: true, depth_write: true, depth_func: "<", cull: "none", blend: "none" };
  var FULL_SCREEN = { key: "full-screen triangle", attributes: {}, vertices: 3, primitive: "triangles" };
  var SOURCES = ["u_src_color", "u_src_position", "u_src_normal"];
  function drawStencilCounted(executor, plan, camera, light, outer, extra) {
    const gl = executor.gl;
    const { programs, params } = plan.multipass;
    const values = numbers(params.values);
    const ranges = numbers(params.ranges);
    const [w, h] = camera.size;
    const target = stencilTarget(executor, w, h);
    const role = (name) => ({ program: programs[name], raster: COUNT });
    gl.bindFramebuffer(gl.FRAMEBUFFER, target.fbo);
    gl.viewport(0, 0, w, h);
    gl.colorMask(true, true, true, true);
    gl.depthMask(true);
    gl.stencilMask(255);
    for (let i = 0; i < SOURCES.length; i++) gl.clearBufferfv(gl.COLOR, i, [0, 0, 0, 0]);
    gl.clearBufferfi(gl.DEPTH_STENCIL, 0, 1, 0);
    const stencil = (func, ref, op, color) => {
      gl.enable(gl.STENCIL_TEST);
      gl.stencilFunc(func, ref, 255);
      gl.stencilOp(gl.KEEP, gl.KEEP, op);
      gl.colorMask(color, color, color, color);
    };
    try {
      for (let g = 0; g < ranges.length; g += 2) {
        const span = { ...plan, first: ranges[g], count: ranges[g + 1] };
        values.forEach((value, i) => {
          stencil(gl.EQUAL, i, gl.INCR, false);
          executor.drawViewed(span, camera, light, { ...role("test"), uniforms: { ...extra.uniforms, [params.uniform]: value } });
        });
        stencil(gl.EQUAL, values.length, gl.INCR, true);
        executor.drawViewed(span, camera, light, { ...role("color"), uniforms: extra.uniforms });
        stencil(gl.GREATER, values.length, gl.ZERO, false);
        executor.drawViewed(span, camera, light, { ...role("color"), uniforms: extra.uniforms });
      }
    } finally {
      gl.disable(gl.STENCIL_TEST);
      gl.colorMask(true, true, true, true);
    }
    outer();
    const copy = {
      name: `${plan.name}: copy`,
      program: { name: programs.copy[0], defines: programs.copy[1] },
      geometry: FULL_SCREEN,
      textures: {},
      uniforms: {},
      raster: COPY,
      origin: plan.origin,
      first: 0,
      count: null
    };
    executor.drawViewed(copy, camera, light, { textures: Object.fromEntries(SOURCES.map((s, i) => [s, target.textures[i]])) });
  }
  function numbers(value) {
    if (value && value.data) return Array.from(value.data, Number);
    return Array.isArray(value) ? value.flat(Infinity).map(Number) : [Number(value)];
  }
  function stencilTarget(executor, w, h) {
    const key = `stencil-count ${w}x${h}`;
    if (!executor.cache.has(key)) {
      const gl = executor.gl;
      const fbo = gl.createFramebuffer();
      gl.bindFramebuffer(gl.FRAMEBUFFER, fbo);
      const textures = SOURCES.map((_, i) => {
        const tex = gl.createTexture();
        gl.bindTexture(gl.TEXTURE_2D, tex);
        gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, w, h, 0, gl.RGBA, gl.FLOAT, null);
        for (const p of [gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER]) gl.texParameteri(gl.TEXTURE_2D, p, gl.NEAREST);
        gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0 + i, gl.TEXTURE_2D, tex, 0);
        return { tex, target: gl.TEXTURE_2D };
      });
      const rbo = gl.createRenderbuffer();
      gl.bindRenderbuffer(gl.RENDERBUFFER, rbo);
      gl.renderbufferStorage(gl.RENDERBUFFER, gl.DEPTH24_STENCIL8, w, h);
      gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.DEPTH_STENCIL_ATTACHMENT, gl.RENDERBUFFER, rbo);
      gl.drawBuffers(SOURCES.map((_, i) => gl.COLOR_ATTACHMENT0 + i));
      const status = gl.checkFramebufferStatus(gl.FRAMEBUFFER);
      if (status !== gl.FRAMEBUFFER_COMPLETE) throw new Error(`a ${w}x${h} framebuffer with a stencil buffer is incomplete (0x${status.toString(16)})`);
      executor.cache.set(key, { fbo, textures, rbo });
    }
    return executor.cache.get(key);
  }

  // web/src/textures/bptc_tables.js
  var PARTITIONS2 = [
    "0011001100110011",
    "0001000100010001",
    "0111011101110111",
    "0001001100110111",
    "0000000100010011",
    "0011011101111111",
    "0001001101111111",
    "0000000100110111",
    "0000000000010011",
    "0011011111111111",
    "0000000101111111",
    "0000000000010111",
    "0001011111111111",
    "0000000011111111",
    "0000111111111111",
    "0000000000001111",
    "0000100011101111",
    "0111000100000000",
    "0000000010001110",
    "0111001100010000",
    "0011000100000000",
    "0000100011001110",
    "0000000010001100",
    "0111001100110001",
    "0011000100010000",
    "0000100010001100",
    "0110011001100110",
    "0011011001101100",
    "0001011111101000",
    "0000111111110000",
    "0111000110001110",
    "0011100110011100",
    "0101010101010101",
    "0000111100001111",
    "0101101001011010",
    "0011001111001100",
    "0011110000111100",
    "0101010110101010",
    "0110100101101001",
    "0101101010100101",
    "0111001111001110",
    "0001001111001000",
    "0011001001001100",
    "0011101111011100",
    "0110100110010110",
    "0011110011000011",
    "0110011010011001",
    "0000011001100000",
    "0100111001000000",
    "0010011100100000",
    "0000001001110010",
    "0000010011100100",
    "0110110010010011",
    "0011011011001001",
    "0110001110011100",
    "0011100111000110",
    "0110110011001001",
    "0110001100111001",
    "0111111010000001",
    "0001100011100111",
    "0000111100110011",
    "0011001111110000",
    "0010001011101110",
    "0100010001110111"
  ];
  var PARTITIONS3 = [
    "0011001102212222",
    "0001001122112221",
    "0000200122112211",
    "0222002200110111",
    "0000000011221122",
    "0011001100220022",
    "0022002211111111",
    "0011001122112211",
    "0000000011112222",
    "0000111111112222",
    "0000111122222222",
    "0012001200120012",
    "0112011201120112",
    "0122012201220122",
    "0011011211221222",
    "0011200122002220",
    "0001001101121122",
    "0111001120012200",
    "0000112211221122",
    "0022002200221111",
    "0111011102220222",
    "0001000122212221",
    "0000001101220122",
    "0000110022102210",
    "0122012200110000",
    "0012001211222222",
    "0110122112210110",
    "0000011012211221",
    "0022110211020022",
    "0110011020022222",
    "0011012201220011",
    "0000200022112221",
    "0000000211221222",
    "0222002200120011",
    "0011001200220222",
    "0120012001200120",
    "0000111122220000",
    "0120120120120120",
    "0120201212010120",
    "0011220011220011",
    "0011112222000011",
    "0101010122222222",
    "0000000021212121",
    "0022112200221122",
    "0022001100220011",
    "0220122102201221",
    "0101222222220101",
    "0000212121212121",
    "0101010101012222",
    "0222011102220111",
    "0002111200021112",
    "0000211221122112",
    "0222011101110222",
    "0002111211120002",
    "0110011001102222",
    "0000000021122112",
    "0110011022222222",
    "0022001100110022",
    "0022112211220022",
    "0000000000002112",
    "0002000100020001",
    "0222122202221222",
    "0101222222222222",
    "0111201122012220"
  ];
  var ANCHORS2 = [
    15,
    15,
    15,
    15,
    15,
    15,
    15,
    15,
    15,
    15,
    15,
    15,
    15,
    15,
    15,
    15,
    15,
    2,
    8,
    2,
    2,
    8,
    8,
    15,
    2,
    8,
    2,
    2,
    8,
    8,
    2,
    2,
    15,
    15,
    6,
    8,
    2,
    8,
    15,
    15,
    2,
    8,
    2,
    2,
    2,
    15,
    15,
    6,
    6,
    2,
    6,
    8,
    15,
    15,
    2,
    2,
    15,
    15,
    15,
    15,
    15,
    2,
    2,
    15
  ];
  var ANCHORS3 = [
    [
      3,
      3,
      15,
      15,
      8,
      3,
      15,
      15,
      8,
      8,
      6,
      6,
      6,
      5,
      3,
      3,
      3,
      3,
      8,
      15,
      3,
      3,
      6,
      10,
      5,
      8,
      8,
      6,
      8,
      5,
      15,
      15,
      8,
      15,
      3,
      5,
      6,
      10,
      8,
      15,
      15,
      3,
      15,
      5,
      15,
      15,
      15,
      15,
      3,
      15,
      5,
      5,
      5,
      8,
      5,
      10,
      5,
      10,
      8,
      13,
      15,
      12,
      3,
      3
    ],
    [
      15,
      8,
      8,
      3,
      15,
      15,
      3,
      8,
      15,
      15,
      15,
      15,
      15,
      15,
      15,
      8,
      15,
      8,
      15,
      3,
      15,
      8,
      15,
      8,
      3,
      15,
      6,
      10,
      15,
      15,
      10,
      8,
      15,
      3,
      15,
      10,
      10,
      8,
      9,
      10,
      6,
      15,
      8,
      15,
      3,
      6,
      6,
      8,
      15,
      3,
      15,
      15,
      15,
      15,
      15,
      15,
      15,
      15,
      15,
      15,
      3,
      15,
      15,
      8
    ]
  ];

  // web/src/textures/bc.js
  var BLOCKS = { bc1: [3, 8], bc4: [1, 8], bc5: [2, 16], bc7: [4, 16] };
  var QUANTIZED = { u8: 1, u16: 2 };
  function layout(encoding) {
    const { format, shape, layered } = encoding;
    const first = layered ? 1 : 0;
    if (!(format in BLOCKS) && !(format in QUANTIZED)) {
      throw new Error(`unknown encoding ${JSON.stringify(format)}`);
    }
    if (shape.length !== 2 + first && shape.length !== 3 + first) {
      throw new Error(`an encoded ${layered ? "layered " : ""}image needs shape (${layered ? "L, " : ""}H, W[, C]), got [${shape}]`);
    }
    const layers = layered ? shape[0] : 1;
    const [height, width] = [shape[first], shape[first + 1]];
    const channels = shape.length === 3 + first ? shape[shape.length - 1] : 1;
    return { layers, height, width, channels };
  }
  function layerBytes(format, height, width, channels) {
    if (format in QUANTIZED) return height * width * channels * QUANTIZED[format];
    return Math.ceil(height / 4) * Math.ceil(width / 4) * BLOCKS[format][1];
  }
  function decodeEncoded(encoding, stored) {
    const { format, dtype, shape } = encoding;
    const { layers, height, width, channels } = layout(encoding);
    const perLayer = layerBytes(format, height, width, channels);
    if (stored.length !== layers * perLayer) {
      throw new Error(`${format} data of a [${shape}] array must be ${layers * perLayer} bytes, got ${stored.length}`);
    }
    const texels = height * width * channels;
    const unorm = new (format === "u16" ? Uint16Array : Uint8Array)(layers * texels);
    for (let k = 0; k < layers; k++) {
      const bytes = stored.subarray(k * perLayer, (k + 1) * perLayer);
      unorm.set(unormLayer(format, bytes, height, width, channels), k * texels);
    }
    if (dtype === "uint8") {
      if (format === "u16") throw new Error("u16 cannot stand for a uint8 array");
      return { dtype, shape: [...shape], data: unorm };
    }
    if (dtype !== "float32") {
      throw new Error(`encoded arrays decode to uint8 or float32, not ${dtype}`);
    }
    const top = format === "u16" ? 65535 : 255;
    const data = new Float32Array(unorm.length);
    if (encoding.srgb) {
      const [colour, linear] = srgbTables(top);
      const coloured = Math.min(channels, 3);
      for (let i = 0; i < data.length; i++) {
        data[i] = (i % channels < coloured ? colour : linear)[unorm[i]];
      }
    } else {
      const f = Math.fround;
      const [fTop, scale2, bias] = [f(top), f(encoding.scale), f(encoding.bias)];
      for (let i = 0; i < data.length; i++) data[i] = f(f(f(unorm[i] / fTop) * scale2) + bias);
    }
    return { dtype, shape: [...shape], data };
  }
  function srgbTables(top) {
    const colour = new Float32Array(top + 1);
    const linear = new Float32Array(top + 1);
    for (let q = 0; q <= top; q++) {
      const x = q / top;
      linear[q] = x;
      colour[q] = x <= 0.04045 ? x / 12.92 : ((x + 0.055) / 1.055) ** 2.4;
    }
    return [colour, linear];
  }
  function unormLayer(format, bytes, height, width, channels) {
    if (format === "u8") return bytes;
    if (format === "u16") {
      const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
      const out2 = new Uint16Array(bytes.length / 2);
      for (let i = 0; i < out2.length; i++) out2[i] = view.getUint16(2 * i, true);
      return out2;
    }
    const image = decodeBlocks(format, bytes, height, width);
    const have = BLOCKS[format][0];
    if (have === channels) return image;
    const out = new Uint8Array(height * width * channels);
    for (let t = 0; t < height * width; t++) {
      for (let c = 0; c < channels; c++) out[t * channels + c] = c < have ? image[t * have + c] : 255;
    }
    return out;
  }
  function decodeBlocks(format, bytes, height, width) {
    const [channels, blockBytes] = BLOCKS[format];
    const across = Math.ceil(width / 4);
    if (bytes.length !== across * Math.ceil(height / 4) * blockBytes) {
      throw new Error(`${format}: ${bytes.length} bytes do not hold a ${width}x${height} image`);
    }
    const decodeBlock = BLOCK_DECODERS[format];
    const out = new Uint8Array(height * width * channels);
    const texels = new Uint8Array(64);
    for (let by = 0; by < height; by += 4) {
      for (let bx = 0; bx < width; bx += 4) {
        decodeBlock(bytes, ((by >> 2) * across + (bx >> 2)) * blockBytes, texels);
        for (let y = by; y < Math.min(by + 4, height); y++) {
          for (let x = bx; x < Math.min(bx + 4, width); x++) {
            const from = ((y - by) * 4 + (x - bx)) * 4;
            const to = (y * width + x) * channels;
            for (let c = 0; c < channels; c++) out[to + c] = texels[from + c];
          }
        }
      }
    }
    return out;
  }
  function rgb565(value, out, at2) {
    const r = value >> 11 & 31, g = value >> 5 & 63, b = value & 31;
    out[at2] = r << 3 | r >> 2;
    out[at2 + 1] = g << 2 | g >> 4;
    out[at2 + 2] = b << 3 | b >> 2;
  }
  var bc1Palette = new Uint8Array(12);
  function decodeBc1(bytes, at2, texels) {
    const q0 = bytes[at2] | bytes[at2 + 1] << 8;
    const q1 = bytes[at2 + 2] | bytes[at2 + 3] << 8;
    const p = bc1Palette;
    rgb565(q0, p, 0);
    rgb565(q1, p, 3);
    for (let c = 0; c < 3; c++) {
      const [c0, c1] = [p[c], p[3 + c]];
      if (q0 > q1) {
        p[6 + c] = Math.floor((2 * c0 + c1) / 3);
        p[9 + c] = Math.floor((c0 + 2 * c1) / 3);
      } else {
        p[6 + c] = c0 + c1 >> 1;
        p[9 + c] = 0;
      }
    }
    const indices = bytes[at2 + 4] | bytes[at2 + 5] << 8 | bytes[at2 + 6] << 16 | bytes[at2 + 7] << 24;
    for (let i = 0; i < 16; i++) {
      const k = (indices >>> 2 * i & 3) * 3;
      texels[4 * i] = p[k];
      texels[4 * i + 1] = p[k + 1];
      texels[4 * i + 2] = p[k + 2];
      texels[4 * i + 3] = 255;
    }
  }
  var bc4Palette = new Uint8Array(8);
  function decodeBc4Channel(bytes, at2, texels, channel) {
    const p = bc4Palette;
    const [a0, a1] = [bytes[at2], bytes[at2 + 1]];
    p[0] = a0;
    p[1] = a1;
    if (a0 > a1) {
      for (let k = 1; k <= 6; k++) p[1 + k] = Math.floor(((7 - k) * a0 + k * a1) / 7);
    } else {
      for (let k = 1; k <= 4; k++) p[1 + k] = Math.floor(((5 - k) * a0 + k * a1) / 5);
      p[6] = 0;
      p[7] = 255;
    }
    for (let half = 0; half < 2; half++) {
      const o = at2 + 2 + 3 * half;
      const bits2 = bytes[o] | bytes[o + 1] << 8 | bytes[o + 2] << 16;
      for (let i = 0; i < 8; i++) texels[4 * (8 * half + i) + channel] = p[bits2 >> 3 * i & 7];
    }
  }
  function decodeBc4(bytes, at2, texels) {
    decodeBc4Channel(bytes, at2, texels, 0);
  }
  function decodeBc5(bytes, at2, texels) {
    decodeBc4Channel(bytes, at2, texels, 0);
    decodeBc4Channel(bytes, at2 + 8, texels, 1);
  }
  var BC7_MODES = [
    [3, 4, 0, 0, 4, 0, 1, 3, 0],
    [2, 6, 0, 0, 6, 0, 2, 3, 0],
    [3, 6, 0, 0, 5, 0, 0, 2, 0],
    [2, 6, 0, 0, 7, 0, 1, 2, 0],
    [1, 0, 2, 1, 5, 6, 0, 2, 3],
    [1, 0, 2, 0, 7, 8, 0, 2, 2],
    [1, 0, 0, 0, 7, 7, 1, 4, 0],
    [2, 6, 0, 0, 5, 5, 1, 2, 0]
  ].map(([
    subsets,
    partitionBits,
    rotationBits,
    selectionBits,
    colourBits,
    alphaBits,
    pBits2,
    indexBits,
    index2Bits
  ]) => ({
    subsets,
    partitionBits,
    rotationBits,
    selectionBits,
    colourBits,
    alphaBits,
    pBits: pBits2,
    indexBits,
    index2Bits
  }));
  var WEIGHTS = {
    2: [0, 21, 43, 64],
    3: [0, 9, 18, 27, 37, 46, 55, 64],
    4: [0, 4, 9, 13, 17, 21, 26, 30, 34, 38, 43, 47, 51, 55, 60, 64]
  };
  var SUBSET_DIGITS = [null, null, PARTITIONS2, PARTITIONS3].map(
    (table) => table && table.map((row) => Uint8Array.from(row, Number))
  );
  var ONE_SUBSET = new Uint8Array(16);
  var SUBSET_ANCHORS = [
    null,
    [[0]],
    ANCHORS2.map((a) => [0, a]),
    ANCHORS3[0].map((a, p) => [0, a, ANCHORS3[1][p]])
  ];
  function bits(bytes, at2, pos, n) {
    const o = at2 + (pos >> 3);
    const word = bytes[o] | bytes[o + 1] << 8 | bytes[o + 2] << 16;
    return word >>> (pos & 7) & (1 << n) - 1;
  }
  function expand(value, n) {
    const shifted = value << 8 - n;
    return (shifted | shifted >> n) & 255;
  }
  var endpoints = new Uint8Array(6 * 4);
  var pBits = new Uint8Array(6);
  function decodeBc7(bytes, at2, texels) {
    let mode = 0;
    while (mode < 8 && !(bytes[at2] >> mode & 1)) mode++;
    if (mode === 8) {
      texels.fill(0);
      return;
    }
    const m = BC7_MODES[mode];
    let pos = mode + 1;
    const partition = bits(bytes, at2, pos, m.partitionBits);
    pos += m.partitionBits;
    const rotation = bits(bytes, at2, pos, m.rotationBits);
    pos += m.rotationBits;
    const selection = bits(bytes, at2, pos, m.selectionBits);
    pos += m.selectionBits;
    const ends = 2 * m.subsets;
    for (let c = 0; c < 4; c++) {
      const width = c < 3 ? m.colourBits : m.alphaBits;
      for (let e = 0; e < ends; e++) {
        endpoints[4 * e + c] = width ? bits(bytes, at2, pos, width) : 255;
        pos += width;
      }
    }
    if (m.pBits === 1) {
      for (let e = 0; e < ends; e++) pBits[e] = bits(bytes, at2, pos++, 1);
    } else if (m.pBits === 2) {
      for (let s = 0; s < m.subsets; s++) pBits[2 * s] = pBits[2 * s + 1] = bits(bytes, at2, pos++, 1);
    }
    const withP = m.pBits ? 1 : 0;
    for (let e = 0; e < ends; e++) {
      for (let c = 0; c < 4; c++) {
        const width = c < 3 ? m.colourBits : m.alphaBits;
        if (width) {
          const value = endpoints[4 * e + c] << withP | (withP && pBits[e]);
          endpoints[4 * e + c] = expand(value, width + withP);
        }
      }
    }
    const subsets = m.subsets === 1 ? ONE_SUBSET : SUBSET_DIGITS[m.subsets][partition];
    const anchors = SUBSET_ANCHORS[m.subsets][partition];
    let pos2 = pos + 16 * m.indexBits - m.subsets;
    const weights = WEIGHTS[m.indexBits];
    const weights2 = WEIGHTS[m.index2Bits || m.indexBits];
    for (let i = 0; i < 16; i++) {
      const s = subsets[i];
      const n = m.indexBits - (anchors[s] === i ? 1 : 0);
      const index = bits(bytes, at2, pos, n);
      pos += n;
      let colourWeight = weights[index];
      let alphaWeight = colourWeight;
      if (m.index2Bits) {
        const n2 = m.index2Bits - (i === 0 ? 1 : 0);
        const alphaIndex = bits(bytes, at2, pos2, n2);
        pos2 += n2;
        alphaWeight = weights2[alphaIndex];
        if (selection) {
          const swapped = colourWeight;
          colourWeight = alphaWeight;
          alphaWeight = swapped;
        }
      }
      for (let c = 0; c < 4; c++) {
        const w = c < 3 ? colourWeight : alphaWeight;
        const [e0, e1] = [8 * s + c, 8 * s + 4 + c];
        texels[4 * i + c] = (64 - w) * endpoints[e0] + w * endpoints[e1] + 32 >> 6;
      }
      if (rotation) {
        const other = 4 * i + rotation - 1;
        const alpha = texels[4 * i + 3];
        texels[4 * i + 3] = texels[other];
        texels[other] = alpha;
      }
    }
  }
  var BLOCK_DECODERS = { bc1: decodeBc1, bc4: decodeBc4, bc5: decodeBc5, bc7: decodeBc7 };

  // web/src/textures.js
  var FORMATS = {
    // dtype -> [internal formats by channel count, format by channel count, type]
    uint8: ["R8 RG8 RGB8 RGBA8", "RED RG RGB RGBA", "UNSIGNED_BYTE"],
    float32: ["R32F RG32F RGB32F RGBA32F", "RED RG RGB RGBA", "FLOAT"],
    float16: ["R16F RG16F RGB16F RGBA16F", "RED RG RGB RGBA", "HALF_FLOAT"],
    uint16: ["R16UI RG16UI RGB16UI RGBA16UI", "RED_INTEGER RG_INTEGER RGB_INTEGER RGBA_INTEGER", "UNSIGNED_SHORT"]
  };
  var TARGETS = { "2d": "TEXTURE_2D", "3d": "TEXTURE_3D", "2d_array": "TEXTURE_2D_ARRAY" };
  function decoded(a) {
    return a.encoding ? decodeEncoded(a.encoding, a.data) : a;
  }
  function decodedChain(a) {
    if (!a.encoding || !a.encoding.mipmaps || !a.mipLevels) return null;
    const { shape, layered } = a.encoding;
    const first = layered ? 1 : 0;
    return [decoded(a), ...a.mipLevels.map((level, k) => {
      const size = shape.slice();
      size[first] = Math.max(shape[first] >> k + 1, 1);
      size[first + 1] = Math.max(shape[first + 1] >> k + 1, 1);
      return decodeEncoded({ ...a.encoding, shape: size }, level.data);
    })];
  }
  function uploadTexture(gl, t) {
    const chain = decodedChain(t.array);
    t = { ...t, array: decoded(t.array), levels: chain || t.levels && t.levels.map(decoded) };
    const target = gl[TARGETS[t.target]];
    const levels = t.levels || [t.array];
    const { shape, dtype } = levels[0];
    const planar = t.target === "2d";
    const dims = planar ? 2 : 3;
    const channels = shape.length > dims ? shape[dims] : 1;
    const format = FORMATS[dtype];
    if (!format || channels < 1 || channels > 4) throw new Error(`${t.what}: a ${dtype} texture of ${channels} channels is not supported`);
    let internal = gl[format[0].split(" ")[channels - 1]];
    if (t.srgb) {
      if (dtype !== "uint8" || channels !== 4) throw new Error(`${t.what}: sRGB textures must be RGBA uint8`);
      internal = gl.SRGB8_ALPHA8;
    }
    const fmt = gl[format[1].split(" ")[channels - 1]];
    const type = gl[format[2]];
    const tex = gl.createTexture();
    gl.bindTexture(target, tex);
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
    let bytes = 0;
    levels.forEach((level, k) => {
      const [d, h, w] = planar ? [1, ...level.shape.slice(0, 2)] : level.shape.slice(0, 3);
      const data = level.dtype === "float64" ? new Float32Array(level.data) : level.data;
      bytes += data.byteLength;
      if (planar) gl.texImage2D(target, k, internal, w, h, 0, fmt, type, data);
      else gl.texImage3D(target, k, internal, w, h, d, 0, fmt, type, data);
    });
    const integer = dtype === "uint16";
    const nearest = t.filter === "nearest" || integer;
    let minify = nearest ? gl.NEAREST : gl.LINEAR;
    if (chain) {
      gl.texParameteri(target, gl.TEXTURE_MAX_LEVEL, chain.length - 1);
      minify = gl.LINEAR_MIPMAP_LINEAR;
    } else if (t.levels) {
      gl.texParameteri(target, gl.TEXTURE_MAX_LEVEL, t.levels.length - 1);
      minify = gl.NEAREST_MIPMAP_NEAREST;
    } else if (t.mipmaps && !nearest) {
      gl.generateMipmap(target);
      minify = gl.LINEAR_MIPMAP_LINEAR;
    }
    gl.texParameteri(target, gl.TEXTURE_MIN_FILTER, minify);
    gl.texParameteri(target, gl.TEXTURE_MAG_FILTER, nearest ? gl.NEAREST : gl.LINEAR);
    const wraps = [gl.TEXTURE_WRAP_S, gl.TEXTURE_WRAP_T, gl.TEXTURE_WRAP_R];
    (t.wrap || []).slice(0, planar ? 2 : 3).forEach((w, i) => {
      gl.texParameteri(target, wraps[i], w === "repeat" ? gl.REPEAT : gl.CLAMP_TO_EDGE);
    });
    return { tex, target, bytes };
  }

  // web/src/executor.js
  var FRAME_ATTACHMENTS = 3;
  var MODES = { triangles: "TRIANGLES", points: "POINTS", lines: "LINES", triangle_strip: "TRIANGLE_STRIP" };
  var BLEND = { under: ["ONE_MINUS_DST_ALPHA", "ONE"], add: ["ONE", "ONE"] };
  var MULTIPASS = {
    "shadow-map": drawShadowMapped,
    "opaque-depth": drawWithOpaqueDepth,
    // its extra passes only place the position and normal AOVs at the half-opacity point,
    // which the page does not show: its colour and coverage are the opaque-depth kind's
    "half-opacity-search": drawWithOpaqueDepth,
    "depth-peel": drawDepthPeeled,
    "stencil-count": drawStencilCounted
  };
  var FRONT_OPACITY_UNIT = 15;
  var Unsupported = class extends Error {
  };
  function createContext(canvas) {
    const gl = canvas.getContext("webgl2", { alpha: true, premultipliedAlpha: false, antialias: false, preserveDrawingBuffer: true });
    if (!gl) throw new Error("this browser has no WebGL2: the viewer needs it");
    if (!gl.getExtension("EXT_color_buffer_float")) throw new Error("this browser cannot render to float textures (EXT_color_buffer_float)");
    gl.getExtension("OES_texture_float_linear");
    return gl;
  }
  var Executor = class {
    /** ``hooks``: the view hooks' ports by the Python function's "module:name" (web/src/hooks/);
     *  ``programs``: the page's own programs (inputs.json: present, copy_depth). */
    constructor(gl, draw, name, hooks, programs) {
      this.gl = gl;
      this.name = name;
      this.hooks = hooks;
      this.sources = new Map(draw.programs.map((p) => [programKey(p.program, p.defines), p]));
      this.programs = /* @__PURE__ */ new Map();
      this.buffers = /* @__PURE__ */ new Map();
      this.vaos = /* @__PURE__ */ new Map();
      this.textures = /* @__PURE__ */ new Map();
      this.groups = /* @__PURE__ */ new Map();
      this.cache = /* @__PURE__ */ new Map();
      this.depthClamp = gl.getExtension("EXT_depth_clamp");
      this.timer = gl.getExtension("EXT_disjoint_timer_query_webgl2");
      this.query = null;
      this.gpuMs = null;
      this.counts = { plans: 0, textureBytes: 0, drawCalls: 0, vertices: 0 };
      this.present = this.link(programs.present.name, programs.present);
      this.copyDepth = this.link(programs.copy_depth.name, programs.copy_depth);
    }
    /** Take ``plan`` to draw (its programs compiled); throws `Unsupported` for one it cannot
     *  draw yet, or an Error (a shader that does not compile). */
    add(plan) {
      this.check(plan);
      this.program(plan.program);
      if (plan.multipass) {
        for (const role of Object.values(plan.multipass.programs)) this.program({ name: role[0], defines: role[1] });
        if (!this.groups.has(plan.geometry.key)) this.groups.set(plan.geometry.key, []);
        this.groups.get(plan.geometry.key).push(plan);
      }
      this.counts.plans += 1;
    }
    check(plan) {
      if (plan.per_view && !this.hooks[plan.per_view.function]) throw new Unsupported(`${plan.name}: its view hook ${plan.per_view.function} is not supported by the viewer yet`);
      if (plan.multipass && !MULTIPASS[plan.multipass.kind]) throw new Unsupported(`${plan.name}: the multi-pass kind ${plan.multipass.kind} is not supported by the viewer yet`);
      if (plan.raster.depth_clamp && !this.depthClamp) throw new Unsupported(`${plan.name}: needs depth clamping, which this browser lacks (EXT_depth_clamp)`);
    }
    program(program) {
      const key = programKey(program.name, program.defines);
      if (!this.programs.has(key)) {
        const sources = this.sources.get(key);
        if (!sources) throw new Error(`${this.name}: no embedded shader for ${key}`);
        this.programs.set(key, this.link(program.name, { vertex: sources.vertex, fragment: sources.fragment }));
      }
      return this.programs.get(key);
    }
    link(name, { vertex, fragment }) {
      const gl = this.gl;
      const prog = gl.createProgram();
      for (const [type, source, stage] of [[gl.VERTEX_SHADER, vertex, "vertex"], [gl.FRAGMENT_SHADER, fragment, "fragment"]]) {
        const shader = gl.createShader(type);
        gl.shaderSource(shader, source);
        gl.compileShader(shader);
        if (!gl.getShaderParameter(shader, gl.COMPILE_STATUS)) {
          throw new Error(`the ${stage} shader of ${name} does not compile in this browser: ${gl.getShaderInfoLog(shader).trim()}`);
        }
        gl.attachShader(prog, shader);
      }
      gl.linkProgram(prog);
      for (const shader of gl.getAttachedShaders(prog)) gl.deleteShader(shader);
      if (!gl.getProgramParameter(prog, gl.LINK_STATUS)) {
        throw new Error(`${name} does not link in this browser: ${gl.getProgramInfoLog(prog).trim()}`);
      }
      const uniforms = /* @__PURE__ */ new Map();
      for (let i = 0; i < gl.getProgramParameter(prog, gl.ACTIVE_UNIFORMS); i++) {
        const info = gl.getActiveUniform(prog, i);
        uniforms.set(info.name.replace(/\[0\]$/, ""), { location: gl.getUniformLocation(prog, info.name), type: info.type, size: info.size });
      }
      return { prog, uniforms, name };
    }
    /** The buffer of a geometry's attribute (or 'indices') holding ``array``: written when the
     *  array is not the one it holds (a view hook's new array; render/executor.py _write). */
    buffer(geometry, name, array, target) {
      const gl = this.gl;
      if (!this.buffers.has(geometry.key)) this.buffers.set(geometry.key, {});
      const made = this.buffers.get(geometry.key);
      if (!made[name]) made[name] = { buffer: gl.createBuffer(), source: null };
      const entry = made[name];
      if (entry.source !== array) {
        gl.bindBuffer(target, entry.buffer);
        gl.bufferData(target, array.dtype === "uint32" || target === gl.ARRAY_BUFFER ? array.data : new Uint32Array(array.data), gl.DYNAMIC_DRAW);
        entry.source = array;
      }
      return entry.buffer;
    }
    vertexArray(linked, geometry) {
      const gl = this.gl;
      const key = `${linked.name} ${geometry.key}`;
      if (!this.vaos.has(key)) {
        const vao = gl.createVertexArray();
        gl.bindVertexArray(vao);
        for (const [name, attr] of Object.entries(geometry.attributes)) {
          const loc = gl.getAttribLocation(linked.prog, name);
          if (loc < 0) continue;
          const { shape, dtype } = attr.array;
          const comps = shape.length === 2 ? shape[1] : 1;
          gl.bindBuffer(gl.ARRAY_BUFFER, this.buffer(geometry, name, attr.array, gl.ARRAY_BUFFER));
          gl.enableVertexAttribArray(loc);
          if (dtype === "int32") gl.vertexAttribIPointer(loc, comps, gl.INT, 0, 0);
          else if (dtype === "float32") gl.vertexAttribPointer(loc, comps, gl.FLOAT, false, 0, 0);
          else throw new Error(`${geometry.key}: vertex array ${name} is ${dtype}, not float32 or int32`);
          gl.vertexAttribDivisor(loc, attr.per_instance ? 1 : 0);
        }
        if (geometry.indices) gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, this.buffer(geometry, "indices", geometry.indices, gl.ELEMENT_ARRAY_BUFFER));
        gl.bindVertexArray(null);
        this.vaos.set(key, vao);
      }
      return this.vaos.get(key);
    }
    texture(t) {
      if (!this.textures.has(t)) {
        const made = uploadTexture(this.gl, t);
        this.counts.textureBytes += made.bytes;
        this.textures.set(t, made);
      }
      return this.textures.get(t);
    }
    /** Draw ``plans`` from ``camera`` into ``targets`` and present them on the canvas: the
     *  opaque pass, then the transparent plans front to back (gl/targets.py draw_passes).
     *  ``presenting(targets)``, called once they are drawn, gives present.glsl's further
     *  uniforms and textures (a debug view's: web/src/debug_views.js). */
    frame(plans, camera, light, targets, presenting = () => ({})) {
      const gl = this.gl;
      const [w, h] = camera.size;
      const pass = (fbo) => () => {
        gl.bindFramebuffer(gl.FRAMEBUFFER, fbo);
        gl.viewport(0, 0, w, h);
      };
      const opaque = pass(targets.fbo);
      const transparent = pass(targets.transparentFbo);
      Object.assign(this.counts, { drawCalls: 1, vertices: 3 });
      const timing = this.timer && !this.query;
      if (timing) {
        this.gpuMs = null;
        this.query = gl.createQuery();
        gl.beginQuery(this.timer.TIME_ELAPSED_EXT, this.query);
      }
      opaque();
      gl.depthMask(true);
      for (let i = 0; i < targets.attachments; i++) gl.clearBufferfv(gl.COLOR, i, [0, 0, 0, 0]);
      gl.clearBufferfv(gl.DEPTH, 0, [1]);
      for (const plan of plans.filter((p) => p.render_pass === "opaque")) this.draw(plan, camera, light, opaque);
      transparent();
      for (let i = 0; i < FRAME_ATTACHMENTS; i++) gl.clearBufferfv(gl.COLOR, i, [0, 0, 0, 0]);
      const front = { u_front_opacity: FRONT_OPACITY_UNIT };
      gl.activeTexture(gl.TEXTURE0 + FRONT_OPACITY_UNIT);
      gl.bindTexture(gl.TEXTURE_2D, targets.frontOpacity.tex);
      for (const plan of plans.filter((p) => p.render_pass === "transparent")) {
        this.draw(plan, camera, light, transparent, { uniforms: front, targets });
      }
      if (timing) gl.endQuery(this.timer.TIME_ELAPSED_EXT);
      const { uniforms = {}, textures = {} } = presenting(targets);
      gl.bindFramebuffer(gl.FRAMEBUFFER, null);
      gl.viewport(0, 0, w, h);
      this.setRaster({ depth_test: false, cull: "none", blend: "none", depth_write: false });
      gl.useProgram(this.present.prog);
      const samplers = this.bindTextures({ u_color: targets.color, u_position: targets.position, u_transparent: targets.transparent, ...textures });
      for (const [name, value] of Object.entries({ u_debug: 0, ...uniforms, ...samplers })) setUniform(gl, this.present, name, value);
      gl.bindVertexArray(null);
      gl.drawArrays(gl.TRIANGLES, 0, 3);
    }
    /** Free every GL object this executor made (programs, buffers, vertex arrays, textures,
     *  a multi-pass kind's targets): its plans are replaced (the page's option controls). */
    dispose() {
      const gl = this.gl;
      for (const { prog } of [...this.programs.values(), this.present, this.copyDepth]) gl.deleteProgram(prog);
      for (const made of this.buffers.values()) for (const { buffer } of Object.values(made)) gl.deleteBuffer(buffer);
      for (const vao of this.vaos.values()) gl.deleteVertexArray(vao);
      for (const { tex } of this.textures.values()) gl.deleteTexture(tex);
      for (const entry of this.cache.values()) releaseAll(gl, entry);
      if (this.query) gl.deleteQuery(this.query);
      for (const map of [this.programs, this.buffers, this.vaos, this.textures, this.cache, this.groups]) map.clear();
      this.query = null;
    }
    /** The GPU time of the latest timed frame's draws in ms (null until one is known): a timer
     *  query's result becomes available only after the page has returned to the browser. */
    gpuTime() {
      const gl = this.gl;
      if (this.query && gl.getQueryParameter(this.query, gl.QUERY_RESULT_AVAILABLE)) {
        if (!gl.getParameter(this.timer.GPU_DISJOINT_EXT)) this.gpuMs = gl.getQueryParameter(this.query, gl.QUERY_RESULT) / 1e6;
        gl.deleteQuery(this.query);
        this.query = null;
      }
      return this.gpuMs;
    }
    /** Wait until the frame is drawn: a one-pixel read back (Chromium's gl.finish() returns
     *  before the GPU process has drawn). */
    finish() {
      const gl = this.gl;
      gl.bindFramebuffer(gl.FRAMEBUFFER, null);
      gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));
    }
    /** ``plan`` as seen from ``camera`` (its hook's update applied), its new arrays written into
     *  the geometry's buffers (render/executor.py Executor.view). */
    view(plan, camera, light) {
      if (!plan.per_view) return plan;
      const hook = this.hooks[plan.per_view.function];
      const viewed = withView(plan, hook(plan, camera, light, plan.per_view.data) || {});
      const gl = this.gl;
      for (const [name, attr] of Object.entries(viewed.geometry.attributes)) this.buffer(plan.geometry, name, attr.array, gl.ARRAY_BUFFER);
      if (viewed.geometry.indices) {
        gl.bindVertexArray(null);
        this.buffer(plan.geometry, "indices", viewed.geometry.indices, gl.ELEMENT_ARRAY_BUFFER);
      }
      return viewed;
    }
    /** Draw ``source`` from ``camera``: its view, then one draw or its multi-pass kind;
     *  ``extra`` (uniforms, the frame's targets) goes to both. */
    draw(source, camera, light, outer, extra = {}) {
      const plan = this.view(source, camera, light);
      if (plan.count === 0) return;
      if (plan.multipass) MULTIPASS[plan.multipass.kind](this, plan, camera, light, outer, extra);
      else this.drawViewed(plan, camera, light, extra);
    }
    /** A full-screen triangle drawn with ``linked`` and ``textures`` under ``raster`` (a pass
     *  of a multi-pass kind). */
    drawFullScreen(linked, textures, raster = { depth_test: false, cull: "none", blend: "none", depth_write: false }) {
      const gl = this.gl;
      this.setRaster(raster);
      gl.useProgram(linked.prog);
      for (const [name, value] of Object.entries(this.bindTextures(textures))) setUniform(gl, linked, name, value);
      gl.bindVertexArray(null);
      gl.drawArrays(gl.TRIANGLES, 0, 3);
      this.counts.drawCalls += 1;
      this.counts.vertices += 3;
    }
    /** One draw of a plan already seen from ``camera``; ``program`` (a [name, defines] role),
     *  ``raster``, ``uniforms`` and ``textures`` replace or add to the plan's. */
    drawViewed(plan, camera, light, { program, raster, uniforms = {}, textures = {} } = {}) {
      const gl = this.gl;
      const linked = this.program(program ? { name: program[0], defines: program[1] } : plan.program);
      const vao = this.vertexArray(linked, plan.geometry);
      gl.useProgram(linked.prog);
      const samplers = this.bindTextures({ ...plan.textures, ...textures });
      const values = { ...cameraUniforms(camera), ...modelOffset(camera, plan.origin), ...light.uniforms, ...plan.uniforms, ...uniforms, ...samplers };
      for (const [name, value] of Object.entries(values)) setUniform(gl, linked, name, value);
      this.setRaster(raster || plan.raster);
      gl.bindVertexArray(vao);
      const { mode, count, first, instances, indexed } = counts(gl, plan);
      if (indexed && instances != null) gl.drawElementsInstanced(mode, count, gl.UNSIGNED_INT, first * 4, instances);
      else if (indexed) gl.drawElements(mode, count, gl.UNSIGNED_INT, first * 4);
      else if (instances != null) gl.drawArraysInstanced(mode, first, count, instances);
      else gl.drawArrays(mode, first, count);
      this.counts.drawCalls += 1;
      this.counts.vertices += count * (instances ?? 1);
      gl.bindVertexArray(null);
    }
    /** Bind textures (sampler name -> plan texture or {tex, target}) to units 0, 1, ...;
     *  the sampler uniforms and each one's `<sampler>_decode` (1, 0: no encoding). */
    bindTextures(textures) {
      const gl = this.gl;
      const out = {};
      const units = /* @__PURE__ */ new Map();
      const uploaded = Object.entries(textures).map(([name, t]) => [name, t.tex ? t : this.texture(t)]);
      for (const [name, made] of uploaded) {
        if (!units.has(made)) {
          units.set(made, units.size);
          gl.activeTexture(gl.TEXTURE0 + units.get(made));
          gl.bindTexture(made.target, made.tex);
        }
        out[name] = units.get(made);
        out[`${name}_decode`] = [1, 0];
      }
      return out;
    }
    setRaster(r) {
      const gl = this.gl;
      (r.depth_test ? gl.enable : gl.disable).call(gl, gl.DEPTH_TEST);
      gl.depthFunc(r.depth_func === "<=" ? gl.LEQUAL : gl.LESS);
      gl.depthMask(!!r.depth_write);
      if (this.depthClamp) (r.depth_clamp ? gl.enable : gl.disable).call(gl, this.depthClamp.DEPTH_CLAMP_EXT);
      if (r.cull && r.cull !== "none") {
        gl.enable(gl.CULL_FACE);
        gl.cullFace(r.cull === "front" ? gl.FRONT : gl.BACK);
      } else gl.disable(gl.CULL_FACE);
      gl.frontFace(r.front_face === "cw" ? gl.CW : gl.CCW);
      if (r.blend && r.blend !== "none") {
        gl.enable(gl.BLEND);
        gl.blendFunc(gl[BLEND[r.blend][0]], gl[BLEND[r.blend][1]]);
      } else gl.disable(gl.BLEND);
    }
  };
  var MAX_TARGET_BYTES = 1 << 30;
  function createTargets(gl, [w, h], extra = 0) {
    const side = gl.getParameter(gl.MAX_TEXTURE_SIZE);
    const bytes = w * h * ((2 * FRAME_ATTACHMENTS + extra + 2) * 16 + 4);
    if (w > side || h > side || bytes > MAX_TARGET_BYTES) {
      throw new Error(`a ${w}x${h} frame needs ${Math.ceil(bytes / 2 ** 20)} MiB of float render targets (limits: ${side} texels a side, ${MAX_TARGET_BYTES / 2 ** 20} MiB): ask for a smaller size`);
    }
    const make = (internal, format, type, attachment) => {
      const tex = gl.createTexture();
      gl.bindTexture(gl.TEXTURE_2D, tex);
      gl.texImage2D(gl.TEXTURE_2D, 0, internal, w, h, 0, format, type, null);
      for (const p of [gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER]) gl.texParameteri(gl.TEXTURE_2D, p, gl.NEAREST);
      gl.framebufferTexture2D(gl.FRAMEBUFFER, attachment, gl.TEXTURE_2D, tex, 0);
      return { tex, target: gl.TEXTURE_2D };
    };
    const attachments = (n) => [...Array(n).keys()].map((i) => gl.COLOR_ATTACHMENT0 + i);
    const framebuffer = (colors, depth2) => {
      const fbo2 = gl.createFramebuffer();
      gl.bindFramebuffer(gl.FRAMEBUFFER, fbo2);
      const made = colors.map((a) => make(gl.RGBA32F, gl.RGBA, gl.FLOAT, a));
      if (depth2) gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.DEPTH_ATTACHMENT, gl.TEXTURE_2D, depth2.tex, 0);
      gl.drawBuffers(colors);
      const status = gl.checkFramebufferStatus(gl.FRAMEBUFFER);
      gl.bindFramebuffer(gl.FRAMEBUFFER, null);
      if (status !== gl.FRAMEBUFFER_COMPLETE) throw new Error(`the ${w}x${h} float render targets are incomplete (status 0x${status.toString(16)})`);
      return [fbo2, made];
    };
    const depth = (() => {
      const tex = gl.createTexture();
      gl.bindTexture(gl.TEXTURE_2D, tex);
      gl.texImage2D(gl.TEXTURE_2D, 0, gl.DEPTH_COMPONENT32F, w, h, 0, gl.DEPTH_COMPONENT, gl.FLOAT, null);
      for (const p of [gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER]) gl.texParameteri(gl.TEXTURE_2D, p, gl.NEAREST);
      return { tex, target: gl.TEXTURE_2D };
    })();
    const [fbo, [color, position, normal, iterations]] = framebuffer(attachments(FRAME_ATTACHMENTS + extra), depth);
    const [transparentFbo, [transparent]] = framebuffer(attachments(FRAME_ATTACHMENTS), depth);
    const [depthCopyFbo, [depthCopy]] = framebuffer([gl.COLOR_ATTACHMENT0], null);
    const [frontFbo, [frontOpacity]] = framebuffer([gl.COLOR_ATTACHMENT0], null);
    gl.bindFramebuffer(gl.FRAMEBUFFER, frontFbo);
    gl.clearBufferfv(gl.COLOR, 0, [0, 0, 0, 0]);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    return { fbo, color, position, normal, iterations, depth, transparentFbo, transparent, depthCopyFbo, depthCopy, frontFbo, frontOpacity, size: [w, h], attachments: FRAME_ATTACHMENTS + extra };
  }
  function counts(gl, plan) {
    const g = plan.geometry;
    let count = plan.count;
    if (count == null) {
      if (g.indices) count = g.indices.data.length;
      else if (g.vertices != null) count = g.vertices;
      else count = Math.min(...Object.values(g.attributes).filter((a) => !a.per_instance).map((a) => a.array.shape[0]));
    }
    return { mode: gl[MODES[g.primitive]], count, first: plan.first || 0, instances: g.instances, indexed: !!g.indices };
  }
  function flat(value) {
    if (value && value.data && value.shape) return Array.from(value.data, Number);
    if (Array.isArray(value)) return value.flatMap(flat);
    return [typeof value === "boolean" ? Number(value) : value];
  }
  function setUniform(gl, linked, name, value) {
    const u = linked.uniforms.get(name);
    if (!u) return;
    const T = gl;
    const rowMajor = !!(value && value.shape && value.shape.length === 2);
    if (Array.isArray(value) && u.size === 1 && Array.isArray(value[0]) && ![T.FLOAT_MAT3, T.FLOAT_MAT4].includes(u.type)) value = value[0];
    const v = flat(value);
    const n = {
      [T.FLOAT_MAT4]: 16,
      [T.FLOAT_MAT3]: 9,
      [T.FLOAT_VEC2]: 2,
      [T.FLOAT_VEC3]: 3,
      [T.FLOAT_VEC4]: 4,
      [T.INT_VEC2]: 2,
      [T.INT_VEC3]: 3,
      [T.INT_VEC4]: 4,
      [T.BOOL_VEC2]: 2,
      [T.BOOL_VEC3]: 3,
      [T.BOOL_VEC4]: 4
    }[u.type] || 1;
    const data = v.slice(0, n * u.size);
    switch (u.type) {
      case T.FLOAT:
        return gl.uniform1fv(u.location, data);
      case T.FLOAT_VEC2:
        return gl.uniform2fv(u.location, data);
      case T.FLOAT_VEC3:
        return gl.uniform3fv(u.location, data);
      case T.FLOAT_VEC4:
        return gl.uniform4fv(u.location, data);
      case T.FLOAT_MAT3:
        return gl.uniformMatrix3fv(u.location, rowMajor, data);
      case T.FLOAT_MAT4:
        return gl.uniformMatrix4fv(u.location, rowMajor, data);
      case T.UNSIGNED_INT:
        return gl.uniform1uiv(u.location, data);
      case T.INT_VEC2:
      case T.BOOL_VEC2:
        return gl.uniform2iv(u.location, data);
      case T.INT_VEC3:
      case T.BOOL_VEC3:
        return gl.uniform3iv(u.location, data);
      case T.INT_VEC4:
      case T.BOOL_VEC4:
        return gl.uniform4iv(u.location, data);
      default:
        return gl.uniform1iv(u.location, data);
    }
  }

  // web/src/glb.js
  var MAGIC = 1179937895;
  var JSON_CHUNK = 1313821514;
  var BIN_CHUNK = 5130562;
  var TYPED = {
    bool: Uint8Array,
    int8: Int8Array,
    uint8: Uint8Array,
    int16: Int16Array,
    uint16: Uint16Array,
    int32: Int32Array,
    uint32: Uint32Array,
    float16: Uint16Array,
    float32: Float32Array,
    float64: Float64Array,
    int64: BigInt64Array,
    uint64: BigUint64Array
  };
  function parseGlb(buffer, name) {
    const data = new DataView(buffer);
    if (buffer.byteLength < 20 || data.getUint32(0, true) !== MAGIC) {
      throw new Error(`${name} is not a GLB file`);
    }
    if (data.getUint32(4, true) !== 2 || data.getUint32(8, true) > buffer.byteLength) {
      throw new Error(`${name}: not a glTF 2.0 GLB, or truncated`);
    }
    let json = null;
    let bin = new ArrayBuffer(0);
    for (let at2 = 12; at2 + 8 <= buffer.byteLength; ) {
      const length = data.getUint32(at2, true);
      const type = data.getUint32(at2 + 4, true);
      if (at2 + 8 + length > buffer.byteLength) throw new Error(`${name}: a chunk runs past the end`);
      const body = buffer.slice(at2 + 8, at2 + 8 + length);
      if (type === JSON_CHUNK) json = parseJson(body, name);
      else if (type === BIN_CHUNK) bin = body;
      at2 += 8 + length;
    }
    if (json === null) throw new Error(`${name}: no JSON chunk`);
    return { json, bin, name };
  }
  function parseJson(bytes, name) {
    try {
      return JSON.parse(new TextDecoder("utf-8", { fatal: true }).decode(bytes));
    } catch (e) {
      throw new Error(`${name}: its JSON chunk does not parse (${e.message})`);
    }
  }
  function drawOf(glb) {
    for (const node of glb.json.nodes || []) {
      for (const [ext, value] of Object.entries(node.extensions || {})) {
        if (!ext.startsWith("RELIEFKIT_")) continue;
        if (!value.draw) throw new Error(`${glb.name}: ${ext} holds no draw plans`);
        if (!Array.isArray(value.draw.programs)) {
          throw new Error(`${glb.name}: its draw plans carry no shaders (export with --embed-shaders)`);
        }
        return value.draw;
      }
    }
    throw new Error(`${glb.name}: no RELIEFKIT_ extension (not exported by reliefkit)`);
  }
  async function readArrays(gl, glb, draw) {
    const out = {};
    for (const [name, ref] of Object.entries(draw.arrays)) {
      out[name] = await readArray(gl, glb, name, ref);
      if (ref.mipLevels) out[name].mipLevels = await Promise.all(ref.mipLevels.map((level, k) => readArray(gl, glb, `${name} level ${k + 1}`, level)));
    }
    return out;
  }
  async function readArray(gl, glb, name, ref) {
    const Typed = TYPED[ref.dtype];
    if (!Typed || !Array.isArray(ref.shape)) throw new Error(`${glb.name}: array ${name} has no known dtype`);
    const count = ref.shape.reduce((a, b) => a * b, 1);
    let data;
    if ("image" in ref) data = await pngValues(gl, glb, ref.image, ref.shape);
    else if ("bufferView" in ref) data = new Typed(viewBytes(glb, ref.bufferView, count * Typed.BYTES_PER_ELEMENT, name));
    else data = new Typed(count);
    return ref.encoding ? { dtype: ref.dtype, shape: ref.shape, data, encoding: ref.encoding } : { dtype: ref.dtype, shape: ref.shape, data };
  }
  function viewBytes(glb, index, length, name) {
    const view = (glb.json.bufferViews || [])[index];
    if (!view || view.byteLength !== length || (view.byteOffset || 0) + length > glb.bin.byteLength) {
      throw new Error(`${glb.name}: array ${name}'s bufferView does not hold it (truncated or forged)`);
    }
    const start = view.byteOffset || 0;
    return glb.bin.slice(start, start + length);
  }
  async function pngValues(gl, glb, index, shape) {
    const image = (glb.json.images || [])[index];
    if (!image) throw new Error(`${glb.name}: image ${index} is missing`);
    const view = (glb.json.bufferViews || [])[image.bufferView];
    if (!view || (view.byteOffset || 0) + view.byteLength > glb.bin.byteLength) {
      throw new Error(`${glb.name}: image ${index}'s bufferView lies outside the file (truncated or forged)`);
    }
    const bytes = glb.bin.slice(view.byteOffset || 0, (view.byteOffset || 0) + view.byteLength);
    let bitmap;
    try {
      bitmap = await createImageBitmap(
        new Blob([bytes], { type: "image/png" }),
        { premultiplyAlpha: "none", colorSpaceConversion: "none" }
      );
    } catch {
      throw new Error(`${glb.name}: image ${index} is not a PNG this browser decodes`);
    }
    const rows = shape.length === 2 ? shape[0] : shape.slice(0, -2).reduce((a, b) => a * b, 1);
    const width = shape.length === 2 ? shape[1] : shape[shape.length - 2];
    if (bitmap.width !== width || bitmap.height !== rows) {
      bitmap.close();
      throw new Error(`${glb.name}: image ${index} is ${bitmap.width}x${bitmap.height}, its array needs ${width}x${rows}`);
    }
    const rgba = readBitmap(gl, bitmap);
    const channels = shape.length === 2 ? 1 : shape[shape.length - 1];
    if (channels === 4) return rgba;
    const pick = { 1: [0], 2: [0, 3], 3: [0, 1, 2] }[channels];
    const out = new Uint8Array(rgba.length / 4 * channels);
    for (let p = 0, q = 0; p < rgba.length; p += 4) for (const c of pick) out[q++] = rgba[p + c];
    return out;
  }
  function readBitmap(gl, bitmap) {
    const tex = gl.createTexture();
    const fbo = gl.createFramebuffer();
    try {
      gl.bindTexture(gl.TEXTURE_2D, tex);
      gl.pixelStorei(gl.UNPACK_FLIP_Y_WEBGL, false);
      gl.pixelStorei(gl.UNPACK_PREMULTIPLY_ALPHA_WEBGL, false);
      gl.pixelStorei(gl.UNPACK_COLORSPACE_CONVERSION_WEBGL, gl.NONE);
      gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, gl.RGBA, gl.UNSIGNED_BYTE, bitmap);
      gl.bindFramebuffer(gl.FRAMEBUFFER, fbo);
      gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, tex, 0);
      const out = new Uint8Array(bitmap.width * bitmap.height * 4);
      gl.readPixels(0, 0, bitmap.width, bitmap.height, gl.RGBA, gl.UNSIGNED_BYTE, out);
      return out;
    } finally {
      gl.bindFramebuffer(gl.FRAMEBUFFER, null);
      gl.deleteFramebuffer(fbo);
      gl.deleteTexture(tex);
      bitmap.close();
    }
  }

  // web/src/hooks/ndarray.js
  var TYPES = {
    float32: Float32Array,
    float64: Float64Array,
    int8: Int8Array,
    uint8: Uint8Array,
    int16: Int16Array,
    uint16: Uint16Array,
    int32: Int32Array,
    uint32: Uint32Array,
    int64: BigInt64Array,
    uint64: BigUint64Array
  };
  function typedArrayOf(dtype) {
    const type = TYPES[dtype];
    if (!type) throw new Error(`no typed array for dtype ${dtype}`);
    return type;
  }
  function ndarray(dtype, shape, data) {
    const Type = typedArrayOf(dtype);
    const big = Type === BigInt64Array || Type === BigUint64Array;
    let typed = data;
    if (!(data instanceof Type)) {
      typed = new Type(data.length);
      for (let i = 0; i < data.length; i++) typed[i] = big ? BigInt(data[i]) : data[i];
    }
    const size = shape.reduce((a, b) => a * b, 1);
    if (typed.length !== size) throw new Error(`${typed.length} values for shape [${shape}]`);
    return { dtype, shape: [...shape], data: typed };
  }
  function at(array, i) {
    return Number(array.data[i]);
  }
  function float64(array) {
    const out = new Float64Array(array.data.length);
    for (let i = 0; i < out.length; i++) out[i] = Number(array.data[i]);
    return out;
  }
  function int32(array) {
    const out = new Int32Array(array.data.length);
    for (let i = 0; i < out.length; i++) out[i] = Number(array.data[i]);
    return out;
  }

  // web/src/hooks/linalg.js
  var identity2 = () => [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1];
  function mat4(m) {
    const flat2 = m.data ? Array.from(m.data, Number) : Array.isArray(m[0]) ? m.flat() : [...m];
    if (flat2.length !== 16) throw new Error(`a 4x4 matrix needs 16 numbers, got ${flat2.length}`);
    return flat2;
  }
  function multiply2(a, b) {
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
  function inverse(m) {
    const a = [...m];
    const inv = identity2();
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
  function translation2(offset) {
    const m = identity2();
    m[3] = offset[0];
    m[7] = offset[1];
    m[11] = offset[2];
    return m;
  }
  function apply4(m, x, y, z, w = 1) {
    const out = [0, 0, 0, 0];
    for (let r = 0; r < 4; r++) {
      out[r] = m[r * 4] * x + m[r * 4 + 1] * y + m[r * 4 + 2] * z + m[r * 4 + 3] * w;
    }
    return out;
  }
  function transformPoint(m, p) {
    const h = apply4(m, p[0], p[1], p[2], 1);
    return [h[0] / h[3], h[1] / h[3], h[2] / h[3]];
  }
  function invertBox(boxToWorld) {
    const centre = transformPoint(boxToWorld, [0.5, 0.5, 0.5]);
    const relative = multiply2(translation2(centre.map((x) => -x)), boxToWorld);
    return multiply2(inverse(relative), translation2(centre.map((x) => -x)));
  }
  function inverse3(m) {
    const [[a, b, c], [d, e, f], [g, h, i]] = m;
    const A = e * i - f * h, B = -(d * i - f * g), C = d * h - e * g;
    const det = a * A + b * B + c * C;
    if (det === 0) throw new Error("singular matrix");
    return [
      [A / det, -(b * i - c * h) / det, (b * f - c * e) / det],
      [B / det, (a * i - c * g) / det, -(a * f - c * d) / det],
      [C / det, -(a * h - b * g) / det, (a * e - b * d) / det]
    ];
  }
  var dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  var sub2 = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
  var cross2 = (a, b) => [
    a[1] * b[2] - a[2] * b[1],
    a[2] * b[0] - a[0] * b[2],
    a[0] * b[1] - a[1] * b[0]
  ];
  var norm2 = (a) => Math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);

  // web/src/hooks/view.js
  function matrixArray(m) {
    return { dtype: "float64", shape: [4, 4], data: Float64Array.from(m) };
  }
  function boxUniforms(camera, boxToWorld) {
    const origin = camera.origin;
    const relative = multiply2(translation2([-origin[0], -origin[1], -origin[2]]), mat4(boxToWorld));
    return { u_box_to_world: matrixArray(relative), u_world_to_box: matrixArray(invertBox(relative)) };
  }
  function cullFace(positions, origin, camera) {
    const v = camera.view;
    let most = -Infinity;
    for (let i = 0; i < positions.data.length; i += 3) {
      const x = at(positions, i) + origin[0];
      const y = at(positions, i + 1) + origin[1];
      const z = at(positions, i + 2) + origin[2];
      most = Math.max(most, v[8] * x + v[9] * y + v[10] * z + v[11]);
    }
    return most > -camera.near * 1.001 ? "front" : "back";
  }
  var isOrthographic = (camera) => camera.ortho_height !== null && camera.ortho_height !== void 0;

  // web/src/hooks/billboard_box_view.js
  var MIN_FLATTEN = 1e-3;
  function pixelSize(camera, distance) {
    if (isOrthographic(camera)) return 2 * camera.ortho_height / camera.size[1];
    return 2 * distance * Math.tan(camera.fov_deg * Math.PI / 180 / 2) / camera.size[1];
  }
  function switchDistance(camera, epsilon) {
    if (isOrthographic(camera)) return epsilon >= pixelSize(camera, 1) ? Infinity : 0;
    return epsilon * camera.size[1] / (2 * Math.tan(camera.fov_deg * Math.PI / 180 / 2));
  }
  function flattenFactor(camera, epsilon, center, transition) {
    const s = switchDistance(camera, epsilon);
    if (!Number.isFinite(s) || s <= 0) return s > 0 ? 1 : 0;
    const distance = norm2(sub2(camera.eye, center));
    const start = transition * s;
    if (distance <= start) return 1;
    return Math.max(0, (s - distance) / (s - start));
  }
  function viewLod(camera, flatten, lod) {
    if (lod) flatten = flattenFactor(camera, lod.epsilon, lod.center, lod.transition);
    const cloud = Boolean(lod) && flatten <= 0;
    return { lod: cloud ? "billboard cloud" : "boxes", flatten };
  }
  function scaleW(factor) {
    return [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, factor, 0.5 * (1 - factor), 0, 0, 0, 1];
  }
  function boxView(plan, camera, light, { box_to_world: boxToWorld, flatten, lod }) {
    const drawn = viewLod(camera, flatten, lod);
    if (drawn.lod !== "boxes") return { count: 0, stats: drawn };
    const handoff = lod ? 1 - drawn.flatten : 0;
    const box = multiply2(mat4(boxToWorld), scaleW(Math.max(drawn.flatten, MIN_FLATTEN)));
    return {
      uniforms: { u_handoff: handoff, ...boxUniforms(camera, box) },
      cull: cullFace(plan.geometry.attributes.in_position.array, plan.origin, camera),
      stats: drawn
    };
  }
  function cloudView(plan, camera, light, { flatten, lod }) {
    const drawn = viewLod(camera, flatten, lod);
    return drawn.lod === "billboard cloud" ? { stats: drawn } : { count: 0, stats: drawn };
  }

  // web/src/hooks/slices.js
  var CORNERS = Array.from({ length: 8 }, (_, i) => [i & 1, i >> 1 & 1, i >> 2 & 1]);
  var EDGES = [];
  for (let i = 0; i < 8; i++) {
    for (let a = 0; a < 3; a++) if (!(i & 1 << a)) EDGES.push([i, i | 1 << a]);
  }
  var ON_PLANE = 1e-12;
  var AXIS_PREFERENCE = [2, 0, 1];
  var TIE = 1e-9;
  var AUTO_MIN = 2;
  var AUTO_MAX = 2048;
  function viewDirection(camera, centre) {
    const f = isOrthographic(camera) ? [0, 1, 2].map((k) => camera.target[k] - camera.eye[k]) : [0, 1, 2].map((k) => centre[k] - camera.eye[k]);
    const n = norm2(f);
    if (!Number.isFinite(n) || n === 0) {
      throw new Error("no view direction: the eye is at the box centre");
    }
    return f.map((x) => x / n);
  }
  function boxParts(boxToWorld) {
    const m = mat4(boxToWorld);
    return [
      [0, 1, 2].map((r) => [m[4 * r], m[4 * r + 1], m[4 * r + 2]]),
      [m[3], m[7], m[11]]
    ];
  }
  var applyA = (a, q) => [0, 1, 2].map((k) => a[k][0] * q[0] + a[k][1] * q[1] + a[k][2] * q[2]);
  var det3 = (a) => dot(a[0], cross2(a[1], a[2]));
  function cutUnitCube(m, c) {
    const tol = ON_PLANE * Math.max(
      Math.abs(m[0]) + Math.abs(m[1]) + Math.abs(m[2]) + Math.abs(c),
      1e-300
    );
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
  function polygon(a, o, normal, d) {
    const m = [0, 1, 2].map((j) => a[0][j] * normal[0] + a[1][j] * normal[1] + a[2][j] * normal[2]);
    let q = cutUnitCube(m, d - dot(normal, o));
    if (q.length < 3) return [[], []];
    let x = q.map((p) => applyA(a, p).map((v, k) => v + o[k]));
    const centre = [0, 1, 2].map((k) => x.reduce((s, p) => s + p[k], 0) / x.length);
    let e1 = cross2(normal, [1, 0, 0]);
    if (norm2(e1) < 0.5) e1 = cross2(normal, [0, 1, 0]);
    const n1 = norm2(e1);
    e1 = e1.map((v) => v / n1);
    const e2 = cross2(normal, e1);
    const angle = x.map((p) => {
      const rel2 = [0, 1, 2].map((k) => p[k] - centre[k]);
      return Math.atan2(dot(rel2, e2), dot(rel2, e1));
    });
    const order = angle.map((_, i) => i).sort((i, j) => angle[i] - angle[j] || i - j);
    q = order.map((i) => q[i]);
    x = order.map((i) => x[i]);
    const rel = x.map((p) => [0, 1, 2].map((k) => p[k] - x[0][k]));
    const sum = [0, 0, 0];
    for (let k = 1; k < rel.length - 1; k++) {
      const c = cross2(rel[k], rel[k + 1]);
      for (let i = 0; i < 3; i++) sum[i] += c[i];
    }
    const largest = Math.max(...rel.flat().map(Math.abs));
    if (dot(sum, normal) <= 1e-14 * largest * largest) return [[], []];
    return [q, x];
  }
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
    const depths = Array.from(
      { length: count },
      (_, i) => near + (count - 1 - i + 0.5) / count * (far - near)
    );
    const normal = f.map((v) => -v);
    const polygons = depths.map((t) => polygon(a, o, normal, -t));
    const front = Array.from({ length: count }, (_, i) => count - 1 - i);
    return assemble(polygons, normal, depths.map((t) => -t), null, spacing, front);
  }
  function bestAxis(a, o, camera) {
    const centre = [0, 1, 2].map((k) => o[k] + 0.5 * (a[k][0] + a[k][1] + a[k][2]));
    const f = viewDirection(camera, centre);
    const g = inverse3(a);
    const score = g.map((row) => Math.abs(dot(row, f)) / norm2(row));
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
    const gn = norm2(g);
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
    if (sign < 0 !== det3(a) < 0) quad = quad.reverse();
    const polygons = levels.map((level) => {
      const q = quad.map((p) => p.map((v, k) => k === axis ? level : v));
      return [q, q.map((p) => applyA(a, p).map((v, k) => v + o[k]))];
    });
    const spacing = levels.length > 1 ? Math.abs((levels[1] - levels[0]) / gn) : 0;
    const front = Array.from({ length: count }, (_, i) => count - 1 - i);
    return assemble(polygons, normal, offsets, axis, spacing, front);
  }
  function sliceBox(boxToWorld, camera, slicing, count) {
    return slicing === "orthogonal" ? orthogonalSlices(boxToWorld, camera, count) : screenSlices(boxToWorld, camera, count);
  }
  function pixelWorldSize(camera, point) {
    const eye = transformPoint(camera.view, point);
    const p = camera.proj;
    const ndcY = (e) => (p[4] * e[0] + p[5] * e[1] + p[6] * e[2] + p[7]) / (p[12] * e[0] + p[13] * e[1] + p[14] * e[2] + p[15]);
    const step = Math.max(Math.abs(eye[2]), 1e-6) * 1e-3;
    const up = [eye[0], eye[1] + step, eye[2]];
    const pixels = Math.abs(ndcY(up) - ndcY(eye)) * 0.5 * camera.size[1];
    return pixels > 0 ? step / pixels : Infinity;
  }
  function autoSliceCount(thickness, camera, centre, finest, maximum = AUTO_MAX) {
    const spacing = Math.max(pixelWorldSize(camera, centre), finest);
    if (!Number.isFinite(spacing) || spacing <= 0) return AUTO_MIN;
    return Math.min(maximum, Math.max(AUTO_MIN, Math.ceil(thickness / spacing - 1e-9)));
  }
  function projectedArea(corners, camera) {
    const m = multiply2(camera.proj, camera.view);
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

  // web/src/hooks/displacement_slices_view.js
  var AUTO_MIN2 = 2;
  var AUTO_MAX2 = 512;
  var MAX_PLANES = 8192;
  var MAX_POLYGONS = 2e6;
  var TET_EDGES = [[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]];
  var TooManyPolygons = class extends Error {
  };
  var CUTS = Array.from({ length: 16 }, (_, m) => {
    const edge2 = (a, b) => TET_EDGES.findIndex(([i, j]) => i === Math.min(a, b) && j === Math.max(a, b));
    const up = [0, 1, 2, 3].filter((i) => m >> i & 1);
    const down = [0, 1, 2, 3].filter((i) => !(m >> i & 1));
    if (up.length === 1 || up.length === 3) {
      const [lone, rest] = up.length === 1 ? [up[0], down] : [down[0], up];
      return rest.map((r) => edge2(lone, r));
    }
    if (up.length === 2) {
      const [a, b] = up, [c, d] = down;
      return [edge2(a, c), edge2(a, d), edge2(b, d), edge2(b, c)];
    }
    return [];
  });
  function baseOf(d) {
    const rel = float64(d.positions), n = rel.length / 3;
    const world = new Float64Array(3 * n);
    for (let i = 0; i < 3 * n; i++) world[i] = rel[i] + d.origin[i % 3];
    return {
      world,
      normals: float64(d.normals),
      uvs: float64(d.uvs),
      tris: int32(d.indices),
      scale: d.scale,
      tile: d.tile,
      height: d.height
    };
  }
  var vec = (a, i) => [a[3 * i], a[3 * i + 1], a[3 * i + 2]];
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
  function texelWorldSize(base) {
    let area = 0, uvArea = 0;
    const { tris, world, uvs } = base;
    for (let f = 0; f < tris.length / 3; f++) {
      const [a, b, c] = [tris[3 * f], tris[3 * f + 1], tris[3 * f + 2]];
      area += 0.5 * norm2(cross2(sub2(vec(world, b), vec(world, a)), sub2(vec(world, c), vec(world, a))));
      const d1 = [uvs[2 * b] - uvs[2 * a], uvs[2 * b + 1] - uvs[2 * a + 1]];
      const d2 = [uvs[2 * c] - uvs[2 * a], uvs[2 * c + 1] - uvs[2 * a + 1]];
      uvArea += 0.5 * Math.abs(d1[0] * d2[1] - d1[1] * d2[0]);
    }
    const perUv = uvArea > 0 ? Math.sqrt(area / uvArea) : Math.sqrt(area);
    const [h, w] = base.height.shape;
    return perUv / Math.max(w * base.tile[0], h * base.tile[1]);
  }
  var part = () => ({ positions: [], box: [], jacobian: [], triangle: [], polygons: 0, levels: 0 });
  function offsetSurface(base, h) {
    const out = part();
    const { tris, world, normals, uvs, scale: scale2 } = base;
    const F = tris.length / 3;
    for (let f = 0; f < F; f++) {
      const v = [tris[3 * f], tris[3 * f + 1], tris[3 * f + 2]];
      const uv = v.map((i) => [uvs[2 * i], uvs[2 * i + 1]]);
      const du = [uv[1][0] - uv[0][0], uv[2][0] - uv[0][0]];
      const dv = [uv[1][1] - uv[0][1], uv[2][1] - uv[0][1]];
      const det = du[0] * dv[1] - du[1] * dv[0];
      const inv = Math.abs(det) > 1e-14 ? [[dv[1] / det, -du[1] / det], [-dv[0] / det, du[0] / det]] : [[0, 0], [0, 0]];
      const tp = v.map((i) => [0, 1, 2].map((k) => world[3 * i + k] + h * scale2 * normals[3 * i + k]));
      const e1 = sub2(tp[1], tp[0]), e2 = sub2(tp[2], tp[0]);
      const ju = [0, 1, 2].map((k) => e1[k] * inv[0][0] + e2[k] * inv[1][0]);
      const jv = [0, 1, 2].map((k) => e1[k] * inv[0][1] + e2[k] * inv[1][1]);
      for (let c = 0; c < 3; c++) {
        out.positions.push(...tp[c]);
        out.box.push(uv[c][0], uv[c][1], h);
        const n = [0, 1, 2].map((k) => scale2 * normals[3 * v[c] + k]);
        for (let k = 0; k < 3; k++) out.jacobian.push(ju[k], jv[k], n[k]);
        out.triangle.push(f);
      }
    }
    out.polygons = F;
    out.levels = 1;
    return out;
  }
  function uvGradients(base) {
    const { tris, world, uvs } = base;
    const F = tris.length / 3;
    const out = new Float64Array(6 * F);
    for (let f = 0; f < F; f++) {
      const [a, b, c] = [tris[3 * f], tris[3 * f + 1], tris[3 * f + 2]];
      const e1 = sub2(vec(world, b), vec(world, a)), e2 = sub2(vec(world, c), vec(world, a));
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
  function orthogonalLevels(base, count, minSpacing) {
    const out = [Array.from({ length: count }, (_, i) => (i + 0.5) / count)];
    const spacing = Math.max(base.scale / count, minSpacing);
    const grads = uvGradients(base);
    const F = grads.length / 6;
    for (let k = 0; k < 2; k++) {
      const g = [];
      for (let f = 0; f < F; f++) {
        const n2 = norm2([grads[6 * f + 3 * k], grads[6 * f + 3 * k + 1], grads[6 * f + 3 * k + 2]]);
        if (n2 > 0) g.push(n2);
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
      const dirs = [
        cross2(sub2(p[1], p[0]), sub2(p[2], p[0])),
        [grads[6 * f], grads[6 * f + 1], grads[6 * f + 2]],
        [grads[6 * f + 3], grads[6 * f + 4], grads[6 * f + 5]]
      ];
      let v = ortho;
      if (!v) {
        const d = sub2(centroids[f], camera.eye);
        const n = Math.max(norm2(d), 1e-300);
        v = d.map((x) => x / n);
      }
      const score = dirs.map((d) => {
        const n = norm2(d);
        return n > 0 ? Math.abs(dot(d.map((x) => x / n), v)) : -1;
      });
      const top = Math.max(...score);
      choice[f] = score[0] >= top - 1e-9 ? 0 : score.indexOf(top);
    }
    return choice;
  }
  function searchSorted(levels, x, right) {
    let lo = 0, hi = levels.length;
    while (lo < hi) {
      const mid = lo + hi >> 1;
      if (right ? levels[mid] <= x : levels[mid] < x) lo = mid + 1;
      else hi = mid;
    }
    return lo;
  }
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
    const used = /* @__PURE__ */ new Set();
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
          return [
            [0, 1, 2].map((k) => vol.positions[3 * ia + k] + u * (vol.positions[3 * ib + k] - vol.positions[3 * ia + k])),
            [0, 1, 2].map((k) => vol.box[3 * ia + k] + u * (vol.box[3 * ib + k] - vol.box[3 * ia + k]))
          ];
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
    return {
      positions: float64(v.positions),
      box: float64(v.box),
      tets: int32(v.tets),
      jacobian: float64(v.jacobian),
      prism_of: int32(v.prism_of)
    };
  }
  function sliceTriangles(base, vol, camera, mode, count, minSpacing) {
    const F = base.tris.length / 3;
    if (mode === "surface") {
      if (count * F > MAX_POLYGONS) throw new TooManyPolygons(`${count * F} slice polygons`);
      const levels2 = count > 1 ? Array.from({ length: count }, (_, i) => i * (1 / (count - 1))) : [0];
      if (count > 1) levels2[count - 1] = 1;
      return joined(
        levels2.map((h) => offsetSurface(base, h)),
        count > 1 ? base.scale / (count - 1) : base.scale,
        "surface",
        { a: F }
      );
    }
    const baseSurface = offsetSurface(base, 0);
    const T = vol.tets.length / 4;
    if (mode === "orthogonal") {
      const choice = orthogonalChoice(base, camera);
      const levels2 = orthogonalLevels(base, count, minSpacing);
      const parts = [baseSurface];
      const directions = {};
      [[0, "a", 2], [1, "b", 0], [2, "c", 1]].forEach(([k, name, axis]) => {
        const which = [];
        for (let t = 0; t < T; t++) if (choice[vol.prism_of[t]] === k) which.push(t);
        directions[name] = choice.filter((c) => c === k).length;
        if (!which.length || !levels2[k].length) return;
        const values = new Float64Array(vol.box.length / 3);
        for (let i = 0; i < values.length; i++) values[i] = vol.box[3 * i + axis];
        parts.push(cutTetrahedra(
          vol,
          which,
          values,
          levels2[k],
          parts.reduce((n2, p) => n2 + p.polygons, 0)
        ));
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
    const cut = cutTetrahedra(
      vol,
      Array.from({ length: T }, (_, t) => t),
      depth,
      levels,
      baseSurface.polygons
    );
    return joined([baseSurface, cut], (far - near) / planes, "screen", { planes });
  }
  function displacementSlicesView(plan, camera, light, {
    displacement,
    layers,
    volume,
    slicing,
    slices,
    alpha_test: alphaTest
  }) {
    const base = baseOf(displacement);
    const vol = volume && volumeOf(volume);
    const [lo, hi] = bounds(base);
    const centre = [0, 1, 2].map((k) => 0.5 * (lo[k] + hi[k]));
    const texel = texelWorldSize(base);
    let count = slices ?? autoSliceCount(base.scale, camera, centre, texel, AUTO_MAX2);
    const finest = slices == null ? Math.max(pixelWorldSize(camera, centre), texel) : 0;
    let tris;
    for (; ; ) {
      try {
        tris = sliceTriangles(base, vol, camera, slicing, count, finest);
        break;
      } catch (error) {
        if (!(error instanceof TooManyPolygons) || slices != null || count <= AUTO_MIN2) throw error;
        count = Math.max(AUTO_MIN2, Math.floor(count / 2));
      }
    }
    const m = tris.positions.length / 3;
    const stats = {
      slices: count,
      slicing,
      alpha_test: alphaTest,
      slice_planes: tris.levels,
      slice_polygons: tris.polygons,
      slice_triangles: Math.floor(m / 3),
      slice_spacing: tris.spacing,
      fill_pixels: projectedArea(tris.positions, camera)
    };
    for (const [k, v] of Object.entries(tris.directions)) stats[`direction_${k}`] = v;
    const origin = plan.origin;
    const column = (c) => ndarray("float32", [m, 3], Array.from(
      { length: 3 * m },
      (_, i) => tris.jacobian[9 * Math.floor(i / 3) + 3 * (i % 3) + c]
    ));
    const layer = float64(layers);
    return {
      uniforms: { u_bound: count > 1 ? 1 / (count - 1) : 1 },
      attributes: {
        in_position: ndarray("float32", [m, 3], tris.positions.map((x, i) => x - origin[i % 3])),
        in_uvh: ndarray("float32", [m, 3], tris.box),
        in_ju: column(0),
        in_jv: column(1),
        in_jh: column(2),
        in_layer: ndarray("float32", [m], tris.triangle.map((f) => layer[f]))
      },
      stats
    };
  }

  // web/src/hooks/instanced_view.js
  function instancedView(plan, camera, light, { hook, data }) {
    const fn = HOOKS[hook];
    if (!fn) throw new Error(`no JavaScript port of the view hook ${hook}`);
    const { cull, ...update } = fn(plan, camera, light, data);
    return update;
  }

  // web/src/hooks/relief_proxy_view.js
  function proxyView(plan, camera, light, { box_to_world: boxToWorld }) {
    return {
      uniforms: boxUniforms(camera, boxToWorld),
      cull: cullFace(plan.geometry.attributes.in_position.array, plan.origin, camera)
    };
  }

  // web/src/hooks/shellvolume_visibility_hook.js
  var RESOLUTION_TIE = 1e-9;
  var RECENT = 4096;
  function roundHalfEven(x) {
    const r = Math.round(x);
    return Math.abs(x % 1) === 0.5 && r % 2 !== 0 ? r - 1 : r;
  }
  function forward(camera) {
    const d = sub2(camera.target, camera.eye);
    const n = norm2(d);
    return [d[0] / n, d[1] / n, d[2] / n];
  }
  function centroidDepths(positions, tets, camera) {
    const ortho = isOrthographic(camera);
    const point = ortho ? forward(camera) : camera.eye;
    const count = tets.length / 4;
    const out = new Float64Array(count);
    const c = [0, 0, 0];
    for (let i = 0; i < count; i++) {
      for (let k = 0; k < 3; k++) {
        c[k] = (positions[tets[4 * i] * 3 + k] + positions[tets[4 * i + 1] * 3 + k] + positions[tets[4 * i + 2] * 3 + k] + positions[tets[4 * i + 3] * 3 + k]) / 4;
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
  function byDepth(depth) {
    const order = Int32Array.from({ length: depth.length }, (_, i) => i);
    return order.sort((a, b) => {
      const da = depth[a], db = depth[b];
      if (da !== da || db !== db) return (da !== da) - (db !== db) || a - b;
      return da - db || a - b;
    });
  }
  function adjacentRelations(cells, camera) {
    const ortho = isOrthographic(camera);
    const point = ortho ? forward(camera) : camera.eye;
    const tol = ortho ? 1e-12 : 1e-12 * cells.scale;
    const tet = int32(cells.pair_tet), other = int32(cells.pair_other);
    const plane = float64(cells.pair_plane);
    const src = [], dst = [];
    for (let k = 0; k < tet.length; k++) {
      const p = 4 * k;
      const facing = ortho ? -(plane[p] * point[0] + plane[p + 1] * point[1] + plane[p + 2] * point[2]) : plane[p] * point[0] + plane[p + 1] * point[1] + plane[p + 2] * point[2] + plane[p + 3];
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
            ends[e][k] = (inv[4 * k] * nx + inv[4 * k + 1] * ny + inv[4 * k + 2] * nz + inv[4 * k + 3]) / hw;
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
    return (tri[6 * i + 2 * a] - x) * (tri[6 * i + 2 * b + 1] - y) - (tri[6 * i + 2 * b] - x) * (tri[6 * i + 2 * a + 1] - y);
  }
  function inside(tri, i, area, x, y) {
    const e0 = edge(tri, i, 1, 2, x, y), e1 = edge(tri, i, 2, 0, x, y);
    const e2 = edge(tri, i, 0, 1, x, y);
    if (area > 0) return e0 >= 0 && e1 >= 0 && e2 >= 0;
    return e0 <= 0 && e1 <= 0 && e2 <= 0;
  }
  function rasterize(screen, front, corners, planes, origins, dirs, w, h) {
    const [tri, box, area] = covered(screen, front, corners, h, w);
    const pixelsOf = [];
    const counts2 = new Float64Array(h * w + 1);
    const n = corners.length / 3;
    for (let i = 0; i < n; i++) {
      const mine = [];
      for (let r = box[4 * i + 2]; r <= box[4 * i + 3]; r++) {
        for (let c = box[4 * i]; c <= box[4 * i + 1]; c++) {
          if (inside(tri, i, area[i], c + 0.5, r + 0.5)) {
            mine.push(r * w + c);
            counts2[r * w + c + 1] += 1;
          }
        }
      }
      pixelsOf.push(mine);
    }
    const starts = counts2;
    for (let p = 0; p < h * w; p++) starts[p + 1] += starts[p];
    const cursor = starts.slice(0, h * w);
    const faces = new Int32Array(starts[h * w]);
    const t = new Float64Array(starts[h * w]);
    for (let i = 0; i < n; i++) {
      for (const p of pixelsOf[i]) {
        const den = planes[4 * i] * dirs[3 * p] + planes[4 * i + 1] * dirs[3 * p + 1] + planes[4 * i + 2] * dirs[3 * p + 2];
        const num = planes[4 * i] * origins[3 * p] + planes[4 * i + 1] * origins[3 * p + 1] + planes[4 * i + 2] * origins[3 * p + 2] + planes[4 * i + 3];
        faces[cursor[p]] = i;
        t[cursor[p]] = den !== 0 ? -num / den : Infinity;
        cursor[p] += 1;
      }
    }
    for (let p = 0; p < h * w; p++) {
      for (let k = starts[p] + 1; k < starts[p + 1]; k++) {
        const tk = t[k], fk = faces[k];
        let j = k - 1;
        while (j >= starts[p] && (t[j] > tk || t[j] === tk && faces[j] > fk)) {
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
              const slot = ta * 40503 + tb & RECENT - 1;
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
  function abufferRelations(cells, positions, camera, resolution) {
    const [w0, h0] = camera.size;
    const s = resolution / Math.max(w0, h0);
    const width = Math.max(1, roundHalfEven(w0 * s)), height = Math.max(1, roundHalfEven(h0 * s));
    const mvp = multiply2(camera.proj, camera.view);
    const [screen, front] = project(positions, mvp, width, height);
    const [origins, dirs, shortest] = pixelRays(inverse(mvp), width, height);
    const [starts, faces, t] = rasterize(
      screen,
      front,
      int32(cells.face_vertices),
      float64(cells.face_plane),
      origins,
      dirs,
      width,
      height
    );
    const tie = RESOLUTION_TIE * cells.scale / Math.max(shortest, 1e-300);
    return rayEdges(starts, faces, t, int32(cells.face_tet), tie);
  }
  function topologicalOrder(order, relations) {
    const count = order.length;
    const rank = new Int32Array(count);
    for (let r = 0; r < count; r++) rank[order[r]] = r;
    const successors = Array.from({ length: count }, () => []);
    for (const [src, dst] of relations) {
      for (let k = 0; k < src.length; k++) {
        if (src[k] !== dst[k]) successors[rank[src[k]]].push(rank[dst[k]]);
      }
    }
    for (let v = 0; v < count; v++) {
      successors[v] = [...new Set(successors[v])].sort((a, b) => b - a);
    }
    const state2 = new Int8Array(count);
    const next = new Int32Array(count);
    const stack = new Int32Array(count);
    const post = new Int32Array(count);
    let nPost = 0, broken = 0;
    for (let root = count - 1; root >= 0; root--) {
      if (state2[root] !== 0) continue;
      let top = 0;
      stack[0] = root;
      state2[root] = 1;
      while (top >= 0) {
        const v = stack[top];
        if (next[v] < successors[v].length) {
          const u = successors[v][next[v]++];
          if (state2[u] === 0) {
            state2[u] = 1;
            stack[++top] = u;
          } else if (state2[u] === 1) {
            broken++;
          }
        } else {
          state2[v] = 2;
          post[nPost++] = v;
          top--;
        }
      }
    }
    const out = new Int32Array(count);
    for (let k = 0; k < count; k++) out[k] = order[post[count - 1 - k]];
    return [out, broken];
  }
  function visibilityOrder(cells, camera, method, resolution) {
    const positions = float64(cells.positions);
    const tets = int32(cells.tets);
    const depthOrder = byDepth(centroidDepths(positions, tets, camera));
    if (method === "centroid") return { order: depthOrder, cycles: 0, method };
    if (method !== "sxmpvo") throw new Error(`no visibility sort ${method}`);
    const gaps = abufferRelations(cells, positions, camera, resolution);
    const [order, cycles] = topologicalOrder(
      depthOrder,
      [adjacentRelations(cells, camera), gaps]
    );
    return { order, cycles, method };
  }
  function visibilityHook(plan, camera, light, { cells, method }) {
    const start = performance.now();
    const sorted = visibilityOrder(cells, camera, method, Math.max(...camera.size));
    return {
      attributes: { in_tet: { dtype: "int32", shape: [sorted.order.length], data: sorted.order } },
      stats: {
        sort: sorted.method,
        sort_seconds: (performance.now() - start) / 1e3,
        cycles: sorted.cycles
      }
    };
  }

  // web/src/hooks/slicing_ray_cast_view.js
  function rayCastView(plan, camera, light, { cube_to_world: cubeToWorld, texturing }) {
    return {
      uniforms: boxUniforms(camera, cubeToWorld),
      cull: cullFace(plan.geometry.attributes.in_position.array, plan.origin, camera),
      stats: { slicing: "raycast", slices: 0, passes: "single", texturing }
    };
  }

  // web/src/hooks/slicing_slices_view.js
  var VISIBLE_TEXELS = 1.5;
  var FINEST_TEXELS = 0.5;
  function sliceStack(cubeToWorld, resolution, slicing, slices, camera) {
    const m = mat4(cubeToWorld);
    const side = norm2([m[0], m[4], m[8]]);
    const centre = [m[3] + 0.5 * side, m[7] + 0.5 * side, m[11] + 0.5 * side];
    let thickness = side;
    if (slicing !== "orthogonal") {
      const f = viewDirection(camera, centre);
      thickness = side * (Math.abs(f[0]) + Math.abs(f[1]) + Math.abs(f[2]));
    }
    const count = slices || autoSliceCount(
      thickness,
      camera,
      centre,
      side / resolution * FINEST_TEXELS
    );
    return [sliceBox(m, camera, slicing, count), side];
  }
  function slicesView(plan, camera, light, {
    cube_to_world: cubeToWorld,
    resolution,
    slicing,
    slices,
    passes,
    alpha_test: alphaTest,
    texturing
  }) {
    const [stack, side] = sliceStack(cubeToWorld, resolution, slicing, slices, camera);
    const slack = alphaTest === "point" ? stack.spacing / side : 0;
    const sizes = stack.front.map((k) => stack.first[k + 1] - stack.first[k]);
    const corners = stack.triangles.flat().flatMap((v) => stack.positions[v]);
    const stats = {
      slicing,
      slices: stack.offsets.length,
      passes,
      texturing,
      alpha_test: alphaTest,
      slice_polygons: sizes.filter((n2) => n2 > 0).length,
      fill_pixels: projectedArea(corners, camera)
    };
    const update = {};
    if (passes === "stencil") {
      const ranges = [];
      let start = 0;
      for (const n2 of sizes) {
        if (n2 > 0) ranges.push(3 * start, 3 * n2);
        start += n2;
      }
      update.params = { ranges: ndarray("int32", [ranges.length / 2, 2], ranges) };
    } else {
      stats.draws = 1;
    }
    const ordered = stack.front.flatMap(
      (k) => stack.triangles.slice(stack.first[k], stack.first[k + 1]).flat()
    );
    const origin = plan.origin;
    const n = stack.positions.length;
    return {
      ...update,
      uniforms: {
        ...boxUniforms(camera, cubeToWorld),
        u_visible_depth: VISIBLE_TEXELS / resolution + slack,
        u_slice_normal: [...stack.normal],
        u_slice_spacing: stack.spacing || side
      },
      attributes: {
        in_position: ndarray(
          "float32",
          [n, 3],
          stack.positions.flatMap((p) => [p[0] - origin[0], p[1] - origin[1], p[2] - origin[2]])
        ),
        in_cube: ndarray("float32", [n, 3], stack.box.flat())
      },
      indices: ndarray("uint32", [ordered.length / 3, 3], ordered),
      stats
    };
  }

  // web/src/hooks/index.js
  var HOOKS = {
    "reliefkit.techniques.relief.render:proxy_view": proxyView,
    "reliefkit.techniques.billboard.box_render:box_view": boxView,
    "reliefkit.techniques.billboard.box_render:cloud_view": cloudView,
    "reliefkit.techniques.slicing.render:ray_cast_view": rayCastView,
    "reliefkit.techniques.slicing.render:slices_view": slicesView,
    "reliefkit.techniques.slicing.displacement_render:slices_view": displacementSlicesView,
    "reliefkit.techniques.shellvolume.render:visibility_hook": visibilityHook,
    "reliefkit.render.instancing:instanced_view": instancedView
  };

  // web/src/drawable.js
  async function makeDrawable(gl, glb, draw, name, programs, report2) {
    const plans = decodePlans(draw, await readArrays(gl, glb, draw));
    const executor = new Executor(gl, draw, name, HOOKS, programs);
    const drawn = [];
    try {
      for (const plan of plans) {
        try {
          executor.add(plan);
          drawn.push(plan);
        } catch (e) {
          if (!(e instanceof Unsupported)) throw e;
          report2(`${name}: ${e.message}`);
        }
      }
    } catch (e) {
      executor.dispose();
      throw e;
    }
    return { executor, plans: drawn };
  }

  // web/src/debug_views.js
  var MODES2 = { picture: 0, normals: 1, depth: 2, iterations: 3, mask: 4 };
  var ITERATIONS_ATTACHMENT = 3;
  var DebugViews = class {
    /** ``params``: the page's URL parameters (``debug`` read, and kept up to date);
     *  ``report``: the page's error line. */
    constructor(params, manifest, panels, report2) {
      this.params = params;
      this.panels = panels;
      this.report = report2;
      this.ramp = manifest.heat_ramp;
      this.programs = manifest.programs;
      this.reference = panels.find((p) => p.input.kind === "mesh") || null;
      this.onChange = () => {
      };
      this.state = window.reliefkit.debug = { mode: "picture", notes: [], iterations: [] };
      for (const p of panels) {
        p.note = document.createElement("p");
        p.note.className = "note";
        p.panel.appendChild(p.note);
      }
      let mode = params.get("debug") || "picture";
      if (!(mode in MODES2)) {
        report2(`error: debug must be one of ${Object.keys(MODES2).join(", ")}, got '${mode}'`);
        mode = "picture";
      }
      this.makeSelector(mode);
      this.ready = this.select(mode);
    }
    /** The selector above the pictures, showing ``mode``. */
    makeSelector(mode) {
      const label = document.createElement("label");
      label.id = "debug-views";
      label.textContent = "show ";
      const select = document.createElement("select");
      for (const name of Object.keys(MODES2)) select.add(new Option(name, name, false, name === mode));
      select.addEventListener("change", () => this.select(select.value).then(() => this.onChange()));
      label.appendChild(select);
      document.getElementById("panels").before(label);
    }
    /** Switch to ``mode``: the URL follows; the instrumented plans are made when first needed. */
    async select(mode) {
      this.mode = mode;
      this.state.mode = mode;
      if (mode === "picture") this.params.delete("debug");
      else this.params.set("debug", mode);
      if (mode === "iterations") {
        await Promise.all(this.panels.map((p) => this.counting(p)));
        if (this.mode !== mode) return;
      }
      for (const p of this.panels) {
        const reference = mode === "mask" && p === this.reference ? "the reference of the mask difference" : "";
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
      if (p.counting === void 0) {
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
      if (this.mode === "iterations" && !p.counting) return `no iteration counts for ${p.input.kind}`;
      if (this.mode === "mask" && !this.reference) return `mask difference needs the mesh as another input: reliefkit view ${p.input.name} MESH`;
      return null;
    }
    setNote(p, text) {
      p.note.textContent = text;
      this.state.notes[this.panels.indexOf(p)] = text;
    }
    /** The panels in the order they draw: the mask's reference first. */
    order(panels) {
      if (this.mode !== "mask" || !this.reference) return panels;
      return [this.reference, ...panels.filter((p) => p !== this.reference)];
    }
    /** The view ``p`` shows now: the current one, or the picture where it cannot. */
    shown(p) {
      return this.unavailable(p) ? "picture" : this.mode;
    }
    /** The executor that draws ``p`` now (its GPU time is the panel's). */
    executor(p) {
      return this.shown(p) === "iterations" ? p.counting.executor : p.executor;
    }
    /** Draw panel ``p`` from ``camera`` and show the current view. */
    draw(p, camera, light) {
      const mode = this.shown(p);
      const { plans, targets } = mode === "iterations" ? p.counting : p;
      const executor = this.executor(p);
      executor.frame(plans, camera, light, targets, (drawn) => this.presenting(p, mode, drawn, camera));
    }
    /** present.glsl's uniforms and textures of ``mode`` for the panel's drawn ``targets``. */
    presenting(p, mode, targets, camera) {
      if (mode === "picture") return {};
      const uniforms = { u_debug: MODES2[mode], u_heat_ramp: this.ramp };
      const textures = { u_normal: targets.normal };
      if (mode === "depth") {
        const toEye = camera.eye.map((x, i) => x - camera.target[i]);
        const distance = Math.hypot(...toEye);
        const radius = distance / camera.distance;
        uniforms.u_eye = camera.eye.map((x, i) => x - camera.origin[i]);
        uniforms.u_depth_range = [distance - radius, distance + radius];
      } else if (mode === "iterations") {
        const counts2 = this.iterations(p, readAttachment(p.gl, targets, ITERATIONS_ATTACHMENT));
        uniforms.u_iteration_scale = counts2.max > 0 ? counts2.max : 1;
        textures.u_iterations = targets.iterations;
      } else if (mode === "mask") {
        if (p === this.reference) this.referenceMask = coverage(readAttachment(p.gl, targets, 1));
        textures.u_reference = uploadMask(p, this.referenceMask, targets.size);
      }
      return { uniforms, textures };
    }
    /** render/draw.py _iteration_stats' iterations_mean and iterations_max of the counts,
     *  shown in the panel's caption and kept in window.reliefkit.debug.iterations. */
    iterations(p, counts2) {
      let fragments = 0, sum = 0, max = 0;
      for (let i = 0; i < counts2.length; i += 4) {
        if (counts2[i + 2] <= 0.5) continue;
        fragments += 1;
        sum += counts2[i];
        max = Math.max(max, counts2[i]);
      }
      const seen = { fragments, mean: fragments ? sum / fragments : 0, max };
      this.state.iterations[this.panels.indexOf(p)] = seen;
      this.setNote(p, `iterations: mean ${seen.mean.toFixed(2)}, max ${seen.max} (heat ramp 0..${seen.max})`);
      return seen;
    }
  };
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
  function coverage(position) {
    const out = new Uint8Array(position.length / 4);
    for (let i = 0; i < out.length; i++) out[i] = position[4 * i + 3] > 0.5 ? 255 : 0;
    return out;
  }
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

  // web/src/navigation.js
  var ORBIT_DEG_PER_PIXEL = 0.4;
  var KEY_ORBIT_DEG = 5;
  var KEY_PAN_PIXELS = 20;
  var KEY_ZOOM = 1.1;
  var clampEl = (e) => Math.max(-89, Math.min(89, e));
  var clampDist = (d) => Math.max(0.01, Math.min(1e4, d));
  function parseTarget(text) {
    const parts = text.split(",").map(Number);
    if (parts.length !== 3 || !parts.every(Number.isFinite)) {
      throw new Error(`target must be X,Y,Z (world coordinates, e.g. 0,0.5,0), got '${text}'`);
    }
    return parts;
  }
  var Navigation = class {
    /** ``opening``: the view the page opens on ({view: [az, el, dist or null], target or
     *  null}, from the URL); ``bounds`` the union of the inputs' framing boxes; ``frame``:
     *  inputs.json's camera defaults. */
    constructor(opening, bounds2, size, frame) {
      this.bounds = bounds2;
      this.size = size;
      this.frame = frame;
      this.opening = opening;
      this.reset();
      this.onChange = () => {
      };
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
      this.fitted = dist === null;
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
      const perPixel = 2 * d * Math.tan(camera.fov_deg * Math.PI / 360) / this.size[1];
      const [right, up] = [camera.view.slice(0, 3), camera.view.slice(4, 7)];
      this.target = camera.target.map((t, i) => t - (dx * right[i] - dy * up[i]) * perPixel);
    }
    /** The view in ``params``: view always (its distance once zoomed, to 10 digits: a copied
     *  URL draws the same picture), target once panned. */
    toUrl(params) {
      const angles = `${+this.az.toFixed(3)},${+this.el.toFixed(3)}`;
      params.set("view", this.fitted ? angles : `${angles},${+this.dist.toPrecision(10)}`);
      if (this.target) params.set("target", this.target.map((x) => +x.toPrecision(7)).join(","));
      else params.delete("target");
    }
    /** Mouse, touch and keyboard on ``canvas``. */
    attach(canvas) {
      const pointers = /* @__PURE__ */ new Map();
      const changed = () => this.onChange();
      canvas.addEventListener("contextmenu", (e) => e.preventDefault());
      canvas.addEventListener("pointerdown", (e) => {
        canvas.setPointerCapture(e.pointerId);
        pointers.set(e.pointerId, [e.clientX, e.clientY]);
      });
      const lift = (e) => pointers.delete(e.pointerId);
      canvas.addEventListener("pointerup", lift);
      canvas.addEventListener("pointercancel", lift);
      canvas.addEventListener("pointermove", (e) => {
        const last = pointers.get(e.pointerId);
        if (!last) return;
        const [dx, dy] = [e.clientX - last[0], e.clientY - last[1]];
        if (pointers.size === 2) {
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
      canvas.addEventListener("keydown", (e) => {
        const arrow = { ArrowLeft: [-1, 0], ArrowRight: [1, 0], ArrowUp: [0, -1], ArrowDown: [0, 1] }[e.key];
        if (arrow && e.shiftKey) this.pan(arrow[0] * KEY_PAN_PIXELS, arrow[1] * KEY_PAN_PIXELS);
        else if (arrow) {
          this.az -= arrow[0] * KEY_ORBIT_DEG;
          this.el = clampEl(this.el - arrow[1] * KEY_ORBIT_DEG);
        } else if (e.key === "+" || e.key === "=") this.zoom(1 / KEY_ZOOM);
        else if (e.key === "-") this.zoom(KEY_ZOOM);
        else if (e.key === "0") this.reset();
        else return;
        e.preventDefault();
        changed();
      });
      canvas.addEventListener("wheel", (e) => {
        e.preventDefault();
        this.zoom(Math.exp(e.deltaY * 1e-3));
        changed();
      }, { passive: false });
    }
  };

  // web/src/main.js
  var state = window.reliefkit = { ready: false, errors: [], frames: 0 };
  function report(message) {
    state.errors.push(message);
    const box = document.getElementById("messages");
    const line = document.createElement("p");
    line.className = "error";
    line.textContent = message;
    box.appendChild(line);
    fetch("log", { method: "POST", body: message }).catch(() => {
    });
  }
  window.addEventListener("error", (e) => report(`error: ${e.message}`));
  window.addEventListener("unhandledrejection", (e) => report(`error: ${e.reason && e.reason.message ? e.reason.message : e.reason}`));
  async function fetchOk(url) {
    const response = await fetch(url);
    if (response.status === 400 && (response.headers.get("Content-Type") || "").startsWith("text/plain")) {
      throw new Error(await response.text());
    }
    if (!response.ok) throw new Error(`cannot load ${url} (${response.status} ${response.statusText})`);
    return response;
  }
  async function loadPlans(gl, url, input, programs) {
    const glb = parseGlb(await (await fetchOk(url)).arrayBuffer(), input.name);
    const draw = drawOf(glb);
    return { glb, draw, ...await makeDrawable(gl, glb, draw, input.name, programs, report) };
  }
  async function reloadPanel(panel, query, programs) {
    const loaded = await loadPlans(panel.executor.gl, `${panel.input.file}?${query}`, panel.input, programs);
    return {
      swap() {
        panel.executor.dispose();
        DebugViews.forget(panel);
        Object.assign(panel, loaded);
      },
      discard() {
        loaded.executor.dispose();
      }
    };
  }
  async function openInput(input, index, size, programs) {
    const panel = document.createElement("figure");
    const canvas = document.createElement("canvas");
    [canvas.width, canvas.height] = size;
    canvas.style.width = `${size[0]}px`;
    canvas.style.height = `${size[1]}px`;
    const caption = document.createElement("figcaption");
    caption.textContent = `${input.name} (${input.kind})`;
    panel.append(canvas, caption);
    document.getElementById("panels").appendChild(panel);
    try {
      const gl = createContext(canvas);
      canvas.addEventListener("webglcontextlost", () => report(`${input.name}: the browser lost the WebGL context (reload the page)`));
      const loaded = await loadPlans(gl, input.file, input, programs);
      return { canvas, input, index, targets: createTargets(gl, size), gl, panel, ...loaded };
    } catch (e) {
      report(`${input.name}: ${e.message}`);
      return null;
    }
  }
  var PAGE_PARAMETERS = ["view", "size", "light", "target", "debug"];
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
  function unknownParameters(params, inputs) {
    const flags = new Set(inputs.flatMap((i) => (i.options || []).map((o) => o.flag)));
    for (const name of [...params.keys()]) {
      if (PAGE_PARAMETERS.includes(name) || flags.has(name)) continue;
      report(`error: the URL's ${name}=${params.get(name)} is no parameter of this page (${PAGE_PARAMETERS.join(", ")}) and no render option of its inputs${flags.size ? ` (${[...flags].join(", ")})` : ""}: ignored`);
      params.delete(name);
    }
  }
  function union(boxes) {
    return [0, 1].map((k) => [0, 1, 2].map((i) => (k ? Math.max : Math.min)(...boxes.map((b) => b[k][i]))));
  }
  async function main() {
    if (location.protocol === "file:") {
      throw new Error("this page was opened as a file: browsers let no page read the files beside it. Serve its folder and open the address printed: python -m http.server -d FOLDER");
    }
    const params = new URLSearchParams(location.search);
    const manifest = await (await fetchOk("inputs.json")).json();
    const frame = manifest.camera;
    unknownParameters(params, manifest.inputs);
    const size = fromUrl(params, "size", parseSize, frame.default_size);
    const [lightAz, lightEl] = fromUrl(params, "light", parseLight, manifest.light.angles);
    let light = lightFrom(manifest.light, lightAz, lightEl);
    const opening = {
      view: fromUrl(params, "view", parseView, frame.default_view),
      target: fromUrl(params, "target", parseTarget, null)
    };
    const nav = new Navigation(opening, union(manifest.inputs.map((i) => i.bounds)), size, frame);
    const panels = (await Promise.all(manifest.inputs.map((i, k) => openInput(i, k, size, manifest.programs)))).filter(Boolean);
    if (!panels.length) return;
    const debug = new DebugViews(params, manifest, panels, report);
    const readout = document.getElementById("stats");
    const render = () => {
      const start = performance.now();
      const camera = nav.camera();
      for (const p of debug.order(panels)) debug.draw(p, camera, light);
      for (const p of panels) p.executor.finish();
      state.frameMs = performance.now() - start;
      state.counts = panels.map((p) => ({ ...p.executor.counts }));
      const shown = () => {
        const gpu = panels.map((p) => debug.executor(p).gpuTime());
        state.gpuMs = gpu.every((t) => t !== null) ? gpu.reduce((a, b) => a + b, 0) : null;
        readout.textContent = `view ${nav.az.toFixed(1)},${nav.el.toFixed(1)},${nav.dist.toFixed(3)}  ${size[0]}x${size[1]}  frame ${state.frameMs.toFixed(1)} ms` + (state.gpuMs === null ? "" : `, GPU ${state.gpuMs.toFixed(2)} ms`) + (loads ? "  (making the plans with the new render options...)" : "");
      };
      shown();
      setTimeout(shown, 50);
      state.view = [nav.az, nav.el, nav.dist];
      state.target = camera.target;
      nav.toUrl(params);
      history.replaceState(null, "", `?${params}`);
      state.frames += 1;
      state.ready = loads === 0;
    };
    let loads = 0;
    let pending = false;
    const redraw = () => {
      if (!pending) {
        pending = true;
        requestAnimationFrame(() => {
          pending = false;
          render();
        });
      }
    };
    debug.onChange = redraw;
    nav.onChange = redraw;
    for (const p of panels) nav.attach(p.canvas);
    await debug.ready;
    lightControls({
      form: document.getElementById("light"),
      angles: [lightAz, lightEl],
      onChange: (a, e) => {
        light = lightFrom(manifest.light, a, e);
        params.set("light", `${a},${e}`);
        redraw();
      }
    });
    await optionControls({
      form: document.getElementById("options"),
      manifest,
      params,
      panels,
      report,
      reload: (panel, query) => reloadPanel(panel, query, manifest.programs),
      loading: (promise) => {
        loads += 1;
        state.ready = false;
        readout.textContent += "  (making the plans with the new render options...)";
        promise.catch(() => {
        }).finally(async () => {
          await debug.refresh();
          loads -= 1;
          redraw();
        });
      }
    });
    state.setView = (a, e, d = null) => {
      nav.set(a, e, d);
      render();
      return new Promise((resolve) => setTimeout(() => resolve({ frameMs: state.frameMs, gpuMs: state.gpuMs }), 60));
    };
    render();
  }
  main().catch((e) => report(`error: ${e.message}`)).finally(() => {
    state.loaded = true;
  });
})();
