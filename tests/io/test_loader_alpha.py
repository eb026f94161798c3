"""Material alpha modes through loading and .rk files, and textures that cannot be read.

References are the files the tests write: the alphaMode / alphaCutoff / d / Tr each file
declares, and texture bytes made broken on purpose (a PNG signature followed by garbage, a
truncated image, a 100-megapixel size claim with almost no data).
"""

from __future__ import annotations

import struct
import zlib

import numpy as np
import pytest
import trimesh
from helpers import write_obj_quad
from PIL import Image

from reliefkit.errors import MeshError
from reliefkit.io import rk
from reliefkit.io.meshes import DEFAULT_COLOR, load_mesh
from reliefkit.scene.mesh import Material, RenderMesh

QUAD_UV = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
QUAD = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)


def quad_mesh(materials, material=None) -> RenderMesh:
    return RenderMesh(QUAD, [[0, 1, 2], [0, 2, 3]], np.tile([0, 0, 1.0], (4, 1)),
                      np.ones((4, 4)), QUAD_UV, materials=materials, material=material)


def test_material_alpha_defaults_and_validation():
    assert (Material().alpha_mode, Material().alpha_cutoff) == ("OPAQUE", 0.5)
    for mode in ("OPAQUE", "MASK", "BLEND"):
        assert Material(alpha_mode=mode).alpha_mode == mode
    for bad in ("mask", "", None, 3):
        with pytest.raises(MeshError, match="alpha_mode"):
            Material(alpha_mode=bad)
    for bad in (-0.1, 1.5, float("nan"), "x", None, True):
        with pytest.raises(MeshError, match="alpha_cutoff"):
            Material(alpha_cutoff=bad)
    assert Material(alpha_mode="MASK") != Material(alpha_mode="BLEND")
    assert Material(alpha_cutoff=0.25) != Material(alpha_cutoff=0.5)
    assert Material(alpha_mode="MASK", alpha_cutoff=0.25) == Material(alpha_mode="MASK",
                                                                      alpha_cutoff=0.25)


def gltf_quad(path, **alpha):
    material = trimesh.visual.material.PBRMaterial(
        name="q", baseColorTexture=Image.fromarray(np.full((2, 2, 4), 100, np.uint8), "RGBA"),
        **alpha)
    mesh = trimesh.Trimesh(QUAD, [[0, 1, 2], [0, 2, 3]], process=False,
                           visual=trimesh.visual.TextureVisuals(uv=QUAD_UV, material=material))
    trimesh.Scene([mesh]).export(str(path))
    return path


@pytest.mark.parametrize("suffix", [".glb", ".gltf"])
@pytest.mark.parametrize("alpha, expected", [
    ({}, ("OPAQUE", 0.5)),
    ({"alphaMode": "MASK"}, ("MASK", 0.5)),
    ({"alphaMode": "MASK", "alphaCutoff": 0.3}, ("MASK", 0.3)),
    ({"alphaMode": "BLEND"}, ("BLEND", 0.5)),
])
def test_gltf_alpha_mode_and_cutoff_reach_the_material(tmp_path, suffix, alpha, expected):
    (material,) = load_mesh(gltf_quad(tmp_path / f"q{suffix}", **alpha)).materials
    assert (material.alpha_mode, material.alpha_cutoff) == pytest.approx(expected)


def obj_quad(tmp_path, mtl: str, image: np.ndarray | None = None, image_bytes=None):
    if image is not None:
        Image.fromarray(image, "RGBA").save(tmp_path / "tex.png")
    if image_bytes is not None:
        (tmp_path / "tex.png").write_bytes(image_bytes)
    return write_obj_quad(tmp_path, mtl, "m", QUAD, QUAD_UV)


@pytest.mark.parametrize("lines, mode, alpha", [
    ("", "OPAQUE", 1.0), ("d 1.0", "OPAQUE", 1.0), ("d 0.5", "BLEND", 0.5),
    ("Tr 0.25", "BLEND", 0.75), ("d 0.4\nTr 0.9", "BLEND", 0.4), ("d 7", "OPAQUE", 1.0),
])
def test_obj_alpha_mode_from_d_and_tr(tmp_path, lines, mode, alpha):
    (material,) = load_mesh(obj_quad(tmp_path, f"newmtl m\nKd 1 0 0\n{lines}\n")).materials
    assert material.alpha_mode == mode
    assert material.color[3] == pytest.approx(alpha)


def test_obj_tr_1_as_meshlab_writes_it_is_opaque_with_a_warning(tmp_path):
    """MeshLab writes 'Tr 1.000000' for opaque materials (trimesh's fuze.obj): read literally
    the mesh would be invisible."""
    mesh = load_mesh(obj_quad(tmp_path, "newmtl m\nKd 1 0 0\nTr 1.000000\n"))
    (material,) = mesh.materials
    assert material.alpha_mode == "OPAQUE" and material.color[3] == 1.0
    (warning,) = mesh.extra["warnings"]
    assert "'m'" in warning and "Tr 1" in warning and "opaque" in warning


def test_obj_rgba_texture_alpha_is_dropped_when_only_d_is_given(tmp_path):
    image = np.full((2, 2, 4), 90, np.uint8)
    mtl = "newmtl m\nmap_Kd tex.png\nd 0.5\n"
    (material,) = load_mesh(obj_quad(tmp_path, mtl, image)).materials
    assert material.alpha_mode == "BLEND" and material.color[3] == pytest.approx(0.5)
    assert (material.texture[..., 3] == 255).all()
    np.testing.assert_array_equal(material.texture[..., :3], image[..., :3])


def test_obj_map_d_of_another_image_is_one_warning(tmp_path):
    mtl = "newmtl m\nmap_Kd tex.png\nmap_d other.png\n"
    mesh = load_mesh(obj_quad(tmp_path, mtl, np.full((2, 2, 4), 90, np.uint8)))
    (warning,) = mesh.extra["warnings"]
    assert "other.png" in warning and "'m'" in warning


def test_alpha_modes_round_trip_through_rk(tmp_path):
    materials = [Material("a"), Material("b", alpha_mode="MASK", alpha_cutoff=0.3),
                 Material("c", alpha_mode="BLEND")]
    mesh = quad_mesh(materials, [1, 2])
    path = rk.save(tmp_path / "m.rk", mesh)
    manifest = rk.read_manifest(path)
    assert manifest["params"]["alpha_modes"] == ["OPAQUE", "MASK", "BLEND"]
    assert "alpha_cutoffs" in manifest["arrays"]
    back = rk.load(path)
    assert [(m.alpha_mode, m.alpha_cutoff) for m in back.materials] == [
        (m.alpha_mode, m.alpha_cutoff) for m in materials]
    assert back.materials == mesh.materials


def test_default_alpha_leaves_the_rk_arrays_and_params_as_before(tmp_path):
    path = rk.save(tmp_path / "m.rk", quad_mesh([Material("a")]))
    manifest = rk.read_manifest(path)
    assert "alpha_modes" not in manifest["params"] and "alpha_cutoffs" not in manifest["arrays"]
    (material,) = rk.load(path).materials
    assert (material.alpha_mode, material.alpha_cutoff) == ("OPAQUE", 0.5)


def test_bad_alpha_params_in_rk_are_format_errors(tmp_path):
    from reliefkit.errors import FormatError
    from reliefkit.io.mesh_codec import _mesh_from_arrays, _mesh_to_arrays

    arrays, params = _mesh_to_arrays(quad_mesh([Material(alpha_mode="MASK")]))
    for bad in (["mask"], "MASK", ["MASK", "BLEND"], [1]):
        with pytest.raises(FormatError, match="alpha_modes"):
            _mesh_from_arrays(arrays, params | {"alpha_modes": bad})
    for bad in ([0.5, 0.5], [1.5]):
        with pytest.raises(FormatError, match="alpha_cutoffs"):
            _mesh_from_arrays(arrays | {"alpha_cutoffs": np.array(bad, np.float32)}, params)


@pytest.mark.parametrize("suffix", [".glb", ".gltf"])
@pytest.mark.parametrize("flag", [False, True])
def test_gltf_double_sided_reaches_the_material_and_survives_rk(tmp_path, suffix, flag):
    (material,) = load_mesh(gltf_quad(tmp_path / f"q{suffix}", doubleSided=flag)).materials
    assert material.double_sided is flag
    mesh = quad_mesh([Material("a"), Material("b", double_sided=flag)], [0, 1])
    path = rk.save(tmp_path / "m.rk", mesh)
    assert ("double_sided" in rk.read_manifest(path)["params"]) is flag
    assert [m.double_sided for m in rk.load(path).materials] == [False, flag]
    with pytest.raises(MeshError, match="double_sided"):
        Material(double_sided="yes")


# --- textures that cannot be read: the material colour and one warning, nothing on stderr


def _chunk(kind: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


def png_claiming(width: int, height: int, idat: bytes) -> bytes:
    """A PNG whose header claims width x height RGBA pixels, with the given image data."""
    header = struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + _chunk(b"IHDR", header) + _chunk(b"IDAT", idat)
            + _chunk(b"IEND", b""))


MTL_TEXTURED = "newmtl m\nKd 0.5 0.25 1\nmap_Kd tex.png\n"


def assert_colour_and_one_warning(mesh: RenderMesh, capfd, *words: str) -> None:
    (material,) = mesh.materials
    assert material.texture is None and not mesh.textured
    np.testing.assert_allclose(material.color[:3], [0.2140, 0.0508, 1.0], atol=1e-3)  # Kd
    (warning,) = mesh.extra["warnings"]
    assert "tex.png" in warning and "material colour" in warning
    for word in words:
        assert word in warning
    out, err = capfd.readouterr()
    assert out == "" and err == ""


def test_a_truncated_texture_keeps_the_colour_with_one_warning(tmp_path, capfd):
    data = png_claiming(2000, 2000, zlib.compress(bytes(5000))[:40])
    mesh = load_mesh(obj_quad(tmp_path, MTL_TEXTURED, image_bytes=data))
    assert_colour_and_one_warning(mesh, capfd, "truncated")


def test_a_100_megapixel_texture_keeps_the_colour_with_one_warning(tmp_path, capfd):
    # PIL's DecompressionBombWarning zone (above MAX_IMAGE_PIXELS, below twice that); the
    # pixels are never decoded
    data = png_claiming(10000, 10000, zlib.compress(bytes(100)))
    mesh = load_mesh(obj_quad(tmp_path, MTL_TEXTURED, image_bytes=data))
    assert_colour_and_one_warning(mesh, capfd, "10000x10000")


def test_the_pixel_limit_is_pils(tmp_path, capfd, monkeypatch):
    monkeypatch.setattr(Image, "MAX_IMAGE_PIXELS", 40)
    image = np.full((6, 6, 4), 200, np.uint8)  # 36 pixels: within the limit
    mesh = load_mesh(obj_quad(tmp_path, MTL_TEXTURED, image))
    assert mesh.textured and "warnings" not in mesh.extra
    image = np.full((8, 8, 4), 200, np.uint8)  # 64: over it, under twice it
    mesh = load_mesh(obj_quad(tmp_path, MTL_TEXTURED, image))
    assert_colour_and_one_warning(mesh, capfd, "8x8")


def test_a_broken_gltf_texture_keeps_the_factor_with_one_warning(tmp_path, capfd):
    path = gltf_quad(tmp_path / "q.glb")
    good = load_mesh(path)
    assert good.textured and "warnings" not in good.extra
    data = path.read_bytes()
    png = data.index(b"\x89PNG")
    idat = data.index(b"IDAT", png)
    broken = data[:idat + 4] + bytes(len(data) - idat - 4)  # the pixels and all after: zeros
    path.write_bytes(broken[:len(data)])
    mesh = load_mesh(path)
    (material,) = mesh.materials
    assert material.texture is None
    (warning,) = mesh.extra["warnings"]
    assert "'q'" in warning and "material colour" in warning
    out, err = capfd.readouterr()
    assert out == "" and err == ""


@pytest.mark.parametrize("data", [
    b"\x89PNG\r\n\x1a\n" + b"\x17garbage" * 40,  # a PNG signature followed by garbage
    png_claiming(20000, 20000, zlib.compress(bytes(5000))[:40]),  # over 2x PIL's limit
], ids=["garbage", "truncated-20000x20000"])
def test_textures_pil_cannot_open_keep_the_colour_with_one_warning(tmp_path, capfd, data):
    mesh = load_mesh(obj_quad(tmp_path, MTL_TEXTURED, image_bytes=data))
    assert_colour_and_one_warning(mesh, capfd)


def test_warnings_of_a_load_that_failed_do_not_reach_the_next(tmp_path):
    from reliefkit.io.meshes import materials

    materials.SurfaceReader(srgb=True).warnings.append("left by a failed load")
    materials.note_texture_problem("x.png", "could not be opened")
    materials.begin_warnings()
    mesh = load_mesh(obj_quad(tmp_path, "newmtl m\nKd 1 1 1\n"))
    assert "warnings" not in mesh.extra
    materials.SurfaceReader(srgb=True).warnings.append("left by a failed load")
    mesh = load_mesh(obj_quad(tmp_path, "newmtl m\nKd 1 1 1\n"))
    assert "warnings" not in mesh.extra  # every load's reader starts its own list


def test_no_warnings_key_for_a_clean_file(tmp_path):
    mesh = load_mesh(obj_quad(tmp_path, "newmtl m\nKd 1 1 1\n"))
    assert "warnings" not in mesh.extra
    assert mesh.materials[0].color[3] == 1.0 and DEFAULT_COLOR[3] == 1.0
