"""Tests of the GLB container (reliefkit.io.gltf.glb): pygltflib, an independent reader,
reads what it writes; writes are byte-identical; truncated or forged files are refused in
one line before anything of their claimed size is allocated."""

from __future__ import annotations

import io
import json
import struct
import tracemalloc

import numpy as np
import pygltflib
import pytest
from PIL import Image

from reliefkit.errors import FormatError
from reliefkit.io.gltf import glb

ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963


def png_bytes(side: int | None = None) -> bytes:
    shape = (side, side, 4) if side else (5, 3, 4)
    pixels = (np.arange(np.prod(shape)) * 4 % 256).astype(np.uint8).reshape(shape)
    out = io.BytesIO()
    Image.fromarray(pixels, "RGBA").save(out, format="PNG")
    return out.getvalue()


def positions() -> np.ndarray:
    # 7 vertices: 84 bytes, so the next view's start needs no padding but a 3-index view does
    return np.array([[0, 0, 0], [1, 0, 0], [0, 2, 0], [0, 0, -3], [1, 2, -3], [0.5, 0.25, 1],
                     [-1, 1, 1]], np.float32)


def indices() -> np.ndarray:
    return np.array([0, 1, 2, 3, 4, 5, 6], np.uint16)  # 14 bytes: the next view is padded


def build(document_extra: dict | None = None) -> glb.GlbBuilder:
    builder = glb.GlbBuilder()
    builder.document["asset"]["generator"] = "reliefkit test"
    builder.document.update(document_extra or {})
    pos = builder.add_array(positions(), target=ARRAY_BUFFER, bounds=True)
    idx = builder.add_array(indices(), target=ELEMENT_ARRAY_BUFFER)
    builder.add_array(np.linspace(0, 1, 10, dtype=np.float32).reshape(5, 2))
    builder.add_png(png_bytes())
    builder.document["meshes"] = [{"primitives": [{"attributes": {"POSITION": pos},
                                                   "indices": idx, "mode": 0}]}]
    return builder


def write(tmp_path, name="a.glb") -> str:
    path = tmp_path / name
    path.write_bytes(build().glb())
    return path


# ------------------------------------------------------------------ independent reader


def test_pygltflib_reads_accessors_views_and_images(tmp_path):
    path = write(tmp_path)
    gltf = pygltflib.GLTF2().load_binary(str(path))
    blob = gltf.binary_blob()
    assert gltf.asset.version == "2.0" and len(gltf.buffers) == 1
    assert gltf.buffers[0].byteLength <= len(blob)
    assert all(view.byteOffset % 4 == 0 for view in gltf.bufferViews)

    def data(accessor, dtype, width):
        view = gltf.bufferViews[accessor.bufferView]
        raw = blob[view.byteOffset:view.byteOffset + view.byteLength]
        return np.frombuffer(raw, dtype).reshape(accessor.count, width)

    pos, idx, uv = gltf.accessors
    assert (pos.componentType, pos.type, pos.count) == (pygltflib.FLOAT, "VEC3", 7)
    assert pos.min == positions().min(axis=0).tolist()
    assert pos.max == positions().max(axis=0).tolist()
    assert np.array_equal(data(pos, "<f4", 3), positions())
    assert gltf.bufferViews[pos.bufferView].target == ARRAY_BUFFER
    assert (idx.componentType, idx.type, idx.count) == (pygltflib.UNSIGNED_SHORT, "SCALAR", 7)
    assert np.array_equal(data(idx, "<u2", 1)[:, 0], indices())
    assert gltf.bufferViews[idx.bufferView].target == ELEMENT_ARRAY_BUFFER
    assert (uv.type, uv.count) == ("VEC2", 5) and not uv.min and not uv.max
    assert np.array_equal(data(uv, "<f4", 2), np.linspace(0, 1, 10, dtype=np.float32)
                          .reshape(5, 2))
    (image,) = gltf.images
    view = gltf.bufferViews[image.bufferView]
    assert image.mimeType == "image/png"
    assert blob[view.byteOffset:view.byteOffset + view.byteLength] == png_bytes()


def test_own_reader_round_trips_arrays_and_images(tmp_path):
    read = glb.read_glb(write(tmp_path))
    assert np.array_equal(glb.accessor_array(read, 0), positions())
    assert np.array_equal(glb.accessor_array(read, 1), indices())
    assert glb.image_bytes(read, 0) == png_bytes()
    assert read.document["asset"]["generator"] == "reliefkit test"


def test_layout_follows_the_specification(tmp_path):
    data = write(tmp_path).read_bytes()
    magic, version, total = struct.unpack_from("<4sII", data)
    json_length, json_type = struct.unpack_from("<II", data, 12)
    bin_length, bin_type = struct.unpack_from("<II", data, 20 + json_length)
    assert (magic, version, total) == (b"glTF", 2, len(data))
    assert (json_type, bin_type) == (0x4E4F534A, 0x004E4942)
    assert json_length % 4 == 0 and bin_length % 4 == 0
    assert 28 + json_length + bin_length == len(data)
    text = data[20:20 + json_length].decode()
    assert text == text.rstrip() + " " * (len(text) - len(text.rstrip()))  # spaces pad
    document = json.loads(text)
    assert text.rstrip() == json.dumps(document, sort_keys=True, separators=(",", ":"))


# ------------------------------------------------------------------------ determinism


def test_two_writes_are_byte_identical_whatever_the_key_order(tmp_path):
    first = glb.write_glb(tmp_path / "a.glb", *build({"extras": {"b": 1, "a": 2}}).finish())
    second = glb.write_glb(tmp_path / "b.glb", *build({"extras": {"a": 2, "b": 1}}).finish())
    assert first.read_bytes() == second.read_bytes()


# ------------------------------------------------------------------------ forged files


def chunks(data: bytes) -> tuple[dict, int]:
    """A written file's document and where its BIN chunk header starts."""
    (json_length,) = struct.unpack_from("<I", data, 12)
    return json.loads(data[20:20 + json_length]), 20 + json_length


def with_document(data: bytes, change) -> bytes:
    """The file with its JSON chunk replaced by ``change(document)``'s (lengths kept right)."""
    document, bin_start = chunks(data)
    change(document)
    text = json.dumps(document).encode()
    text += b" " * (-len(text) % 4)
    rest = data[bin_start:]
    body = struct.pack("<II", len(text), 0x4E4F534A) + text + rest
    return struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body


def set_in(key, index, field, value):
    def change(document):
        document[key][index][field] = value
    return change


def patched(data: bytes, offset: int, fmt: str, value) -> bytes:
    out = bytearray(data)
    struct.pack_into(fmt, out, offset, value)
    return bytes(out)


HUGE = 10**12
FORGERIES = {
    "bad magic": (lambda d: b"gLTF" + d[4:], "no 'glTF' magic"),
    "version 1": (lambda d: patched(d, 4, "<I", 1), "GLB version 1"),
    "truncated": (lambda d: d[:-9], "header says"),
    "header too short": (lambda d: d[:7], "no 'glTF' magic"),
    "total length forged": (lambda d: patched(d, 8, "<I", 2**32 - 4), "header says"),
    "json chunk past the end": (lambda d: patched(d, 12, "<I", 2**32 - 4), "only"),
    "bin chunk past the end": (lambda d: patched(d, chunks(d)[1], "<I", 2**32 - 4), "only"),
    "chunk length not aligned": (lambda d: patched(d, 12, "<I", 5), "multiple of 4"),
    "first chunk not json": (lambda d: patched(d, 16, "<I", 0x004E4942), "not JSON"),
    "json not json": (lambda d: d[:20] + b"[" + d[21:], "not valid UTF-8 JSON"),
    "no asset": (lambda d: with_document(d, lambda doc: doc.pop("asset")), "no 'asset'"),
    "buffer claims more": (lambda d: with_document(d, set_in("buffers", 0, "byteLength", HUGE)),
                           "buffers[0] claims"),
    "external buffer": (lambda d: with_document(d, set_in("buffers", 0, "uri", "x.bin")),
                        "external file"),
    "view past the buffer": (lambda d: with_document(
        d, set_in("bufferViews", 1, "byteOffset", HUGE)), "bufferViews[1] ends"),
    "view of no buffer": (lambda d: with_document(d, set_in("bufferViews", 0, "buffer", 3)),
                          "names no buffer"),
    "negative offset": (lambda d: with_document(d, set_in("bufferViews", 0, "byteOffset", -8)),
                        "not an integer >= 0"),
    "accessor count huge": (lambda d: with_document(d, set_in("accessors", 0, "count", HUGE)),
                            "accessors[0]"),
    "accessor offset past": (lambda d: with_document(
        d, set_in("accessors", 1, "byteOffset", 16)), "accessors[1]"),
    "accessor dtype": (lambda d: with_document(
        d, set_in("accessors", 0, "componentType", 5130)), "componentType 5130"),
    "accessor of no view": (lambda d: with_document(d, set_in("accessors", 2, "bufferView", 9)),
                            "names no bufferView"),
    "image of no view": (lambda d: with_document(d, set_in("images", 0, "bufferView", 9)),
                         "images[0]"),
    "stride too small": (lambda d: with_document(d, set_in("bufferViews", 0, "byteStride", 4)),
                         "byteStride 4"),
}


@pytest.mark.parametrize("name", FORGERIES)
def test_forged_files_are_refused_in_one_line_without_allocating(tmp_path, name):
    forge, message = FORGERIES[name]
    path = tmp_path / "forged.glb"
    path.write_bytes(forge(write(tmp_path).read_bytes()))
    tracemalloc.start()
    try:
        with pytest.raises(FormatError) as caught:
            glb.read_glb(path)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    text = str(caught.value)
    assert message in text and text.startswith(f"{path}: ") and "\n" not in text
    assert peak < 1 << 20


def test_a_file_over_the_cap_is_refused_before_reading(tmp_path):
    path = write(tmp_path)
    with pytest.raises(FormatError, match="over the 100-byte limit"):
        glb.read_glb(path, max_bytes=100)


def test_missing_file_and_folder_are_refused(tmp_path):
    with pytest.raises(FormatError, match="no such file"):
        glb.read_glb(tmp_path / "none.glb")
    with pytest.raises(FormatError, match="is not a file"):
        glb.read_glb(tmp_path)


def test_unknown_chunks_after_bin_are_skipped(tmp_path):
    data = write(tmp_path).read_bytes() + struct.pack("<II", 4, 0x12345678) + b"abcd"
    path = tmp_path / "extra.glb"
    path.write_bytes(patched(data, 8, "<I", len(data)))
    assert np.array_equal(glb.accessor_array(glb.read_glb(path), 0), positions())


def test_non_finite_values_are_refused_on_write(tmp_path):
    with pytest.raises(FormatError, match="cannot be written as JSON"):
        glb.write_glb(tmp_path / "nan.glb", {"asset": {"version": "2.0"}, "extras": float("nan")})
    assert not list(tmp_path.iterdir())


def test_arrays_glTF_cannot_hold_are_refused():
    builder = glb.GlbBuilder()
    with pytest.raises(FormatError, match="glTF accessors hold"):
        builder.add_array(np.zeros(4, np.float64))
    with pytest.raises(FormatError, match="shape"):
        builder.add_array(np.zeros((2, 5), np.float32))


# ------------------------------------------------------------------ Khronos validator


def test_a_textured_triangle_validates_without_errors_or_warnings(tmp_path):
    from gltf_validator import problems, validate

    builder = glb.GlbBuilder()
    corners = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32)
    position = builder.add_array(corners, target=ARRAY_BUFFER, bounds=True)
    texcoord = builder.add_array(corners[:, :2], target=ARRAY_BUFFER)
    index = builder.add_array(np.array([0, 1, 2], np.uint16), target=ELEMENT_ARRAY_BUFFER)
    builder.add_png(png_bytes(side=4))
    builder.document.update({
        "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": position,
                                                   "TEXCOORD_0": texcoord},
                                    "indices": index, "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0},
                                                "metallicFactor": 0}}],
        "textures": [{"source": 0}],
    })
    path = glb.write_glb(tmp_path / "triangle.glb", *builder.finish())
    report = validate(path)
    assert report["issues"]["numErrors"] == 0 and not problems(report), problems(report)
    assert report["info"]["resources"][0]["storage"] == "glb"


def test_vertex_attribute_rows_are_padded_to_four_bytes(tmp_path):
    """An RGB uint8 colour per vertex is 3 bytes: glTF wants each vertex's on a 4-byte
    boundary, so the bufferView gets byteStride 4 (the validator's
    MESH_PRIMITIVE_ACCESSOR_UNALIGNED otherwise)."""
    from gltf_validator import problems, validate

    colours = np.array([[255, 0, 0], [0, 255, 0], [0, 0, 255]], np.uint8)
    builder = glb.GlbBuilder()
    position = builder.add_array(np.eye(3, dtype=np.float32), target=ARRAY_BUFFER, bounds=True)
    colour = builder.add_array(colours, target=ARRAY_BUFFER, normalized=True)
    builder.document.update({
        "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": position, "COLOR_0": colour}}]}],
    })
    path = glb.write_glb(tmp_path / "colours.glb", *builder.finish())
    gltf = pygltflib.GLTF2().load_binary(str(path))
    view = gltf.bufferViews[gltf.accessors[colour].bufferView]
    raw = np.frombuffer(gltf.binary_blob()[view.byteOffset:view.byteOffset + view.byteLength],
                        np.uint8)
    assert view.byteStride == 4 and np.array_equal(raw.reshape(3, 4)[:, :3], colours)
    assert np.array_equal(glb.accessor_array(glb.read_glb(path), colour), colours)
    report = validate(path)
    assert report["issues"]["numErrors"] == 0 and not problems(report), problems(report)


def test_empty_arrays_make_empty_accessors(tmp_path):
    builder = glb.GlbBuilder()
    index = builder.add_array(np.zeros((0, 3), np.uint8), target=ARRAY_BUFFER, bounds=True)
    builder.add_array(np.ones(3, np.float32))
    path = tmp_path / "empty.glb"
    path.write_bytes(builder.glb())
    read = glb.read_glb(path)
    assert read.document["accessors"][index]["count"] == 0
    assert glb.accessor_array(read, index).shape == (0, 3)
