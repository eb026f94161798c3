"""Billboard cloud baking: atlas packing, and each rectangle's maps against the mesh's own
colours and normals (analytic meshes whose colour is a known function of position)."""

from __future__ import annotations

import numpy as np
import pytest
from helpers import triangles_covering

from reliefkit.colorspace import srgb_decode
from reliefkit.errors import UsageError
from reliefkit.scene.mesh import RenderMesh
from reliefkit.techniques.billboard.atlas import pack
from reliefkit.techniques.billboard.bake import bake_billboard_cloud
from reliefkit.techniques.billboard.representation import GUTTER


def test_packed_blocks_never_overlap_and_stay_inside_their_page():
    sizes = [(37, 12), (5, 60), (64, 64), (1, 1), (20, 33), (40, 7)] * 3
    side, pages, placed = pack(sizes, max_page=128)
    assert pages > 1 and side == 128
    taken = np.zeros((pages, side, side), int)
    for (w, h), (page, x, y) in zip(sizes, placed, strict=True):
        assert x - GUTTER >= 0 and y - GUTTER >= 0
        assert x + w + GUTTER <= side and y + h + GUTTER <= side
        taken[page, y - GUTTER:y + h + GUTTER, x - GUTTER:x + w + GUTTER] += 1
    assert taken.max() == 1  # gutters included
    again = pack(sizes, max_page=128)
    assert again[0] == side and np.array_equal(again[2], placed)


def test_one_page_is_the_smallest_power_of_two_that_holds_everything():
    side, pages, _ = pack([(10, 10)] * 4)
    assert (side, pages) == (32, 1)  # 4 blocks of 14 with gutters: 28 <= 32
    with pytest.raises(UsageError, match="texel-size"):
        pack([(5000, 10)])


def colour_of(points: np.ndarray) -> np.ndarray:
    """The test meshes' linear colour at world points: a smooth function of position."""
    p = np.asarray(points, dtype=np.float64)
    return np.stack([0.2 + 0.3 * (p[..., 0] + 1), 0.2 + 0.3 * (p[..., 1] + 1),
                     0.2 + 0.3 * (p[..., 2] + 1), np.ones(p.shape[:-1])], axis=-1)


def box(subdivisions: int = 4) -> RenderMesh:
    """The cube [-1, 1]^3 with finely subdivided faces, coloured by `colour_of`."""
    import trimesh

    mesh = trimesh.creation.box(extents=(2, 2, 2))
    for _ in range(subdivisions):
        mesh = mesh.subdivide() if len(mesh.faces) < 2000 else mesh
    positions = np.asarray(mesh.vertices)
    faces = np.asarray(mesh.faces)
    # flat-shaded faces: one vertex per corner, so the normal is the face's own
    corners = positions[faces.reshape(-1)]
    face_normals = np.repeat(np.cross(corners[1::3] - corners[0::3], corners[2::3] - corners[0::3]),
                             3, axis=0)
    normals = face_normals / np.linalg.norm(face_normals, axis=1, keepdims=True)
    return RenderMesh(corners, np.arange(len(corners)).reshape(-1, 3), normals,
                      colour_of(corners), name="box")


def block(cloud, p: int, array: np.ndarray) -> np.ndarray:
    page, x, y, w, h = cloud.rects[p]
    return array[page, y:y + h, x:x + w]


def texel_points(cloud, p: int) -> np.ndarray:
    """(h, w, 3) world points of rectangle p's texel centres (row j = t, column i = s)."""
    w, h = cloud.rects[p][3:]
    s, t = np.meshgrid((np.arange(w) + 0.5) / w, (np.arange(h) + 0.5) / h)
    return (cloud.corners[p] + s[..., None] * cloud.u_axes[p]
            + t[..., None] * cloud.v_axes[p])


def footprint(cloud, p: int, triangles: np.ndarray) -> np.ndarray:
    """(h, w) texels of rectangle p well inside the projection of `triangles` (F, 3, 3): the
    centre and four points 0.3 texel around it each inside one of them."""
    w, h = cloud.rects[p][3:]
    u, v = cloud.u_axes[p], cloud.v_axes[p]
    st = np.stack([(triangles - cloud.corners[p]) @ u / (u @ u),
                   (triangles - cloud.corners[p]) @ v / (v @ v)], axis=-1)
    s, t = np.meshgrid((np.arange(w) + 0.5) / w, (np.arange(h) + 0.5) / h)
    inside = np.ones((h, w), bool)
    for ds, dt in ((0, 0), (0.3, 0), (-0.3, 0), (0, 0.3), (0, -0.3)):
        points = np.stack([(s + ds / w).ravel(), (t + dt / h).ravel()], axis=1)
        inside &= (triangles_covering(st, points) > 0).reshape(h, w)
    return inside


def test_a_box_bakes_each_planes_faces_with_their_colours_and_normals(gl):
    """Each plane holds a face of the box and, within epsilon, strips of the side faces along
    its edges (so it may lie a little inside the face). Seen from outside, each texel over
    the plane's own faces shows the face point straight below it, its colour and normal."""
    from reliefkit.techniques.billboard.cloud import build_billboard_cloud

    mesh = box()
    cloud = bake_billboard_cloud(mesh, epsilon=0.05, texel_size=0.05)
    plan = build_billboard_cloud(mesh, epsilon=0.05, texel_size=0.05)  # deterministic
    assert cloud.count == len(plan.planes) == 6
    corners = mesh.world_positions[mesh.indices]
    normals = cloud.normals
    for p, plane in enumerate(plan.planes):
        axis = int(np.argmax(np.abs(normals[p])))
        assert np.abs(normals[p][axis]) > 0.999
        mine = corners[plane.faces]
        facing = np.abs(np.cross(mine[:, 1] - mine[:, 0], mine[:, 2] - mine[:, 0])[:, axis]) > 0
        inside = footprint(cloud, p, mine[facing])  # the strips are seen edge-on
        assert inside.sum() > 0.5 * inside.size
        on_face = texel_points(cloud, p)
        on_face[..., axis] = np.sign(normals[p][axis])
        alpha = block(cloud, p, cloud.color)[..., 3]
        assert (alpha[inside] == 255).all()
        rgb = srgb_decode(block(cloud, p, cloud.color)[..., :3] / 255.0)
        assert np.abs(rgb[inside] - colour_of(on_face)[inside][:, :3]).max() < 0.01
        decoded = block(cloud, p, cloud.normal)[inside] / 127.5 - 1.0
        assert np.abs(decoded - normals[p]).max() < 0.01
        # the plane's normal points out of the box, through the face it holds
        assert normals[p] @ texel_points(cloud, p).reshape(-1, 3).mean(axis=0) > 0.7
    assert cloud.params["generation"]["skipped"] == 0


def test_an_open_card_maps_s_and_t_like_its_rectangle(gl):
    """A lone quad with colour varying along x and y: every covered texel shows the colour of
    the world point its (s, t) names (a mirrored or rotated atlas fails)."""
    quad = np.array([[-1, -0.5, 0.2], [1, -0.5, 0.2], [1, 0.5, 0.2], [-1, 0.5, 0.2]])
    rotated = quad @ np.array([[0.8, 0.6, 0], [-0.6, 0.8, 0], [0, 0, 1.0]]).T
    mesh = RenderMesh(rotated, [[0, 1, 2], [0, 2, 3]], np.tile([0, 0, 1.0], (4, 1)),
                      colour_of(rotated), name="card")
    cloud = bake_billboard_cloud(mesh, texel_size=0.05)
    assert cloud.count == 1
    alpha = block(cloud, 0, cloud.color)[..., 3]
    covered = alpha == 255
    assert covered.mean() > 0.8
    rgb = srgb_decode(block(cloud, 0, cloud.color)[..., :3] / 255.0)
    expected = colour_of(texel_points(cloud, 0))[..., :3]
    assert np.abs(rgb[covered] - expected[covered]).max() < 0.02


def test_too_many_texels_are_refused_before_anything_is_allocated(gl):
    with pytest.raises(UsageError, match="larger --texel-size"):
        bake_billboard_cloud(box(), texel_size=2e-4)


def test_the_plan_is_kept_in_the_params(gl):
    cloud = bake_billboard_cloud(box(), epsilon=0.05, max_planes=2, texel_size=0.1)
    assert cloud.count == 2 and cloud.params["max_planes"] == 2
    generation = cloud.params["generation"]
    assert generation["skipped"] > 0 and "max_planes" in generation["skipped_reason"]
