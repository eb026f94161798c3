"""Ground-truth rasterizer against analytic scenes: a quad and a sphere at known places."""

import numpy as np
import pytest
import trimesh

from reliefkit.render import render
from reliefkit.scene.camera import Camera
from reliefkit.scene.mesh import RenderMesh, vertex_normals


def _mesh(positions, faces, color=(0.8, 0.4, 0.2, 1.0), normals=None):
    positions = np.asarray(positions, np.float32)
    faces = np.asarray(faces)
    normals = vertex_normals(positions, faces) if normals is None else normals
    return RenderMesh(positions, faces, normals, np.tile(color, (len(positions), 1)))


QUAD = _mesh([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], [[0, 1, 2], [0, 2, 3]])


def _window_depth(camera, points):
    clip = np.concatenate([points, np.ones(points.shape[:-1] + (1,))], axis=-1) @ (
        camera.proj @ camera.view).T
    return 0.5 * clip[..., 2] / clip[..., 3] + 0.5


def _plane_hits(camera, z=0.0):
    origins, dirs = camera.pixel_rays()
    t = (z - origins[..., 2]) / dirs[..., 2]
    return origins + t[..., None] * dirs


@pytest.mark.parametrize("camera", [
    Camera.orbit((0, 0, 0), 25, 30, 5.0, size=(48, 40)),
    Camera(eye=(0.3, 0.2, 4.0), target=(0, 0, 0), size=(40, 40), near=1.0, far=10.0,
           ortho_height=1.5),
])
def test_quad_position_and_depth_match_ray_plane_intersection(gl, camera):
    frame = render(QUAD, camera)
    hits = _plane_hits(camera)
    inside = (np.abs(hits[..., 0]) < 0.98) & (np.abs(hits[..., 1]) < 0.98)
    outside = (np.abs(hits[..., 0]) > 1.02) | (np.abs(hits[..., 1]) > 1.02)
    assert inside.sum() > 200
    assert frame.mask[inside].all() and not frame.mask[outside].any()
    scene_size = 2.0 * np.sqrt(2.0)
    err = np.linalg.norm(frame.position[inside] - hits[inside], axis=-1)
    assert err.max() < 1e-4 * scene_size
    depth_err = np.abs(frame.depth[inside] - _window_depth(camera, hits[inside]))
    assert depth_err.max() < 1e-5
    assert np.isnan(frame.position[~frame.mask]).all()
    np.testing.assert_allclose(frame.normal[inside], np.tile([0, 0, 1.0], (inside.sum(), 1)),
                               atol=1e-5)
    np.testing.assert_allclose(frame.color[inside][:, 3], 1.0)


def test_top_row_is_row_zero(gl):
    # the quad lies above the camera's axis, so only the upper rows of the image see it
    upper = _mesh([[-1, 0.1, 0], [1, 0.1, 0], [1, 2, 0], [-1, 2, 0]], [[0, 1, 2], [0, 2, 3]])
    frame = render(upper, Camera(eye=(0, 0, 3), target=(0, 0, 0), size=(16, 16)))
    assert frame.mask[:7].any(axis=1).all()
    assert not frame.mask[9:].any()


def test_sphere_positions_lie_on_sphere_and_on_pixel_rays(gl):
    sphere = trimesh.creation.icosphere(subdivisions=6, radius=1.0)
    center = np.array([0.3, -0.2, 0.1])
    mesh = _mesh(sphere.vertices + center, sphere.faces,
                 normals=np.asarray(sphere.vertex_normals, np.float32))
    camera = Camera.orbit(tuple(center), 40, 20, 4.0, size=(64, 64))
    frame = render(mesh, camera)
    origins, dirs = camera.pixel_rays()
    # analytic coverage: rays whose distance to the centre is clearly below / above the radius
    to_c = center - origins
    closest = np.linalg.norm(to_c - (to_c * dirs).sum(-1, keepdims=True) * dirs, axis=-1)
    assert frame.mask[closest < 0.97].all() and not frame.mask[closest > 1.03].any()
    m = frame.mask
    scene_size = 2.0
    radial = np.abs(np.linalg.norm(frame.position[m] - center, axis=-1) - 1.0)
    assert radial.max() < 1e-4 * scene_size  # polygonal sphere: sagitta ~5e-5
    rel = frame.position[m] - origins[m]
    off_ray = np.linalg.norm(rel - (rel * dirs[m]).sum(-1, keepdims=True) * dirs[m], axis=-1)
    assert off_ray.max() < 1e-4 * scene_size
    # analytic first hit of each ray with the exact sphere
    b = (to_c * dirs).sum(-1)
    t_hit = b - np.sqrt(np.maximum(b**2 - (to_c**2).sum(-1) + 1.0, 0.0))
    exact = origins + t_hit[..., None] * dirs
    core = closest < 0.97
    assert np.linalg.norm(frame.position[core] - exact[core], axis=-1).max() < 1e-3
    assert np.abs(frame.depth[core] - _window_depth(camera, exact[core])).max() < 1e-4
    normal_err = np.linalg.norm(frame.normal[core] - (exact[core] - center), axis=-1)
    assert normal_err.max() < 1e-2


def test_lambert_shading_follows_light(gl):
    from reliefkit.render import render as render_mesh
    from reliefkit.scene.light import DirectionalLight

    camera = Camera(eye=(0, 0, 3), target=(0, 0, 0), size=(16, 16))
    lit = render_mesh(QUAD, camera, light=DirectionalLight(direction=(0, 0, 1), specular=0.0))
    grazing = render_mesh(QUAD, camera, light=DirectionalLight(direction=(1, 0, 0.0001),
                                                               specular=0.0))
    c = lit.color[8, 8, :3]
    np.testing.assert_allclose(c, np.array([0.8, 0.4, 0.2]) * (0.25 + 0.85), rtol=1e-4)
    np.testing.assert_allclose(grazing.color[8, 8, :3], np.array([0.8, 0.4, 0.2]) * 0.25,
                               rtol=1e-3)


def test_frame_save_and_aovs(gl, tmp_path):
    frame = render(QUAD, Camera(eye=(0, 0, 3), target=(0, 0, 0), size=(20, 10)))
    frame.save(tmp_path / "q.png")
    frame.save_aovs(tmp_path / "q.npz")
    from PIL import Image

    img = np.asarray(Image.open(tmp_path / "q.png"))
    assert img.shape == (10, 20, 4)
    np.testing.assert_array_equal(img[..., 3] > 0, frame.mask)
    with np.load(tmp_path / "q.npz", allow_pickle=False) as data:
        assert set(data.files) == {"color", "mask", "depth", "position", "normal", "view",
                                   "proj", "viewport"}
        np.testing.assert_array_equal(data["mask"], frame.mask)
        np.testing.assert_array_equal(data["view"], frame.view)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["q.npz", "q.png"]  # no temp files


def test_textured_glb_renders_its_texture_the_right_way_up(gl, tmp_path):
    from PIL import Image

    from reliefkit.io.meshes import load_mesh

    # a 2x2 texture: red top-left, green top-right, blue bottom-left, white bottom-right
    image = Image.fromarray(np.array([[[255, 0, 0], [0, 255, 0]], [[0, 0, 255],
                                      [255, 255, 255]]], np.uint8))
    quad = trimesh.Trimesh(vertices=[[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]],
                           faces=[[0, 1, 2], [0, 2, 3]], process=False)
    quad.visual = trimesh.visual.TextureVisuals(
        uv=np.array([[0, 0], [1, 0], [1, 1], [0, 1.0]]),
        material=trimesh.visual.material.SimpleMaterial(image=image, diffuse=(255, 255, 255)))
    quad.export(tmp_path / "quad.glb")
    mesh = load_mesh(tmp_path / "quad.glb")
    from reliefkit.render import render as render_mesh
    from reliefkit.scene.light import DirectionalLight

    flat = DirectionalLight(intensity=0.0, ambient=1.0, specular=0.0)
    frame = render_mesh(mesh, Camera(eye=(0, 0, 3), target=(0, 0, 0), size=(32, 32),
                                     ortho_height=1.0), light=flat)
    rgb = frame.color[..., :3]  # linear
    # the image's top-left texel shows at the quad's top-left (uv (0.25, 0.75)), and so on;
    # pixels (8, 8) etc. sit on the texel centres, where bilinear filtering is exact
    np.testing.assert_allclose(rgb[7:9, 7:9].mean(axis=(0, 1)), [1, 0, 0], atol=0.1)
    np.testing.assert_allclose(rgb[7:9, 23:25].mean(axis=(0, 1)), [0, 1, 0], atol=0.1)
    np.testing.assert_allclose(rgb[23:25, 7:9].mean(axis=(0, 1)), [0, 0, 1], atol=0.1)
    np.testing.assert_allclose(rgb[23:25, 23:25].mean(axis=(0, 1)), [1, 1, 1], atol=0.1)


# --------------------------------------------------------------------------- materials

def _flat_light():
    """A light under which a pixel shows its base colour."""
    from reliefkit.scene.light import DirectionalLight

    return DirectionalLight(intensity=0.0, ambient=1.0, specular=0.0)


def _srgb_to_linear(byte):
    c = np.asarray(byte, float) / 255.0
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


# two 2x2 images, as PIL stores them (row 0 is the top), every texel different
IMAGE_A = np.array([[[230, 20, 20, 255], [20, 230, 20, 255]],
                    [[20, 20, 230, 255], [230, 230, 230, 255]]], np.uint8)
IMAGE_B = np.array([[[250, 200, 0, 255], [0, 200, 250, 255]],
                    [[120, 0, 120, 255], [40, 40, 40, 255]]], np.uint8)


def _two_textured_quads(tmp_path):
    """A GLB of two unit quads in z = 0, at x in [0, 1] (IMAGE_A) and [2, 3] (IMAGE_B)."""
    from PIL import Image

    quads = []
    for x, image in ((0.0, IMAGE_A), (2.0, IMAGE_B)):
        blocks = np.repeat(np.repeat(image, 4, axis=0), 4, axis=1)  # bilinear-proof blocks
        material = trimesh.visual.material.PBRMaterial(
            baseColorTexture=Image.fromarray(blocks, "RGBA"), baseColorFactor=[255] * 4)
        quads.append(trimesh.Trimesh(
            np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float) + [x, 0, 0],
            [[0, 1, 2], [0, 2, 3]], process=False,
            visual=trimesh.visual.TextureVisuals(
                uv=np.array([[0, 0], [1, 0], [1, 1], [0, 1.0]]), material=material)))
    path = tmp_path / "two_materials.glb"
    trimesh.Scene(quads).export(str(path))
    return path


def _assert_texels_shown(rgb, image, col0, top_row, step):
    """Each 4x4-texel block of a 2x2 `image` (32 pixels wide) at its centre in `rgb`.

    The quad's left edge is column `col0`; picture rows go down from `top_row` (step -1 for
    images with row 0 at v = 0). Inside a uniform block bilinear filtering is exact.
    """
    for r in range(2):
        for c in range(2):
            rows = top_row + step * (8 + 16 * r) + np.arange(-4, 4)
            cols = col0 + 8 + 16 * c + np.arange(-4, 4)
            got = rgb[np.ix_(rows, cols)].reshape(-1, 3)
            np.testing.assert_allclose(got, np.tile(_srgb_to_linear(image[r, c, :3]), (64, 1)),
                                       atol=3e-3, err_msg=f"texel ({r}, {c})")


def test_two_materials_render_each_its_own_texture(gl, tmp_path):
    from reliefkit.io.meshes import load_mesh

    mesh = load_mesh(_two_textured_quads(tmp_path))
    camera = Camera(eye=(1.5, 0.5, 3), target=(1.5, 0.5, 0), size=(96, 32), ortho_height=0.5)
    frame = render(mesh, camera, light=_flat_light())
    rgb = frame.color[..., :3]
    _assert_texels_shown(rgb, IMAGE_A, col0=0, top_row=0, step=1)
    _assert_texels_shown(rgb, IMAGE_B, col0=64, top_row=0, step=1)


def test_projected_bake_colour_shows_both_textures(gl, tmp_path):
    from reliefkit.bake.project import project_mesh
    from reliefkit.io.meshes import load_mesh

    mesh = load_mesh(_two_textured_quads(tmp_path))
    box_to_world = np.array([[3.0, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, -0.5], [0, 0, 0, 1]])
    projection = project_mesh(mesh, box_to_world, (96, 32))
    assert projection.mask[:, :32].all() and projection.mask[:, 64:].all()
    rgb = projection.color[..., :3]  # row 0 at v = 0: the picture's bottom row
    _assert_texels_shown(rgb, IMAGE_A, col0=0, top_row=31, step=-1)
    _assert_texels_shown(rgb, IMAGE_B, col0=64, top_row=31, step=-1)


def _unit_quad(**mesh_kwargs) -> RenderMesh:
    positions = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], np.float32)
    return RenderMesh(positions, [[0, 1, 2], [0, 2, 3]], np.tile([0, 0, 1.0], (4, 1)),
                      mesh_kwargs.pop("colors", np.ones((4, 4))),
                      uvs=np.array([[0, 0], [1, 0], [1, 1], [0, 1.0]]), **mesh_kwargs)


def test_material_colour_texture_and_vertex_colour_multiply(gl):
    from reliefkit.scene.mesh import Material

    white = np.full((2, 2, 4), 255, np.uint8)
    colors = np.tile([0.5, 1.0, 1.0, 1.0], (4, 1))
    mesh = _unit_quad(colors=colors,
                      materials=[Material(color=(1.0, 0.5, 0.25, 1.0), texture=white)])
    frame = render(mesh, Camera(eye=(0, 0, 3), target=(0, 0, 0), size=(16, 16),
                                ortho_height=1.0), light=_flat_light())
    np.testing.assert_allclose(frame.color[4:12, 4:12, :3].reshape(-1, 3),
                               np.tile([0.5, 0.5, 0.25], (64, 1)), atol=1e-3)


def test_uv_transform_moves_the_lookup(gl):
    from reliefkit.scene.mesh import Material

    texture = IMAGE_A[::-1].copy()  # row 0 at v = 0
    to_one_texel = [[0, 0, 0.75], [0, 0, 0.75], [0, 0, 1]]  # every uv -> (0.75, 0.75)
    mesh = _unit_quad(materials=[Material(texture=texture, uv_transform=to_one_texel)])
    frame = render(mesh, Camera(eye=(0, 0, 3), target=(0, 0, 0), size=(16, 16),
                                ortho_height=1.0), light=_flat_light())
    expected = _srgb_to_linear(IMAGE_A[0, 1, :3])  # the top-right texel
    np.testing.assert_allclose(frame.color[2:14, 2:14, :3].reshape(-1, 3),
                               np.tile(expected, (144, 1)), atol=3e-3)


def test_uvs_without_an_image_render_the_default_colour(gl, tmp_path):
    from reliefkit.io.meshes import DEFAULT_COLOR, load_mesh

    path = tmp_path / "uv_only.obj"
    path.write_text("v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                    "f 1/1 2/2 3/3 4/4\n")
    frame = render(load_mesh(path), Camera(eye=(0, 0, 3), target=(0, 0, 0), size=(16, 16),
                                           ortho_height=1.0), light=_flat_light())
    np.testing.assert_allclose(frame.color[4:12, 4:12, :3].reshape(-1, 3),
                               np.tile(DEFAULT_COLOR[:3], (64, 1)), atol=1e-3)


def test_rotated_textured_boxes_are_lit_from_the_front(gl, tmp_path):
    """Boxes under rotated glTF nodes: on every visible pixel the normal faces the camera."""
    from PIL import Image
    from scipy.spatial.transform import Rotation

    from reliefkit.io.meshes import load_mesh

    box = trimesh.creation.box(extents=(1.0, 1.5, 2.0))
    corners = box.vertices[box.faces].reshape(-1, 3)
    faces = np.arange(len(corners)).reshape(-1, 3)
    material = trimesh.visual.material.PBRMaterial(
        baseColorTexture=Image.fromarray(IMAGE_A, "RGBA"), baseColorFactor=[255] * 4)
    textured = trimesh.Trimesh(
        corners, faces, vertex_normals=np.repeat(box.face_normals, 3, axis=0), process=False,
        visual=trimesh.visual.TextureVisuals(uv=corners[:, :2] + 0.5, material=material))
    scene = trimesh.Scene()
    for k, rotvec in enumerate(([1.2, 0, 0], [0, 0.8, 0.5], [-0.4, 2.0, 1.1])):
        node = np.eye(4)
        node[:3, :3] = Rotation.from_rotvec(rotvec).as_matrix()
        node[:3, 3] = [3.0 * k, 0, 0]
        scene.add_geometry(textured, node_name=f"box{k}", geom_name="box", transform=node)
    path = tmp_path / "boxes.glb"
    scene.export(str(path))
    mesh = load_mesh(path)
    for azimuth, elevation in ((0, 20), (140, -35), (260, 60)):
        camera = Camera.orbit(tuple(mesh.center), azimuth, elevation, 9.0, size=(128, 64))
        frame = render(mesh, camera)
        m = frame.mask
        assert m.sum() > 400
        to_eye = np.asarray(camera.eye) - frame.position[m]
        facing = (frame.normal[m] * to_eye).sum(axis=1)
        assert (facing > 0).all(), f"{(facing <= 0).mean():.0%} of the pixels face away"


def _box_over_plane(half=0.25, height=0.75):
    """A cube of side 2 * ``half`` centred ``height`` above a 4 x 4 plane at y = 0."""
    cube = trimesh.creation.box(extents=(2 * half,) * 3)
    cube.apply_translation((0.0, height, 0.0))
    cube.unmerge_vertices()  # flat faces: a face turned from the light gets no diffuse light
    plane = [[-2, 0, -2], [2, 0, -2], [2, 0, 2], [-2, 0, 2]]
    positions = np.concatenate([cube.vertices, plane])
    faces = np.concatenate([cube.faces, np.array([[0, 2, 1], [0, 3, 2]]) + len(cube.vertices)])
    return _mesh(positions, faces, color=(0.8, 0.8, 0.8, 1.0))


def _ray_hits_box(origins, direction, lo, hi):
    """Whether rays from ``origins`` along ``direction`` hit the box [lo, hi] (slab test)."""
    with np.errstate(divide="ignore"):
        inv = 1.0 / np.asarray(direction, np.float64)
    t0, t1 = (lo - origins) * inv, (hi - origins) * inv
    near = np.minimum(t0, t1).max(axis=-1)
    far = np.maximum(t0, t1).min(axis=-1)
    return (far >= np.maximum(near, 0.0))


@pytest.mark.parametrize("light_angles", [(-60.0, 45.0), (120.0, 30.0)])
def test_mesh_shadows_fall_where_the_light_is_blocked(gl, light_angles):
    """A cube over a plane: plane points whose ray to the light hits the cube (on the CPU)
    are dark with --shadows and lit without; the rest keep their light. Points within
    0.03 of the shadow's edge (the shadow map's filter) are not judged."""
    from reliefkit.scene.light import DirectionalLight

    half, height, margin = 0.25, 0.75, 0.03
    mesh = _box_over_plane(half, height)
    light = DirectionalLight.from_angles(*light_angles)
    camera = Camera.orbit((0, 0, 0), 30, 60, 6.0, size=(96, 96))
    plain = render(mesh, camera, light=light)
    shaded = render(mesh, camera, light=light, shadows=True)
    np.testing.assert_array_equal(plain.mask, shaded.mask)
    on_plane = plain.mask & (np.abs(plain.position[..., 1]) < 1e-4)
    points = plain.position[on_plane]
    centre = np.array([0.0, height, 0.0])
    towards = light.unit_direction
    inside = _ray_hits_box(points, towards, centre - half + margin, centre + half - margin)
    outside = ~_ray_hits_box(points, towards, centre - half - margin, centre + half + margin)
    assert inside.sum() > 30 and outside.sum() > 1000
    ratio = shaded.color[on_plane][:, :3].mean(-1) / plain.color[on_plane][:, :3].mean(-1)
    assert (ratio[inside] < 0.6).all(), ratio[inside].max()
    np.testing.assert_allclose(ratio[outside], 1.0, atol=1e-3)
    cube = plain.mask & (plain.position[..., 1] > 0.01)  # lit faces never shadow themselves
    np.testing.assert_allclose(shaded.color[cube], plain.color[cube], atol=1e-3)
