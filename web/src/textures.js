// Plan textures (render/plan.py Texture) as WebGL2 textures, with the formats and sampler
// state gl/textures.py gives them: uint8 normalised (sRGB-decoded with srgb), float32 and
// float16 float, uint16 unsigned integer; given mip levels, built mipmaps, wrap per axis.

const FORMATS = { // dtype -> [internal formats by channel count, format by channel count, type]
  uint8: ['R8 RG8 RGB8 RGBA8', 'RED RG RGB RGBA', 'UNSIGNED_BYTE'],
  float32: ['R32F RG32F RGB32F RGBA32F', 'RED RG RGB RGBA', 'FLOAT'],
  float16: ['R16F RG16F RGB16F RGBA16F', 'RED RG RGB RGBA', 'HALF_FLOAT'],
  uint16: ['R16UI RG16UI RGB16UI RGBA16UI', 'RED_INTEGER RG_INTEGER RGB_INTEGER RGBA_INTEGER', 'UNSIGNED_SHORT'],
};
const TARGETS = { '2d': 'TEXTURE_2D', '3d': 'TEXTURE_3D', '2d_array': 'TEXTURE_2D_ARRAY' };

import { decodeEncoded } from './textures/bc.js';

/** An array as the page uploads it: a block-compressed or quantized one (``encoding``)
 *  decoded to the values `reliefkit.compact.encodings.decoded` gives (the array the Python
 *  executor uploads where its GL lacks the format; `<sampler>_decode` stays (1, 0)). */
function decoded(a) {
  return a.encoding ? decodeEncoded(a.encoding, a.data) : a;
}

/** An encoded texture's mip chain as the Python executor uploads it (its blocks' levels,
 *  docs/gltf.md `mipLevels`), each decoded; null where it has none. */
function decodedChain(a) {
  if (!a.encoding || !a.encoding.mipmaps || !a.mipLevels) return null;
  const { shape, layered } = a.encoding;
  const first = layered ? 1 : 0;
  return [decoded(a), ...a.mipLevels.map((level, k) => {
    const size = shape.slice();
    size[first] = Math.max(shape[first] >> (k + 1), 1);
    size[first + 1] = Math.max(shape[first + 1] >> (k + 1), 1);
    return decodeEncoded({ ...a.encoding, shape: size }, level.data);
  })];
}

export function uploadTexture(gl, t) {
  const chain = decodedChain(t.array);
  t = { ...t, array: decoded(t.array), levels: chain || (t.levels && t.levels.map(decoded)) };
  const target = gl[TARGETS[t.target]];
  const levels = t.levels || [t.array];
  const { shape, dtype } = levels[0];
  const planar = t.target === '2d';
  const dims = planar ? 2 : 3;
  const channels = shape.length > dims ? shape[dims] : 1;
  const format = FORMATS[dtype];
  if (!format || channels < 1 || channels > 4) throw new Error(`${t.what}: a ${dtype} texture of ${channels} channels is not supported`);
  let internal = gl[format[0].split(' ')[channels - 1]];
  if (t.srgb) {
    if (dtype !== 'uint8' || channels !== 4) throw new Error(`${t.what}: sRGB textures must be RGBA uint8`);
    internal = gl.SRGB8_ALPHA8;
  }
  const fmt = gl[format[1].split(' ')[channels - 1]];
  const type = gl[format[2]];
  const tex = gl.createTexture();
  gl.bindTexture(target, tex);
  gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
  let bytes = 0;
  levels.forEach((level, k) => {
    const [d, h, w] = planar ? [1, ...level.shape.slice(0, 2)] : level.shape.slice(0, 3);
    const data = level.dtype === 'float64' ? new Float32Array(level.data) : level.data;
    bytes += data.byteLength;
    if (planar) gl.texImage2D(target, k, internal, w, h, 0, fmt, type, data);
    else gl.texImage3D(target, k, internal, w, h, d, 0, fmt, type, data);
  });
  const integer = dtype === 'uint16';
  const nearest = t.filter === 'nearest' || integer;
  let minify = nearest ? gl.NEAREST : gl.LINEAR;
  if (chain) { // trilinear over the given chain, as the executor samples an encoded one
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
    gl.texParameteri(target, wraps[i], w === 'repeat' ? gl.REPEAT : gl.CLAMP_TO_EDGE);
  });
  return { tex, target, bytes };
}
