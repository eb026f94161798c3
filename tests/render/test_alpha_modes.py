"""Alpha as the file's material says: glTF alphaMode / alphaCutoff, OBJ d / Tr / map_d.

The references are the test's own data: the alpha bytes written into each texture, the
cutoff and the d value written into each file. A quad of side 2 faces an orthographic camera;
its left half has texture alpha LOW, its right half HIGH, and only pixels well inside each
half are compared (linear filtering blends the texels at the seam and, as the texture repeats,
at the outer edges).
"""

from __future__ import annotations

import json
import struct

import numpy as np
import pytest
import trimesh
from helpers import write_obj_quad
from PIL import Image

from reliefkit.io.meshes import load_mesh
from reliefkit.render import render
from reliefkit.scene.camera import Camera

LOW, HIGH = 26, 204  # texture alpha bytes of the left and right half
CAMERA = Camera(eye=(0, 0, 4), target=(0, 0, 0), size=(48, 48), near=1.0, far=10.0,
                ortho_height=2.5)
QUAD_POSITIONS = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], float)
QUAD_UV = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])


def half_alpha_image() -> np.ndarray:
    """8x8 RGBA: a mid grey whose alpha is LOW in columns 0-3 (u < 0.5) and HIGH in 4-7."""
    image = np.full((8, 8, 4), 180, np.uint8)
    image[:, :4, 3], image[:, 4:, 3] = LOW, HIGH
    return image


def halves() -> tuple[np.ndarray, np.ndarray]:
    """Pixel masks well inside the left and the right half of the quad."""
    origins, dirs = CAMERA.pixel_rays()
    hits = origins + ((0 - origins[..., 2]) / dirs[..., 2])[..., None] * dirs
    x, y = hits[..., 0], hits[..., 1]
    inner = (np.abs(y) < 0.8) & (np.abs(x) > 0.35) & (np.abs(x) < 0.8)  # the texture repeats
    return inner & (x < 0), inner & (x > 0)


def glb_quad(tmp_path, material_fields: dict):
    """A GLB quad with the half-alpha texture, its material JSON extended by the given fields.

    trimesh writes the file; the material's fields are set in its JSON chunk, so the file says
    exactly what a glTF writer would (no alphaMode at all for the default).
    """
    material = trimesh.visual.material.PBRMaterial(
        name="quad", baseColorTexture=Image.fromarray(half_alpha_image()[::-1], "RGBA"))
    mesh = trimesh.Trimesh(QUAD_POSITIONS, [[0, 1, 2], [0, 2, 3]], process=False,
                           visual=trimesh.visual.TextureVisuals(uv=QUAD_UV, material=material))
    data = trimesh.Scene([mesh]).export(file_type="glb")
    length = struct.unpack("<I", data[12:16])[0]
    tree = json.loads(data[20:20 + length])
    (gltf_material,) = tree["materials"]
    for key in ("alphaMode", "alphaCutoff"):
        gltf_material.pop(key, None)
    gltf_material.update(material_fields)
    text = json.dumps(tree).encode()
    text += b" " * (-len(text) % 4)
    rest = data[20 + length:]
    out = struct.pack("<4sII", b"glTF", 2, 12 + 8 + len(text) + len(rest))
    out += struct.pack("<I4s", len(text), b"JSON") + text + rest
    path = tmp_path / "quad.glb"
    path.write_bytes(out)
    return path


def test_gltf_default_alpha_mode_is_opaque(gl, tmp_path):
    frame = render(load_mesh(glb_quad(tmp_path, {})), CAMERA)
    left, right = halves()
    assert left.sum() > 50 and right.sum() > 50
    assert frame.mask[left | right].all()
    np.testing.assert_allclose(frame.color[left | right][:, 3], 1.0)


def test_gltf_opaque_ignores_the_factor_alpha_too(gl, tmp_path):
    path = glb_quad(tmp_path, {"alphaMode": "OPAQUE",
                               "pbrMetallicRoughness": {"baseColorTexture": {"index": 0},
                                                        "baseColorFactor": [1, 1, 1, 0.2]}})
    frame = render(load_mesh(path), CAMERA)
    left, right = halves()
    np.testing.assert_allclose(frame.color[left | right][:, 3], 1.0)


@pytest.mark.parametrize("fields, cutoff", [({"alphaMode": "MASK"}, 0.5),
                                            ({"alphaMode": "MASK", "alphaCutoff": 0.05}, 0.05),
                                            ({"alphaMode": "MASK", "alphaCutoff": 0.9}, 0.9)])
def test_gltf_mask_discards_below_the_cutoff_and_is_opaque_elsewhere(gl, tmp_path, fields,
                                                                     cutoff):
    frame = render(load_mesh(glb_quad(tmp_path, fields)), CAMERA)
    for half, alpha in zip(halves(), (LOW, HIGH), strict=True):
        if alpha / 255 < cutoff:
            assert not frame.mask[half].any()
            np.testing.assert_allclose(frame.color[half][:, 3], 0.0)
            assert (frame.depth[half] == 1.0).all()
        else:
            assert frame.mask[half].all()
            np.testing.assert_allclose(frame.color[half][:, 3], 1.0)


def test_gltf_blend_keeps_the_texture_alpha(gl, tmp_path):
    frame = render(load_mesh(glb_quad(tmp_path, {"alphaMode": "BLEND"})), CAMERA)
    for half, alpha in zip(halves(), (LOW, HIGH), strict=True):
        np.testing.assert_allclose(frame.color[half][:, 3], alpha / 255, atol=1.5 / 255)


def obj_quad(tmp_path, mtl_lines: list[str], alpha: int = LOW):
    """An OBJ quad whose map_Kd is a uniform RGBA image with the given alpha byte."""
    Image.fromarray(np.full((4, 4, 4), (200, 120, 60, alpha), np.uint8), "RGBA").save(
        tmp_path / "rgba.png")
    mtl = "\n".join(["newmtl paint", "Kd 1 1 1", "map_Kd rgba.png", *mtl_lines]) + "\n"
    return write_obj_quad(tmp_path, mtl, "paint", QUAD_POSITIONS, QUAD_UV, name="quad")


@pytest.mark.parametrize("lines, expected", [
    ([], 1.0),  # the RGBA texture's alpha channel is unused without d/Tr/map_d
    (["d 1"], 1.0),
    (["d 0.5"], 0.5),  # alpha from d alone, not d times the texture's
    (["Tr 0.25"], 0.75),
    (["d 0.5", "map_d rgba.png"], 0.5 * LOW / 255),  # map_d: the texture's alpha channel
    (["map_d rgba.png"], LOW / 255),
])
def test_obj_alpha_comes_from_d_tr_and_map_d_only(gl, tmp_path, lines, expected):
    frame = render(load_mesh(obj_quad(tmp_path, lines)), CAMERA)
    left, right = halves()
    assert frame.mask[left | right].all()
    np.testing.assert_allclose(frame.color[left | right][:, 3], expected, atol=1.5 / 255)


def test_mask_draws_the_same_pixels_instrumented(gl, tmp_path):
    mesh = load_mesh(glb_quad(tmp_path, {"alphaMode": "MASK"}))
    plain = render(mesh, CAMERA)
    counted = render(mesh, CAMERA, count_iterations=True)
    np.testing.assert_array_equal(plain.mask, counted.mask)
    assert plain.mask.any() and not plain.mask.all()


def test_a_fully_transparent_blend_material_covers_nothing(gl, tmp_path):
    """d 0 draws nothing, so no pixel claims coverage, a point or a normal (the CLI's count
    of covered pixels would otherwise report an invisible mesh as drawn)."""
    frame = render(load_mesh(obj_quad(tmp_path, ["d 0"])), CAMERA)
    assert not frame.mask.any() and np.isnan(frame.position).all()
    np.testing.assert_array_equal(frame.color[..., 3], 0.0)
