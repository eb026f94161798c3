"""Displacement maps drawn by slicing against the exact CPU reference (ray vs bilinear
heightfield, `reliefkit.reference.heightfield`) and against a finely tessellated displaced
mesh; the alpha tests of §3.1 and §3.2."""

from __future__ import annotations

import numpy as np
import pytest
from helpers import assert_same_frames
from slicing_scenes import frame_from_json_plans

from reliefkit.core.transforms import homogeneous, invert_box
from reliefkit.render import render
from reliefkit.scene.views import orbit_bounds
from reliefkit.techniques.slicing.displacement import DisplacementMap
from reliefkit.techniques.slicing.displacement_bake import square_base
from reliefkit.techniques.slicing.displacement_reference import reference_hits, wrong_hits
from reliefkit.techniques.slicing.displacement_textures import terrain_colors, waves

RES = 32
HOLE = (0.3, 0.65, 0.15)  # centre u, v and radius of the zero-displacement disc


def heights() -> np.ndarray:
    x, y = np.meshgrid((np.arange(RES) + 0.5) / RES, (np.arange(RES) + 0.5) / RES)
    h = np.clip(0.5 + 0.3 * np.sin(2 * np.pi * x * 1.5) * np.cos(2 * np.pi * y), 0, 1)
    h[np.hypot(x - HOLE[0], y - HOLE[1]) < HOLE[2]] = 0.0
    return h.astype(np.float32)


@pytest.fixture(scope="module")
def rep():
    h = heights()
    return DisplacementMap(square_base(), terrain_colors(h), h, 0.5)


def reference_colors(rep: DisplacementMap, camera, *, floor: bool = True) -> np.ndarray:
    """(H, W, 3) the unlit linear colour at the exact first hits (`reference_hits`), NaN
    where none: the texture's colour times the surface's tint at the hit's uv, from the base
    triangle under it (`DisplacementMap.tint`)."""
    mask, position = reference_hits(rep, camera, floor=floor)
    uv = (homogeneous(position[mask]) @ invert_box(rep.one_polygon_box()).T)[:, :2]
    color = np.full((*mask.shape, 3), np.nan)
    color[mask] = rep.sample_color(uv[:, 0], uv[:, 1])[:, :3] * rep.tint(
        uv, base_triangle_at(rep.base, uv))
    return color


def base_triangle_at(base, uv) -> np.ndarray:
    """(N,) the base triangle whose uv triangle holds each of ``uv`` (N, 2), the nearest to
    inside for points on no triangle (barycentric test, one triangle at a time)."""
    tri_uv = np.asarray(base.uvs, np.float64)[np.asarray(base.indices, np.int64)]
    best = np.zeros(len(uv), np.int64)
    depth = np.full(len(uv), -np.inf)  # the smallest barycentric coordinate so far
    for k, (a, b, c) in enumerate(tri_uv):
        m = np.column_stack([b - a, c - a])
        if abs(np.linalg.det(m)) < 1e-30:
            continue
        l1, l2 = np.linalg.solve(m, (uv - a).T)
        inside = np.minimum(np.minimum(l1, l2), 1.0 - l1 - l2)
        better = inside > depth
        best[better], depth[better] = k, inside[better]
    return best


def camera(rep, az=30.0, el=40.0, size=96):
    return orbit_bounds(rep.bounds, az, el, 2.4, size=(size, size))


def _save_failure(tmp_path, name, frame, wrong):
    from PIL import Image

    Image.fromarray((frame.mask * 255).astype(np.uint8)).save(tmp_path / f"{name}_mask.png")
    Image.fromarray((wrong * 255).astype(np.uint8)).save(tmp_path / f"{name}_wrong.png")
    return str(tmp_path)


# the slice count at which each mode first reaches <= 0.5% wrong pixels here (measured)
CONVERGED = {("surface", "fill"): 128, ("orthogonal", "fill"): 64, ("screen", "fill"): 64}


@pytest.mark.parametrize("mode, test", list(CONVERGED))
def test_wrong_hits_fall_with_the_slice_count(gl, rep, mode, test, tmp_path):
    cam = camera(rep)
    fractions = []
    for k in (4, 16, CONVERGED[(mode, test)]):
        frame = render(rep, cam, slicing=mode, slices=k, alpha_test=test, unlit=True)
        assert frame.stats["slices"] == k and frame.stats["slicing"] == mode
        out = wrong_hits(frame, rep, cam)
        fractions.append(out["wrong_fraction"])
    assert fractions[0] > 0.2 > fractions[1] > fractions[2], fractions
    where = _save_failure(tmp_path, mode, frame, out["wrong"])
    assert fractions[2] <= 0.005, f"{fractions}; masks in {where}"
    assert out["depth_error_texels"] < 0.5


@pytest.mark.parametrize("mode", ["surface", "orthogonal", "screen"])
def test_every_slicing_draws_the_base_where_the_height_is_zero(gl, rep, mode):
    """Height 0 is surface, not empty: the hole's floor is drawn on the base plane, and the
    picture is the exact reference's with the floor."""
    cam = orbit_bounds(rep.bounds, 7.0, 80.0, 2.0, size=(96, 96))
    hole_world = np.array([2 * HOLE[0] - 1, 0.0, 2 * HOLE[1] - 1])
    assert rep.one_polygon_box() is not None
    frame = render(rep, cam, slicing=mode, slices=64)
    on_base = np.linalg.norm(frame.position - hole_world, axis=-1) < 0.1
    assert on_base.sum() > 20, mode
    np.testing.assert_allclose(frame.position[on_base][:, 1], 0.0, atol=1e-5)
    floor_ref, _ = reference_hits(rep, cam, floor=True)
    assert (frame.mask != floor_ref).sum() <= 0.01 * floor_ref.sum()
    assert wrong_hits(frame, rep, cam)["wrong_fraction"] <= 0.01


def test_bound_sees_through_where_fill_fills(gl, rep):
    """Schaufler's bound keeps only fragments within one slice of the height: at an oblique
    view it leaves holes in steep walls that Dietrich's fill closes (§3.1)."""
    cam = camera(rep, az=30.0, el=20.0)
    fill = render(rep, cam, slicing="surface", slices=24, alpha_test="fill")
    bound = render(rep, cam, slicing="surface", slices=24, alpha_test="bound")
    assert bound.mask.sum() < 0.97 * fill.mask.sum()
    # where the bound test draws, the fill draws too (but for slices up to one spacing
    # above the surface at silhouettes)
    assert (bound.mask & ~fill.mask).sum() <= 0.04 * bound.mask.sum()
    assert bound.stats["alpha_test"] == "bound" and fill.stats["alpha_test"] == "fill"


def test_surface_slicing_looks_through_at_grazing_angles(gl, rep):
    """Fig. 4: surface-aligned slices seen from a grazing angle leave gaps that orthogonal
    slicing does not."""
    cam = camera(rep, az=30.0, el=6.0)
    surface = wrong_hits(render(rep, cam, slicing="surface", slices=16, alpha_test="bound"),
                         rep, cam)
    ortho = wrong_hits(render(rep, cam, slicing="orthogonal", slices=16), rep, cam)
    assert ortho["missed"] < 0.5 * surface["missed"]


def test_normals_and_positions_of_a_flat_displacement(gl):
    res = 8
    h = np.full((res, res), 0.5, np.float32)
    rep = DisplacementMap(square_base(), np.ones((res, res, 4), np.float32), h, 0.4)
    cam = orbit_bounds(rep.bounds, 15.0, 60.0, 2.4, size=(64, 64))
    for mode in ("surface", "orthogonal", "screen"):
        frame = render(rep, cam, slicing=mode, slices=20)
        spacing = frame.stats["slice_spacing"]
        top = frame.mask & (frame.position[..., 1] > 0.2 - spacing - 1e-5)
        assert top.sum() > 0.5 * frame.mask.sum(), mode
        np.testing.assert_allclose(frame.normal[top], [[0, 1, 0]] * int(top.sum()), atol=1e-4)
        # the top at 0.2 is found within one slice spacing below it
        assert (frame.position[top][:, 1] <= 0.2 + 1e-5).all()
        assert frame.stats["slice_polygons"] > 0 and frame.stats["fill_pixels"] > 0


def test_coverage_of_a_displaced_torus_matches_its_tessellation(gl):
    from reliefkit.scene.assets.surfaces import torus

    color, height = waves(res=32)
    rep = DisplacementMap(torus(major_segments=25, minor_segments=25), color, height, 0.12,
                          (2.0, 1.0), True)
    truth = rep.displaced_mesh(6)
    cam = orbit_bounds(rep.bounds, 30.0, 35.0, 2.4, size=(96, 96))
    expected = render(truth, cam).mask
    for mode in ("orthogonal", "screen"):
        got = render(rep, cam, slicing=mode, slices=24).mask
        iou = (got & expected).sum() / (got | expected).sum()
        assert iou > 0.97, (mode, iou)


def test_compare_metric_scores_one_polygon_maps_only(gl, rep):
    from reliefkit.core.technique import technique
    from reliefkit.techniques.slicing.displacement_demo import furry_donut

    tech = technique("slicing")
    (metric,) = [m for m in tech.compare_metrics if m.name == "displacement reference"]
    cam = camera(rep, size=64)
    good = render(rep, cam, slicing="screen", slices=64)
    poor = render(rep, cam, slicing="screen", slices=4)
    scores, wrong = metric.measure(good, rep, cam)
    worse, _ = metric.measure(poor, rep, cam)
    assert wrong.shape == (64, 64) and scores["slices"] == 64
    assert scores["reference_wrong"] < 0.02 < worse["reference_wrong"]
    assert scores["reference_depth_texels"] < worse["reference_depth_texels"]
    donut = furry_donut(res=16)
    assert metric.measure(render(donut, cam, slices=4), donut, cam) == ({}, None)
    names = [v.name for v in tech.compare_variants if v.available(rep)]
    assert {"orthogonal slicing", "screen slicing", "surface slicing (fill)",
            "surface slicing (bound)"} <= set(names)


def test_the_furry_donut_tile_is_figure_1(gl):
    from reliefkit.core.technique import technique

    tech = technique("slicing")
    (tile,) = [t for t in tech.demo_tiles() if t.slug == "displacement-donut"]
    rep = tile.make()
    assert rep.triangle_count == 2 * 625  # 25 x 25 quads
    assert tile.options["slicing"] == "orthogonal" and 15 <= tile.options["slices"] <= 25
    cam = orbit_bounds(rep.bounds, *tile.view, size=(64, 64))
    frame = render(rep, cam, **tile.options)
    assert frame.mask.sum() > 500 and frame.stats["direction_b"] + frame.stats[
        "direction_c"] > 0  # grazing prisms slice along b or c
    sample = tech.samples()["displacement"]
    assert sample.triangle_count == 1250
    for other in tech.demo_tiles():
        if other.slug.startswith("displacement-") and other is not tile:
            made = other.make()
            small = orbit_bounds(made.bounds, *other.view, size=(32, 32))
            shot = render(made, small, **other.options)
            assert shot.mask.sum() > 50 and shot.stats["slicing"] == other.options["slicing"]


def test_automatic_slices_halve_to_fit_the_polygon_budget(gl, rep, monkeypatch):
    from reliefkit.errors import UsageError
    from reliefkit.techniques.slicing import displacement_slices

    cam = orbit_bounds(rep.bounds, 30.0, 40.0, 2.4, size=(256, 256))
    free = render(rep, cam, slicing="screen")
    assert free.stats["slices"] == 8  # scale 0.5 / texel 2/32, the texel bound
    monkeypatch.setattr(displacement_slices, "MAX_POLYGONS", free.stats["slice_polygons"] - 1)
    fitted = render(rep, cam, slicing="screen")
    assert fitted.stats["slices"] == 4
    with pytest.raises(UsageError, match="slice polygons"):
        render(rep, cam, slicing="screen", slices=8)


@pytest.mark.parametrize("mode", ["orthogonal", "screen"])
def test_a_displacement_thinner_than_a_pixel_is_its_base(gl, mode):
    """Fur 1e-9 thick draws exactly the base mesh's pixels (skin and all, no holes between
    the tufts), with no more slice polygons than a visible displacement needs: automatic
    slices are never closer than a pixel, so their count does not grow as 1 / scale."""
    from reliefkit.techniques.slicing.displacement_demo import furry_donut

    thin, thick = furry_donut(res=32, scale=1e-9), furry_donut(res=32, scale=0.08)
    cam = orbit_bounds(thin.base.bounds, 30.0, 35.0, 2.4, size=(96, 96))
    frame = render(thin, cam, slicing=mode)
    np.testing.assert_array_equal(frame.mask, render(thin.base, cam).mask)
    assert frame.stats["slice_polygons"] <= render(thick, cam, slicing=mode).stats[
        "slice_polygons"]


MATERIAL_COLORS = ((1.0, 0.2, 0.2), (0.2, 0.3, 1.0))  # linear factors of the two triangles
PAINT = (0.8, 0.7, 0.6)  # the displacement texture's colour


def two_material_square(degenerate: bool = False):
    """`square_base` with a red factor on its triangle x > z and a blue one on x < z (and,
    with ``degenerate``, a third triangle of no area)."""
    from reliefkit.scene.mesh import Material, RenderMesh

    square = square_base()
    faces = np.asarray(square.indices)
    if degenerate:
        faces = np.vstack([faces, [0, 1, 1]])
    materials = [Material("red", (*MATERIAL_COLORS[0], 1.0)),
                 Material("blue", (*MATERIAL_COLORS[1], 1.0))]
    return RenderMesh(square.world_positions, faces, square.normals, square.colors,
                      square.uvs, materials=materials,
                      material=np.arange(len(faces)).clip(0, 1).astype(np.uint16))


def baked_on(mesh, tmp_path):
    """``mesh`` baked as a displacement of a flat PAINT texture at half height."""
    from reliefkit.bake import bake

    texture = np.empty((8, 8, 4), np.float32)
    texture[..., :3], texture[..., 3] = PAINT, 0.5
    np.save(tmp_path / "flat.npy", texture)
    return bake(mesh, "displacement", displacement=str(tmp_path / "flat.npy"),
                displacement_scale=0.2)


def test_the_surface_material_tints_every_slicing(gl, tmp_path):
    """Seen from above, each triangle's displacement is the texture's colour times that
    triangle's material factor, in every slicing, after a round trip through the .rk
    file, in the exact CPU reference and in the displaced mesh (the CPU ground truth)."""
    from reliefkit.io.rk import load, save
    from reliefkit.scene.camera import Camera

    rep = baked_on(two_material_square(), tmp_path)
    assert rep.surface is not None and len(rep.surface.rgba8) == 2
    save(tmp_path / "tinted.rk", rep)
    back = load(tmp_path / "tinted.rk")
    assert np.array_equal(back.surface.rgba8, rep.surface.rgba8)
    assert np.array_equal(back.base.material, [0, 1])
    cam = Camera(eye=(0.0, 3.0, 0.0), target=(0.0, 0.0, 0.0), up=(0.0, 0.0, -1.0),
                 size=(48, 48), near=0.5, far=10.0, ortho_height=1.2)
    o, _ = cam.pixel_rays()
    inside = (np.abs(o[..., 0]) < 0.8) & (np.abs(o[..., 2]) < 0.8)
    sides = (inside & (o[..., 0] > o[..., 2] + 0.2), inside & (o[..., 0] < o[..., 2] - 0.2))
    for mode in ("surface", "orthogonal", "screen"):
        frame = render(back, cam, slicing=mode, slices=8, unlit=True)
        for side, factor in zip(sides, MATERIAL_COLORS, strict=True):
            assert side.sum() > 200
            expected = np.multiply(PAINT, factor)
            np.testing.assert_allclose(frame.color[..., :3][side],
                                       np.broadcast_to(expected, (int(side.sum()), 3)),
                                       atol=5e-3, err_msg=mode)
    ref = reference_colors(back, cam)  # the exact CPU reference, as the last slicing
    both = frame.mask & ~np.isnan(ref[..., 0])
    assert both.sum() > 0.9 * frame.mask.sum()
    for side, factor in zip(sides, MATERIAL_COLORS, strict=True):
        np.testing.assert_allclose(ref[side], np.broadcast_to(np.multiply(PAINT, factor),
                                                              (int(side.sum()), 3)), atol=5e-3)
    off_seam = both & (sides[0] | sides[1])  # on the seam a pixel may take either side
    assert np.abs(frame.color[..., :3][off_seam] - ref[off_seam]).max() < 5e-3
    truth = rep.displaced_mesh(2)  # 6 lattice points per base triangle
    for k, factor in enumerate(MATERIAL_COLORS):
        np.testing.assert_allclose(truth.colors[6 * k:6 * (k + 1), :3],
                                   np.broadcast_to(np.multiply(PAINT, factor), (6, 3)),
                                   atol=5e-3)


def test_plain_white_meshes_keep_the_texture_colours(gl, tmp_path):
    rep = baked_on(square_base(), tmp_path)
    assert rep.surface is None
    cam = orbit_bounds(rep.bounds, 0.0, 89.0, 2.4, size=(32, 32))
    frame = render(rep, cam, unlit=True)
    np.testing.assert_allclose(frame.color[..., :3][frame.mask],
                               np.broadcast_to(PAINT, (int(frame.mask.sum()), 3)), atol=2e-3)


def test_the_bake_report_counts_the_triangles_left_out(tmp_path):
    rep = baked_on(two_material_square(degenerate=True), tmp_path)
    assert rep.triangle_count == 2
    report = rep.bake_report()
    assert "warning: 1 triangles were left out of the base (no area in space or in uv)" in \
        report
    assert np.array_equal(rep.base.material, [0, 1])  # the kept triangles keep theirs


DRAWINGS = [{"slicing": "orthogonal"}, {"slicing": "screen", "slices": 12},
            {"slicing": "surface", "alpha_test": "bound", "slices": 10},
            {"slicing": "orthogonal", "count_iterations": True}]


@pytest.fixture(scope="module")
def tinted(gl, tmp_path_factory):
    """A map whose base has two materials (a surface atlas, a third texture)."""
    return baked_on(two_material_square(), tmp_path_factory.mktemp("tinted"))


@pytest.mark.parametrize("options", DRAWINGS, ids=str)
def test_a_list_of_cameras_draws_each_as_if_alone(gl, rep, tinted, options):
    """One upload, the slices per camera: the same frames as one render per camera."""
    for drawn in (rep, tinted):
        a, b = camera(drawn, 30.0, 40.0, 48), camera(drawn, 200.0, 15.0, 48)
        both = render(drawn, [a, b], **options)
        assert_same_frames(both[0], render(drawn, a, **options))
        assert_same_frames(both[1], render(drawn, b, **options))


@pytest.mark.parametrize("options", DRAWINGS, ids=str)
def test_plans_read_back_from_json_draw_the_same_frame(gl, rep, tinted, options):
    for drawn in (rep, tinted):
        cam = camera(drawn, 120.0, 30.0, 48)
        assert_same_frames(frame_from_json_plans(drawn, cam, **options),
                           render(drawn, cam, **options))


def test_a_list_of_cameras_holds_one_view_of_slices_at_a_time(gl, rep, monkeypatch):
    """The upload is kept across views, the slices are not: each view's vertex arrays are
    freed once the next view's replace them (24 views of 2M slice triangles would
    otherwise hold 10 GiB)."""
    import gc
    import weakref

    from reliefkit.render.draw import Scene
    from reliefkit.techniques.slicing import displacement_render

    hook, views = displacement_render.slices_view, []

    def recording(*args, **kwargs):
        update = hook(*args, **kwargs)
        views.append(weakref.ref(update.attributes["in_position"]))
        return update

    monkeypatch.setattr(displacement_render, "slices_view", recording)
    with Scene(rep, slicing="screen", slices=8) as scene:
        for az in (30.0, 120.0, 210.0):
            scene.frame(camera(rep, az, 40.0, 32))
            gc.collect()
            assert [v() is not None for v in views] == [False] * (len(views) - 1) + [True]
