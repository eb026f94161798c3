// Reading a GLB that `reliefkit export --embed-shaders` (or `reliefkit view`) wrote: the JSON
// chunk, the BIN chunk, and the typed arrays of reliefkit's extension (docs/gltf.md):
// bufferView bytes or PNG images, each with its dtype and shape.

const MAGIC = 0x46546c67; // "glTF"
const JSON_CHUNK = 0x4e4f534a;
const BIN_CHUNK = 0x004e4942;

const TYPED = {
  bool: Uint8Array, int8: Int8Array, uint8: Uint8Array, int16: Int16Array,
  uint16: Uint16Array, int32: Int32Array, uint32: Uint32Array, float16: Uint16Array,
  float32: Float32Array, float64: Float64Array, int64: BigInt64Array, uint64: BigUint64Array,
};

/** The JSON document and BIN chunk of a GLB file's bytes; throws in words on anything else. */
export function parseGlb(buffer, name) {
  const data = new DataView(buffer);
  if (buffer.byteLength < 20 || data.getUint32(0, true) !== MAGIC) {
    throw new Error(`${name} is not a GLB file`);
  }
  if (data.getUint32(4, true) !== 2 || data.getUint32(8, true) > buffer.byteLength) {
    throw new Error(`${name}: not a glTF 2.0 GLB, or truncated`);
  }
  let json = null;
  let bin = new ArrayBuffer(0);
  for (let at = 12; at + 8 <= buffer.byteLength;) {
    const length = data.getUint32(at, true);
    const type = data.getUint32(at + 4, true);
    if (at + 8 + length > buffer.byteLength) throw new Error(`${name}: a chunk runs past the end`);
    const body = buffer.slice(at + 8, at + 8 + length);
    if (type === JSON_CHUNK) json = parseJson(body, name);
    else if (type === BIN_CHUNK) bin = body;
    at += 8 + length;
  }
  if (json === null) throw new Error(`${name}: no JSON chunk`);
  return { json, bin, name };
}

function parseJson(bytes, name) {
  try {
    return JSON.parse(new TextDecoder('utf-8', { fatal: true }).decode(bytes));
  } catch (e) {
    throw new Error(`${name}: its JSON chunk does not parse (${e.message})`);
  }
}

/** The ``draw`` object of the file's reliefkit extension (plans, arrays, programs). */
export function drawOf(glb) {
  for (const node of glb.json.nodes || []) {
    for (const [ext, value] of Object.entries(node.extensions || {})) {
      if (!ext.startsWith('RELIEFKIT_')) continue;
      if (!value.draw) throw new Error(`${glb.name}: ${ext} holds no draw plans`);
      if (!Array.isArray(value.draw.programs)) {
        throw new Error(`${glb.name}: its draw plans carry no shaders (export with --embed-shaders)`);
      }
      return value.draw;
    }
  }
  throw new Error(`${glb.name}: no RELIEFKIT_ extension (not exported by reliefkit)`);
}

/** Every named array of ``draw.arrays`` as {dtype, shape, data} (plus ``encoding`` for a
 *  texture stored as its blocks); PNG images are decoded through ``gl`` so their bytes stay
 *  exact (no premultiplying, no colour conversion). */
export async function readArrays(gl, glb, draw) {
  const out = {};
  for (const [name, ref] of Object.entries(draw.arrays)) {
    out[name] = await readArray(gl, glb, name, ref);
    // an encoded texture's mip levels as the GPU gets them (re-encoded: docs/gltf.md)
    if (ref.mipLevels) out[name].mipLevels = await Promise.all(ref.mipLevels.map((level, k) => readArray(gl, glb, `${name} level ${k + 1}`, level)));
  }
  return out;
}

async function readArray(gl, glb, name, ref) {
  const Typed = TYPED[ref.dtype];
  if (!Typed || !Array.isArray(ref.shape)) throw new Error(`${glb.name}: array ${name} has no known dtype`);
  const count = ref.shape.reduce((a, b) => a * b, 1);
  let data;
  if ('image' in ref) data = await pngValues(gl, glb, ref.image, ref.shape);
  else if ('bufferView' in ref) data = new Typed(viewBytes(glb, ref.bufferView, count * Typed.BYTES_PER_ELEMENT, name));
  else data = new Typed(count);
  // an encoded array is its stored blocks with the record that decodes them (docs/gltf.md)
  return ref.encoding ? { dtype: ref.dtype, shape: ref.shape, data, encoding: ref.encoding }
    : { dtype: ref.dtype, shape: ref.shape, data };
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
    bitmap = await createImageBitmap(new Blob([bytes], { type: 'image/png' }),
      { premultiplyAlpha: 'none', colorSpaceConversion: 'none' });
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
  const out = new Uint8Array((rgba.length / 4) * channels);
  for (let p = 0, q = 0; p < rgba.length; p += 4) for (const c of pick) out[q++] = rgba[p + c];
  return out;
}

/** The RGBA bytes of an image bitmap, rows top first (as the PNG stores them). */
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
