"""Baking relief textures: conventions against analytic meshes, frusta and cubes vs the mesh."""

import numpy as np
import pytest

from reliefkit import metrics
from reliefkit.errors import UsageError
from reliefkit.render import render
from reliefkit.scene.assets import make_asset
from reliefkit.scene.mesh import RenderMesh, vertex_normals
from reliefkit.scene.views import orbit_bounds
from reliefkit.techniques.relief.bake import bake_relief, relief_from_heights
from reliefkit.techniques.relief.frustum import bake_relief_cube, bake_relief_frustum


def tilted_plane(n=24):
    """A grid over x, z in [-1, 1] with y = 0.2 + 0.3 x + 0.1 z, coloured by x."""
    x, z = np.meshgrid(np.linspace(-1, 1, n), np.linspace(-1, 1, n))
    y = 0.2 + 0.3 * x + 0.1 * z
    pos = np.stack([x, y, z], -1).reshape(-1, 3).astype(np.float32)
    idx = np.arange(n * n).reshape(n, n)
    a, b, c, d = idx[:-1, :-1], idx[:-1, 1:], idx[1:, :-1], idx[1:, 1:]
    faces = np.concatenate([np.stack([a, c, b], -1).reshape(-1, 3),
                            np.stack([b, c, d], -1).reshape(-1, 3)])
    colors = np.c_[(pos[:, 0] + 1) / 2, np.full(len(pos), 0.5), np.full(len(pos), 0.2),
                   np.ones(len(pos))]
    return RenderMesh(pos, faces, vertex_normals(pos, faces), colors, name="plane")


def test_bake_heights_follow_texel_centre_convention(gl):
    mesh = tilted_plane()
    relief = bake_relief(mesh, depth_res=32, safety=False)
    h, w = relief.height.shape
    u, v = np.meshgrid((np.arange(w) + 0.5) / w, (np.arange(h) + 0.5) / h)
    covered = relief.height > 0
    assert covered[2:-2, 2:-2].all() and not covered[0].any() and not covered[:, -1].any()
    # the surface point above each texel centre, in world space, lies on the plane
    world = relief.to_world(np.stack([u, v, relief.height], -1))[covered]
    expected_y = 0.2 + 0.3 * world[:, 0] + 0.1 * world[:, 2]
    assert np.abs(world[:, 1] - expected_y).max() < 1e-4
    n = np.array([-0.3, 1.0, -0.1]) / np.linalg.norm([-0.3, 1.0, -0.1])
    np.testing.assert_allclose(relief.normal[3:-3, 3:-3] @ n, 1.0, atol=1e-4)
    # colour varies with x as the mesh's does (sRGB of (x + 1) / 2)
    red = relief.color[h // 2, 2:-2, 0].astype(float)
    assert np.all(np.diff(red) >= 0) and red[-1] - red[0] > 150


def test_independent_resolutions(gl):
    relief = bake_relief(tilted_plane(), depth_res=16, color_res=64, safety=False)
    assert relief.height.shape == (16, 16) and relief.color.shape == (64, 64, 4)
    assert relief.normal.shape == (64, 64, 3)


def test_from_heights_keeps_the_array():
    heights = np.random.default_rng(0).random((12, 20))
    relief = relief_from_heights(heights, size=(4.0, 1.0, 2.0), safety=False)
    scaled = (heights - heights.min()) / np.ptp(heights)
    np.testing.assert_allclose((relief.height - 0.01) / 0.99, scaled, atol=1e-6)
    lo, hi = relief.bounds
    np.testing.assert_allclose(hi - lo, [4.0, 1.0, 2.0])


def _scores(rep, mesh, view, size=(128, 128), **options):
    camera = orbit_bounds(mesh.bounds, *view, size=size)
    truth = render(mesh, camera)
    frame = render(rep, camera, method="exact", **options)
    return metrics.compare(frame, truth, scene_size=mesh.radius), frame


@pytest.fixture(scope="module")
def vehicle():
    return make_asset("vehicle")


def test_reverse_frustum_captures_the_sides(gl, vehicle):
    ortho = bake_relief(vehicle, depth_res=96, safety=False)
    frustum = bake_relief_frustum(vehicle, depth_res=96, safety=False)
    side = (80.0, 12.0, 2.2)  # looking at the van's flank, nearly horizontal
    s_ortho, _ = _scores(ortho, vehicle, side)
    s_frustum, _ = _scores(frustum, vehicle, side)
    assert s_frustum["psnr"] > s_ortho["psnr"] + 1.0
    assert s_frustum["position_mean_rel"] < s_ortho["position_mean_rel"]
    assert s_frustum["iou"] > 0.85


def test_clipped_frustum_draws_fewer_fragments_for_the_same_image(gl, vehicle):
    clipped = bake_relief_frustum(vehicle, depth_res=64, safety=False)
    full = bake_relief_frustum(vehicle, depth_res=64, safety=False, clip=False)
    camera = orbit_bounds(full.bounds, 30, 30, 2.0, size=(96, 96))  # near/far hold both
    a = render(clipped, camera, method="exact", count_iterations=True)
    b = render(full, camera, method="exact", count_iterations=True)
    assert a.stats["fragments"] < b.stats["fragments"]
    assert np.mean(a.mask != b.mask) < 0.002


def star_shaped(n=4):
    """A closed bumpy sphere: every ray from its centre meets it once, so six
    heightfields from the centre represent it exactly up to sampling."""
    import trimesh

    s = trimesh.creation.icosphere(subdivisions=n)
    v = np.asarray(s.vertices)
    r = 1.0 + 0.15 * np.sin(3 * v[:, 0]) * np.cos(2 * v[:, 1]) + 0.1 * v[:, 2] ** 2
    pos = (v * r[:, None] + [0.3, -0.2, 0.1]).astype(np.float32)
    colors = np.c_[0.5 + 0.4 * v, np.ones(len(v))]
    return RenderMesh(pos, s.faces, vertex_normals(pos, s.faces), colors, name="star")


def test_six_frusta_represent_a_closed_object(gl):
    mesh = star_shaped()
    cube = bake_relief_cube(mesh, depth_res=96, safety=False)
    assert len(cube.parts) == 6
    for view in [(35.0, 25.0, 2.5), (200.0, -30.0, 2.5), (100.0, 80.0, 2.5)]:
        scores, _ = _scores(cube, mesh, view)
        assert scores["iou"] > 0.97
        assert scores["position_p95_rel"] < 0.02


def plate(color, half=0.5):
    """A square over x, z in [-half, half], y = 0.3 + 0.2 x, one colour."""
    xz = np.array([[-half, -half], [half, -half], [half, half], [-half, half]])
    pos = np.column_stack([xz[:, 0], 0.3 + 0.2 * xz[:, 0], xz[:, 1]]).astype(np.float32)
    faces = np.array([[0, 3, 2], [0, 2, 1]])
    return RenderMesh(pos, faces, vertex_normals(pos, faces), np.tile(color, (4, 1)),
                      name="plate")


def test_maps_are_padded_so_lookups_at_the_edge_stay_opaque(gl):
    """Empty texels take the nearest covered texel's colour and normal (impostor padding)."""
    relief = bake_relief(plate([0.9, 0.1, 0.1, 1.0]), depth_res=32, color_res=40, safety=False)
    assert (relief.height == 0).sum() > 100  # the border ring and the margin are empty
    assert (relief.color[..., 3] == 255).all()
    inner = relief.color[relief.color.shape[0] // 2, relief.color.shape[1] // 2, :3]
    np.testing.assert_array_equal(relief.color[..., :3],
                                  np.broadcast_to(inner, relief.color.shape[:2] + (3,)))
    n = np.array([-0.2, 1.0, 0.0]) / np.linalg.norm([-0.2, 1.0, 0.0])
    np.testing.assert_allclose(relief.normal.reshape(-1, 3), np.tile(n, (relief.normal.size
                                                                       // 3, 1)), atol=1e-5)


@pytest.mark.parametrize("kind", ["relief", "relief-frustum", "relief-cube"])
def test_hits_are_opaque(gl, vehicle, kind):
    from reliefkit.bake import bake

    rep = bake(vehicle, kind, depth_res=64, safety=False)
    for view in ((40, 20, 2.2), (200, 5, 2.0)):
        frame = render(rep, orbit_bounds(vehicle.bounds, *view, size=(96, 96)), method="exact")
        assert frame.mask.sum() > 500
        np.testing.assert_array_equal(frame.color[frame.mask, 3], 1.0)


def test_heightmaps_read_like_a_map_from_above(gl, tmp_path):
    """An asymmetric image (an L of high ground in its top-left corner) seen from above with
    north (-z) up and east (+x) right shows the L where the image has it."""
    from PIL import Image

    from reliefkit.scene.camera import Camera
    from reliefkit.scene.heightmap import load_heightmap

    image = np.zeros((40, 60), np.uint8)
    image[2:20, 3:9] = 255      # the L's stem, top-left
    image[14:20, 3:30] = 255    # its foot, running right
    Image.fromarray(image).save(tmp_path / "l.png")
    relief = relief_from_heights(load_heightmap(tmp_path / "l.png"), size=(3.0, 0.5, 2.0),
                                 safety=False)
    camera = Camera(eye=(0, 5, 0), target=(0, 0, 0), up=(0, 0, -1), size=(60, 40),
                    ortho_height=1.0, near=0.1, far=10)
    frame = render(relief, camera, method="exact")
    high = frame.position[..., 1] > 0.3
    np.testing.assert_array_equal(high, image > 0)


@pytest.mark.parametrize("kind", ["relief", "relief-frustum", "relief-cube"])
def test_a_mesh_and_its_bakes_share_one_camera(gl, tmp_path, kind):
    """Every .rk keeps its source mesh's bounds, so the same --view gives the same camera
    (the AOV file's view and projection matrices) for the mesh and for the bake."""
    from reliefkit import cli
    from reliefkit.io import rk

    assert cli.main(["bake", "demo:blob", "--as", kind, "--depth-res", "64", "--no-safety",
                     "-o", str(tmp_path / "b.rk")]) == 0
    rep = rk.load(tmp_path / "b.rk")
    np.testing.assert_allclose(rep.source_bounds, make_asset("blob").bounds)
    cameras = []
    for name, options in (("demo:blob", []), (str(tmp_path / "b.rk"), ["--method", "exact"])):
        args = ["render", name, "--view", "30,25", "--size", "96x96", *options,
                "-o", str(tmp_path / "x.png"), "--aovs", str(tmp_path / "x.npz")]
        assert cli.main(args) == 0
        with np.load(tmp_path / "x.npz", allow_pickle=False) as aovs:
            cameras.append((aovs["view"], aovs["proj"]))
            assert aovs["mask"].sum() > 500
    np.testing.assert_array_equal(cameras[0][0], cameras[1][0])
    np.testing.assert_array_equal(cameras[0][1], cameras[1][1])


@pytest.mark.parametrize("kind, res", [("relief", 2048), ("relief-frustum", 4096),
                                        ("relief-cube", 512)])
def test_bakes_that_would_run_for_many_minutes_are_refused_up_front(kind, res):
    from reliefkit.bake import bake
    from reliefkit.errors import UsageError

    with pytest.raises(UsageError, match=r"would take about \d+ minutes.*--no-safety"):
        bake(make_asset("blob"), kind, depth_res=res)
    with pytest.raises(UsageError, match="would take about"):
        bake(np.zeros((2048, 2048)), "relief")


@pytest.mark.parametrize("kind", ["relief", "relief-frustum", "relief-cube"])
@pytest.mark.parametrize("options, named", [(["--safety-octants"], "--safety-octants"),
                                            (["--safety-tolerance", "0.05"],
                                             "--safety-tolerance")])
def test_safety_options_with_no_safety_are_refused_in_one_line(tmp_path, capsys, kind,
                                                                 options, named):
    from reliefkit import cli

    out = tmp_path / "b.rk"
    code = cli.main(["bake", "demo:blob", "--as", kind, "--depth-res", "16", "--no-safety",
                     *options, "-o", str(out)])
    err = capsys.readouterr().err.strip()
    assert code != 0 and not out.exists()
    assert len(err.splitlines()) == 1 and named in err and "--no-safety" in err


@pytest.mark.parametrize("box", ["3,1,3", "2,0.5,2"])
def test_box_with_a_mesh_is_refused_in_one_line(tmp_path, capsys, box):
    """--box sizes a heightmap's box; a mesh's relief keeps the mesh's size, so the flag
    was silently ignored (a byte-identical file), the heightmap default included."""
    from reliefkit import cli

    out = tmp_path / "b.rk"
    code = cli.main(["bake", "demo:blob", "--as", "relief", "--depth-res", "16",
                     "--no-safety", "--box", box, "-o", str(out)])
    err = capsys.readouterr().err.strip()
    assert code == 2 and not out.exists()
    assert len(err.splitlines()) == 1 and err.startswith("error:") and "--box" in err


@pytest.mark.parametrize("flags", [["--depth-res", "64"], ["--color-res", "32"],
                                   ["--axis", "y"], ["--axis", "z", "--depth-res", "256"]])
def test_mesh_options_with_a_heightmap_are_refused_in_one_line(tmp_path, capsys, flags):
    """A heightmap keeps its own size and its y axis: these flags were silently ignored
    (their defaults included)."""
    from reliefkit import cli

    heights = tmp_path / "h.npy"
    np.save(heights, np.random.default_rng(0).random((12, 12)).astype(np.float32))
    out = tmp_path / "h.rk"
    code = cli.main(["bake", str(heights), "--as", "relief", "--no-safety", *flags,
                     "-o", str(out)])
    err = capsys.readouterr().err.strip()
    assert code == 2 and not out.exists()
    assert len(err.splitlines()) == 1 and err.startswith("error:")
    assert all(flag in err for flag in flags if flag.startswith("--")), err


def test_a_mesh_relief_keeps_its_defaults_when_none_are_given(gl):
    from reliefkit import bake
    from reliefkit.scene.assets import make_asset

    relief = bake(make_asset("blob"), "relief", safety=False)
    assert max(relief.height.shape) == 256 and relief.params["axis"] == "y"


@pytest.mark.parametrize("kind", ["relief", "relief-frustum", "relief-cube"])
def test_default_bakes_leave_out_radii_that_the_default_render_never_reads(gl, kind):
    """Robust draws fields with W + H <= 256 with the exact walk: a default bake of such a
    field has no radii (a cube of 128² faces spent minutes on them) and renders the same
    pixels as a bake with them; robust asked to jump on it names --safety."""
    from reliefkit.bake import bake
    from reliefkit.errors import UsageError

    mesh = make_asset("blob")
    lean, full = (bake(mesh, kind, depth_res=24, **extra) for extra in ({}, {"safety": True}))
    parts = lambda rep: getattr(rep, "parts", [rep])  # noqa: E731
    assert all(p.safety is None for p in parts(lean))
    assert all(p.safety is not None for p in parts(full))
    camera = orbit_bounds(mesh.bounds, 30, 25, 2.6, size=(64, 64))
    plain, radii = render(lean, camera), render(full, camera)
    assert plain.mask.mean() > 0.1 and np.array_equal(plain.color, radii.color)
    with pytest.raises(UsageError, match="no safety radii.*--safety"):
        render(lean, camera, method="robust", exact_field=0)


def test_default_bakes_keep_radii_where_robust_jumps_or_octants_are_asked(gl):
    """A 136² field (W + H > 256) is drawn jumping by its radii, so a default bake keeps
    them; asking for octant radii asks for radii on a small field too."""
    from reliefkit.bake import bake

    u, v = np.meshgrid(np.linspace(0, 3, 136), np.linspace(0, 2, 136))
    assert relief_from_heights(np.sin(u) * np.cos(v)).safety is not None
    assert bake(make_asset("blob"), "relief-cube", depth_res=16,
                safety_octants=True).parts[0].safety.shape == (8, 16, 16)


def test_a_frustum_takes_octant_radii_and_robust_keeps_the_reference_hits(gl):
    """Rays are straight in a frustum's texel space, so the radii per direction octant hold
    there as in an orthographic box: robust with every ray jumping meets the exact reference."""
    from reliefkit.techniques.relief.reference import wrong_hits

    rep = bake_relief_frustum(make_asset("vehicle"), depth_res=48, octants=True)
    assert rep.safety.shape == (8, *rep.height.shape)
    camera = orbit_bounds(rep.bounds, 30, 25, 2.6, size=(96, 96))
    frame = render(rep, camera, method="robust", exact_field=0)
    assert wrong_hits(frame, rep, camera)["wrong_fraction"] <= 0.005


def test_a_cube_bakes_octant_radii_per_face(gl):
    """Each of the six faces gets (8, H, W) radii; at 24² (W + H <= exact_field) robust draws
    the faces with the exact walk, which meets the reference."""
    from reliefkit.techniques.relief.reference import wrong_hits

    rep = bake_relief_cube(make_asset("blob"), depth_res=24, octants=True)
    assert all(p.safety.shape == (8, 24, 24) for p in rep.parts)
    camera = orbit_bounds(rep.bounds, 30, 25, 2.6, size=(96, 96))
    frame = render(rep, camera, method="robust")
    assert wrong_hits(frame, rep, camera)["wrong_fraction"] <= 0.001


@pytest.mark.parametrize("model", ["vehicle", "blob"])
def test_robust_jumps_on_a_cube_meet_the_reference(gl, model):
    """A pyramid's h is perspective depth: cut near the centre, the surface got a sliver of h
    and the default tolerance spanned a third of the object (robust missed up to 24% of the
    vehicle's pixels). Each pyramid is cut just inside its surface, the tolerance scaled to
    its far end, and every field jumping stays within robust's budget at grazing views."""
    from reliefkit.techniques.relief.reference import wrong_hits

    mesh = make_asset(model)
    rep = bake_relief_cube(mesh, depth_res=64, safety=True)  # 64² faces: radii on request
    for part in rep.parts:  # the surface spans the pyramid's depth, not a sliver at its top
        covered = part.height[part.height > 0]
        assert covered.size == 0 or np.ptp(covered) > 0.1 or covered.min() < 0.5
    for azimuth, elevation in ((30, 45), (120, 20), (200, 8)):
        camera = orbit_bounds(rep.bounds, azimuth, elevation, 2.6, size=(128, 96))
        frame = render(rep, camera, method="robust", exact_field=0)
        assert wrong_hits(frame, rep, camera)["wrong_fraction"] <= 0.005, (azimuth, elevation)


def test_far_tolerance_is_near_over_far_for_a_frustum_and_one_for_a_box():
    """Perspective depth: dh/dr = near * far / ((far - near) r^2), so at the far end one unit of
    h spans far / near times the mean depth per unit (an analytic check of the scaling)."""
    from reliefkit.bake.project import axis_frame
    from reliefkit.techniques.relief.bake import far_tolerance
    from reliefkit.techniques.relief.frustum import frustum_matrix

    for near, far in ((0.25, 1.0), (0.02, 1.0), (3.0, 4.5)):
        m = frustum_matrix(np.array([0.3, -1.0, 2.0]), axis_frame("y"), 1.0, 0.7, near, far)
        assert far_tolerance(m, 0.01) == pytest.approx(0.01 * near / far, rel=1e-3)
    box = np.diag([2.0, 0.5, 3.0, 1.0])
    box[:3, 3] = [1.0, 2.0, 3.0]
    assert far_tolerance(box, 0.01) == 0.01


def flat_square():
    """Two triangles in the plane z = 0.3 (a decal, a sign): flat across z."""
    pos = np.array([[-1, -1, 0.3], [1, -1, 0.3], [1, 1, 0.3], [-1, 1, 0.3]], np.float32)
    faces = np.array([[0, 1, 2], [0, 2, 3]])
    colors = np.tile([0.8, 0.5, 0.2, 1.0], (4, 1)).astype(np.float32)
    return RenderMesh(pos, faces, vertex_normals(pos, faces), colors, name="sign")


@pytest.mark.parametrize("bake", [bake_relief, bake_relief_frustum])
def test_a_flat_mesh_bakes_along_its_normal_and_is_refused_edge_on(gl, bake):
    """A flat mesh's box was 1e-9 deep: its heights were lost to float precision and the
    bake was refused as "the heightfield is empty" (--axis z too), or a frustum's near plane
    came out negative; edge-on (the default --axis y) it was the same line, saying nothing of
    why. Now the box is at least 1/1000 of the footprint deep, and edge-on names the axis."""
    mesh = flat_square()
    relief = bake(mesh, depth_res=64, axis="z", safety=False)
    scores, _ = _scores(relief, mesh, (25.0, 15.0, 2.5))
    assert scores["iou"] > 0.97
    with pytest.raises(UsageError, match="the mesh is flat across z: seen along --axis y it is "
                                         "edge-on and covers nothing; bake it along --axis z"):
        bake(mesh, depth_res=64, safety=False)


def test_a_flat_mesh_is_refused_by_the_relief_cube_with_what_to_do(gl):
    with pytest.raises(UsageError, match="six frusta meet .* bake it as relief --axis z"):
        bake_relief_cube(flat_square(), depth_res=32, safety=False)
