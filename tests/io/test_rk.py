"""Tests of the .rk container (reliefkit.formats): round trips, forged files, atomic writes."""

from __future__ import annotations

import hashlib
import io
import json
import os
import re
import struct
import tracemalloc
import zipfile
import zlib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest
from numpy.lib import format as npy

import reliefkit
from reliefkit.builtins import registry
from reliefkit.errors import FormatError
from reliefkit.io import rk as formats
from reliefkit.io.rk import ArraySpec, Codec
from reliefkit.scene.mesh import RenderMesh

SOURCE_HASH = hashlib.sha256(b"source mesh").hexdigest()


@pytest.fixture(autouse=True)
def _strict_numpy():
    with np.errstate(all="raise"):
        yield


# ------------------------------------------------------------------------- fixtures


@dataclass(eq=False)
class Bag:
    """A throwaway representation: named arrays of several dtypes plus JSON metadata."""

    arrays: dict
    meta: dict = field(default_factory=dict)


BAG = Codec(
    kind="test-bag",
    cls=Bag,
    arrays={
        "f64": ArraySpec(("float64",), (1, 2)),
        "f32": ArraySpec(("float32",), 3, finite=True, trailing=(None, 3)),
        "ints": ArraySpec(("uint8", "uint16"), 2),
        "i64": ArraySpec(("int64",), 1),
        "matrix": ArraySpec(("float32",), 2, trailing=(4, 4)),
        "flags": ArraySpec(("bool",), 1, required=False),
    },
    to_arrays=lambda bag: (bag.arrays, bag.meta),
    from_arrays=lambda arrays, params: Bag(arrays, params),
)


def with_kinds(*codecs: Codec) -> formats.CodecTable:
    """The process's kinds plus ``codecs``."""
    return formats.CodecTable((*registry().codecs(), *codecs))


@pytest.fixture(autouse=True)
def _bag_kind():
    """The functions' default table holds the bag kind during each test."""
    table = with_kinds(BAG)
    formats.use_codecs(lambda: table)
    yield
    formats.use_codecs(registry().codecs)


def make_mesh(textured: bool = False) -> RenderMesh:
    rng = np.random.default_rng(0)
    positions = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], np.float32)
    positions += rng.normal(scale=0.01, size=positions.shape).astype(np.float32)
    extra = {}
    if textured:
        extra = {"uvs": rng.random((4, 2), dtype=np.float32),
                 "texture": rng.integers(0, 256, (8, 16, 4), dtype=np.uint8)}
    return RenderMesh(positions=positions, indices=np.array([[0, 1, 2], [0, 2, 3]]),
                      normals=np.tile(np.float32([0, 0, 1]), (4, 1)),
                      colors=rng.random((4, 4), dtype=np.float32), name="quad", **extra)


def make_bag(dtype_ints=np.uint16) -> Bag:
    rng = np.random.default_rng(0)
    f64 = rng.normal(size=(5, 7))
    f64[0, :3] = [np.nan, -0.0, np.inf]
    f64[1, 0] = np.frombuffer(np.uint64(0x7FF8_0000_DEAD_BEEF).tobytes(), np.float64)[0]
    arrays = {
        "f64": f64,
        "f32": rng.random((2, 3, 3), dtype=np.float32),
        "ints": rng.integers(0, 60000, (4, 6)).astype(dtype_ints),
        "i64": rng.integers(-(2**62), 2**62, 9),
        "matrix": np.eye(4, dtype=np.float32),
        "flags": rng.random(11) > 0.5,
    }
    params = {"size": [256, 256], "method": "robust", "scale": 0.5, "nested": {"a": None}}
    return Bag(arrays, params)


def rk_file(tmp_path, rep=None, name="x.rk", **kw) -> Path:
    return formats.save(tmp_path / name, make_mesh() if rep is None else rep, **kw)


def npy_bytes(arr: np.ndarray) -> bytes:
    bio = io.BytesIO()
    npy.write_array(bio, arr, allow_pickle=False)
    return bio.getvalue()


def forged_npy(descr: str, shape: tuple, payload: bytes) -> bytes:
    """A .npy member written by hand: any header, any payload (never pickled)."""
    bio = io.BytesIO()
    npy.write_array_header_1_0(bio, {"descr": descr, "fortran_order": False, "shape": shape})
    return bio.getvalue() + payload


def rewrite(path: Path, *, members: dict | None = None, manifest=None,
            method: int = zipfile.ZIP_DEFLATED, methods: dict | None = None,
            raw_manifest: bytes | None = None) -> None:
    """Rebuild the zip at `path` (valid CRCs) with members replaced (None deletes one), every
    member written with `method` unless `methods` names another for it."""
    with zipfile.ZipFile(path) as zf:
        content = {info.filename: zf.read(info) for info in zf.infolist()}
    man = json.loads(content["manifest.json"])
    if manifest is not None:
        manifest(man)
    content["manifest.json"] = json.dumps(man).encode() if raw_manifest is None else raw_manifest
    for name, data in (members or {}).items():
        if data is None:
            content.pop(name, None)
        else:
            content[name] = data
    with zipfile.ZipFile(path, "w") as zf:
        for name, data in content.items():
            zf.writestr(name, data, (methods or {}).get(name, method))


def deflate(data: bytes, level: int = 1) -> bytes:
    """A raw deflate stream, as zip members hold it."""
    co = zlib.compressobj(level, zlib.DEFLATED, -zlib.MAX_WBITS)
    return co.compress(data) + co.flush()


def local_header(name: str, method: int, crc: int, csize: int, usize: int) -> bytes:
    raw = name.encode()
    return struct.pack("<4s5H3L2H", b"PK\x03\x04", 20, 0, method, 0, 0x21, crc, csize, usize,
                       len(raw), 0) + raw


def central_entry(name: str, method: int, crc: int, csize: int, usize: int,
                  offset: int) -> bytes:
    raw = name.encode()
    return struct.pack("<4s6H3L5H2L", b"PK\x01\x02", 20, 20, 0, method, 0, 0x21, crc, csize,
                       usize, len(raw), 0, 0, 0, 0, 0o644 << 16, offset) + raw


def end_record(count: int, cd_size: int, cd_offset: int) -> bytes:
    return struct.pack("<4s4H2LH", b"PK\x05\x06", 0, 0, count, count, cd_size, cd_offset, 0)


def members_of(path: Path) -> dict[str, bytes]:
    with zipfile.ZipFile(path) as zf:
        return {info.filename: zf.read(info) for info in zf.infolist()}


def write_raw_zip(path: Path, members: dict[str, bytes], forged: dict | None = None) -> None:
    """Write a zip by hand, each member deflated at level 1 unless `forged` gives it other
    directory fields: name -> dict of raw (the bytes as stored), method, crc, usize (the
    declared uncompressed size), csize (the compressed size in both headers)."""
    body, central = b"", b""
    for name, data in members.items():
        entry = {"raw": deflate(data), "method": zipfile.ZIP_DEFLATED,
                 "crc": zlib.crc32(data), "usize": len(data)}
        entry.update((forged or {}).get(name, {}))
        entry.setdefault("csize", len(entry["raw"]))
        fields = (entry["method"], entry["crc"], entry["csize"], entry["usize"])
        central += central_entry(name, *fields, offset=len(body))
        body += local_header(name, *fields) + entry["raw"]
    path.write_bytes(body + central + end_record(len(members), len(central), len(body)))


def data_offset(path: Path, member: str) -> tuple[int, zipfile.ZipInfo]:
    """Where a member's raw (stored or deflated) bytes start in the file, and its ZipInfo."""
    with zipfile.ZipFile(path) as zf:
        info = zf.getinfo(member)
    head = path.read_bytes()[info.header_offset:info.header_offset + 30]
    name_len, extra_len = struct.unpack("<2H", head[26:30])
    return info.header_offset + 30 + name_len + extra_len, info


def replace_array(path: Path, name: str, data: bytes, *, dtype=None, shape=None) -> None:
    """Swap one .npy member and update its manifest entry so only the forgery is wrong."""

    def edit(man):
        entry = man["arrays"].setdefault(name, {})
        entry["sha256"] = hashlib.sha256(data).hexdigest()
        if dtype is not None:
            entry["dtype"], entry["shape"] = dtype, list(shape)

    rewrite(path, members={f"{name}.npy": data}, manifest=edit)


def consistent_array(path: Path, name: str, arr: np.ndarray) -> None:
    replace_array(path, name, npy_bytes(arr), dtype=arr.dtype.str, shape=arr.shape)


def fails(path, *patterns: str, **kw) -> str:
    """Assert that loading raises FormatError naming the file and matching every pattern,
    and that loading the file's bytes raises the same one line naming "the .rk bytes"."""
    msg = load_error(path, **kw)
    assert str(path) in msg and "\n" not in msg
    for pattern in patterns:
        assert re.search(pattern, msg), msg
    if Path(path).is_file():
        in_memory = load_error(Path(path).read_bytes(), **kw)
        assert in_memory == msg.replace(str(path), "the .rk bytes")
    return msg


def load_error(source, **kw) -> str:
    with pytest.raises(FormatError) as info:
        formats.load(source, **kw)
    return str(info.value)


def assert_same_arrays(a: dict, b: dict) -> None:
    assert a.keys() == b.keys()
    for name in a:
        assert a[name].dtype == b[name].dtype, name
        assert a[name].shape == b[name].shape, name
        assert a[name].tobytes() == b[name].tobytes(), name  # bit for bit, NaN payloads too


# ------------------------------------------------------------------------ round trips


@pytest.mark.parametrize("textured", [False, True])
def test_mesh_round_trip_is_bit_exact(tmp_path, textured):
    mesh = make_mesh(textured)
    path = formats.save(tmp_path / "m.rk", mesh, source_hash=SOURCE_HASH)
    back = formats.load(path)
    assert isinstance(back, RenderMesh) and back.name == "quad"
    for name in ("positions", "indices", "normals", "colors", "uvs", "texture"):
        a, b = getattr(mesh, name), getattr(back, name)
        if a is None:
            assert b is None
        else:
            assert np.array_equal(a, b) and a.dtype == b.dtype, name
    manifest = formats.read_manifest(path)
    assert manifest["source_hash"] == SOURCE_HASH and manifest["kind"] == "mesh"
    assert ("texture" in manifest["arrays"]) == textured


@pytest.mark.parametrize("textured", [False, True])
def test_rk_bytes_are_the_bytes_save_writes(tmp_path, textured):
    mesh = make_mesh(textured)
    key = hashlib.sha256(b"cache key").hexdigest()
    path = formats.save(tmp_path / "m.rk", mesh, source_hash=SOURCE_HASH, cache_key=key)
    assert formats.rk_bytes(mesh, source_hash=SOURCE_HASH, cache_key=key) == path.read_bytes()
    assert formats.read_manifest(path)["cache_key"] == key


@pytest.mark.parametrize("rep", [make_mesh(textured=True), make_bag()], ids=["mesh", "bag"])
def test_the_bytes_load_as_the_file_does(tmp_path, rep):
    """What a batch worker returns reads back without a file: bytes, bytearray, memoryview
    or a binary file object, through every reader and the public load."""
    data = formats.rk_bytes(rep, source_hash=SOURCE_HASH)
    path = formats.save(tmp_path / "x.rk", rep, source_hash=SOURCE_HASH)
    from_file = formats.read_rk(path)
    for source in (data, bytearray(data), memoryview(data), io.BytesIO(data)):
        assert formats.read_manifest(source) == formats.read_manifest(path)
        in_memory = formats.read_rk(source)
        assert in_memory.manifest == from_file.manifest
        assert_same_arrays(in_memory.arrays, from_file.arrays)
    for back in (formats.load(data), reliefkit.load(data)):
        assert type(back) is type(rep)
        assert_same_arrays(arrays_of(back), arrays_of(formats.load(path)))


def test_a_file_object_is_named_by_its_path_and_left_open(tmp_path):
    path = rk_file(tmp_path)
    rewrite(path, manifest=lambda man: man.update(kind="hologram"))
    with open(path, "rb") as fh:
        with pytest.raises(FormatError, match=f"^{re.escape(str(path))}: .*unknown kind"):
            formats.load(fh)
        assert not fh.closed
    with open(path) as text, pytest.raises(FormatError, match="opened in binary mode"):
        formats.load(text)


def arrays_of(rep) -> dict:
    """A representation's arrays as its codec saves them."""
    arrays, _ = formats.codec_of(rep).to_arrays(rep)
    return {name: np.asarray(a) for name, a in arrays.items() if a is not None}


def test_the_cache_key_is_written_only_when_given(tmp_path):
    path = formats.save(tmp_path / "m.rk", make_mesh(False))
    assert "cache_key" not in formats.read_manifest(path)
    with pytest.raises(FormatError, match="cache_key must be"):
        formats.rk_bytes(make_mesh(False), cache_key="not a digest")


@pytest.mark.parametrize("ints", [np.uint8, np.uint16])
def test_multi_dtype_round_trip_keeps_bits_params_and_hash(tmp_path, ints):
    bag = make_bag(ints)
    path = formats.save(tmp_path / "b.rk", bag, source_hash=SOURCE_HASH)
    rk = formats.read_rk(path)
    assert rk.kind == "test-bag" and rk.manifest["source_hash"] == SOURCE_HASH
    assert rk.params == bag.meta
    assert_same_arrays(rk.arrays, bag.arrays)
    back = formats.load(path)
    assert isinstance(back, Bag) and back.meta == bag.meta
    assert_same_arrays(back.arrays, bag.arrays)


def test_optional_array_may_be_absent_and_big_endian_input_is_normalized(tmp_path):
    bag = make_bag()
    del bag.arrays["flags"]
    bag.arrays["f64"] = bag.arrays["f64"].astype(">f8")
    bag.arrays["matrix"] = np.asfortranarray(np.arange(16, dtype=np.float32).reshape(4, 4))
    back = formats.load(formats.save(tmp_path / "b.rk", bag))
    assert "flags" not in back.arrays
    assert back.arrays["f64"].dtype.str == "<f8"
    np.testing.assert_array_equal(back.arrays["f64"], bag.arrays["f64"])
    np.testing.assert_array_equal(back.arrays["matrix"], bag.arrays["matrix"])


def test_fortran_order_member_is_read_correctly(tmp_path):
    path = rk_file(tmp_path, make_bag())
    matrix = np.asfortranarray(np.arange(16, dtype=np.float32).reshape(4, 4))
    consistent_array(path, "matrix", matrix)  # numpy writes fortran_order: True
    back = formats.load(path).arrays["matrix"]
    assert back.flags.c_contiguous
    np.testing.assert_array_equal(back, matrix)


def test_plain_numpy_can_open_the_file(tmp_path):
    mesh = make_mesh(textured=True)
    path = rk_file(tmp_path, mesh)
    with np.load(path, allow_pickle=False) as npz:
        assert set(npz.files) == {"manifest.json", "positions", "indices", "normals", "colors",
                                  "uvs", "texture"}
        np.testing.assert_array_equal(npz["texture"], mesh.texture)
        assert json.loads(npz["manifest.json"])["format"] == "reliefkit"


def test_manifest_fields_and_deflated_members(tmp_path):
    path = rk_file(tmp_path, source_hash=SOURCE_HASH)
    man = formats.read_manifest(path)
    assert man["format"] == "reliefkit" and man["format_version"] == 1
    assert man["kind_version"] == registry().codecs().for_kind("mesh").version
    assert man["params"] == {"name": "quad"}
    assert man["created_by"].startswith("reliefkit ")
    assert man["arrays"]["indices"]["dtype"] == "<u4"
    assert man["arrays"]["positions"]["shape"] == [4, 3]
    whole = path.read_bytes()
    with zipfile.ZipFile(path) as zf:
        for info in zf.infolist():
            assert info.compress_type == zipfile.ZIP_DEFLATED
            assert info.date_time == (1980, 1, 1, 0, 0, 0)
            data = zf.read(info)
            start, _ = data_offset(path, info.filename)
            # deflate at the fixed level, nothing else (so the bytes are reproducible)
            assert whole[start:start + info.compress_size] == deflate(data, level=1)
            if info.filename.endswith(".npy"):
                name = info.filename[:-4]
                digest = hashlib.sha256(data).hexdigest()  # of the uncompressed .npy
                assert man["arrays"][name]["sha256"] == digest


def test_same_input_gives_identical_bytes(tmp_path):
    a = rk_file(tmp_path, make_mesh(True), name="a.rk")
    b = rk_file(tmp_path, make_mesh(True), name="b.rk")
    assert a.read_bytes() == b.read_bytes()


def test_file_sha256_matches_hashlib(tmp_path):
    path = rk_file(tmp_path)
    assert formats.file_sha256(path) == hashlib.sha256(path.read_bytes()).hexdigest()
    with pytest.raises(FormatError, match="cannot read"):
        formats.file_sha256(tmp_path / "missing.obj")


# --------------------------------------------------------------------- forged files


def test_shape_larger_than_data_fails_without_allocating(tmp_path):
    path = rk_file(tmp_path, make_bag())
    shape = (10**6, 10**6)
    replace_array(path, "f64", forged_npy("<f8", shape, b"\0" * 64), dtype="<f8", shape=shape)
    tracemalloc.start()
    try:
        fails(path, r"declares shape \(1000000, 1000000\)", "truncated or forged")
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak < 2 * 2**20


def test_moderate_shape_claim_is_rejected_before_any_array_is_made(tmp_path, monkeypatch):
    path = rk_file(tmp_path, make_bag())
    shape = (1000, 1000)  # 8 MB claimed, 64 bytes stored
    replace_array(path, "f64", forged_npy("<f8", shape, b"\0" * 64), dtype="<f8", shape=shape)
    made = []
    real_empty = np.empty
    monkeypatch.setattr(np, "empty", lambda *a, **k: made.append(a) or real_empty(*a, **k))
    fails(path, "holds 64 bytes of data")
    assert made == []


def test_size_cap_applies_to_declared_bytes(tmp_path):
    path = rk_file(tmp_path, make_bag())
    assert formats.read_rk(path, max_bytes=10**6).kind == "test-bag"
    fails(path, "over the .* GiB limit", "max_bytes", max_bytes=100)


def test_flipped_data_byte_is_a_checksum_mismatch(tmp_path):
    path = rk_file(tmp_path)
    data = bytearray(npy_bytes(make_mesh().positions))
    data[-1] ^= 0x01
    rewrite(path, members={"positions.npy": bytes(data)})  # valid CRC, stale sha256
    fails(path, "checksum mismatch for array 'positions'", "corrupt")


def test_flipped_byte_on_disk_is_a_checksum_mismatch(tmp_path):
    path = rk_file(tmp_path)
    rewrite(path, method=zipfile.ZIP_STORED)  # a stored member: the byte is the data's own
    data_at, info = data_offset(path, "colors.npy")
    raw = bytearray(path.read_bytes())
    raw[data_at + info.file_size - 1] ^= 0x40  # last data byte: the CRC no longer matches
    path.write_bytes(bytes(raw))
    fails(path, "checksum mismatch for array 'colors' \\(zip CRC-32\\)")


def test_every_flipped_byte_of_a_deflated_member_is_refused_or_harmless(tmp_path):
    """A flip anywhere in a deflate stream is refused with FormatError naming the array, or
    (a flip in the padding bits after the last block) decodes to the very same bytes."""
    mesh = make_mesh(textured=True)
    path = rk_file(tmp_path, mesh)
    data_at, info = data_offset(path, "colors.npy")
    whole = path.read_bytes()
    harmless = 0
    for i in range(data_at, data_at + info.compress_size):
        raw = bytearray(whole)
        raw[i] ^= 0xFF
        path.write_bytes(bytes(raw))
        try:
            back = formats.load(path)
        except FormatError as exc:
            assert "array 'colors'" in str(exc) and "\n" not in str(exc), str(exc)
            continue
        harmless += 1
        assert back.colors.tobytes() == mesh.colors.tobytes()
    assert harmless < 3


def test_tampered_manifest_checksum(tmp_path):
    path = rk_file(tmp_path)

    def edit(man):
        man["arrays"]["normals"]["sha256"] = "0" * 64

    rewrite(path, manifest=edit)
    fails(path, "checksum mismatch for array 'normals'")


def test_truncated_zip_fails_at_every_cut(tmp_path):
    path = rk_file(tmp_path, make_mesh(True))
    whole = path.read_bytes()
    cuts = sorted({0, 1, 4, 30, 100, len(whole) // 3, len(whole) // 2, len(whole) - 23,
                   len(whole) - 22, len(whole) - 5, len(whole) - 1})
    for cut in cuts:
        path.write_bytes(whole[:cut])
        fails(path, "truncated|corrupt")


def test_data_missing_from_the_middle(tmp_path):
    path = rk_file(tmp_path)
    whole = path.read_bytes()
    path.write_bytes(whole[:200] + whole[400:])  # end records intact, offsets now wrong
    fails(path, "truncated|corrupt")


def test_object_array_is_refused_and_never_unpickled(tmp_path, monkeypatch):
    import pickle

    def no_unpickling(*args, **kwargs):
        raise AssertionError("pickle must never be used")

    monkeypatch.setattr(pickle, "load", no_unpickling)
    monkeypatch.setattr(pickle, "loads", no_unpickling)
    path = rk_file(tmp_path)
    member = forged_npy("|O", (4, 3), b"\x80\x04cos\nsystem\n.")
    replace_array(path, "positions", member, dtype="|O", shape=(4, 3))
    fails(path, "object dtype", "pickle")


@pytest.mark.parametrize("dtype, shape, pattern", [
    ("<f8", (4, 3), r"dtype <f8; kind 'mesh' allows float32"),
    (">f4", (4, 3), r"dtype >f4"),
    ("<f4", (4, 5), r"shape \(4, 5\); kind 'mesh' expects \(\*, 3\)"),
    ("<f4", (12,), r"expects \(\*, 3\)"),
])
def test_header_dtype_or_shape_outside_the_spec(tmp_path, dtype, shape, pattern):
    path = rk_file(tmp_path)
    arr = np.zeros(shape, dtype)
    consistent_array(path, "positions", arr)
    fails(path, pattern)


def test_header_disagrees_with_manifest(tmp_path):
    path = rk_file(tmp_path)
    arr = np.zeros((3, 3), np.float32)
    replace_array(path, "positions", npy_bytes(arr))  # manifest still says (4, 3)
    fails(path, r"header says <f4 \(3, 3\) but the manifest says <f4 \(4, 3\)")


def test_malformed_npy_header(tmp_path):
    path = rk_file(tmp_path)
    replace_array(path, "positions", b"\x93NUMPY\x01\x00\x10\x00{'descr': 'zz' ...}")
    fails(path, "malformed .npy header")


def test_unknown_kind_lists_known_kinds(tmp_path):
    path = rk_file(tmp_path)
    rewrite(path, manifest=lambda man: man.update(kind="hologram"))
    fails(path, "unknown kind 'hologram'", "known kinds: .*mesh")


@pytest.mark.parametrize("field_name, value, pattern", [
    ("format_version", 2, "written by a newer reliefkit.*upgrade"),
    ("format_version", 0, "unsupported format_version 0"),
    ("format_version", "1", "unsupported format_version '1'"),
    ("format_version", None, "unsupported format_version None"),
    ("kind_version", 7, "kind 'mesh' version 7 was written by a newer reliefkit"),
    ("format", "numpy", "format is 'numpy', not 'reliefkit'"),
    ("params", [1], "params is not a JSON object"),
    ("source_hash", "abc", "source_hash must be"),
    ("cache_key", "ABC", "cache_key must be"),
    ("cache_key", 12, "cache_key must be"),
    ("arrays", {"positions": {"dtype": "<f4"}}, "manifest entry for array 'positions'"),
])
def test_bad_manifest_fields(tmp_path, field_name, value, pattern):
    path = rk_file(tmp_path)
    rewrite(path, manifest=lambda man: man.update({field_name: value}))
    fails(path, pattern)


def test_missing_manifest(tmp_path):
    path = tmp_path / "plain.rk"
    with open(path, "wb") as fh:
        np.savez(fh, positions=np.zeros((4, 3), np.float32))
    fails(path, "no manifest.json", "not a .rk file")


@pytest.mark.parametrize("raw, pattern", [
    (b"{not json", "not valid JSON"),
    (b"\xff\xfe", "not valid JSON"),
    (b"[1, 2]", "not a JSON object"),
    (b" " * (2**20 + 1), "over the 1 MiB limit"),
])
def test_manifest_not_json(tmp_path, raw, pattern):
    path = rk_file(tmp_path)
    rewrite(path, raw_manifest=raw)
    fails(path, pattern)


def test_missing_required_array(tmp_path):
    path = rk_file(tmp_path)

    def edit(man):
        del man["arrays"]["normals"]

    rewrite(path, members={"normals.npy": None}, manifest=edit)
    fails(path, "missing required array 'normals'")


def test_extra_unknown_array(tmp_path):
    path = rk_file(tmp_path)
    consistent_array(path, "weights", np.ones(4, np.float32))
    fails(path, "unknown array 'weights' for kind 'mesh'")


def test_listed_array_missing_from_zip(tmp_path):
    path = rk_file(tmp_path)
    rewrite(path, members={"normals.npy": None})
    fails(path, "normals.npy is not in the zip")


def test_member_not_listed_in_manifest(tmp_path):
    path = rk_file(tmp_path)
    rewrite(path, members={"sneaky.npy": npy_bytes(np.zeros(3))})
    fails(path, "'sneaky.npy' is not listed in the manifest")


def test_duplicate_member(tmp_path):
    path = rk_file(tmp_path)
    with pytest.warns(UserWarning), zipfile.ZipFile(path, "a") as zf:
        zf.writestr("colors.npy", npy_bytes(np.zeros((4, 4), np.float32)))
    fails(path, "duplicate member")


def test_deflated_and_stored_members_may_be_mixed(tmp_path):
    mesh = make_mesh()
    path = rk_file(tmp_path, mesh)
    rewrite(path, method=zipfile.ZIP_STORED, methods={"indices.npy": zipfile.ZIP_DEFLATED})
    np.testing.assert_array_equal(formats.load(path).indices, mesh.indices)


@pytest.mark.parametrize("method, label", [(zipfile.ZIP_BZIP2, "bzip2"),
                                           (zipfile.ZIP_LZMA, "lzma")])
def test_other_compression_methods_are_refused(tmp_path, method, label):
    path = rk_file(tmp_path)
    rewrite(path, methods={"indices.npy": method})
    fails(path, f"array 'indices' uses zip compression method {method} \\({label}\\)",
          "stored or deflated")
    rewrite(path, methods={"manifest.json": method})
    fails(path, f"manifest.json uses zip compression method {method}")


def test_unknown_compression_method_is_refused(tmp_path):
    path = tmp_path / "x.rk"
    content = members_of(rk_file(tmp_path))
    write_raw_zip(path, content, {"normals.npy": {"method": 99}})  # AES, say
    fails(path, "array 'normals' uses zip compression method 99 \\(unknown\\)")


def test_nan_in_finite_array(tmp_path):
    path = rk_file(tmp_path)
    positions = make_mesh().positions.copy()
    positions[2, 1] = np.nan
    consistent_array(path, "positions", positions)
    fails(path, "'positions' has 1 NaN or Inf")


def test_representation_rejects_data_with_the_file_named(tmp_path):
    path = rk_file(tmp_path)
    consistent_array(path, "indices", np.array([[0, 1, 2], [0, 2, 9]], np.uint32))
    msg = fails(path, "invalid mesh data", "out of range")
    assert msg.startswith(str(path))


@pytest.mark.parametrize("content", [b"", b"hello, not a zip", b"PK\x03\x04" + b"\0" * 50],
                         ids=["empty", "text", "zip-magic-only"])
def test_not_a_zip(tmp_path, content):
    path = tmp_path / "junk.rk"
    path.write_bytes(content)
    fails(path, "not a zip archive")


def test_nonexistent_path_and_folder(tmp_path):
    fails(tmp_path / "nope.rk", "no such file")
    fails(tmp_path, "is not a file")


def test_read_manifest_validates_headers_but_reads_no_data(tmp_path):
    path = rk_file(tmp_path)
    data = bytearray(npy_bytes(make_mesh().positions))
    data[-1] ^= 0x01
    rewrite(path, members={"positions.npy": bytes(data)})  # only a checksum is wrong
    assert formats.read_manifest(path)["kind"] == "mesh"
    consistent_array(path, "positions", np.zeros((4, 3), np.float64))
    with pytest.raises(FormatError, match="dtype <f8"):
        formats.read_manifest(path)


# ------------------------------------------------------------------ compressed members


def test_deflated_round_trip_is_bit_exact_and_smaller(tmp_path):
    bag = make_bag()
    big = np.zeros((256, 256))  # compressible, 512 KiB, with the NaN payloads of make_bag
    big[:5, :7] = bag.arrays["f64"]
    bag.arrays["f64"] = big
    path = formats.save(tmp_path / "b.rk", bag)
    with zipfile.ZipFile(path) as zf:
        assert {i.compress_type for i in zf.infolist()} == {zipfile.ZIP_DEFLATED}
        big = zf.getinfo("f64.npy")
        assert big.compress_size * 100 < big.file_size
    assert path.stat().st_size < 16 * 1024
    back = formats.load(path)
    assert_same_arrays(back.arrays, bag.arrays)  # NaN payloads, -0.0 and all
    with np.load(path, allow_pickle=False) as npz:  # plain numpy inflates it too
        assert_same_arrays({k: npz[k] for k in bag.arrays}, bag.arrays)


def test_old_stored_files_still_load(tmp_path):
    bag = make_bag()
    path = rk_file(tmp_path, bag)
    rewrite(path, method=zipfile.ZIP_STORED)  # the layout every earlier reliefkit wrote
    with zipfile.ZipFile(path) as zf:
        assert {i.compress_type for i in zf.infolist()} == {zipfile.ZIP_STORED}
    assert formats.read_manifest(path)["kind"] == "test-bag"
    assert_same_arrays(formats.load(path).arrays, bag.arrays)
    mesh = make_mesh(True)
    path = rk_file(tmp_path, mesh, name="m.rk")
    rewrite(path, method=zipfile.ZIP_STORED)
    assert formats.load(path).texture.tobytes() == mesh.texture.tobytes()



@pytest.mark.parametrize("chunk", [1, 7, 4096])
@pytest.mark.parametrize("method", [zipfile.ZIP_DEFLATED, zipfile.ZIP_STORED])
def test_any_read_chunk_size_gives_the_same_arrays(tmp_path, monkeypatch, chunk, method):
    """Stream ends, header ends and chunk ends may fall anywhere: a valid file always loads."""
    bag = make_bag()
    bag.arrays["f64"] = np.linspace(0, 1, 3000).reshape(60, 50)
    path = rk_file(tmp_path, bag)
    rewrite(path, method=method)
    monkeypatch.setattr(formats, "_CHUNK", chunk)
    assert_same_arrays(formats.load(path).arrays, bag.arrays)

@pytest.mark.parametrize("extra", [1, 64 << 20], ids=["one-byte", "64MiB"])
def test_deflated_member_longer_than_declared_is_refused_without_inflating_it(tmp_path,
                                                                              extra):
    """The directory declares the real .npy (size, CRC-32 and manifest SHA-256 all of it),
    but the deflate stream goes on: a zip bomb or a lying size. Nothing past the declared
    size is inflated, let alone allocated."""
    path = rk_file(tmp_path, make_bag())
    content = members_of(path)
    declared = content["i64.npy"]
    stream = deflate(declared + bytes(extra))
    tracemalloc.start()
    try:
        write_raw_zip(path, content, {"i64.npy": {"raw": stream}})
        fails(path, "array 'i64' inflates to more than its declared "
              f"{len(declared)} bytes", "forged")
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak < 2 * 2**20 + 2 * len(stream)


def test_deflated_member_shorter_than_declared_is_refused(tmp_path):
    """A lying size the other way: the directory and the .npy header claim more than the
    stream holds. The read stops at the stream's end, and never goes past what was declared."""
    path = rk_file(tmp_path, make_bag())
    content = members_of(path)
    arr = np.arange(1000, dtype=np.int64)
    claimed = npy_bytes(arr)
    real = claimed[:len(claimed) - 800]  # the header and the first 200 bytes only
    content["i64.npy"] = claimed

    def edit(man):
        man["arrays"]["i64"].update(shape=[1000], sha256=hashlib.sha256(claimed).hexdigest())

    man = json.loads(content["manifest.json"])
    edit(man)
    content["manifest.json"] = json.dumps(man).encode()
    write_raw_zip(path, content, {"i64.npy": {"raw": deflate(real)}})
    fails(path, f"array 'i64' inflates to {len(real)} bytes, fewer than its declared "
          f"{len(claimed)}", "truncated, corrupt or forged")


def test_impossible_deflate_ratio_is_refused_before_allocating(tmp_path, monkeypatch):
    path = rk_file(tmp_path, make_bag())
    content = members_of(path)
    shape = (1000, 1000)  # 8 MB claimed from about a hundred deflated bytes
    claimed = forged_npy("<f8", shape, b"")
    content["f64.npy"] = claimed

    def edit(man):
        man["arrays"]["f64"].update(shape=list(shape), dtype="<f8")

    man = json.loads(content["manifest.json"])
    edit(man)
    content["manifest.json"] = json.dumps(man).encode()
    write_raw_zip(path, content, {"f64.npy": {"usize": len(claimed) + 8 * 10**6}})
    made = []
    real_empty = np.empty
    monkeypatch.setattr(np, "empty", lambda *a, **k: made.append(a) or real_empty(*a, **k))
    fails(path, "array 'f64' claims 8000128 bytes from", "more than deflate can expand")
    assert made == []


def test_truncated_deflate_stream_is_refused(tmp_path):
    path = rk_file(tmp_path, make_bag())
    content = members_of(path)
    stream = deflate(content["f32.npy"])
    write_raw_zip(path, content, {"f32.npy": {"raw": stream[:len(stream) // 2]}})
    fails(path, "array 'f32'", "ends early|fewer than its declared", "truncated")
    write_raw_zip(path, content, {"f32.npy": {"raw": stream[:-1]}})
    fails(path, "array 'f32'", "truncated")


def test_bytes_after_the_deflate_stream_are_refused(tmp_path):
    path = rk_file(tmp_path, make_bag())
    content = members_of(path)
    stream = deflate(content["f32.npy"]) + b"\0" * 16
    write_raw_zip(path, content, {"f32.npy": {"raw": stream}})
    fails(path, "array 'f32' has compressed bytes after the end of its deflate stream")


def test_corrupt_deflate_stream_is_refused(tmp_path):
    path = rk_file(tmp_path, make_bag())
    content = members_of(path)
    write_raw_zip(path, content, {"f32.npy": {"raw": b"\xff" * 64}})  # invalid block type
    fails(path, "array 'f32': its deflate stream is corrupt")


def test_stored_member_with_lying_sizes_is_refused(tmp_path):
    path = rk_file(tmp_path, make_bag())
    content = members_of(path)
    data = content["f32.npy"]
    write_raw_zip(path, content, {"f32.npy": {"raw": data + bytes(64), "method": 0,
                                              "usize": len(data)}})
    fails(path, f"array 'f32' is stored in {len(data) + 64} bytes but claims {len(data)}")


def test_compressed_size_past_the_end_of_the_file_is_refused(tmp_path):
    path = rk_file(tmp_path, make_bag())
    content = members_of(path)
    write_raw_zip(path, content, {"f32.npy": {"csize": 10**6}})
    fails(path, "zip member 'f32.npy' claims 1000000 bytes of data", "more than the zip holds")


def test_overlapping_members_are_refused(tmp_path):
    """One member's data holds another's local header and data: the classic way to make a
    small zip inflate many times its size."""
    path = rk_file(tmp_path, make_bag())
    content = members_of(path)
    inner_data = content["f32.npy"]
    inner_raw = deflate(inner_data)
    inner = local_header("f32.npy", 8, zlib.crc32(inner_data), len(inner_raw),
                         len(inner_data)) + inner_raw
    outer = local_header("f64.npy", 0, zlib.crc32(inner), len(inner), len(inner))
    body = outer + inner
    central = central_entry("f64.npy", 0, zlib.crc32(inner), len(inner), len(inner), 0)
    central += central_entry("f32.npy", 8, zlib.crc32(inner_data), len(inner_raw),
                             len(inner_data), len(outer))
    for name, data in content.items():
        if name in ("f32.npy", "f64.npy"):
            continue
        raw = deflate(data)
        fields = (8, zlib.crc32(data), len(raw), len(data))
        central += central_entry(name, *fields, offset=len(body))
        body += local_header(name, *fields) + raw
    count = len(content)
    path.write_bytes(body + central + end_record(count, len(central), len(body)))
    fails(path, "zip members 'f64.npy' and 'f32.npy' overlap")


def test_local_header_name_must_match_the_directory(tmp_path):
    path = rk_file(tmp_path)
    whole = bytearray(path.read_bytes())
    with zipfile.ZipFile(path) as zf:
        at = zf.getinfo("normals.npy").header_offset + 30
    whole[at:at + 7] = b"NORMALS"
    path.write_bytes(bytes(whole))
    fails(path, "zip member 'normals.npy' has the name 'NORMALS.npy' in its local header")


# ---------------------------------------------------------------------- writing checks


@pytest.mark.parametrize("name, value, pattern", [
    ("f32", np.zeros((2, 3, 3), np.float64), "dtype <f8; kind 'test-bag' allows float32"),
    ("f32", np.zeros((2, 3, 4), np.float32), r"expects \(\*, \*, 3\)"),
    ("matrix", np.zeros((3, 3), np.float32), r"expects \(4, 4\)"),
    ("f64", np.zeros((2, 2, 2)), r"expects \(\*,\) or \(\*, \*\)"),
    ("i64", np.array([{"a": 1}], dtype=object), "object dtype"),
    ("f32", np.full((1, 1, 3), np.inf, np.float32), "3 NaN or Inf"),
    ("extra", np.zeros(3), "unknown array 'extra'"),
])
def test_write_validates_arrays(tmp_path, name, value, pattern):
    bag = make_bag()
    bag.arrays[name] = value
    with pytest.raises(FormatError, match=pattern):
        formats.save(tmp_path / "b.rk", bag)
    assert list(tmp_path.iterdir()) == []


def test_write_needs_required_arrays(tmp_path):
    bag = make_bag()
    bag.arrays["matrix"] = None
    with pytest.raises(FormatError, match="missing required array 'matrix'"):
        formats.save(tmp_path / "b.rk", bag)


@pytest.mark.parametrize("params, pattern", [
    ({"n": np.int64(3)}, "params\\['n'\\] is a int64"),
    ({"s": {1, 2}}, "is a set"),
    ({"x": [1.0, float("nan")]}, r"params\['x'\]\[1\] is nan"),
    ({1: "a"}, "JSON keys must be strings"),
    ([1, 2], "params must be a dict"),
])
def test_write_refuses_non_json_params(tmp_path, params, pattern):
    with pytest.raises(FormatError, match=pattern):
        formats.write_rk(tmp_path / "b.rk", "test-bag", make_bag().arrays, params)


def test_write_refuses_bad_source_hash_unknown_kind_and_type(tmp_path):
    with pytest.raises(FormatError, match="source_hash"):
        rk_file(tmp_path, source_hash="ABC")
    with pytest.raises(FormatError, match="unknown kind 'nope'"):
        formats.write_rk(tmp_path / "b.rk", "nope", {}, {})
    with pytest.raises(FormatError, match="no .rk kind is registered for it"):
        formats.save(tmp_path / "b.rk", object())


def test_codec_table_refuses_conflicts_and_bad_specs():
    with pytest.raises(FormatError, match="already registered"):
        with_kinds(BAG, Codec("mesh", Bag, {}, BAG.to_arrays, BAG.from_arrays))
    with pytest.raises(FormatError, match="already registered as kind 'test-bag'"):
        with_kinds(BAG, Codec("bag2", Bag, {}, BAG.to_arrays, BAG.from_arrays))
    with pytest.raises(FormatError, match="not a plain numeric dtype"):
        with_kinds(Codec("bad", dict, {"a": ArraySpec(("O",), 1)}, None, None))
    with pytest.raises(FormatError, match="invalid kind"):
        with_kinds(Codec("Bad Kind", dict, {}, None, None))
    assert "mesh" in registry().codecs().kinds and "bad" not in registry().codecs().kinds


# ------------------------------------------------------------------------ atomic writes


def _folder_listing(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir())


def test_failing_to_arrays_leaves_old_file_and_no_temp(tmp_path):
    path = rk_file(tmp_path)
    before = path.read_bytes()

    def broken(bag):
        raise RuntimeError("bake exploded")

    kinds = with_kinds(Codec("test-broken", dict, {}, broken, BAG.from_arrays))
    with pytest.raises(RuntimeError, match="bake exploded"):
        formats.save(path, {}, codecs=kinds)
    assert path.read_bytes() == before and _folder_listing(tmp_path) == ["x.rk"]


@pytest.mark.parametrize("error, expected", [(RuntimeError, RuntimeError),
                                             (OSError, FormatError)])
def test_failing_replace_leaves_old_file_and_no_temp(tmp_path, monkeypatch, error, expected):
    path = rk_file(tmp_path)
    before = path.read_bytes()

    def broken_replace(src, dst):
        assert Path(src).name.startswith(".x.rk.") and Path(src).exists()
        raise error("disk on fire")

    monkeypatch.setattr(os, "replace", broken_replace)
    with pytest.raises(expected, match="disk on fire"):
        formats.save(path, make_mesh(True))
    assert path.read_bytes() == before and _folder_listing(tmp_path) == ["x.rk"]


def test_failure_midway_through_writing_leaves_nothing(tmp_path, monkeypatch):
    real_write_array = npy.write_array
    calls = []

    def write_then_fail(fp, arr, **kw):
        calls.append(arr.shape)
        if len(calls) == 3:
            fp.write(b"\x93NUMPY partial")
            raise KeyboardInterrupt
        real_write_array(fp, arr, **kw)

    monkeypatch.setattr(npy, "write_array", write_then_fail)
    with pytest.raises(KeyboardInterrupt):
        formats.save(tmp_path / "new.rk", make_mesh())
    assert _folder_listing(tmp_path) == []


def test_write_into_missing_folder(tmp_path):
    with pytest.raises(FormatError, match="cannot write .*check that the folder exists"):
        rk_file(tmp_path / "no" / "such")


def test_overwrite_replaces_content(tmp_path):
    path = rk_file(tmp_path, make_mesh(False))
    rk_file(tmp_path, make_mesh(True))
    assert "texture" in formats.read_manifest(path)["arrays"]
    assert _folder_listing(tmp_path) == ["x.rk"]


def test_a_stream_whose_last_chunk_stops_before_its_end_marker_loads(tmp_path, monkeypatch):
    """A sparse array deflates so well that the read which completes its declared size can
    leave the stream's end marker in zlib's bit buffer, all input consumed (a shootout's
    billboard atlas of a CAD engine did): still a valid file."""
    monkeypatch.setattr(formats, "_CHUNK", 64)
    for n in range(600, 1500, 7):
        bag = make_bag()
        bag.arrays["ints"] = np.zeros((n, 1), np.uint16)
        bag.arrays["ints"][::97] = 7
        path = rk_file(tmp_path, bag)
        assert_same_arrays(formats.load(path).arrays, bag.arrays)
