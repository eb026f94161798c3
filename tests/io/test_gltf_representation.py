"""Reading a representation back from glTF: forged and broken files refused in one line
before anything of a claimed size is allocated, .gltf's files, deterministic bytes, and
exports that fail leaving nothing behind. References: files the tests forge from a real
export, and the .rk reader's limits."""

from __future__ import annotations

import copy
import errno
import os
import tracemalloc

import numpy as np
import pytest
from helpers import sample

import reliefkit as rk
from reliefkit.builtins import registry
from reliefkit.errors import FormatError, ReliefkitError
from reliefkit.io.gltf.glb import ARRAY_BUFFER, GlbBuilder, glb_bytes, read_glb, write_glb
from reliefkit.io.gltf.representation import extension_name

KIND = "relief-object"


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    path = tmp_path_factory.mktemp("export") / "rep.glb"
    rk.export(sample("relief", KIND), path, fallback=False)
    return path


def forged(tmp_path, source, edit, binary_edit=None):
    glb = read_glb(source)
    document = copy.deepcopy(glb.document)
    node = next(n for n in document["nodes"] if "extensions" in n)
    edit(document, node["extensions"][extension_name(KIND)])
    binary = bytearray(glb.binary)
    if binary_edit:
        binary_edit(document, binary)
    path = tmp_path / "forged.glb"
    path.write_bytes(glb_bytes(document, bytes(binary)))
    return path


def refused(path, match: str, peak_limit: int = 8 << 20) -> str:
    tracemalloc.start()
    try:
        with pytest.raises(FormatError, match=match) as info:
            rk.load(path)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    message = str(info.value)
    assert "\n" not in message and str(path) in message
    assert peak < peak_limit, f"{peak:,} bytes allocated before refusing"
    return message


def _array(ext, name="p0_height"):
    return ext["arrays"][name]


def _set(key, value, name="p0_height"):
    return lambda doc, ext: _array(ext, name).__setitem__(key, value)


FORGERIES = {
    "huge shape": (_set("shape", [1 << 20, 1 << 20]), "4096.00 GiB, over the 4.00 GiB"),
    "huge shape, within the limit": (_set("shape", [1 << 14, 1 << 14]), "bufferView holds"),
    "dtype": (_set("dtype", "float64"), "dtype"),
    "unknown dtype": (_set("dtype", "object"), "dtype"),
    "negative dim": (_set("shape", [-1, 16]), "shape"),
    "view past the list": (_set("bufferView", 10_000), "bufferView"),
    "view and image": (_set("image", 0), "at most one"),
    "bad sha": (_set("sha256", "0" * 64), "sha256"),
    "kind": (lambda doc, ext: ext.__setitem__("kind", "no-such-kind"), "unknown kind"),
    "version": (lambda doc, ext: ext.__setitem__("kindVersion", 99), "version"),
    "params": (lambda doc, ext: ext.__setitem__("params", []), "params"),
    "missing array": (lambda doc, ext: ext["arrays"].pop("p0_height"), "missing"),
    "unknown array": (lambda doc, ext: ext["arrays"].__setitem__(
        "extra", dict(ext["arrays"]["p0_height"])), "unknown array"),
    "encoding": (_set("encoding", {"format": "bc7"}), "encoding"),
}


@pytest.mark.parametrize("name", FORGERIES)
def test_a_forged_extension_is_refused_in_one_line_without_allocating(tmp_path, exported, name):
    edit, match = FORGERIES[name]
    refused(forged(tmp_path, exported, edit), match)


def test_a_view_shorter_than_its_shape_and_flipped_bytes_are_refused(tmp_path, exported):
    def shorten(doc, ext):
        doc["bufferViews"][_array(ext)["bufferView"]]["byteLength"] -= 4
    refused(forged(tmp_path, exported, shorten), "bufferView holds")

    def flip(doc, binary):
        ext = next(n for n in doc["nodes"] if "extensions" in n)["extensions"]
        view = doc["bufferViews"][ext[extension_name(KIND)]["arrays"]["p0_height"]["bufferView"]]
        binary[view["byteOffset"] + 5] ^= 0xFF
    refused(forged(tmp_path, exported, lambda d, e: None, flip), "sha256")


def test_a_png_whose_header_disagrees_with_the_shape_is_refused(tmp_path, exported):
    def shape(doc, ext):
        ref = _array(ext, "p0_color")
        assert "image" in ref  # colour goes into PNG images
        ref["shape"] = [8, 8, 4]
    refused(forged(tmp_path, exported, shape), "needs")


def test_a_plain_gltf_mesh_is_not_a_representation(tmp_path):
    builder = GlbBuilder()
    position = builder.add_array(np.eye(3, dtype=np.float32), target=ARRAY_BUFFER, bounds=True)
    builder.document.update(meshes=[{"primitives": [{"attributes": {"POSITION": position}}]}],
                            nodes=[{"mesh": 0}], scenes=[{"nodes": [0]}], scene=0)
    path = write_glb(tmp_path / "plain.glb", *builder.finish())
    assert "not a file reliefkit exported" in refused(path, "reliefkit extension")


def test_a_truncated_export_is_refused(tmp_path, exported):
    data = exported.read_bytes()
    path = tmp_path / "cut.glb"
    path.write_bytes(data[:len(data) // 2])
    refused(path, "truncated")


def test_gltf_files_round_trip_and_refuse_what_is_missing_or_outside(tmp_path):
    rep = sample("relief", KIND)
    path = rk.export(rep, tmp_path / "rep.gltf", fallback=False)
    names = sorted(os.listdir(tmp_path))
    assert names[0] == "rep.bin" and "rep.gltf" in names and any(n.endswith(".png") for n in names)
    back = rk.load(path)
    codec = registry().codecs().for_object(rep)
    (want, want_params), (got, got_params) = codec.to_arrays(rep), codec.to_arrays(back)
    assert got_params == want_params and set(got) == set(want)
    assert all(got[k].tobytes() == want[k].tobytes() for k in want if want[k] is not None)
    text = path.read_text()
    (tmp_path / "up.gltf").write_text(text.replace('"rep.bin"', '"../rep.bin"'))
    refused(tmp_path / "up.gltf", "plain file names")
    os.remove(tmp_path / "rep.bin")
    refused(path, "rep.bin .* missing")


def test_equal_inputs_give_byte_identical_files(tmp_path):
    rep = sample("relief", KIND)
    a = rk.export(rep, tmp_path / "a.glb", embed_shaders=True, fallback=False)
    b = rk.export(rep, tmp_path / "b.glb", embed_shaders=True, fallback=False)
    assert a.read_bytes() == b.read_bytes()


def test_failed_exports_leave_no_file(tmp_path, monkeypatch):
    rep = sample("relief", KIND)
    (tmp_path / "folder.glb").mkdir()
    with pytest.raises(ReliefkitError, match="directory"):
        rk.export(rep, tmp_path / "folder.glb", fallback=False)
    with pytest.raises(ReliefkitError, match=r"\.glb or \.gltf"):
        rk.export(rep, tmp_path / "x.obj", fallback=False)
    old = tmp_path / "old.glb"
    old.write_bytes(b"old")
    real_write = os.write

    def full(fd, data):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(os, "write", full)
    monkeypatch.setattr(os, "fsync", lambda fd: full(fd, b""))
    with pytest.raises(ReliefkitError, match="No space left"):
        rk.export(rep, old, fallback=False)
    monkeypatch.setattr(os, "write", real_write)
    assert old.read_bytes() == b"old"
    assert sorted(os.listdir(tmp_path)) == ["folder.glb", "old.glb"]
    if os.geteuid() != 0:  # root writes into read-only folders
        locked = tmp_path / "locked"
        locked.mkdir(mode=0o500)
        with pytest.raises(ReliefkitError):
            rk.export(rep, locked / "x.glb", fallback=False)
        assert os.listdir(locked) == []


@pytest.mark.parametrize("shape", [(5, 7), (5, 7, 1), (5, 7, 2), (5, 7, 3), (3, 5, 7, 4),
                                   (5, 7, 6), (0, 4)])
def test_typed_arrays_round_trip_as_png_or_bytes(shape):
    from reliefkit.io.gltf.arrays import array_of, put_array
    from reliefkit.io.gltf.glb import Glb

    array = np.random.default_rng(1).integers(0, 256, shape, dtype=np.uint8)
    builder = GlbBuilder()
    ref = put_array(builder, array, png=True)
    assert ("image" in ref) == (len(shape) == 2 and array.size > 0
                                or len(shape) > 2 and shape[-1] <= 4)
    document, binary = builder.finish()
    back = array_of(Glb(document, binary), ref, "test")
    assert back.dtype == array.dtype and back.shape == array.shape
    assert back.tobytes() == array.tobytes()


def test_a_deeply_nested_document_is_refused_in_one_line(tmp_path):
    path = tmp_path / "deep.gltf"
    path.write_text('{"asset": {"version": "2.0"}, "x": ' + "[" * 100_000 + "]" * 100_000 + "}")
    refused(path, "nests too deeply")
