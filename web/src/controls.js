// The page's controls: the render options of its inputs and the light's direction.
//
// Options: one control per option name over all inputs (inputs.json `options`: each input's
// declarations, from render_options, and the value its GLB was made with), labelled with the
// CLI's flag and applying to every input that declares it, as the CLI routes `--method` to
// each input that takes it. Changing one fetches those inputs' GLBs made again with the new
// options (`input-K.glb?FLAG=VALUE...`, the server checks them as the CLI does) and swaps
// their plans. The values that differ from the defaults are in the URL with the CLI's names
// (`&method=binary`), and a URL with them opens with them. A static export has no server to
// make plans: its controls show the exported values, disabled, and a URL asking for others
// is said.
//
// Values are handled as the URL's text: booleans 'true'/'false', none '', lists 'a,b,c'.

/** A JSON value of inputs.json as the URL's text. */
export function asText(value) {
  if (value === null || value === undefined) return '';
  if (Array.isArray(value)) return value.map(String).join(',');
  return String(value);
}

/** Whether two texts are the same value of ``opt`` ('8' and '8.0' are). */
export function sameValue(opt, a, b) {
  if (['int', 'float', 'floats'].includes(opt.kind) && a !== '' && b !== '') {
    const [x, y] = [a, b].map((t) => t.split(',').map(Number));
    return x.length === y.length && x.every((v, i) => v === y[i]);
  }
  return a === b;
}

/** The options of all inputs by flag: the first declaration, the declaring inputs' indices. */
export function optionUnion(inputs) {
  const union = new Map();
  inputs.forEach((input, index) => {
    for (const opt of input.options || []) {
      if (!union.has(opt.flag)) union.set(opt.flag, { opt, owners: [] });
      union.get(opt.flag).owners.push(index);
    }
  });
  return union;
}

/** The query that makes input ``input``'s GLB with ``values`` (flag -> text; every option it
 *  declares, so the server needs no other state). */
export function optionQuery(input, values) {
  const query = new URLSearchParams();
  for (const opt of input.options) query.set(opt.flag, values[opt.flag]);
  return query.toString();
}

/**
 * Build the option controls into ``form`` and apply the URL's options.
 * ``panels``: the opened inputs ({index, ...}); ``reload(panel, query)`` loads the plans of
 * the panel's GLB with ``query``: {swap(), discard()} (rejects on failure);
 * ``loading(promise)`` marks the page not ready until the promise ends and a frame is drawn;
 * ``report(message)`` shows an error line. Returns the promise of the URL's options applied.
 */
export function optionControls({ form, manifest, params, panels, reload, loading, report }) {
  const inputs = manifest.inputs;
  const union = optionUnion(inputs);
  // what each input's current plans are made with
  const current = inputs.map((input) => Object.fromEntries(
    (input.options || []).map((o) => [o.flag, asText(o.value)])));
  const shown = (flag) => current[union.get(flag).owners[0]][flag];
  const defaultOf = (k, flag) => asText(inputs[k].options.find((o) => o.flag === flag).default);
  const syncUrl = () => {
    for (const [flag, { opt, owners }] of union) {
      const differs = owners.some((k) => !sameValue(opt, current[k][flag], defaultOf(k, flag)));
      if (differs) params.set(flag, shown(flag));
      else params.delete(flag);
    }
    history.replaceState(null, '', `?${params}`);
  };

  let queue = Promise.resolve();
  /** ``flag`` set to ``text`` on every input declaring it: all their GLBs fetched and swapped, or none. */
  const apply = (flag, text) => {
    const { owners } = union.get(flag);
    queue = queue.then(async () => {
      const targets = panels.filter((p) => owners.includes(p.index) && current[p.index][flag] !== text);
      const wanted = new Map(targets.map((p) => [p, { ...current[p.index], [flag]: text }]));
      const loads = await Promise.allSettled(targets.map((p) => reload(p, optionQuery(inputs[p.index], wanted.get(p)))));
      const failed = loads.filter((r) => r.status === 'rejected');
      if (failed.length) {
        for (const r of loads) if (r.status === 'fulfilled') r.value.discard();
        for (const r of failed) report(r.reason.message);
      } else {
        for (const r of loads) r.value.swap();
        for (const [p, values] of wanted) current[p.index] = values;
      }
      setControl(flag, shown(flag)); // the values drawn
      syncUrl();
    });
    loading(queue);
    return queue;
  };

  const controls = new Map();
  const setControl = (flag, text) => {
    const input = controls.get(flag);
    if (input.type === 'checkbox') input.checked = text === 'true';
    else input.value = text;
  };
  form.replaceChildren();
  form.addEventListener('submit', (e) => e.preventDefault()); // Enter applies, never navigates
  for (const [flag, { opt, owners }] of union) {
    const label = document.createElement('label');
    const kinds = [...new Set(owners.map((k) => inputs[k].kind))].join(', ');
    label.title = `${opt.help} (applies to: ${kinds})`;
    const name = document.createElement('span');
    name.textContent = `--${flag}`;
    const input = control(opt);
    input.id = `option-${flag}`;
    input.name = flag;
    input.disabled = !manifest.live;
    const small = document.createElement('small');
    small.textContent = kinds;
    label.append(name, input, small);
    form.appendChild(label);
    controls.set(flag, input);
    setControl(flag, shown(flag));
    input.addEventListener('change', () => apply(flag, input.type === 'checkbox' ? String(input.checked) : input.value));
  }
  if (!union.size) return Promise.resolve();
  if (!manifest.live) {
    const why = document.createElement('p');
    why.className = 'why';
    why.textContent = 'This static export holds the plans made with these options: run '
      + '`reliefkit view` on its inputs with other render options (or export again with them) to change them.';
    form.appendChild(why);
  }

  // the URL's options: applied (served), or said (static)
  const asked = [...union].filter(([flag]) => params.has(flag));
  for (const [flag, { opt, owners }] of asked) {
    const text = params.get(flag);
    const differing = owners.filter((k) => !sameValue(opt, current[k][flag], text));
    if (!differing.length) continue;
    if (manifest.live) apply(flag, text);
    else {
      report(`the URL asks for ${flag}=${text}, but this static export holds the plans made with `
        + `${flag}=${current[differing[0]][flag]} (export again with --${flag} ${text} to see them)`);
    }
  }
  return queue.then(syncUrl); // what is drawn: the values it was exported or switched with
}

/** The input element for one option: choices a select, a bool a checkbox, numbers a number
 *  field within lo..hi; an option whose default is none may be left empty. */
function control(opt) {
  if (opt.choices) {
    const select = document.createElement('select');
    const choices = (opt.default === null ? [''] : []).concat(opt.choices.map(String));
    for (const choice of choices) {
      const option = document.createElement('option');
      option.value = choice;
      option.textContent = choice === '' ? '(none)' : choice;
      select.appendChild(option);
    }
    return select;
  }
  const input = document.createElement('input');
  if (opt.kind === 'bool') {
    input.type = 'checkbox';
    return input;
  }
  if (opt.kind === 'int' || opt.kind === 'float') {
    input.type = 'number';
    input.step = opt.kind === 'int' ? '1' : 'any';
    if (opt.lo !== null) input.min = String(opt.lo);
    if (opt.hi !== null) input.max = String(opt.hi);
  } else input.type = 'text';
  if (opt.default === null) input.placeholder = 'none';
  return input;
}

/** Two sliders (azimuth, elevation in degrees) for the light; ``onChange(az, el)`` as they move. */
export function lightControls({ form, angles, onChange }) {
  form.addEventListener('submit', (e) => e.preventDefault());
  const sliders = [['azimuth', -180, 180, angles[0]], ['elevation', -90, 90, angles[1]]].map(([what, lo, hi, value]) => {
    const label = document.createElement('label');
    label.title = `the light's ${what} in degrees (render --light AZ,EL)`;
    const name = document.createElement('span');
    name.textContent = `light ${what}`;
    const input = document.createElement('input');
    Object.assign(input, { type: 'range', min: String(lo), max: String(hi), step: '1', value: String(value), id: `light-${what}` });
    const readout = document.createElement('output');
    readout.textContent = String(value);
    label.append(name, input, readout);
    form.appendChild(label);
    return [input, readout];
  });
  for (const [input, readout] of sliders) {
    input.addEventListener('input', () => {
      readout.textContent = input.value;
      onChange(Number(sliders[0][0].value), Number(sliders[1][0].value));
    });
  }
}
