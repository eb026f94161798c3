// Draw plans in the browser: `render.plan.to_json`'s document (as an export's `draw` object
// holds it) decoded into plain objects, every array reference resolved.

/** A `to_json` value as plain JS: {"array": key} -> arrays[key], tuples -> arrays, dicts ->
 * objects, numpy scalars -> numbers. */
export function decodeValue(value, arrays) {
  if (Array.isArray(value)) return value.map((v) => decodeValue(v, arrays));
  if (value === null || typeof value !== "object") return value;
  if ("array" in value) {
    if (!(value.array in arrays)) throw new Error(`the plans name no array ${value.array}`);
    return arrays[value.array];
  }
  if ("scalar" in value) return value.value;
  if ("tuple" in value) return value.tuple.map((v) => decodeValue(v, arrays));
  if ("encoded" in value) return decodeObject(value.encoded, arrays);
  return decodeObject(value.dict, arrays);
}

function decodeObject(entries, arrays) {
  return Object.fromEntries(Object.entries(entries).map(([k, v]) => [k, decodeValue(v, arrays)]));
}

function geometryOf(g, arrays) {
  const out = {};
  for (const [k, v] of Object.entries(g)) {
    if (k !== "attributes") out[k] = decodeValue(v, arrays);
  }
  out.attributes = {};
  for (const [name, a] of Object.entries(g.attributes)) {
    const [array, perInstance] = decodeValue(a, arrays);
    out.attributes[name] = { array, per_instance: perInstance };
  }
  return out;
}

/** The plans of a `to_json` document with `arrays` ({key: {dtype, shape, data}}): each
 * {name, program: {name, defines}, geometry: {attributes: {name: {array, per_instance}},
 * indices, primitive, vertices, instances}, textures, uniforms, raster, render_pass, origin,
 * first, count, per_view: {function, data} | null, multipass: {kind, programs, params} |
 * null}. Shared geometries and textures stay shared objects. */
export function decodePlans(doc, arrays) {
  const geometries = {};
  for (const [key, g] of Object.entries(doc.geometries)) geometries[key] = geometryOf(g, arrays);
  const textures = {};
  for (const [key, t] of Object.entries(doc.textures)) textures[key] = decodeObject(t, arrays);
  return doc.plans.map((entry) => {
    const plan = {};
    for (const [k, v] of Object.entries(entry)) {
      if (k !== "geometry" && k !== "textures") plan[k] = decodeValue(v, arrays);
    }
    const [program, defines] = plan.program;
    plan.program = { name: program, defines };
    plan.geometry = geometries[entry.geometry];
    plan.textures = Object.fromEntries(
      Object.entries(entry.textures).map(([n, k]) => [n, textures[k]]));
    plan.per_view = plan.per_view && { function: plan.per_view[0], data: plan.per_view[1] };
    if (plan.multipass) {
      const [kind, programs, params] = plan.multipass;
      plan.multipass = {
        kind, params,
        programs: Object.fromEntries(Object.entries(programs).map(
          ([role, [name, defs]]) => [role, { name, defines: defs }])),
      };
    }
    return plan;
  });
}
