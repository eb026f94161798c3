"""`compress` on every kind's sample: what the GPU draws from the encoded textures is what
it draws from their decoded values uploaded raw, a compressed .rk keeps that frame and
shrinks by the formats' bits per texel, and a broken encoded member is refused in one line
before anything is allocated."""

from __future__ import annotations

import json
import zipfile

import numpy as np
import pytest
from helpers import frame_of_plans, sample, technique_samples

from reliefkit import render
from reliefkit.compact.compact import CompressOptions, compress
from reliefkit.compact.encodings import encoding_of
from reliefkit.errors import FormatError
from reliefkit.io.rk import array_bytes, codec_of, load, save
from reliefkit.scene.views import orbit_bounds

#: Views where the colour's texels are magnified (level 0 only): from above, close.
LEVEL0_VIEWS = ((0.0, 89.0), (90.0, 80.0))
#: How far the compressed draw may be from the decoded arrays' raw draw, in linear colour.
#: Not bit-exact: llvmpipe filters 8-bit texels (BC7 decodes to 8 bits) with 8-bit weights
#: and float textures in float, and decodes sRGB blocks through its own path; 2/255 bounds
#: both. (Minified views differ more: the encoded mip levels are encoded again, the raw
#: upload's are the GL's own; docs/compact.md.)
COLOR_TOLERANCE = 2 / 255
#: Kinds that threshold a filtered value, and the share of covered pixels whose colour may
#: therefore jump: the impostor keeps a frame where its filtered coverage is >= 0.5, and
#: llvmpipe filters BC7 in float but RGBA8 with 8-bit weights, so at outlines a frame drops
#: in or out (measured: 26-52 of ~3,200 pixels on its sample sphere).
THRESHOLD_FLIPS = {"octahedral-impostor": 0.02}


def encoded_samples():
    """(technique, kind) of the samples that hold an array with a role (the others have
    nothing to compress: a shell volume without a surface)."""
    out = []
    for tech, kind in technique_samples():
        rep = sample(tech, kind)
        try:
            codec = codec_of(rep)
        except FormatError:
            continue
        arrays, _ = codec.to_arrays(rep)
        if any(codec.arrays[n].role for n, a in arrays.items() if a is not None):
            out.append((tech, kind))
    return out


def raw_twin(rep):
    """The same representation with copies of its arrays: the decoded values, no encoding."""
    codec = codec_of(rep)
    arrays, params = codec.to_arrays(rep)
    copies = {n: None if a is None else np.array(a) for n, a in arrays.items()}
    return codec.from_arrays(copies, dict(params))


def encoded_names(rep) -> dict[str, str]:
    arrays, _ = codec_of(rep).to_arrays(rep)
    return {n: encoding_of(a).format for n, a in arrays.items()
            if a is not None and encoding_of(a) is not None}


@pytest.mark.parametrize("tech_kind", encoded_samples(), ids="-".join)
def test_the_encoded_textures_draw_their_decoded_values(gl, tech_kind):
    rep = sample(*tech_kind)
    compact = compress(rep)
    assert encoded_names(compact), "compress encoded nothing"
    raw = raw_twin(compact)
    assert not encoded_names(raw)
    for view in LEVEL0_VIEWS:
        camera = orbit_bounds(compact.bounds, *view, size=(128, 128))
        got, expected = render(compact, camera), render(raw, camera)
        np.testing.assert_array_equal(got.mask, expected.mask)
        np.testing.assert_allclose(got.depth, expected.depth, atol=1e-6)
        off = np.abs(got.color - expected.color).max(axis=-1) > COLOR_TOLERANCE
        assert off.sum() <= THRESHOLD_FLIPS.get(tech_kind[1], 0.0) * got.mask.sum()


@pytest.mark.parametrize("tech_kind", encoded_samples(), ids="-".join)
def test_a_compressed_rk_round_trips_its_frame(gl, tmp_path, tech_kind):
    compact = compress(sample(*tech_kind))
    path = save(tmp_path / "c.rk", compact)
    loaded = load(path)
    assert encoded_names(loaded) == encoded_names(compact)
    camera = orbit_bounds(compact.bounds, 30.0, 25.0, size=(80, 64))
    got, expected = render(loaded, camera), render(compact, camera)
    for name in ("color", "mask", "depth", "normal"):
        np.testing.assert_array_equal(getattr(got, name), getattr(expected, name))


#: Bytes a texel of each format takes (BC: a 4x4 block's bytes over 16 texels).
BYTES_PER_TEXEL = {"bc1": 0.5, "bc7": 1.0, "u8": 1.0, "u16": 2.0}


def member_data_bytes(path, name: str) -> int:
    """The data bytes of member NAME.npy (its size less the .npy header)."""
    with zipfile.ZipFile(path) as zf, zf.open(f"{name}.npy") as fh:
        head = fh.read(10)
        header = int.from_bytes(head[8:10], "little")
        return zf.getinfo(f"{name}.npy").file_size - 10 - header


def test_a_compressed_relief_file_shrinks_by_its_formats_bits(tmp_path):
    rep = sample("relief", "relief")
    options = CompressOptions(color_format="bc1", normal_format="bc7", height_bits=8)
    compact = compress(rep, options)
    raw_path, compact_path = save(tmp_path / "raw.rk", rep), save(tmp_path / "c.rk", compact)
    for name, fmt, array in (("height", "u8", rep.height), ("color", "bc1", rep.color),
                             ("normal", "bc7", rep.normal)):
        height, width = array.shape[:2]
        blocks_area = -(-height // 4) * 4 * -(-width // 4) * 4 if fmt.startswith("bc") \
            else height * width
        assert member_data_bytes(compact_path, name) == blocks_area * BYTES_PER_TEXEL[fmt]
        assert array_bytes(compact)[name] == blocks_area * BYTES_PER_TEXEL[fmt]
        assert member_data_bytes(raw_path, name) == array.nbytes
    assert compact_path.stat().st_size < raw_path.stat().st_size


def rewrite_member(path, name: str, edit) -> None:
    """Rebuild the zip with member NAME.npy's bytes and manifest entry passed through
    ``edit(data, entry) -> (data, entry)``."""
    with zipfile.ZipFile(path) as zf:
        content = {info.filename: zf.read(info) for info in zf.infolist()}
    manifest = json.loads(content["manifest.json"])
    content[f"{name}.npy"], manifest["arrays"][name] = edit(content[f"{name}.npy"],
                                                            manifest["arrays"][name])
    content["manifest.json"] = json.dumps(manifest).encode()
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as zf:
        for member, data in content.items():
            zf.writestr(member, data)


def truncated(data, entry):
    """The blocks one 4x4 block short, header, shape and checksum kept consistent."""
    import hashlib
    import io

    from numpy.lib import format as npy

    blocks = np.load(io.BytesIO(data))[:-16]
    out = io.BytesIO()
    npy.write_array(out, blocks, allow_pickle=False)
    raw = out.getvalue()
    return raw, entry | {"shape": [blocks.size], "sha256": hashlib.sha256(raw).hexdigest()}


def huge_claim(data, entry):
    """An encoding that claims a 100000 x 100000 colour image for the same bytes."""
    return data, entry | {"encoding": entry["encoding"] | {"shape": [100000, 100000, 4]}}


def flipped(data, entry):
    """One byte of the blocks changed (the manifest's checksum no longer matches)."""
    return data[:-5] + bytes([data[-5] ^ 0xFF]) + data[-4:], entry


@pytest.mark.parametrize("edit, words", [
    (truncated, "bc7 encoding of (16, 16, 4) is (256,) uint8, its member holds (240,)"),
    (huge_claim, "is (10000000000,) uint8"),
    (flipped, "checksum mismatch for array 'color'"),
])
def test_a_broken_encoded_member_is_refused_before_allocating(tmp_path, monkeypatch, edit,
                                                              words):
    compact = compress(sample("relief", "relief"))
    path = save(tmp_path / "c.rk", compact)
    rewrite_member(path, "color", edit)
    if edit is not flipped:  # nothing may be allocated for a refused claim
        monkeypatch.setattr(np, "empty", lambda *a, **k: pytest.fail("allocated"))
    with pytest.raises(FormatError, match=words.replace("(", r"\(").replace(")", r"\)")) as err:
        load(path)
    assert "\n" not in str(err.value)


@pytest.mark.parametrize("tech_kind", encoded_samples(), ids="-".join)
def test_encoded_plans_round_trip_through_json_and_draw_the_same_frame(gl, tech_kind):
    from reliefkit.render.plan import from_json, to_json
    from reliefkit.render.registry import make_drawables
    from reliefkit.scene.light import DirectionalLight

    compact = compress(sample(*tech_kind))
    camera = orbit_bounds(compact.bounds, 30.0, 35.0, size=(48, 40))
    light = DirectionalLight()
    expected = render(compact, camera, light=light)
    (drawable,) = make_drawables([compact], {})
    doc, arrays = to_json(drawable.plans)
    back = from_json(json.loads(json.dumps(doc)), {k: v.copy() for k, v in arrays.items()})
    pairs = [(t, r) for p, q in zip(drawable.plans, back, strict=True)
             for t, r in zip(p.textures.values(), q.textures.values(), strict=True)]
    encoded = [(t.encoded, r.encoded) for t, r in pairs if t.encoded is not None]
    assert encoded
    for mine, read in encoded:
        assert (read.format, read.shape, read.srgb, read.mipmaps, read.scale, read.bias) == \
            (mine.format, mine.shape, mine.srgb, mine.mipmaps, mine.scale, mine.bias)
        np.testing.assert_array_equal(read.data, mine.data)
    frame = frame_of_plans(gl, compact, drawable, back, camera, light)
    np.testing.assert_array_equal(frame.color, expected.color)
    np.testing.assert_array_equal(frame.depth, expected.depth)


def test_safety_radii_are_those_of_the_quantized_heights():
    from reliefkit.techniques.relief.safety import safety_radii

    rep = sample("relief", "relief")
    compact = compress(rep, CompressOptions(height_bits=8))
    expected = safety_radii(compact.height, tolerance=rep.params["safety_tolerance"])
    assert not np.array_equal(expected, rep.safety)  # 8-bit heights move a radius here
    np.testing.assert_array_equal(compact.safety, expected)


def test_without_the_format_the_decoded_arrays_are_uploaded(gl, monkeypatch):
    from reliefkit.render import executor

    compact = compress(sample("relief", "relief"))
    camera = orbit_bounds(compact.bounds, 30.0, 25.0, size=(64, 64))
    monkeypatch.setattr(executor, "encoded_supported", lambda *args: False)
    got, expected = render(compact, camera), render(raw_twin(compact), camera)
    for name in ("color", "mask", "depth", "normal"):
        np.testing.assert_array_equal(getattr(got, name), getattr(expected, name))


def test_a_textured_mesh_draws_and_stores_its_encoded_texture(gl, tmp_path):
    from reliefkit.scene.camera import Camera
    from reliefkit.scene.mesh import Material, RenderMesh

    v, u = np.mgrid[:32, :32] / 31.0
    texture = np.round(np.stack([u, v, 1 - u, np.ones_like(u)], -1) * 255).astype(np.uint8)
    positions = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], np.float32)
    mesh = RenderMesh(positions, [[0, 1, 2], [0, 2, 3]], np.tile([0, 0, 1.0], (4, 1)),
                      np.ones((4, 4)), uvs=np.array([[0, 0], [1, 0], [1, 1], [0, 1.0]]),
                      materials=[Material(texture=texture)])
    compact = compress(mesh)
    assert encoding_of(compact.materials[0].texture).format == "bc7"
    camera = Camera(eye=(0, 0, 3), target=(0, 0, 0), size=(96, 96), ortho_height=1.0)
    got, expected = render(compact, camera), render(raw_twin(compact), camera)
    np.testing.assert_array_equal(got.mask, expected.mask)
    assert np.abs(got.color - expected.color).max() <= COLOR_TOLERANCE
    path = save(tmp_path / "m.rk", compact)
    assert member_data_bytes(path, "texture") == 32 * 32  # BC7: a byte a texel
    np.testing.assert_array_equal(render(load(path), camera).color, got.color)
