// Draw plans as `render.plan.to_json` writes them, decoded: tuples become arrays, dicts
// objects, {"array": name} the named typed array; geometries and textures stay shared.

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
      return [name, { array, perInstance }];
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
      renderPass: entry.render_pass,
      origin: decode(entry.origin, arrays),
      first: entry.first,
      count: entry.count,
      perView: hook && { function: hook[0], data: hook[1] },
      multipass: multipass && { kind: multipass[0], programs: multipass[1], params: multipass[2] },
    };
  });
}

/** The key `export.draw` files a program's sources under: its name and sorted defines. */
export function programKey(name, defines) {
  const sorted = Object.keys(defines || {}).sort().map((k) => [k, defines[k]]);
  return `${name} ${JSON.stringify(sorted)}`;
}
