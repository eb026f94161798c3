"""Compact GPU bytes: textures block-compressed (BC1/BC4/BC5/BC7) or quantized (8/16-bit
unorm), as engines ship them.

`blocks` encodes and decodes one image in 4x4 blocks, `encodings` holds the record of an
encoded array (`EncodedImage`: format, decoded shape, per-level bytes, decode rule) and the
bytes a GPU holds for any texture, `compact` turns a representation into its compressed twin
(`compress`) through the roles its codec declares. This package imports no GL and no
technique; `io.rk` stores encodings, `render.plan.Texture` carries them and the executor
uploads them (docs/compact.md).
"""
