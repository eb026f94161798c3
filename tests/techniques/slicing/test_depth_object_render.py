"""Depth objects and visual hulls on the GPU against the exact CPU reference (reference.py),
analytic scenes, and each other (single pass vs stencil passes)."""

from __future__ import annotations

import numpy as np
import pytest
from helpers import assert_same_frames
from slicing_scenes import (
    CUP_FLOOR,
    CUP_TOP,
    box_mesh,
    cup_mesh,
    frame_from_json_plans,
    sphere_mesh,
)

from reliefkit.errors import UsageError
from reliefkit.render import render
from reliefkit.scene.camera import Camera
from reliefkit.techniques.slicing.depth_images import bake_depth_images
from reliefkit.techniques.slicing.measure import against_reference
from reliefkit.techniques.slicing.reference import exact_intersection
from reliefkit.techniques.slicing.representation import DepthObject, VisualHull

N = 32
SIZE = (64, 64)


@pytest.fixture(scope="module")
def objects(gl):
    return {name: DepthObject(bake_depth_images(make(), N))
            for name, make in (("box", box_mesh), ("sphere", sphere_mesh), ("cup", cup_mesh))}


def cameras(rep):
    centre = tuple(rep.bounds.mean(axis=0))
    side = rep.images.side
    return [Camera.orbit(centre, 30, 25, 1.7 * side, size=SIZE),
            Camera.orbit(centre, -120, -40, 1.7 * side, size=SIZE),
            Camera.orbit(centre, 75, 60, 1.7 * side, size=SIZE, ortho_height=0.6 * side)]


@pytest.mark.parametrize("name", ["box", "sphere", "cup"])
def test_ray_casting_is_the_exact_reference(objects, name):
    rep = objects[name]
    for cam in cameras(rep):
        frame = render(rep, cam, slicing="raycast")
        s = against_reference(frame, rep.images, cam)
        assert s["reference_pixels"] > 300
        assert s["wrong_fraction"] <= 0.002 and s["depth_rms_texels"] < 0.02, s


@pytest.mark.parametrize("slicing", [None, "orthogonal", "screen"])
def test_default_renders_are_the_exact_reference(objects, slicing):
    """Left to their defaults, a render (ray casting) and the paper's slicings (the slab
    test, here at 8 slices where the point test misses a third of the pixels) draw the
    exact intersection."""
    rep = objects["cup"]
    options = {} if slicing is None else {"slicing": slicing, "slices": 8}
    for cam in cameras(rep):
        frame = render(rep, cam, **options)
        s = against_reference(frame, rep.images, cam)
        assert s["reference_pixels"] > 300
        assert s["wrong_fraction"] <= 0.003 and s["depth_rms_texels"] < 0.1, s
    assert frame.stats["slicing"] == (slicing or "raycast")


@pytest.mark.parametrize("slicing", ["orthogonal", "screen"])
def test_slab_test_is_exact_at_few_slices(objects, slicing):
    rep = objects["sphere"]
    for cam in cameras(rep):
        frame = render(rep, cam, slicing=slicing, slices=8, alpha_test="slab")
        s = against_reference(frame, rep.images, cam)
        assert s["wrong_fraction"] <= 0.003 and s["depth_rms_texels"] < 0.1, s


@pytest.mark.parametrize("slicing", ["orthogonal", "screen"])
def test_point_test_converges_with_slices(objects, slicing):
    """The paper's alpha test samples the object at the slice planes: wrong pixels fall as
    slices grow, and the depth error with them."""
    rep = objects["sphere"]
    cam = cameras(rep)[0]
    reference = exact_intersection(rep.images, cam)
    scores = [against_reference(render(rep, cam, slicing=slicing, slices=n, alpha_test="point"),
                                rep.images, cam, reference=reference) for n in (8, 32, 128)]
    wrong = [s["wrong_fraction"] for s in scores]
    rms = [s["depth_rms_texels"] for s in scores]
    assert wrong[0] > wrong[1] > wrong[2] and wrong[0] > 0.3 and wrong[2] < 0.05, wrong
    assert rms[0] > rms[1] > rms[2], rms
    assert scores[2]["iou"] >= 0.98


@pytest.mark.parametrize("hull", [False, True])
def test_stencil_passes_draw_the_single_pass_picture(objects, hull):
    rep = objects["cup"]
    rep = VisualHull.of(rep.images) if hull else rep
    cam = cameras(rep)[0]
    single = render(rep, cam, slicing="orthogonal", slices=24, alpha_test="point")
    stencil = render(rep, cam, slicing="orthogonal", slices=24, passes="stencil")
    assert stencil.stats["alpha_test"] == "point"  # the stencil passes' own test
    assert single.mask.sum() > 300
    assert np.array_equal(single.mask, stencil.mask)
    m = single.mask
    assert np.abs(single.color[m] - stencil.color[m]).max() < 1e-6
    assert np.abs(single.position[m] - stencil.position[m]).max() < 1e-5
    assert np.abs(single.depth[m] - stencil.depth[m]).max() < 1e-6
    # one counting pass per tested image, one texturing and one reset pass, per slice
    tested = 3 if hull else 6
    assert stencil.stats["draws"] == stencil.stats["slices"] * (tested + 2)


@pytest.mark.parametrize("slicing", ["raycast", "orthogonal", "screen"])
def test_the_cup_needs_depth_the_hull_fills_it(objects, slicing):
    """§5: a visual hull cannot show the cup's hole; the depth object sees its floor."""
    rep = objects["cup"]
    top = Camera.orbit(tuple(rep.bounds.mean(axis=0)), 0, 89.9, 3.0, size=SIZE,
                       ortho_height=1.2)
    options = {"slicing": slicing} | ({} if slicing == "raycast" else {"slices": 64})
    depth = render(rep, top, **options)
    hull = render(VisualHull.of(rep.images), top, **options)
    centre = (slice(28, 36), slice(28, 36))  # inside the hole, |x|, |z| < 0.5
    assert np.allclose(depth.position[centre][..., 1], CUP_FLOOR, atol=0.06)
    assert np.allclose(hull.position[centre][..., 1], CUP_TOP, atol=0.06)


def test_texturing_takes_each_face_colour_from_the_image_that_sees_it(gl):
    """A box whose faces have different colours, seen across a corner: both texturings give
    each face its own colour (the images that do not see a point are left out)."""
    import trimesh

    from reliefkit.scene.mesh import RenderMesh

    tm = trimesh.creation.box(extents=(1.0, 1.0, 1.0))
    tm = tm.subdivide()  # face-coloured vertices: split per face
    tm = trimesh.Trimesh(tm.vertices[tm.faces].reshape(-1, 3),
                         np.arange(3 * len(tm.faces)).reshape(-1, 3), process=False)
    normal = np.repeat(tm.face_normals, 3, axis=0)
    palette = {0: (0.9, 0.1, 0.1), 1: (0.1, 0.9, 0.1), 2: (0.1, 0.1, 0.9)}
    axis = np.abs(normal).argmax(axis=1)
    colors = np.array([[*palette[a], 1.0] for a in axis])
    mesh = RenderMesh(tm.vertices, tm.faces, normal, colors, name="coloured box")
    rep = DepthObject(bake_depth_images(mesh, N))
    cam = Camera.orbit((0.0, 0.0, 0.0), 40, 30, 3.0, size=SIZE)
    for texturing in ("blend3", "nearest"):
        frame = render(rep, cam, slicing="raycast", texturing=texturing, unlit=True)
        n = frame.normal[frame.mask]
        got = frame.color[frame.mask][:, :3]
        face = np.abs(n).argmax(axis=1)
        expected = np.array([palette[a] for a in face])
        close = np.abs(got - expected).max(axis=1) < 0.02
        assert close.mean() > 0.9, (texturing, close.mean())


def coloured_box() -> DepthObject:
    """A unit box whose faces are red, green or blue by their axis."""
    import trimesh

    from reliefkit.scene.mesh import RenderMesh

    tm = trimesh.creation.box(extents=(1.0, 1.0, 1.0))
    tm = trimesh.Trimesh(tm.vertices[tm.faces].reshape(-1, 3),
                         np.arange(3 * len(tm.faces)).reshape(-1, 3), process=False)
    normal = np.repeat(tm.face_normals, 3, axis=0)
    palette = np.array([(0.9, 0.1, 0.1, 1.0), (0.1, 0.9, 0.1, 1.0), (0.1, 0.1, 0.9, 1.0)])
    mesh = RenderMesh(tm.vertices, tm.faces, normal, palette[np.abs(normal).argmax(axis=1)],
                      name="coloured box")
    return DepthObject(bake_depth_images(mesh, N))


@pytest.mark.parametrize("options", [{}, {"slicing": "orthogonal", "slices": 24}])
def test_empty_texels_add_nothing_whatever_they_hold(objects, options):
    """Texturing filters only the texels whose column is set in the depth image: colour and
    normals stored in empty texels (what a block-compressed 0 decodes to) change nothing."""
    from dataclasses import replace

    for name in ("sphere", "cup"):
        rep = objects[name]
        images = rep.images
        empty = ~images.mask
        color, normal = images.color.copy(), images.normal.copy()
        color[empty] = (1.0, 0.0, 1.0, 1.0)
        normal[empty] = (0.6, -0.8, 0.0)
        garbage = DepthObject(replace(images, color=color, normal=normal))
        for cam in cameras(rep):
            got, expected = render(garbage, cam, **options), render(rep, cam, **options)
            np.testing.assert_array_equal(got.mask, expected.mask)
            np.testing.assert_allclose(got.color, expected.color, atol=1e-6)
            np.testing.assert_allclose(got.normal, expected.normal, atol=1e-6)


#: Linear colour error of a lit face of one flat colour and one normal compressed BC7 (one
#: 8-bit sRGB step at 0.9 is 0.008 linear; 0.0075 measured).
BC7_FLAT_COLOUR = 0.02


@pytest.mark.parametrize("hull", [False, True])
def test_compressed_colour_and_normals_keep_the_picture(gl, hull):
    """``--compress bc``: colour and normals BC7, depth exact: the same pixels covered at
    the same depths, each face lit in its own colour within BC7's error."""
    from reliefkit.compact.compact import compress
    from reliefkit.compact.encodings import encoding_of

    rep = coloured_box()
    rep = VisualHull.of(rep.images) if hull else rep
    compact = compress(rep)
    assert encoding_of(compact.images.color).format == "bc7"
    assert encoding_of(compact.images.normal).format == "bc7"
    assert encoding_of(compact.images.depth) is None
    for cam in cameras(rep):
        got, expected = render(compact, cam), render(rep, cam)
        np.testing.assert_array_equal(got.mask, expected.mask)
        np.testing.assert_array_equal(got.depth, expected.depth)
        off = np.abs(got.color - expected.color).max(axis=-1)[expected.mask]
        assert off.max() <= BC7_FLAT_COLOUR, off.max()  # the faces are 0.8 apart


def test_bad_option_combinations_are_refused(objects):
    rep = objects["box"]
    cam = cameras(rep)[0]
    with pytest.raises(UsageError, match="ray casting has no slices"):
        render(rep, cam, slicing="raycast", passes="stencil")
    with pytest.raises(UsageError, match="stencil passes test one image"):
        render(rep, cam, slicing="screen", alpha_test="slab", passes="stencil")
    with pytest.raises(UsageError, match="--slices set the slices"):
        render(rep, cam, slices=10)
    with pytest.raises(UsageError, match="--alpha-test set the slices"):
        render(rep, cam, slicing="raycast", alpha_test="point")


def test_stats_count_the_fill(objects):
    rep = objects["sphere"]
    cam = cameras(rep)[0]
    frame = render(rep, cam, slicing="screen", slices=20)
    assert frame.stats["slices"] == 20 and frame.stats["slice_polygons"] == 20
    # screen slices fill about the cube's depth in slices over its silhouette
    assert frame.stats["fill_per_covered_pixel"] > 5


def test_bounds_hold_the_object_within_half_a_texel(objects):
    from slicing_scenes import BOX_HI, BOX_LO

    rep = objects["box"]
    half = 0.5 * rep.images.texel
    lo, hi = rep.bounds
    assert (lo <= BOX_LO + 1e-9).all() and (hi >= BOX_HI - 1e-9).all()
    assert (lo >= BOX_LO - 2 * half).all() and (hi <= BOX_HI + 2 * half).all()
    assert (rep.cube_bounds[0] <= lo).all() and (rep.cube_bounds[1] >= hi).all()


def test_bake_report_warns_when_a_sheet_is_carved_away(gl):
    """A ground plane under a box: the side images see the plane edge-on (no texels), so
    they carve it away; the report says so. The closed box alone gets no warning."""
    import trimesh

    from reliefkit.scene.mesh import RenderMesh
    from reliefkit.techniques.slicing.reference import carved_fraction

    box = trimesh.creation.box(extents=(0.6, 0.6, 0.6))
    box.apply_translation((0.0, 0.3, 0.0))
    plane = trimesh.Trimesh([[-1, 0, -1], [1, 0, -1], [1, 0, 1], [-1, 0, 1]],
                            [[0, 2, 1], [0, 3, 2]], process=False)
    both = trimesh.util.concatenate([box, plane])

    def mesh(tm):
        pos = np.asarray(tm.vertices, np.float32)
        return RenderMesh(pos, tm.faces, np.tile((0.0, 1.0, 0.0), (len(pos), 1)),
                          np.ones((len(pos), 4)), name="scene")

    closed = DepthObject(bake_depth_images(mesh(box), N))
    sheet = DepthObject(bake_depth_images(mesh(both), N))
    assert carved_fraction(closed.images).max() < 0.01
    carved = carved_fraction(sheet.images)
    assert carved[2] > 0.5 and carved[3] > 0.5  # the +y and -y images: mostly plane
    assert not any(line.startswith("warning:") for line in closed.bake_report())
    warning = [line for line in sheet.bake_report() if line.startswith("warning:")]
    assert len(warning) == 1 and "carved away" in warning[0]


def test_a_render_over_the_host_memory_limit_is_refused_before_uploading(objects,
                                                                         monkeypatch):
    """Drawing N = 32 images needs 6 x 32² texels x 88 B = 528 KiB at its peak: with the
    host-memory limit below that it is refused with the estimate before any texture is
    made; above it (and above the 16² frame's read-back) it renders."""
    import reliefkit.gl.targets as targets
    from reliefkit.render import executor

    rep = objects["sphere"]
    cam = Camera.orbit(tuple(rep.bounds.mean(axis=0)), 30, 25, 1.7 * rep.images.side,
                       size=(16, 16))
    uploads = []
    upload = executor.texture_array
    monkeypatch.setattr(executor, "texture_array",
                        lambda *a, **k: uploads.append(1) or upload(*a, **k))
    monkeypatch.setattr(targets, "host_limit", lambda: 6 * N**2 * 88 - 1)
    with pytest.raises(UsageError, match=r"res 32: to render .*528\.0 KiB of host memory"):
        render(rep, cam)
    assert not uploads
    monkeypatch.setattr(targets, "host_limit", lambda: 6 * N**2 * 88)
    assert render(rep, cam).mask.any()
    assert len(uploads) == 3


DRAWINGS = [{"slicing": "raycast"}, {"slicing": "raycast", "count_iterations": True},
            {"slicing": "orthogonal", "slices": 12}, {"slicing": "screen"},
            {"slicing": "screen", "alpha_test": "point", "slices": 12},
            {"slicing": "orthogonal", "passes": "stencil", "slices": 12}]


@pytest.mark.parametrize("options", DRAWINGS, ids=str)
@pytest.mark.parametrize("hull", [False, True])
def test_a_list_of_cameras_draws_each_as_if_alone(objects, options, hull):
    """One upload, the slices (or the proxy's culling) per camera: the same frames as one
    render per camera."""
    rep = VisualHull.of(objects["cup"].images) if hull else objects["cup"]
    a, b, _ = cameras(rep)
    both = render(rep, [a, b], **options)
    assert_same_frames(both[0], render(rep, a, **options))
    assert_same_frames(both[1], render(rep, b, **options))


@pytest.mark.parametrize("options", DRAWINGS, ids=str)
def test_plans_read_back_from_json_draw_the_same_frame(objects, options):
    rep = objects["cup"]
    cam = cameras(rep)[1]
    assert_same_frames(frame_from_json_plans(rep, cam, **options), render(rep, cam, **options))
