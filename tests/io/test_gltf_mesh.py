"""Tests of the RenderMesh -> core glTF writer (reliefkit.io.gltf.mesh), against readers that
are not the writer's: pygltflib and PIL read the file, the Khronos validator checks it, and
reliefkit's mesh loader (trimesh underneath) reads it back to be drawn beside the original."""

from __future__ import annotations

import io

import numpy as np
import pygltflib
import pytest
from gltf_validator import problems, validate
from mesh_scenes import asymmetric_texture, sampler_mesh
from PIL import Image

from reliefkit.errors import FormatError
from reliefkit.io.gltf.glb import GlbBuilder
from reliefkit.io.gltf.mesh import add_render_mesh
from reliefkit.io.meshes import load_mesh
from reliefkit.render import render
from reliefkit.scene.camera import Camera
from reliefkit.scene.mesh import Material, RenderMesh

VIEWS = [(30.0, 20.0), (150.0, -10.0), (270.0, 60.0)]
REPEAT, LINEAR, LINEAR_MIPMAP_LINEAR = 10497, 9729, 9987

def write(path, mesh: RenderMesh, **kw) -> pygltflib.GLTF2:
    builder = GlbBuilder()
    builder.document["asset"]["generator"] = "reliefkit test"
    builder.document.update(nodes=[add_render_mesh(builder, mesh, name=mesh.name, **kw)],
                            scenes=[{"nodes": [0]}], scene=0)
    path.write_bytes(builder.glb())
    return pygltflib.GLTF2().load_binary(str(path))


def accessor(gltf: pygltflib.GLTF2, index: int) -> np.ndarray:
    """An accessor's values read through pygltflib's objects (strides honoured)."""
    acc = gltf.accessors[index]
    view = gltf.bufferViews[acc.bufferView]
    dtype = {pygltflib.FLOAT: "<f4", pygltflib.UNSIGNED_SHORT: "<u2",
             pygltflib.UNSIGNED_INT: "<u4"}[acc.componentType]
    width = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}[acc.type]
    itemsize = np.dtype(dtype).itemsize
    stride = view.byteStride or itemsize * width
    start = view.byteOffset + (acc.byteOffset or 0)
    rows = np.ndarray((acc.count, width), dtype, buffer=gltf.binary_blob(), offset=start,
                      strides=(stride, itemsize))
    return rows[:, 0].copy() if width == 1 else rows.copy()


def image(gltf: pygltflib.GLTF2, texture_index: int) -> np.ndarray:
    """A texture's image as PIL decodes it: (h, w, 4) uint8, row 0 the image's top."""
    view = gltf.bufferViews[gltf.images[gltf.textures[texture_index].source].bufferView]
    data = gltf.binary_blob()[view.byteOffset:view.byteOffset + view.byteLength]
    return np.asarray(Image.open(io.BytesIO(data)).convert("RGBA"))


def primitives_by_material(gltf: pygltflib.GLTF2) -> dict[str, pygltflib.Primitive]:
    (mesh,) = gltf.meshes
    return {gltf.materials[p.material].name: p for p in mesh.primitives}


# ----------------------------------------------------------- (a) an independent reader


@pytest.mark.parametrize("offset", [0.0, 1e6])
def test_pygltflib_reads_the_mesh_its_materials_and_images(tmp_path, offset):
    mesh = sampler_mesh(offset)
    gltf = write(tmp_path / "m.glb", mesh)
    (node,) = gltf.nodes
    assert gltf.meshes[node.mesh].primitives and node.name == "sampler"
    if offset:  # far away: float32 positions about the node's float64 translation
        assert node.translation == mesh.origin.tolist() == [offset] * 3
    else:
        assert node.translation is None
    by_name = primitives_by_material(gltf)
    assert sorted(by_name) == ["cutout", "painted", "tinted", "turned"]  # "unused" is not
    for k, material in enumerate(mesh.materials[:4]):
        prim = by_name[material.name]
        corners = mesh.indices[mesh.material == k]  # in order
        index = accessor(gltf, prim.indices)
        assert gltf.accessors[prim.indices].componentType == pygltflib.UNSIGNED_SHORT
        got = accessor(gltf, prim.attributes.POSITION)
        assert np.array_equal(got[index].reshape(-1, 3, 3), mesh.positions[corners])
        pos = gltf.accessors[prim.attributes.POSITION]
        assert pos.min == got.min(axis=0).tolist() and pos.max == got.max(axis=0).tolist()
        normals = accessor(gltf, prim.attributes.NORMAL)[index].reshape(-1, 3, 3)
        np.testing.assert_allclose(normals, mesh.normals[corners], atol=1e-6)
        if material.texture is None:
            assert prim.attributes.TEXCOORD_0 is None
        has_colors = prim.attributes.COLOR_0 is not None
        assert has_colors == (material.name == "painted")
        if has_colors:
            colors = accessor(gltf, prim.attributes.COLOR_0)[index].reshape(-1, 3, 4)
            assert np.array_equal(colors, mesh.colors[corners])

    for material in mesh.materials[:4]:
        gl = gltf.materials[by_name[material.name].material]
        pbr = gl.pbrMetallicRoughness
        np.testing.assert_array_equal(np.float32(pbr.baseColorFactor), material.color)
        assert (pbr.metallicFactor, pbr.roughnessFactor) == (0.0, 1.0)
        assert (pbr.baseColorTexture is not None) == (material.texture is not None)
        assert gl.alphaMode == material.alpha_mode
        assert gl.doubleSided == material.double_sided
    cutout = gltf.materials[by_name["cutout"].material]
    assert cutout.alphaCutoff == pytest.approx(0.4)
    assert gltf.materials[by_name["turned"].material].alphaCutoff is None  # not MASK
    # one image for the two materials that share a texture, one sampler: trilinear, repeat
    assert len(gltf.images) == 2 and len(gltf.samplers) == 1
    (sampler,) = gltf.samplers
    assert (sampler.magFilter, sampler.minFilter) == (LINEAR, LINEAR_MIPMAP_LINEAR)
    assert (sampler.wrapS, sampler.wrapT) == (REPEAT, REPEAT)


def test_texture_lookups_land_on_the_same_texels_as_reliefkits(tmp_path):
    """At each triangle's centroid, the texel glTF's convention picks in the written image
    (u right, v down from the top row; TEXCOORD_0 as written) is the texel reliefkit's picks
    in the texture array (v up from row 0, through the material's uv transform)."""
    mesh = sampler_mesh()
    gltf = write(tmp_path / "m.glb", mesh)
    by_name = primitives_by_material(gltf)
    for k, material in enumerate(mesh.materials[:3]):
        prim = by_name[material.name]
        index = accessor(gltf, prim.indices).reshape(-1, 3)
        written = accessor(gltf, prim.attributes.TEXCOORD_0)[index].mean(axis=1)
        picture = image(gltf, gltf.materials[prim.material].pbrMetallicRoughness
                        .baseColorTexture.index)
        h, w = picture.shape[:2]
        got = picture[(written[:, 1] * h).astype(int) % h, (written[:, 0] * w).astype(int) % w]
        uv = mesh.uvs[mesh.indices[mesh.material == k]].mean(axis=1).astype(np.float64)
        if material.uv_transform is not None:
            uv = np.c_[uv, np.ones(len(uv))] @ material.uv_transform.T.astype(np.float64)
        tex = material.texture
        expected = tex[(uv[:, 1] * h).astype(int) % h, (uv[:, 0] * w).astype(int) % w]
        np.testing.assert_array_equal(got[:, :3], expected[:, :3], err_msg=material.name)


# ------------------------------------------------------------------- (b) the validator


@pytest.mark.parametrize("offset", [0.0, 1e6])
def test_the_khronos_validator_finds_nothing_wrong(tmp_path, offset):
    path = tmp_path / "m.glb"
    write(path, sampler_mesh(offset))
    report = validate(path)
    assert problems(report) == []
    assert report["issues"]["numErrors"] == report["issues"]["numWarnings"] == 0


# ---------------------------------------------------- (c) reliefkit's loader reads it back


def cameras(mesh: RenderMesh) -> list[Camera]:
    return [Camera.orbit(mesh.center, az, el, 3.2 * mesh.radius, size=(128, 128))
            for az, el in VIEWS]


@pytest.mark.parametrize("offset", [0.0, 1e6])
def test_the_reread_mesh_draws_as_the_original(gl, tmp_path, offset):
    mesh = sampler_mesh(offset)
    write(tmp_path / "m.glb", mesh)
    back = load_mesh(tmp_path / "m.glb")
    assert sorted(m.name for m in back.materials) == ["cutout", "painted", "tinted", "turned"]
    cutout = next(m for m in back.materials if m.name == "cutout")
    assert (cutout.alpha_mode, cutout.double_sided) == ("MASK", True)
    for camera in cameras(mesh):
        want, got = render(mesh, camera), render(back, camera)
        union = want.mask | got.mask
        iou = (want.mask & got.mask).sum() / union.sum()
        assert want.mask.sum() > 2000 and iou > 0.999
        both = want.mask & got.mask
        diff = np.abs(want.rgba8().astype(int) - got.rgba8().astype(int))[both]
        assert diff.max() <= 2


# ---------------------------------------------------------------- (d) dilated cut-outs


def speckled_texture() -> np.ndarray:
    """24 x 20 random colours, about half the texels fully transparent, some half so."""
    rng = np.random.default_rng(7)
    rgba = rng.integers(0, 256, (24, 20, 4), dtype=np.uint8)
    rgba[..., 3] = rng.choice([0, 0, 128, 255], size=(24, 20)).astype(np.uint8)
    return rgba


def quads(*materials: Material) -> RenderMesh:
    """One textured quad per material, side by side."""
    positions, faces = [], []
    for k in range(len(materials)):
        base = len(positions)
        positions += [(k, 0, 0), (k + 1, 0, 0), (k + 1, 1, 0), (k, 1, 0)]
        faces += [(base, base + 1, base + 2), (base, base + 2, base + 3)]
    uvs = np.tile([(0, 0), (1, 0), (1, 1), (0, 1)], (len(materials), 1))
    normals = np.tile([0.0, 0.0, 1.0], (len(positions), 1))
    return RenderMesh(positions, faces, normals, np.ones((len(positions), 4)), uvs,
                      materials=materials, material=np.repeat(np.arange(len(materials)), 2))


@pytest.mark.parametrize("mode", ["MASK", "BLEND"])
def test_cutout_textures_are_dilated_into_their_transparent_texels_only(tmp_path, mode):
    texture = speckled_texture()
    mesh = quads(Material("seen", texture=texture, alpha_mode=mode),
                 Material("opaque", texture=texture))
    gltf = write(tmp_path / "m.glb", mesh)
    by_name = primitives_by_material(gltf)

    def written(name):
        texture_index = gltf.materials[by_name[name].material].pbrMetallicRoughness \
            .baseColorTexture.index
        return image(gltf, texture_index)[::-1]  # back to row 0 at v = 0

    assert np.array_equal(written("opaque"), texture)  # alpha unused: nothing to dilate
    got = written("seen")
    alpha = texture[..., 3]
    assert np.array_equal(got[..., 3], alpha)
    assert np.array_equal(got[alpha > 0], texture[alpha > 0])
    # each transparent texel's colour is that of a nearest texel with some alpha
    seen = np.argwhere(alpha > 0)
    for row, col in np.argwhere(alpha == 0):
        distance = ((seen - (row, col)) ** 2).sum(axis=1)
        nearest = seen[distance == distance.min()]
        assert any(np.array_equal(got[row, col, :3], texture[r, c, :3]) for r, c in nearest)
    assert not np.array_equal(got, texture)  # it did change some
    assert problems(validate(tmp_path / "m.glb")) == []


# --------------------------------------------------------------- sharing, sizes, options


def test_a_second_mesh_in_the_same_file_reuses_images_materials_and_the_sampler(tmp_path):
    mesh = sampler_mesh()
    builder = GlbBuilder()
    nodes = [add_render_mesh(builder, mesh, name=name) for name in ("a", "b")]
    document = builder.document
    assert [n["mesh"] for n in nodes] == [0, 1]
    assert len(document["images"]) == 2 and len(document["samplers"]) == 1
    assert len(document["textures"]) == 2 and len(document["materials"]) == 4
    assert [p["material"] for p in document["meshes"][0]["primitives"]] == \
        [p["material"] for p in document["meshes"][1]["primitives"]]


def test_two_writes_of_a_mesh_are_byte_identical(tmp_path):
    write(tmp_path / "a.glb", sampler_mesh(1e6))
    write(tmp_path / "b.glb", sampler_mesh(1e6))
    assert (tmp_path / "a.glb").read_bytes() == (tmp_path / "b.glb").read_bytes()


def test_indices_are_uint32_where_a_primitive_has_more_vertices_than_uint16_reaches(tmp_path):
    count = 70_000  # a fan of thin triangles: 65535 would be the forbidden restart index
    angle = np.linspace(0, np.pi, count - 1)
    positions = np.r_[[[0.0, 0.0, 0.0]], np.c_[np.cos(angle), np.sin(angle), np.zeros_like(angle)]]
    faces = np.c_[np.zeros(count - 2, int), np.arange(1, count - 1), np.arange(2, count)]
    normals = np.tile([0.0, 0.0, 1.0], (count, 1))
    mesh = RenderMesh(positions, faces, normals, np.ones((count, 4)), name="fan")
    gltf = write(tmp_path / "fan.glb", mesh)
    (prim,) = gltf.meshes[0].primitives
    assert gltf.accessors[prim.indices].componentType == pygltflib.UNSIGNED_INT
    assert np.array_equal(accessor(gltf, prim.indices).reshape(-1, 3), faces)
    assert prim.attributes.COLOR_0 is None  # all white: left out
    assert problems(validate(tmp_path / "fan.glb")) == []


def test_normals_are_written_at_unit_length(tmp_path):
    """glTF requires unit normals; a mesh's may have drifted (or be zero, where a vertex
    lies on no triangle with area): rescaled, and +y for no direction."""
    mesh = quads(Material("a"))
    drifted = RenderMesh(mesh.positions, mesh.indices, [(0, 0, 3.0), (0, 0, 0.5), (0, 0, 0),
                                                        (0.0, 0.0, 1.0001)], mesh.colors)
    gltf = write(tmp_path / "u.glb", drifted)
    (prim,) = gltf.meshes[0].primitives
    np.testing.assert_allclose(accessor(gltf, prim.attributes.NORMAL),
                               [(0, 0, 1), (0, 0, 1), (0, 1, 0), (0, 0, 1)], atol=1e-7)
    assert problems(validate(tmp_path / "u.glb")) == []


def test_normal_textures_become_normal_texture_references(tmp_path):
    flat = np.zeros((4, 4, 3), np.uint8)
    flat[..., :2], flat[..., 2] = 128, 255
    flat[0, 0] = (200, 90, 230)  # an asymmetric texel: its place checks the image's rows
    mesh = quads(Material("bumpy", texture=asymmetric_texture()), Material("plain"))
    gltf = write(tmp_path / "n.glb", mesh, normal_textures={1: flat})
    by_name = primitives_by_material(gltf)
    plain = gltf.materials[by_name["plain"].material]
    assert plain.pbrMetallicRoughness.baseColorTexture is None
    assert by_name["plain"].attributes.TEXCOORD_0 is not None  # the normal map needs uvs
    assert np.array_equal(image(gltf, plain.normalTexture.index)[::-1, :, :3], flat)
    assert gltf.materials[by_name["bumpy"].material].normalTexture is None
    assert by_name["bumpy"].attributes.TANGENT is None
    assert problems(validate(tmp_path / "n.glb")) == []


def test_tangents_point_along_u_and_their_sign_along_v(tmp_path):
    """Quads facing +z: u along +x on the first and along -x on the second (mirrored), v
    along +y on both, so glTF's bitangent cross(normal, tangent) * w must point along +v (up
    in the written image, the normal map's +y) on both; the third's uvs span nothing, and
    its tangents are still unit vectors in its plane."""
    square = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)]
    positions = np.array([(x + 2 * k, y, z) for k in range(3) for x, y, z in square], float)
    uvs = [(0, 0), (1, 0), (1, 1), (0, 1), (1, 0), (0, 0), (0, 1), (1, 1)] + [(0.5, 0.5)] * 4
    faces = [(0, 1, 2), (0, 2, 3), (4, 5, 6), (4, 6, 7), (8, 9, 10), (8, 10, 11)]
    normals = np.tile([0.0, 0.0, 1.0], (12, 1))
    mesh = RenderMesh(positions, faces, normals, np.ones((12, 4)), uvs,
                      materials=(Material("a"), Material("b"), Material("c")),
                      material=[0, 0, 1, 1, 2, 2])
    bump = np.full((2, 2, 3), 128, np.uint8)
    gltf = write(tmp_path / "t.glb", mesh, normal_textures={0: bump, 1: bump, 2: bump})
    by_name = primitives_by_material(gltf)
    for name, tangent in (("a", [1, 0, 0, 1]), ("b", [-1, 0, 0, -1])):
        got = accessor(gltf, by_name[name].attributes.TANGENT)
        np.testing.assert_allclose(got, np.tile(tangent, (4, 1)), atol=1e-6, err_msg=name)
    spanless = accessor(gltf, by_name["c"].attributes.TANGENT)
    np.testing.assert_allclose(np.linalg.norm(spanless[:, :3], axis=1), 1.0, atol=1e-6)
    assert np.allclose(spanless[:, 2], 0.0) and set(spanless[:, 3]) <= {-1.0, 1.0}
    assert problems(validate(tmp_path / "t.glb")) == []


def test_normal_textures_for_missing_materials_are_refused():
    mesh = quads(Material("only", texture=asymmetric_texture()))
    with pytest.raises(FormatError, match="material 3"):
        add_render_mesh(GlbBuilder(), mesh, name="q",
                        normal_textures={3: np.zeros((2, 2, 3), np.uint8)})
