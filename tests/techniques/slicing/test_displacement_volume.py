"""The displacement volume (prisms split into tetrahedra) and the slice polygons cut from it,
against independent geometry: shared faces, volumes, exact (u, v, h) at slice vertices,
§3.4's slice counts and the automatic slice count rule."""

from __future__ import annotations

from collections import Counter

import numpy as np
import pytest

from reliefkit.errors import UsageError
from reliefkit.scene.assets.surfaces import torus
from reliefkit.scene.camera import Camera
from reliefkit.techniques.slicing.displacement import DisplacementMap, bilinear, prism_tets
from reliefkit.techniques.slicing.displacement_bake import square_base
from reliefkit.techniques.slicing.displacement_render import auto_slices, texel_world_size
from reliefkit.techniques.slicing.displacement_slices import (
    cut_tetrahedra,
    orthogonal_choice,
    orthogonal_levels,
    slice_triangles,
)

SCALE = 0.5


def flat(res=8, value=0.5, scale=SCALE, **kw):
    h = np.full((res, res), value, np.float32)
    c = np.ones((res, res, 4), np.float32)
    return DisplacementMap(square_base(), c, h, scale, **kw)


def square_box(scale=SCALE):
    """box (u, v, h) -> world of the 2 x 2 square of `square_base`."""
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = (2, 0, 0), (0, 0, 2), (0, scale, 0), (-1, 0, -1)
    return m


def tet_volumes(positions, tets):
    d = positions[tets[:, 1:]] - positions[tets[:, :1]]
    return np.linalg.det(d) / 6.0


def test_neighbouring_prisms_split_their_shared_sides_alike():
    base = torus(major_segments=25, minor_segments=25)
    tets = prism_tets(base.indices, len(base.positions))
    faces = Counter(tuple(sorted(f)) for t in tets for f in
                    ((t[0], t[1], t[2]), (t[0], t[1], t[3]), (t[0], t[2], t[3]),
                     (t[1], t[2], t[3])))
    once = sum(1 for n in faces.values() if n == 1)
    assert max(faces.values()) == 2
    # the torus (seams duplicated) is closed only through its seams: the faces seen once
    # are the bottom and top triangles plus the side faces along the two seams
    seam_sides = 2 * (25 + 25) * 2
    assert once == 2 * len(base.indices) + seam_sides


def test_the_volume_of_a_flat_square_is_its_box():
    rep = flat()
    vol = rep.volume()
    v = tet_volumes(vol.positions, vol.tets)
    assert (np.abs(v) > 0).all()
    assert vol.total_volume() == pytest.approx(2 * 2 * SCALE, rel=1e-12)
    # the Jacobian maps box coordinates to world exactly at all four corners of each tet
    q = vol.box[vol.tets] - vol.box[vol.tets[:, :1]]
    p = vol.positions[vol.tets] - vol.positions[vol.tets[:, :1]]
    np.testing.assert_allclose(np.einsum("txy,tky->tkx", vol.jacobian, q), p, atol=1e-12)


def test_slice_vertices_carry_exact_box_coordinates():
    rep = flat()
    box = square_box()
    cam = Camera.orbit((0, 0.25, 0), 37, 28, 5.0, size=(64, 64))
    for mode in ("surface", "orthogonal", "screen"):
        tris = slice_triangles(rep, cam, mode, 7)
        assert tris.triangle_count > 0
        world = tris.box @ box[:3, :3].T + box[:3, 3]
        np.testing.assert_allclose(tris.positions, world, atol=1e-9, err_msg=mode)
        assert (tris.box >= -1e-12).all() and (tris.box <= 1 + 1e-12).all()


def test_cut_tetrahedron_cross_sections_integrate_to_its_volume():
    rng = np.random.default_rng(3)
    positions = rng.random((4, 3))
    tets = np.array([[0, 1, 2, 3]])
    values = positions @ np.array([0.3, -0.5, 0.8])
    n = 400
    levels = values.min() + (values.max() - values.min()) * (np.arange(n) + 0.5) / n
    pos, _, _, polygons, used, _ = cut_tetrahedra(positions, positions, tets,
                                                  np.eye(3)[None], values, levels)
    assert polygons == used == n
    t = pos.reshape(-1, 3, 3)
    area = 0.5 * np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1).sum()
    spacing = (values.max() - values.min()) / n / np.linalg.norm([0.3, -0.5, 0.8])
    assert area * spacing == pytest.approx(abs(tet_volumes(positions, tets)[0]), rel=1e-3)


@pytest.mark.parametrize("which", ["square", "donut"])
def test_screen_slices_are_exact_cross_sections_of_the_volume(which):
    if which == "square":
        rep = flat()
    else:
        color = np.ones((4, 4, 4), np.float32)
        rep = DisplacementMap(torus(major_segments=25, minor_segments=25), color,
                              np.full((4, 4), 0.5, np.float32), 0.1, (2.0, 2.0), True)
    cam = Camera.orbit(tuple(rep.bounds.mean(axis=0)), 25, 40, 6.0, size=(64, 64))
    tris = slice_triangles(rep, cam, "screen", 40)
    assert tris.base == len(rep.base.indices)  # the base, then the planes' cuts
    cuts = tris.positions[3 * tris.base:].reshape(-1, 3, 3)
    area = 0.5 * np.linalg.norm(np.cross(cuts[:, 1] - cuts[:, 0], cuts[:, 2] - cuts[:, 0]),
                                axis=1).sum()
    assert area * tris.spacing == pytest.approx(rep.volume().total_volume(), rel=2e-3)
    # every plane is perpendicular to the view direction: vertices of a triangle share depth
    f = np.asarray(cam.target) - np.asarray(cam.eye)
    f /= np.linalg.norm(f)
    d = (cuts.reshape(-1, 3) @ f).reshape(-1, 3)
    assert np.ptp(d, axis=1).max() < 1e-9


def test_orthogonal_counts_follow_the_edge_to_displacement_ratio():
    """§3.4: edge 2, displacement 0.5 -> four times the slices along u and v."""
    rep = flat()
    for k in (3, 8, 20):
        h, u, v = orthogonal_levels(rep, k)
        assert len(h) == k
        assert len(u) == len(v) == 4 * k
        np.testing.assert_allclose(np.diff(u), 1 / (4 * k))


def test_orthogonal_direction_is_the_most_perpendicular_to_the_view():
    rep = flat()
    above = Camera.orbit((0, 0, 0), 10, 80, 5.0)
    along_x = Camera.orbit((0, 0, 0), 90, 10, 5.0)   # looking along -x: u = x planes face it
    along_z = Camera.orbit((0, 0, 0), 0, 10, 5.0)    # along -z: v = z planes
    assert (orthogonal_choice(rep, above) == 0).all()
    assert (orthogonal_choice(rep, along_x) == 1).all()
    assert (orthogonal_choice(rep, along_z) == 2).all()
    tris = slice_triangles(rep, along_x, "orthogonal", 5)
    assert tris.directions == {"a": 0, "b": 2, "c": 0}
    # after the base, b slices are planes u = const: x constant per triangle
    assert tris.base == 2 and (tris.box[:6, 2] == 0).all()
    x = tris.positions[6:, 0].reshape(-1, 3)
    assert np.ptp(x, axis=1).max() < 1e-12 and len(np.unique(x[:, 0].round(9))) == 20


def test_surface_slices_are_offset_copies_of_the_base():
    rep = flat()
    tris = slice_triangles(rep, Camera.orbit((0, 0, 0), 0, 60, 5.0), "surface", 5)
    heights = np.unique(tris.positions[:, 1].round(12))
    np.testing.assert_allclose(heights, np.linspace(0, SCALE, 5))
    assert tris.polygons == 5 * 2


def test_automatic_slice_count_rule():
    rep = flat(res=32)
    texel = texel_world_size(rep)
    assert texel == pytest.approx(2 / 32)
    far = Camera.orbit((0, 0, 0), 20, 40, 30.0, size=(16, 16))
    near = Camera.orbit((0, 0, 0), 20, 40, 3.0, size=(512, 512))
    k_far, k_near = auto_slices(rep, far), auto_slices(rep, near)
    assert k_far == 2  # a pixel is far wider than the displacement: the lower clamp
    # big on screen: no finer than one texel, K = scale / texel
    assert k_near == int(np.ceil(SCALE / texel)) == 8
    mid = Camera.orbit((0, 0, 0), 20, 40, 6.0, size=(64, 64))
    assert k_far <= auto_slices(rep, mid) <= k_near


def test_displaced_mesh_moves_each_point_by_its_height():
    rep = flat(value=0.25)
    mesh = rep.displaced_mesh(4)
    assert len(mesh.indices) == 2 * 16
    np.testing.assert_allclose(mesh.world_positions[:, 1], 0.25 * SCALE, atol=1e-6)


def test_bilinear_matches_texel_centres_and_wraps():
    img = np.arange(12, dtype=np.float64).reshape(3, 4)
    s = (np.arange(4) + 0.5) / 4
    np.testing.assert_allclose(bilinear(img, s, np.full(4, 0.5 / 3), False), img[0])
    # halfway across the wrap seam: the mean of the last and the first column
    assert bilinear(img, np.array([0.0]), np.array([0.5 / 3]), True)[0] == pytest.approx(1.5)
    assert bilinear(img, np.array([0.0]), np.array([0.5 / 3]), False)[0] == pytest.approx(0.0)


@pytest.mark.parametrize("kwargs, words", [
    ({"scale": -1.0}, "scale"), ({"scale": float("nan")}, "scale"),
    ({"tile": (0.0, 1.0)}, "tile"), ({"height_value": 1.5}, "[0, 1]"),
])
def test_bad_maps_are_refused(kwargs, words):
    value = kwargs.pop("height_value", 0.5)
    args = {"scale": SCALE} | kwargs
    with pytest.raises(UsageError, match=None) as info:
        flat(value=value, **args)
    assert words in str(info.value) and "\n" not in str(info.value)


def test_a_base_without_uvs_is_refused():
    from reliefkit.scene.mesh import RenderMesh

    b = square_base()
    bare = RenderMesh(b.world_positions, b.indices, b.normals, b.colors, None)
    with pytest.raises(UsageError, match="uvs"):
        DisplacementMap(bare, np.ones((4, 4, 4), np.float32), np.zeros((4, 4), np.float32), 1.0)
