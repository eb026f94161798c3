// Block-compressed textures in the browser (no DOM): a draw plan's encoded texture (its
// blocks or unorm values plus the `encoding` record, docs/gltf.md "Typed arrays") is
// uploaded as a compressed texture where the browser has the extension (`glFormatOf`),
// else decoded on the CPU to exactly the array Python's
// `reliefkit.compact.encodings.decoded` gives (`decodeEncoded`), texture2ddecoder's
// arithmetic included (integer divisions that truncate in BC1 and BC4/BC5).

import { ANCHORS2, ANCHORS3, PARTITIONS2, PARTITIONS3 } from "./bptc_tables.js";

/** Block formats: channels decoded, bytes of a 4x4 block (compact/blocks.py's FORMATS). */
const BLOCKS = { bc1: [3, 8], bc4: [1, 8], bc5: [2, 16], bc7: [4, 16] };
/** Quantized formats: bytes of one unorm value. */
const QUANTIZED = { u8: 1, u16: 2 };

/** Block format -> WebGL2 internal formats (linear, sRGB or null), the extensions naming
 * them and the targets they allow (gl/textures.py's BLOCK_FORMATS). BC1 is opaque colour
 * here (its alpha is not kept): uploaded as RGB DXT1, whose three-colour blocks' fourth
 * entry is opaque black, as decoded, not transparent as RGBA DXT1 would sample it. */
export const GL_FORMATS = {
  bc1: { linear: 0x83f0, srgb: 0x8c4c, extension: "WEBGL_compressed_texture_s3tc",
    srgbExtension: "WEBGL_compressed_texture_s3tc_srgb", targets: ["2d", "2d_array"] },
  bc4: { linear: 0x8dbb, srgb: null, extension: "EXT_texture_compression_rgtc",
    targets: ["2d", "2d_array"] },
  bc5: { linear: 0x8dbd, srgb: null, extension: "EXT_texture_compression_rgtc",
    targets: ["2d", "2d_array"] },
  bc7: { linear: 0x8e8c, srgb: 0x8e8d, extension: "EXT_texture_compression_bptc",
    srgbExtension: "EXT_texture_compression_bptc", targets: ["2d", "2d_array", "3d"] },
};

// -- the record -----------------------------------------------------------------------------

function layout(encoding) {
  const { format, shape, layered } = encoding;
  const first = layered ? 1 : 0;
  if (!(format in BLOCKS) && !(format in QUANTIZED)) {
    throw new Error(`unknown encoding ${JSON.stringify(format)}`);
  }
  if (shape.length !== 2 + first && shape.length !== 3 + first) {
    throw new Error(`an encoded ${layered ? "layered " : ""}image needs shape `
      + `(${layered ? "L, " : ""}H, W[, C]), got [${shape}]`);
  }
  const layers = layered ? shape[0] : 1;
  const [height, width] = [shape[first], shape[first + 1]];
  const channels = shape.length === 3 + first ? shape[shape.length - 1] : 1;
  return { layers, height, width, channels };
}

/** Bytes of one layer's level 0 (compact/encodings.py's stored_bytes, per layer). */
function layerBytes(format, height, width, channels) {
  if (format in QUANTIZED) return height * width * channels * QUANTIZED[format];
  return Math.ceil(height / 4) * Math.ceil(width / 4) * BLOCKS[format][1];
}

/** The number of mip levels the Python executor uploads of an encoded texture: the whole
 * chain (each level encoded from level 0, encodings.py's `levels`) where the texture has
 * mipmaps and the encoding derives them, else level 0 alone (always for u8/u16). */
export function mipLevels(encoding, mipmaps) {
  if (!(mipmaps && encoding.mipmaps && encoding.format in BLOCKS)) return 1;
  const { height, width } = layout(encoding);
  return Math.floor(Math.log2(Math.max(height, width))) + 1;
}

/** The WebGL2 compressed internal format to upload `encoding`'s blocks with, or null where
 * the viewer must upload `decodeEncoded`'s array instead: u8/u16 (WebGL2 has no 16-bit
 * unorm textures: both go decoded), the extension missing (`gl.getExtension`, which also
 * enables it), a target or sRGB variant the format lacks, a level 0 not a multiple of 4
 * (WebGL's rule for these extensions), or a mip chain the executor would upload: only level
 * 0 is stored, the browser can neither encode the other levels nor generate them for a
 * compressed texture, so the decoded array gets its mipmaps generated instead.
 * `texture` is the plan's texture record ({target, srgb, mipmaps}); sampled as sRGB is
 * the texture's `srgb` for a uint8 array, the encoding's for a float one (executor.py). */
export function glFormatOf(encoding, gl, texture = {}) {
  const formats = GL_FORMATS[encoding.format];
  if (!formats) return null;
  const { target = "2d", srgb = false, mipmaps = false } = texture;
  const { height, width } = layout(encoding);
  const sampledSrgb = encoding.dtype === "uint8" ? Boolean(srgb) : Boolean(encoding.srgb);
  if (!formats.targets.includes(target) || height % 4 !== 0 || width % 4 !== 0
      || mipLevels(encoding, mipmaps) > 1) return null;
  if (sampledSrgb) {
    return formats.srgb !== null && gl.getExtension(formats.srgbExtension) ? formats.srgb : null;
  }
  return gl.getExtension(formats.extension) ? formats.linear : null;
}

/** The `<sampler>_decode` uniform (scale, bias) of a program sampling `encoding`
 * (executor.py): the encoding's own where its unorm values are uploaded (`internalFormat`,
 * glFormatOf's answer, not null), (1, 0) where the decoded array is. */
export function samplerDecode(encoding, internalFormat) {
  return internalFormat === null ? [1, 0] : [encoding.scale, encoding.bias];
}

// -- the decode -------------------------------------------------------------------------------

/** What `reliefkit.compact.encodings.decoded` gives for `encoding` (the record) and its
 * level-0 bytes `stored` (Uint8Array, layer after layer): {dtype, shape, data}, data a
 * Uint8Array or Float32Array row-major over shape. */
export function decodeEncoded(encoding, stored) {
  const { format, dtype, shape } = encoding;
  const { layers, height, width, channels } = layout(encoding);
  const perLayer = layerBytes(format, height, width, channels);
  if (stored.length !== layers * perLayer) {
    throw new Error(`${format} data of a [${shape}] array must be ${layers * perLayer} bytes, `
      + `got ${stored.length}`);
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
    // numpy's float32 arithmetic: each step rounded to float32 (exact: a double result of
    // one float32 operation rounds to the same float32 as the float32 operation).
    const f = Math.fround;
    const [fTop, scale, bias] = [f(top), f(encoding.scale), f(encoding.bias)];
    for (let i = 0; i < data.length; i++) data[i] = f(f(f(unorm[i] / fTop) * scale) + bias);
  }
  return { dtype, shape: [...shape], data };
}

/** unorm value -> float32 of [0, top]: sRGB-decoded colour (colorspace.srgb_decode in
 * float64, then float32) and linear alpha. */
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

/** One layer's unorm values (H, W, C) row-major; a BC1 image standing for RGBA has alpha
 * 255 (BC1's alpha is not kept, encodings.py refuses to encode one that is not 1). */
function unormLayer(format, bytes, height, width, channels) {
  if (format === "u8") return bytes;
  if (format === "u16") {
    const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
    const out = new Uint16Array(bytes.length / 2);
    for (let i = 0; i < out.length; i++) out[i] = view.getUint16(2 * i, true);
    return out;
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

/** The (H, W, C) uint8 image of one level of `format` blocks (C: 3 for BC1, 1 BC4, 2 BC5,
 * 4 BC7), row-major; blocks past the image's edge are cut off (compact/blocks.py's decode). */
export function decodeBlocks(format, bytes, height, width) {
  const [channels, blockBytes] = BLOCKS[format];
  const across = Math.ceil(width / 4);
  if (bytes.length !== across * Math.ceil(height / 4) * blockBytes) {
    throw new Error(`${format}: ${bytes.length} bytes do not hold a ${width}x${height} image`);
  }
  const decodeBlock = BLOCK_DECODERS[format];
  const out = new Uint8Array(height * width * channels);
  const texels = new Uint8Array(64); // RGBA of the 16 texels
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

// -- BC1 ----------------------------------------------------------------------------------------

/** RGB565 -> 8-bit RGB, each channel's top bits repeated below it. */
function rgb565(value, out, at) {
  const r = (value >> 11) & 31, g = (value >> 5) & 63, b = value & 31;
  out[at] = (r << 3) | (r >> 2);
  out[at + 1] = (g << 2) | (g >> 4);
  out[at + 2] = (b << 3) | (b >> 2);
}

const bc1Palette = new Uint8Array(12);

function decodeBc1(bytes, at, texels) {
  const q0 = bytes[at] | (bytes[at + 1] << 8);
  const q1 = bytes[at + 2] | (bytes[at + 3] << 8);
  const p = bc1Palette;
  rgb565(q0, p, 0);
  rgb565(q1, p, 3);
  for (let c = 0; c < 3; c++) {
    const [c0, c1] = [p[c], p[3 + c]];
    if (q0 > q1) { // four colours: thirds, truncated as texture2ddecoder does
      p[6 + c] = Math.floor((2 * c0 + c1) / 3);
      p[9 + c] = Math.floor((c0 + 2 * c1) / 3);
    } else { // three colours and black (alpha kept 1: BC1 stands for opaque colour here)
      p[6 + c] = (c0 + c1) >> 1;
      p[9 + c] = 0;
    }
  }
  const indices = bytes[at + 4] | (bytes[at + 5] << 8) | (bytes[at + 6] << 16)
    | (bytes[at + 7] << 24);
  for (let i = 0; i < 16; i++) {
    const k = ((indices >>> (2 * i)) & 3) * 3;
    texels[4 * i] = p[k];
    texels[4 * i + 1] = p[k + 1];
    texels[4 * i + 2] = p[k + 2];
    texels[4 * i + 3] = 255;
  }
}

// -- BC4 / BC5 ----------------------------------------------------------------------------------

const bc4Palette = new Uint8Array(8);

/** One BC4 block (8 bytes at `at`) into channel `channel` of the texels. */
function decodeBc4Channel(bytes, at, texels, channel) {
  const p = bc4Palette;
  const [a0, a1] = [bytes[at], bytes[at + 1]];
  p[0] = a0;
  p[1] = a1;
  if (a0 > a1) { // six interpolated values, sevenths truncated
    for (let k = 1; k <= 6; k++) p[1 + k] = Math.floor(((7 - k) * a0 + k * a1) / 7);
  } else { // four interpolated values, fifths truncated, then 0 and 255
    for (let k = 1; k <= 4; k++) p[1 + k] = Math.floor(((5 - k) * a0 + k * a1) / 5);
    p[6] = 0;
    p[7] = 255;
  }
  // 48 bits of 3-bit indices: two 24-bit halves of 8 texels each
  for (let half = 0; half < 2; half++) {
    const o = at + 2 + 3 * half;
    const bits = bytes[o] | (bytes[o + 1] << 8) | (bytes[o + 2] << 16);
    for (let i = 0; i < 8; i++) texels[4 * (8 * half + i) + channel] = p[(bits >> (3 * i)) & 7];
  }
}

function decodeBc4(bytes, at, texels) {
  decodeBc4Channel(bytes, at, texels, 0);
}

function decodeBc5(bytes, at, texels) {
  decodeBc4Channel(bytes, at, texels, 0);
  decodeBc4Channel(bytes, at + 8, texels, 1);
}

// -- BC7 ----------------------------------------------------------------------------------------

/** Per mode: subsets, partition bits, rotation bits, index-selection bits, colour bits,
 * alpha bits, P-bits (0 none, 1 one per endpoint, 2 one shared per subset), index bits,
 * second index bits (modes 4 and 5). */
const BC7_MODES = [
  [3, 4, 0, 0, 4, 0, 1, 3, 0],
  [2, 6, 0, 0, 6, 0, 2, 3, 0],
  [3, 6, 0, 0, 5, 0, 0, 2, 0],
  [2, 6, 0, 0, 7, 0, 1, 2, 0],
  [1, 0, 2, 1, 5, 6, 0, 2, 3],
  [1, 0, 2, 0, 7, 8, 0, 2, 2],
  [1, 0, 0, 0, 7, 7, 1, 4, 0],
  [2, 6, 0, 0, 5, 5, 1, 2, 0],
].map(([subsets, partitionBits, rotationBits, selectionBits, colourBits, alphaBits, pBits,
  indexBits, index2Bits]) => ({ subsets, partitionBits, rotationBits, selectionBits,
  colourBits, alphaBits, pBits, indexBits, index2Bits }));

/** Interpolation weights (of 64) per index width. */
const WEIGHTS = {
  2: [0, 21, 43, 64],
  3: [0, 9, 18, 27, 37, 46, 55, 64],
  4: [0, 4, 9, 13, 17, 21, 26, 30, 34, 38, 43, 47, 51, 55, 60, 64],
};
const SUBSET_DIGITS = [null, null, PARTITIONS2, PARTITIONS3].map(
  (table) => table && table.map((row) => Uint8Array.from(row, Number)));
const ONE_SUBSET = new Uint8Array(16);
/** Per subset count and partition: each subset's anchor texel. */
const SUBSET_ANCHORS = [null, [[0]], ANCHORS2.map((a) => [0, a]),
  ANCHORS3[0].map((a, p) => [0, a, ANCHORS3[1][p]])];

/** Bits [pos, pos + n) of a block, least significant first (n <= 16). */
function bits(bytes, at, pos, n) {
  const o = at + (pos >> 3);
  const word = bytes[o] | (bytes[o + 1] << 8) | (bytes[o + 2] << 16);
  return (word >>> (pos & 7)) & ((1 << n) - 1);
}

/** A `bits`-bit endpoint value -> 8 bits, its top bits repeated below it. */
function expand(value, n) {
  const shifted = value << (8 - n);
  return (shifted | (shifted >> n)) & 255;
}

const endpoints = new Uint8Array(6 * 4); // [subset][end][RGBA]
const pBits = new Uint8Array(6); // [subset][end]

function decodeBc7(bytes, at, texels) {
  let mode = 0;
  while (mode < 8 && !((bytes[at] >> mode) & 1)) mode++;
  if (mode === 8) { // reserved: every channel 0
    texels.fill(0);
    return;
  }
  const m = BC7_MODES[mode];
  let pos = mode + 1;
  const partition = bits(bytes, at, pos, m.partitionBits);
  pos += m.partitionBits;
  const rotation = bits(bytes, at, pos, m.rotationBits);
  pos += m.rotationBits;
  const selection = bits(bytes, at, pos, m.selectionBits);
  pos += m.selectionBits;
  const ends = 2 * m.subsets;
  for (let c = 0; c < 4; c++) {
    const width = c < 3 ? m.colourBits : m.alphaBits;
    for (let e = 0; e < ends; e++) {
      endpoints[4 * e + c] = width ? bits(bytes, at, pos, width) : 255;
      pos += width;
    }
  }
  if (m.pBits === 1) {
    for (let e = 0; e < ends; e++) pBits[e] = bits(bytes, at, pos++, 1);
  } else if (m.pBits === 2) {
    for (let s = 0; s < m.subsets; s++) pBits[2 * s] = pBits[2 * s + 1] = bits(bytes, at, pos++, 1);
  }
  const withP = m.pBits ? 1 : 0;
  for (let e = 0; e < ends; e++) {
    for (let c = 0; c < 4; c++) {
      const width = c < 3 ? m.colourBits : m.alphaBits;
      if (width) {
        const value = (endpoints[4 * e + c] << withP) | (withP && pBits[e]);
        endpoints[4 * e + c] = expand(value, width + withP);
      }
    }
  }
  const subsets = m.subsets === 1 ? ONE_SUBSET : SUBSET_DIGITS[m.subsets][partition];
  const anchors = SUBSET_ANCHORS[m.subsets][partition];
  // the indices: the primary stream, then (modes 4, 5) the second stream
  let pos2 = pos + 16 * m.indexBits - m.subsets;
  const weights = WEIGHTS[m.indexBits];
  const weights2 = WEIGHTS[m.index2Bits || m.indexBits];
  for (let i = 0; i < 16; i++) {
    const s = subsets[i];
    const n = m.indexBits - (anchors[s] === i ? 1 : 0);
    const index = bits(bytes, at, pos, n);
    pos += n;
    let colourWeight = weights[index];
    let alphaWeight = colourWeight;
    if (m.index2Bits) {
      const n2 = m.index2Bits - (i === 0 ? 1 : 0);
      const alphaIndex = bits(bytes, at, pos2, n2);
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
      texels[4 * i + c] = ((64 - w) * endpoints[e0] + w * endpoints[e1] + 32) >> 6;
    }
    if (rotation) { // the alpha channel swapped with channel rotation - 1
      const other = 4 * i + rotation - 1;
      const alpha = texels[4 * i + 3];
      texels[4 * i + 3] = texels[other];
      texels[other] = alpha;
    }
  }
}

const BLOCK_DECODERS = { bc1: decodeBc1, bc4: decodeBc4, bc5: decodeBc5, bc7: decodeBc7 };
