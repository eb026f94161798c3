"""Every registered .rk kind (and the toy technique's): bit-exact round trips, and forged files
refused with FormatError before anything large is allocated. New techniques get these free."""

from __future__ import annotations

import hashlib
import io
import json
import zipfile

import numpy as np
import pytest
from helpers import sample, sample_ids, technique_samples
from numpy.lib import format as npy

from reliefkit.builtins import registry
from reliefkit.errors import FormatError
from reliefkit.io import rk

pytestmark = pytest.mark.usefixtures("toy_registered")

SAMPLES = technique_samples()
IDS = sample_ids(SAMPLES)



@pytest.fixture(params=SAMPLES, ids=IDS)
def written(request, tmp_path):
    tech, kind = request.param
    rep = sample(tech, kind)
    path = tmp_path / "sample.rk"
    rk.save(path, rep)
    return kind, rep, path


def _arrays_of(rep):
    codec = registry().codecs().for_object(rep)
    arrays, params = codec.to_arrays(rep)
    return {k: np.asarray(v) for k, v in arrays.items() if v is not None}, params


def _members(path):
    with zipfile.ZipFile(path) as zf:
        return {info.filename: zf.read(info) for info in zf.infolist()}


def _rewrite(path, members):
    with zipfile.ZipFile(path, "w") as zf:
        for name, data in members.items():
            zf.writestr(name, data)


def _edit(path, edit_manifest=None, members=None):
    content = _members(path)
    manifest = json.loads(content["manifest.json"])
    if edit_manifest:
        edit_manifest(manifest)
    content["manifest.json"] = json.dumps(manifest).encode()
    for name, data in (members or {}).items():
        if data is None:
            content.pop(name, None)
        else:
            content[name] = data
    _rewrite(path, content)


def _npy(arr):
    bio = io.BytesIO()
    npy.write_array(bio, arr, allow_pickle=False)
    return bio.getvalue()


def _refused(path, *words):
    with pytest.raises(FormatError) as info:
        rk.load(path)
    message = str(info.value)
    assert "\n" not in message and str(path) in message
    for word in words:
        assert word in message, message
    return message


def test_kind_is_registered_in_a_fresh_view(written):
    kind, rep, path = written
    assert kind in registry().codecs().kinds
    assert rk.read_manifest(path)["kind"] == kind


def test_round_trip_is_bit_exact(written, tmp_path):
    kind, rep, path = written
    back = rk.load(path)
    assert type(back) is type(rep)
    (a, pa), (b, pb) = _arrays_of(rep), _arrays_of(back)
    assert a.keys() == b.keys()
    for name in a:
        assert a[name].dtype == b[name].dtype and a[name].shape == b[name].shape, name
        assert a[name].tobytes() == b[name].tobytes(), name
    assert json.loads(json.dumps(pa)) == pb
    again = tmp_path / "again.rk"
    rk.save(again, back)
    assert again.read_bytes() == path.read_bytes()  # deterministic, so caches and diffs work


def test_shape_claims_are_refused_without_allocating(written, monkeypatch):
    kind, rep, path = written
    manifest = rk.read_manifest(path)
    name, entry = next(iter(manifest["arrays"].items()))
    claim = (4096, 4096, 64)
    forged = io.BytesIO()
    npy.write_array_header_1_0(forged, {"descr": entry["dtype"], "fortran_order": False,
                                        "shape": claim})
    data = forged.getvalue() + b"\0" * 64

    def claim_shape(man):
        man["arrays"][name].update(shape=list(claim), sha256=hashlib.sha256(data).hexdigest())

    _edit(path, claim_shape, {f"{name}.npy": data})
    made = []
    real_empty = np.empty
    monkeypatch.setattr(np, "empty", lambda *a, **k: made.append(a) or real_empty(*a, **k))
    _refused(path, name)
    assert made == [], "an array was allocated before the file was refused"


def test_wrong_checksum_is_refused(written):
    kind, rep, path = written
    name = next(iter(rk.read_manifest(path)["arrays"]))
    data = bytearray(_members(path)[f"{name}.npy"])
    data[-1] ^= 0x01
    _edit(path, members={f"{name}.npy": bytes(data)})
    _refused(path, "checksum", name)


def test_missing_required_part_is_refused(written):
    kind, rep, path = written
    codec = registry().codecs().for_kind(kind)
    present = rk.read_manifest(path)["arrays"]
    required = [n for n, spec in codec.arrays.items() if spec.required and n in present]
    if not required:  # kinds made of optional parts (several prefixed parts) check themselves
        required = [next(iter(present))]
    name = required[0]
    _edit(path, lambda man: man["arrays"].pop(name), {f"{name}.npy": None})
    _refused(path)


def test_extra_part_is_refused(written):
    kind, rep, path = written
    data = _npy(np.zeros(3, np.float32))

    def add(man):
        man["arrays"]["zz_extra"] = {"dtype": "<f4", "shape": [3],
                                     "sha256": hashlib.sha256(data).hexdigest()}

    _edit(path, add, {"zz_extra.npy": data})
    _refused(path, "zz_extra")


def test_unlisted_member_is_refused(written):
    kind, rep, path = written
    _edit(path, members={"stowaway.npy": _npy(np.zeros(2))})
    _refused(path, "stowaway")


@pytest.mark.parametrize("forgery", ["dtype", "nan", "huge", "negative"])
def test_bad_typed_fields_are_refused_or_valid(written, forgery):
    """Every array forged in turn (wrong dtype, NaN, huge or negative values): the file is
    refused with FormatError or loads as a valid representation, never another error."""
    kind, rep, path = written
    original = _members(path)
    for name in rk.read_manifest(path)["arrays"]:
        arr = np.load(io.BytesIO(original[f"{name}.npy"]), allow_pickle=False)
        if forgery == "dtype":
            bad = arr.astype(np.complex64 if arr.dtype != np.complex64 else np.float64)
        elif arr.dtype.kind != "f":
            bad = np.full_like(arr, np.iinfo(arr.dtype).max if forgery == "huge" else 0)
        else:
            value = {"nan": np.nan, "huge": 1e30, "negative": -1.0}[forgery]
            bad = np.full_like(arr, value)
        data = _npy(bad)
        _rewrite(path, original)

        def swap(man, name=name, bad=bad, data=data):
            man["arrays"][name].update(dtype=bad.dtype.str, shape=list(bad.shape),
                                       sha256=hashlib.sha256(data).hexdigest())

        _edit(path, swap, {f"{name}.npy": data})
        try:
            back = rk.load(path)
        except FormatError as exc:
            assert "\n" not in str(exc)
            continue
        assert type(back) is type(rep), f"{name} forged as {forgery}"
        if forgery == "dtype":
            pytest.fail(f"{kind}: array {name} with dtype {bad.dtype} was accepted")
        if forgery == "nan" and registry().codecs().for_kind(kind).arrays[name].finite:
            pytest.fail(f"{kind}: NaN accepted in finite array {name}")


def test_members_are_deflated_and_stored_copies_load_the_same(written):
    """Files are written deflated; a stored copy (what earlier versions wrote) reads the same."""
    kind, rep, path = written
    with zipfile.ZipFile(path) as zf:
        assert {info.compress_type for info in zf.infolist()} == {zipfile.ZIP_DEFLATED}
    deflated = rk.read_rk(path).arrays
    _rewrite(path, _members(path))  # zipfile's default: ZIP_STORED
    with zipfile.ZipFile(path) as zf:
        assert {info.compress_type for info in zf.infolist()} == {zipfile.ZIP_STORED}
    stored = rk.read_rk(path).arrays
    assert deflated.keys() == stored.keys()
    for name in deflated:
        assert deflated[name].dtype == stored[name].dtype, name
        assert deflated[name].tobytes() == stored[name].tobytes(), name
