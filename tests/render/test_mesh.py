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

    from reliefkit.scene.loader import load_mesh

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
