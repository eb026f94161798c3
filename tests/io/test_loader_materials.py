"""Every material of a file kept with its own texture; "textured" only where an image exists.

References are the files' own data: the images written next to them, the factors they
declare, the triangles each material was given.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
import trimesh
from PIL import Image

from reliefkit.io.inputs import describe
from reliefkit.io.meshes import DEFAULT_COLOR, load_mesh
from reliefkit.scene.mesh import Material, RenderMesh

QUAD_UV = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])


def checker(a, b) -> np.ndarray:
    """A 2x2 RGBA image (row 0 at the top, as PIL stores it) of two colours."""
    return np.array([[a, b], [b, a]], np.uint8)


IMAGES = {
    "bricks": checker((200, 40, 30, 255), (90, 20, 10, 255)),
    "grass": checker((30, 180, 40, 255), (10, 90, 20, 255)),
    "sky": checker((40, 60, 220, 255), (200, 210, 255, 255)),
}


def textured_quad(image: np.ndarray, x: float, name: str, factor=(255, 255, 255, 255)):
    material = trimesh.visual.material.PBRMaterial(
        name=name, baseColorTexture=Image.fromarray(image, "RGBA"), baseColorFactor=factor)
    vertices = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float) + [x, 0, 0]
    return trimesh.Trimesh(vertices, [[0, 1, 2], [0, 2, 3]], process=False,
                           visual=trimesh.visual.TextureVisuals(uv=QUAD_UV, material=material))


def material_of_quad(mesh_out: RenderMesh, x: float) -> Material:
    """The one material of the triangles whose centre lies in [x, x + 1]."""
    centre = mesh_out.positions[mesh_out.indices][:, :, 0].mean(axis=1)
    (index,) = set(mesh_out.material[(centre > x) & (centre < x + 1)].tolist())
    return mesh_out.materials[index]


@pytest.mark.parametrize("suffix", [".glb", ".gltf"])
def test_gltf_materials_keep_their_textures_and_factors(tmp_path, suffix):
    factors = {"bricks": (255, 255, 255, 255), "grass": (255, 128, 0, 255),
               "sky": (255, 255, 255, 255)}
    quads = [textured_quad(IMAGES[n], 2.0 * k, n, factors[n]) for k, n in enumerate(IMAGES)]
    path = tmp_path / f"three{suffix}"
    trimesh.Scene(quads).export(str(path))
    mesh_out = load_mesh(path)

    assert len(mesh_out.materials) == 3 and mesh_out.textured
    for k, name in enumerate(IMAGES):
        material = material_of_quad(mesh_out, 2.0 * k)
        assert material.name == name
        np.testing.assert_array_equal(material.texture, IMAGES[name][::-1])  # row 0 at v = 0
        np.testing.assert_allclose(material.color, np.array(factors[name]) / 255, atol=1e-6)
    np.testing.assert_array_equal(mesh_out.colors, 1.0)


def test_one_material_used_twice_is_kept_once(tmp_path):
    quads = [textured_quad(IMAGES["bricks"], 0.0, "bricks"),
             textured_quad(IMAGES["bricks"], 2.0, "bricks")]
    path = tmp_path / "same.glb"
    trimesh.Scene(quads).export(str(path))
    mesh_out = load_mesh(path)
    assert len(mesh_out.materials) == 1
    np.testing.assert_array_equal(mesh_out.texture, IMAGES["bricks"][::-1])


def write_obj_with_materials(folder, names) -> object:
    """Quads side by side, each with its own `usemtl` and `map_Kd` image."""
    mtl, obj = [], ["mtllib scene.mtl"]
    for k, name in enumerate(names):
        Image.fromarray(IMAGES[name], "RGBA").save(folder / f"{name}.png")
        mtl += [f"newmtl {name}", "Kd 1 1 1", f"map_Kd {name}.png"]
        x = 2.0 * k
        obj += [f"v {x} 0 0", f"v {x + 1} 0 0", f"v {x + 1} 1 0", f"v {x} 1 0"]
        obj += ["vt 0 0", "vt 1 0", "vt 1 1", "vt 0 1"]
        first = 4 * k + 1
        corners = [f"{first + i}/{first + i}" for i in range(4)]
        obj += [f"usemtl {name}", "f " + " ".join(corners)]
    (folder / "scene.mtl").write_text("\n".join(mtl) + "\n")
    path = folder / "scene.obj"
    path.write_text("\n".join(obj) + "\n")
    return path


def test_obj_with_several_map_kd_keeps_every_texture(tmp_path):
    mesh_out = load_mesh(write_obj_with_materials(tmp_path, list(IMAGES)))
    assert len(mesh_out.materials) == 3
    for k, name in enumerate(IMAGES):
        material = material_of_quad(mesh_out, 2.0 * k)
        assert material.name == name
        np.testing.assert_array_equal(material.texture, IMAGES[name][::-1])


def test_obj_uvs_without_any_material_are_not_textured(tmp_path):
    path = tmp_path / "uv_only.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n")
    mesh_out = load_mesh(path)
    assert not mesh_out.textured and mesh_out.texture is None
    np.testing.assert_allclose(mesh_out.materials[0].color * mesh_out.colors[0], DEFAULT_COLOR)
    assert describe(mesh_out)["textured"] is False


def test_gltf_uvs_without_an_image_are_not_textured(tmp_path):
    material = trimesh.visual.material.PBRMaterial(baseColorFactor=[255, 0, 0, 255])
    shape = trimesh.Trimesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]], process=False,
                            visual=trimesh.visual.TextureVisuals(uv=QUAD_UV[:3],
                                                                 material=material))
    path = tmp_path / "uv_only.glb"
    shape.export(str(path))
    mesh_out = load_mesh(path)
    assert not mesh_out.textured
    np.testing.assert_allclose(mesh_out.materials[0].color, [1, 0, 0, 1])


def test_describe_counts_materials_and_says_textured_only_with_an_image(tmp_path):
    mesh_out = load_mesh(write_obj_with_materials(tmp_path, ["bricks", "sky"]))
    summary = describe(mesh_out)
    assert summary["textured"] is True and summary["materials"] == 2


def gltf_uv_transform(offset=(0.0, 0.0), rotation=0.0, scale=(1.0, 1.0)) -> np.ndarray:
    """KHR_texture_transform on glTF UVs (v down): the specification's translation * rotation
    * scale, with the rotation [[cos, sin], [-sin, cos]] that three.js, Babylon.js and Blender
    use and under which Khronos' TextureTransformTest arrows point at their "Correct" markers
    (the GLSL listing of the specification has the other sign, KhronosGroup/glTF#1563)."""
    c, s = np.cos(rotation), np.sin(rotation)
    translate = np.array([[1, 0, offset[0]], [0, 1, offset[1]], [0, 0, 1.0]])
    rotate = np.array([[c, s, 0], [-s, c, 0], [0, 0, 1.0]])
    return translate @ rotate @ np.diag([scale[0], scale[1], 1.0])


# the transforms of Khronos' TextureTransformTest sample, by material, and one with an
# unequal scale (where the order of rotation and scale shows)
SAMPLE_TRANSFORMS = {
    "offset_u": {"offset": [0.5, 0.0]},
    "offset_v": {"offset": [0.0, 0.5]},
    "offset_uv": {"offset": [0.5, 0.5]},
    "rotation": {"rotation": 0.39269908169872414},
    "scale": {"scale": [1.5, 1.5]},
    "all": {"offset": [-0.2, -0.1], "rotation": 0.3, "scale": [1.5, 1.5]},
    "unequal_scale": {"offset": [0.25, 0.5], "rotation": 0.4, "scale": [0.5, 2.0]},
}


@pytest.mark.parametrize("case", SAMPLE_TRANSFORMS)
def test_gltf_texture_transform_is_kept_per_material(tmp_path, case):
    path = tmp_path / "transformed.gltf"
    quads = [textured_quad(IMAGES["bricks"], 0.0, "plain"),
             textured_quad(IMAGES["sky"], 2.0, "atlas")]
    trimesh.Scene(quads).export(str(path))
    tree = json.loads(path.read_text())
    params = SAMPLE_TRANSFORMS[case]
    (atlas,) = [m for m in tree["materials"] if m["name"] == "atlas"]
    atlas["pbrMetallicRoughness"]["baseColorTexture"]["extensions"] = {
        "KHR_texture_transform": params}
    tree["extensionsUsed"] = [*tree.get("extensionsUsed", []), "KHR_texture_transform"]
    path.write_text(json.dumps(tree))
    mesh_out = load_mesh(path)

    assert material_of_quad(mesh_out, 0.0).uv_transform is None
    ours = material_of_quad(mesh_out, 2.0).uv_transform.astype(np.float64)
    uv = np.random.default_rng(0).random((10, 2))
    gltf_uv = np.column_stack([uv[:, 0], 1 - uv[:, 1], np.ones(10)])  # glTF's v runs down
    moved = gltf_uv @ gltf_uv_transform(**params).T
    expected = np.column_stack([moved[:, 0], 1 - moved[:, 1]])
    got = (np.column_stack([uv, np.ones(10)]) @ ours.T)[:, :2]
    np.testing.assert_allclose(got, expected, atol=1e-6)


def test_gltf_texture_rotation_draws_the_texels_the_viewers_draw(gl, tmp_path):
    """A quarter turn (KHR_texture_transform rotation pi/2) on a 4x4 image of 16 colours,
    rendered from the front: at every pixel over a texel's centre, the colour of the texel
    the reference transform picks (the old sign picked the mirror-image texel)."""
    from reliefkit.render import render
    from reliefkit.scene.camera import Camera
    from reliefkit.scene.light import DirectionalLight

    image = np.zeros((4, 4, 4), np.uint8)  # PIL rows: row 0 at glTF's v = 0
    image[..., 0] = np.arange(16).reshape(4, 4) * 16
    image[..., 1] = 255 - np.arange(16).reshape(4, 4) * 16
    image[..., 2], image[..., 3] = 128, 255
    quad = textured_quad(image, -1.0, "turned")
    quad.vertices = quad.vertices * [2, 2, 1] - [-1, 1, 0]  # x, y in [-1, 1]
    path = tmp_path / "turned.gltf"
    quad.export(str(path))
    tree = json.loads(path.read_text())
    tree["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"] = {
        "KHR_texture_transform": {"rotation": np.pi / 2}}
    tree["extensionsUsed"] = [*tree.get("extensionsUsed", []), "KHR_texture_transform"]
    path.write_text(json.dumps(tree))

    frame = render(load_mesh(path), Camera(eye=(0, 0, 3), target=(0, 0, 0), size=(20, 20),
                                           ortho_height=1.0),
                   light=DirectionalLight(intensity=0.0, ambient=1.0, specular=0.0))
    centres = np.arange(2, 20, 5)  # 5 pixels per texel: these pixels sit on texel centres
    rows, cols = np.meshgrid(centres, centres, indexing="ij")
    u, v_up = (cols + 0.5) / 20, 1 - (rows + 0.5) / 20  # the quad's UVs (v up) there
    gltf = np.stack([u.ravel(), 1 - v_up.ravel(), np.ones(u.size)])  # glTF's v runs down
    moved = (gltf_uv_transform(rotation=np.pi / 2) @ gltf)[:2] % 1.0  # the sampler repeats
    texel = image[(moved[1] * 4).astype(int), (moved[0] * 4).astype(int), :3] / 255.0
    expected = np.where(texel <= 0.04045, texel / 12.92, ((texel + 0.055) / 1.055) ** 2.4)
    np.testing.assert_allclose(frame.color[rows.ravel(), cols.ravel(), :3], expected,
                               atol=2e-3)
