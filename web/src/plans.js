// Draw plans as `render.plan.to_json` writes them, decoded: tuples become arrays, dicts
// objects, {"array": name} the named typed array; geometries and textures stay shared. A plan
// keeps the Python field names (render_pass, per_view, per_instance, ...), the form the view
// hooks' ports (web/src/hooks/) take; `withView` is `DrawPlan.with_view`.

function decode(value, arrays) {
  if (Array.isArray(value)) return value.map((v) => decode(v, arrays));
  if (value === null || typeof value !== 'object') return value;
  if ('array' in value) return arrays[value.array];
  if ('scalar' in value) return value.value;
  if ('tuple' in value) return value.tuple.map((v) => decode(v, arrays));
  if ('encoded' in value) return { encoded: decodeFields(value.encoded, arrays) };
  return decodeFields(value.dict, arrays);
}

function decodeFields(object, arrays) {
  return Object.fromEntries(Object.entries(object).map(([k, v]) => [k, decode(v, arrays)]));
}

/** The plans of a ``draw`` object with its arrays (`glb.readArrays`). */
export function decodePlans(draw, arrays) {
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
      multipass: multipass && { kind: multipass[0], programs: multipass[1], params: multipass[2] },
    };
  });
}

/** The key `export.draw` files a program's sources under: its name and sorted defines. */
export function programKey(name, defines) {
  const sorted = Object.keys(defines || {}).sort().map((k) => [k, defines[k]]);
  return `${name} ${JSON.stringify(sorted)}`;
}

/** ``plan`` as drawn from a view: render/plan.py DrawPlan.with_view with a hook's update
 *  (a plain object with ViewUpdate's fields; omitted ones leave the plan's own). */
export function withView(plan, update) {
  let geometry = plan.geometry;
  const { attributes = {}, indices, vertices, instances } = update;
  if (Object.keys(attributes).length || indices != null || vertices != null || instances != null) {
    geometry = {
      ...geometry,
      attributes: Object.fromEntries(Object.entries(geometry.attributes).map(
        ([name, attr]) => [name, { ...attr, array: attributes[name] || attr.array }])),
      indices: indices != null ? indices : geometry.indices,
      vertices: vertices != null ? vertices : geometry.vertices,
      instances: instances != null ? instances : geometry.instances,
    };
  }
  const params = update.params && Object.keys(update.params).length ? update.params : null;
  return {
    ...plan,
    geometry,
    raster: update.cull != null ? { ...plan.raster, cull: update.cull } : plan.raster,
    count: update.count != null ? update.count : plan.count,
    multipass: params ? { ...plan.multipass, params: { ...plan.multipass.params, ...params } } : plan.multipass,
    uniforms: { ...plan.uniforms, ...(update.uniforms || {}) },
  };
}
