"""Baking displacement-mapped billboard clouds: the boxes' planes, the three variants against
analytic meshes (quads and a cube coloured by a known function of position), the distance
textures against a brute-force distance, memory and determinism."""

from __future__ import annotations

import numpy as np
import pytest
from billboard_scenes import colour_of, flat, quads, stacked

from reliefkit.colorspace import srgb_decode
from reliefkit.errors import UsageError
from reliefkit.scene.mesh import RenderMesh
from reliefkit.techniques.billboard.bake import bake_billboard_cloud
from reliefkit.techniques.billboard.box_bake import bake_boxes
from reliefkit.techniques.billboard.boxes import MAX_DISTANCE
from reliefkit.techniques.billboard.distance import voxel_sides


def cube(subdivisions: int = 3) -> RenderMesh:
    import trimesh

    mesh = trimesh.creation.box(extents=(2, 2, 2))
    for _ in range(subdivisions):
        mesh = mesh.subdivide()
    corners = np.asarray(mesh.vertices)[np.asarray(mesh.faces).reshape(-1)]
    n = np.cross(corners[1::3] - corners[0::3], corners[2::3] - corners[0::3])
    normals = np.repeat(n / np.linalg.norm(n, axis=1, keepdims=True), 3, axis=0)
    return RenderMesh(corners, np.arange(len(corners)).reshape(-1, 3), normals,
                      colour_of(corners), name="cube")


def to_box(box, points) -> np.ndarray:
    inverse = np.linalg.inv(box.box_to_world)
    return np.asarray(points) @ inverse[:3, :3].T + inverse[:3, 3]


def column_points(box, w: np.ndarray | float = 0.5) -> np.ndarray:
    """(H, W, 3) world points of the texel centres at box height w."""
    width, height, _ = box.resolution
    u, v = np.meshgrid((np.arange(width) + 0.5) / width, (np.arange(height) + 0.5) / height)
    uvw = np.stack([u, v, np.broadcast_to(w, u.shape)], -1)
    return uvw @ box.box_to_world[:3, :3].T + box.box_to_world[:3, 3]


def interior(box, margin: int = 1) -> np.ndarray:
    """(H, W) columns at least ``margin`` texels inside the rectangle."""
    width, height, _ = box.resolution
    inside = np.zeros((height, width), bool)
    inside[margin:height - margin, margin:width - margin] = True
    return inside


def plane_w(box, plane_points) -> tuple[np.ndarray, np.ndarray]:
    """The (H, W) box w of the plane through ``plane_points`` above each texel centre, and
    the voxel index it falls in."""
    p = to_box(box, plane_points)
    normal = np.cross(p[1] - p[0], p[2] - p[0])
    width, height, depth = box.resolution
    u, v = np.meshgrid((np.arange(width) + 0.5) / width, (np.arange(height) + 0.5) / height)
    w = p[0, 2] - (normal[0] * (u - p[0, 0]) + normal[1] * (v - p[0, 1])) / normal[2]
    return w, np.floor(w * depth).astype(int)


def decoded_rgb(color8: np.ndarray) -> np.ndarray:
    return srgb_decode(color8[..., :3] / 255.0)


def decoded_normal(normal8: np.ndarray) -> np.ndarray:
    return normal8 / 127.5 - 1.0


# -- 1: the planes ----------------------------------------------------------------------

def test_the_boxes_stand_on_the_planes_of_the_flat_cloud(gl):
    mesh = cube()
    boxes = bake_boxes(mesh, "shell", epsilon=0.05, texel_size=0.1)
    flat_cloud = bake_billboard_cloud(mesh, epsilon=0.05, texel_size=0.1)
    for name in ("corners", "u_axes", "v_axes", "rects", "color", "normal"):
        assert np.array_equal(getattr(boxes.cloud, name), getattr(flat_cloud, name)), name
    assert boxes.epsilon == flat_cloud.epsilon
    for p, box in enumerate(boxes.boxes):
        m = box.box_to_world
        assert np.allclose(m[:3, 0], flat_cloud.u_axes[p]) and np.allclose(m[:3, 1],
                                                                           flat_cloud.v_axes[p])
        assert np.isclose(np.linalg.norm(m[:3, 2]), 2 * flat_cloud.epsilon)
        assert box.resolution[:2] == tuple(flat_cloud.rects[p][3:])


# -- 2: volumetric ----------------------------------------------------------------------

def test_a_plane_parallel_quad_fills_exactly_its_layer_with_its_colour_and_normal(gl):
    mesh = quads(flat(0.0))  # diagonal sqrt(5): epsilon 0.1118, D = round(4.97) = 5
    boxes = bake_boxes(mesh, epsilon=0.05, texel_size=0.045)
    (box,) = boxes.boxes
    width, height, depth = box.resolution
    assert depth == 5
    w, k = plane_w(box, flat(0.0)[:3])
    assert np.allclose(w, 0.5)  # the plane goes through the quad: the middle layer
    occupied = box.color[..., 3] == 255
    assert set(np.unique(box.color[..., 3])) <= {0, 255}
    expected = np.zeros_like(occupied)
    expected[2] = True
    assert np.array_equal(occupied, expected)
    rgb = decoded_rgb(box.color[2])
    assert np.abs(rgb - colour_of(column_points(box))[..., :3]).max() < 0.01
    assert np.abs(decoded_normal(box.normal[2]) - [0, 0, 1]).max() < 0.01


def cells_cut(box, w: np.ndarray) -> np.ndarray:
    """(D, H, W): the cells a plane of box height ``w`` (per texel centre, linear in u, v)
    meets over each texel's footprint."""
    depth = box.resolution[2]
    dv, du = np.gradient(w)
    spread = 0.5 * (np.abs(du) + np.abs(dv)) + 1e-6
    layers = np.arange(depth)[:, None, None]
    return (layers / depth <= w + spread) & ((layers + 1) / depth >= w - spread)


def test_a_tilted_quad_occupies_the_voxels_it_passes_through(gl):
    """A flat quad below forces the plane; the tilted one crosses layers. Every occupied
    voxel is cut by one of the two, and the voxel holding the tilted surface above each texel
    centre is occupied, with its colour and normal."""
    tilt = np.array([[-1, -0.5, -0.06], [1, -0.5, 0.06], [1, 0.5, 0.06], [-1, 0.5, -0.06]])
    below = flat(-0.1, half=(1.2, 0.6))
    mesh = quads(tilt, below)
    boxes = bake_boxes(mesh, epsilon=0.05, texel_size=0.04)
    (box,) = boxes.boxes
    w, k = plane_w(box, tilt[:3])
    w_below, k_below = plane_w(box, below[:3])
    assert np.ptp(k) >= 2  # it really crosses layers
    points = column_points(box)
    inside = (np.abs(points[..., 0]) < 0.95) & (np.abs(points[..., 1]) < 0.45)
    occupied = box.color[..., 3] == 255
    cut = cells_cut(box, w) | cells_cut(box, w_below)
    assert not (occupied[:, inside] & ~cut[:, inside]).any()
    rows, cols = np.nonzero(inside)
    layer = k[rows, cols]
    assert occupied[layer, rows, cols].all()
    alone = ~cells_cut(box, w_below)[layer, rows, cols]  # not shared with the flat quad
    assert alone.mean() > 0.5
    rows, cols, layer = rows[alone], cols[alone], layer[alone]
    rgb = decoded_rgb(box.color[layer, rows, cols])
    surface = column_points(box, w)[rows, cols]
    assert np.abs(rgb - colour_of(surface)[:, :3]).max() < 0.03
    n = np.cross(tilt[1] - tilt[0], tilt[2] - tilt[0])
    n /= np.linalg.norm(n)
    assert np.abs(decoded_normal(box.normal[layer, rows, cols]) - n).max() < 0.01


def test_each_cube_face_fills_one_layer_of_its_box(gl):
    mesh = cube()
    boxes = bake_boxes(mesh, epsilon=0.05, texel_size=0.1)
    assert len(boxes.boxes) == 6
    for box in boxes.boxes:
        axis_n = box.box_to_world[:3, 2] / np.linalg.norm(box.box_to_world[:3, 2])
        axis = int(np.argmax(np.abs(axis_n)))
        face = column_points(box)
        face[..., axis] = np.sign(axis_n[axis])  # the face point above each texel centre
        w = to_box(box, face)[..., 2]
        k = np.floor(w * box.resolution[2]).astype(int)
        assert np.ptp(k) == 0 and np.abs(w * box.resolution[2] - k - 0.5).max() < 0.45
        inside = interior(box)
        occupied = box.color[..., 3] == 255
        expected = np.zeros_like(occupied)
        expected[k[0, 0]] = True
        assert np.array_equal(occupied[:, inside], expected[:, inside])
        layer = k[0, 0]
        rgb = decoded_rgb(box.color[layer])[inside]
        assert np.abs(rgb - colour_of(face)[inside][:, :3]).max() < 0.01
        assert np.abs(decoded_normal(box.normal[layer][inside]) - axis_n).max() < 0.01


def test_outside_prefers_the_outer_side_of_a_thin_double_sided_sheet(gl):
    """A red sheet facing +z over a smaller blue one facing -z, a hair below, in the same
    voxels: averaging mixes the colours and cancels the normals, "outside" shows the red."""
    red, blue = (0.8, 0.1, 0.1, 1.0), (0.1, 0.1, 0.8, 1.0)
    mesh = quads(flat(0.0), flat(-0.001, half=(0.8, 0.4), down=True), colours=[red, blue])
    kw = {"epsilon": 0.05, "texel_size": 0.045}
    average = bake_boxes(mesh, **kw).boxes[0]
    outside = bake_boxes(mesh, surfaces="outside", **kw).boxes[0]
    assert len(bake_boxes(mesh, **kw).boxes) == 1
    assert np.array_equal(average.color[..., 3], outside.color[..., 3])
    both = column_points(outside)
    shared = (np.abs(both[..., 0]) < 0.7) & (np.abs(both[..., 1]) < 0.3)
    layer = np.argmax(outside.color[..., 3] == 255, axis=0)
    rows, cols = np.nonzero(shared)
    out_rgb = decoded_rgb(outside.color[layer[rows, cols], rows, cols])
    avg_rgb = decoded_rgb(average.color[layer[rows, cols], rows, cols])
    assert np.abs(out_rgb - red[:3]).max() < 0.01
    assert np.abs(avg_rgb - np.add(red[:3], blue[:3]) / 2).max() < 0.02
    assert np.abs(decoded_normal(outside.normal[layer[rows, cols], rows, cols])
                  - [0, 0, 1]).max() < 0.01
    assert np.abs(decoded_normal(average.normal[layer[rows, cols], rows, cols])).max() < 0.01


# -- 3, 4: shells -----------------------------------------------------------------------

def test_a_shell_of_a_plane_parallel_quad_displaces_to_its_w(gl):
    mesh = quads(flat(0.0))
    boxes = bake_boxes(mesh, "shell", epsilon=0.05, texel_size=0.045, thickness=0.3)
    (box,) = boxes.boxes
    depth = box.resolution[2]
    covered = box.color[..., 3] == 255
    assert covered[interior(box)].all()
    w, _ = plane_w(box, flat(0.0)[:3])
    d = box.displacement[..., 0] / 65535
    # voxel-centre displacement: within half a voxel of the surface, plus the encoding
    assert np.abs(d - w)[covered].max() <= 0.5 / depth + 1 / 65535
    assert boxes.thickness == 0.3 and boxes.params["thickness_auto"] is False
    rgb = decoded_rgb(box.color)
    assert np.abs(rgb - colour_of(column_points(box))[..., :3])[covered].max() < 0.01


def test_automatic_thickness_is_the_spread_of_the_displacements(gl):
    mesh = quads(flat(0.0), flat(0.1, half=(0.5, 0.25)))  # two heights: a real spread
    boxes = bake_boxes(mesh, "shell", epsilon=0.05, texel_size=0.015)
    values = np.concatenate([b.displacement[..., 0][b.color[..., 3] >= 128] / 65535
                             for b in boxes.boxes])
    depth = boxes.boxes[0].resolution[2]
    expected = min(max(float(np.std(values)), 1 / depth), 1.0)
    assert expected > 1 / depth  # not the clamp
    assert boxes.thickness == pytest.approx(expected, abs=1e-9)
    assert boxes.params["thickness"] == boxes.thickness and boxes.params["thickness_auto"]
    one = bake_boxes(quads(flat(0.0)), "shell", epsilon=0.05, texel_size=0.045)
    assert one.thickness == pytest.approx(1 / one.boxes[0].resolution[2])  # no spread: clamp


@pytest.mark.parametrize("surfaces", ["average", "outside"])
def test_a_shell_of_stacked_quads_keeps_the_upper_one(gl, surfaces):
    """The lower quad is hidden under the upper one from the box's outside: the shell sits on
    the upper quad and shows its colour, whichever way shared voxels combine."""
    boxes = bake_boxes(stacked(), "shell", epsilon=0.05, texel_size=0.03, thickness=0.2,
                       surfaces=surfaces)
    (box,) = boxes.boxes
    depth = box.resolution[2]
    w_high, k_high = plane_w(box, flat(0.1)[:3])
    _, k_low = plane_w(box, flat(0.0)[:3])
    assert (k_high > k_low + 1).all()  # a gap between the two: two surfaces
    points = column_points(box)
    both = (np.abs(points[..., 0]) < 0.85) & (np.abs(points[..., 1]) < 0.4)
    d = box.displacement[..., 0] / 65535
    assert np.allclose(d[both], ((k_high + 0.5) / depth)[both], atol=1 / 65535)
    high = colour_of(column_points(box, w_high))[both][:, :3]
    assert np.abs(decoded_rgb(box.color[both]) - high).max() < 0.01


def sawtooth_z(x: np.ndarray) -> np.ndarray:
    """Teeth 0.2 wide between z = -0.1 and 0.1: slopes of 2, two voxels per column."""
    phase = np.mod(x + 1, 0.2) / 0.1
    return 0.1 * (np.minimum(phase, 2 - phase) * 2 - 1)


def test_a_shell_of_a_steep_surface_sits_in_the_middle_of_its_voxels(gl):
    """Where one surface crosses several voxels of a column, the shell's displacement is the
    middle of that run: within half a voxel of where the surface crosses the column's centre
    line (not its highest voxel, which sits up to the run's half length above it)."""
    x = np.linspace(-1, 1, 21)
    mesh = quads(*[[[a, -0.5, sawtooth_z(a)], [b, -0.5, sawtooth_z(b)],
                    [b, 0.5, sawtooth_z(b)], [a, 0.5, sawtooth_z(a)]]
                   for a, b in zip(x[:-1], x[1:], strict=True)])
    (box,) = bake_boxes(mesh, "shell", epsilon=0.05, texel_size=0.02, thickness=0.2).boxes
    depth = box.resolution[2]
    points = column_points(box)
    surface = np.stack([points[..., 0], points[..., 1], sawtooth_z(points[..., 0])], -1)
    w = to_box(box, surface)[..., 2]
    kink = np.abs(np.mod(points[..., 0] + 1 + 0.05, 0.1) - 0.05)  # distance to a kink
    steep = interior(box) & (kink > 0.02) & (box.color[..., 3] == 255)
    d = box.displacement[..., 0] / 65535
    assert steep.sum() > 100
    assert np.abs(d - w)[steep].max() <= 0.75 / depth


def closed_box_around_a_red_plate() -> RenderMesh:
    """A closed grey cube of side 2 and, hidden inside it 0.1 under the lid (within
    epsilon 0.05, 0.17, of the lid's plane), a red double-sided plate."""
    grey, red = (0.5, 0.5, 0.5, 1.0), (0.9, 0.05, 0.05, 1.0)
    square = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], float)
    sides = []
    for axis in range(3):
        for sign in (-1, 1):
            corners = np.insert(square, axis, sign, axis=1)
            normal = np.cross(corners[1] - corners[0], corners[2] - corners[0])
            sides.append(corners if normal[axis] * sign > 0 else corners[::-1])
    plate = [flat(0.9, half=(0.8, 0.8)), flat(0.89, half=(0.8, 0.8), down=True)]
    return quads(*sides, *plate, colours=[grey] * 6 + [red] * 2)


@pytest.mark.parametrize("variant", ["shell", "thick-shell"])
def test_shells_do_not_show_what_a_closed_model_hides(gl, variant):
    """The plate shares the lid's box and columns; the mesh hides it, so must the shells with
    the default surfaces (averaging each column showed it through the lid as a red tint)."""
    from reliefkit.render import render
    from reliefkit.scene.camera import Camera
    from reliefkit.scene.light import DirectionalLight

    mesh = closed_box_around_a_red_plate()
    boxes = bake_boxes(mesh, variant, epsilon=0.05, texel_size=0.05)
    centres = [b.box_to_world[:3] @ [0.5, 0.5, 0.5, 1] for b in boxes.boxes]
    assert sum(c[2] > 0.5 for c in centres) == 1  # the plate is in the lid's box
    camera = Camera(eye=(0.6, 1.0, 3.5), target=(0, 0, 0), up=(0, 1, 0), size=(96, 96),
                    fov_deg=40, near=0.5, far=10)
    light = DirectionalLight(intensity=0.0, ambient=1.0, specular=0.0)
    truth, frame = render(mesh, camera, light=light), render(boxes, camera, light=light)
    both = truth.mask & frame.mask
    assert both.sum() > 0.9 * truth.mask.sum()
    assert np.abs(truth.color[truth.mask, :3] - 0.5).max() < 0.01  # the mesh shows grey only
    tint = frame.color[both, 0] - frame.color[both, 1]
    assert np.abs(frame.color[both, :3] - 0.5).max() < 0.02, f"red tint up to {tint.max():.3f}"


@pytest.mark.parametrize("variant", ["shell", "thick-shell"])
def test_shells_show_the_outward_surface_under_an_underside(gl, variant):
    """A column along a wall: the underside of something closed beyond the box (the van's
    window sill, facing -w, seen from the box on its belt line) above a surface facing +w
    (the door's chamfer). From w = 1 the mesh shows the +w-facing one (the sill's top hides
    the underside), and a thick shell seen from the side paints its one colour over the
    whole interval: taking the underside's painted the glass down the van's doors."""
    paint, glass = (0.1, 0.5, 0.2, 1.0), (0.02, 0.03, 0.05, 1.0)
    mesh = quads(flat(0.0), flat(0.1, half=(0.9, 0.45), down=True), colours=[paint, glass])
    (box,) = bake_boxes(mesh, variant, epsilon=0.05, texel_size=0.03).boxes
    depth = box.resolution[2]
    _, k_low = plane_w(box, flat(0.0)[:3])
    _, k_high = plane_w(box, flat(0.1)[:3])
    points = column_points(box)
    both = (np.abs(points[..., 0]) < 0.85) & (np.abs(points[..., 1]) < 0.4)
    assert (k_high > k_low + 1).all() and both.sum() > 100
    assert np.abs(decoded_rgb(box.color[both]) - paint[:3]).max() < 0.01
    assert (decoded_normal(box.normal[both])[:, 2] > 0.9).all()  # the +w-facing one's
    if variant == "shell":
        d = box.displacement[..., 0] / 65535
        assert np.allclose(d[both], ((k_low + 0.5) / depth)[both], atol=1 / 65535)


def test_a_thick_shell_of_stacked_quads_spans_both_cells(gl):
    mesh = stacked()
    boxes = bake_boxes(mesh, "thick-shell", epsilon=0.05, texel_size=0.03)
    (box,) = boxes.boxes
    depth = box.resolution[2]
    _, k_low = plane_w(box, flat(0.0)[:3])
    _, k_high = plane_w(box, flat(0.1)[:3])
    points = column_points(box)
    both = (np.abs(points[..., 0]) < 0.85) & (np.abs(points[..., 1]) < 0.4)
    only_low = (np.abs(points[..., 0]) > 0.95) & (np.abs(points[..., 1]) < 0.45)
    lo, hi = box.displacement[..., 0] / 65535, box.displacement[..., 1] / 65535
    assert np.allclose(lo[both], (k_low / depth)[both], atol=1 / 65535)
    assert np.allclose(hi[both], ((k_high + 1) / depth)[both], atol=1 / 65535)
    assert np.allclose(hi[only_low] - lo[only_low], 1 / depth, atol=2 / 65535)
    assert boxes.thickness is None and box.displacement.shape[2] == 2


# -- 5: distance textures ---------------------------------------------------------------

def brute_force_distance(occupied: np.ndarray, box_to_world: np.ndarray) -> np.ndarray:
    sides = voxel_sides(box_to_world, occupied.shape)
    sides = sides / sides.min()
    grid = np.stack(np.meshgrid(*(np.arange(n) for n in occupied.shape), indexing="ij"), -1)
    centres = grid.reshape(-1, 3) * sides
    filled = centres[occupied.reshape(-1)]
    nearest = np.sqrt(((centres[:, None] - filled[None]) ** 2).sum(-1)).min(axis=1)
    return np.minimum(np.floor(nearest + 1e-6), MAX_DISTANCE).reshape(occupied.shape)


def reference_occupancy(boxes, box) -> np.ndarray:
    """The variant's occupied cells, from its stored maps alone."""
    depth = box.resolution[2]
    if boxes.variant == "volumetric":
        return box.color[..., 3] >= 128
    covered = box.color[..., 3] >= 128
    d = box.displacement / 65535
    if boxes.variant == "shell":
        lo = np.clip(d[..., 0] - boxes.thickness / 2, 0, 1)
        hi = np.clip(d[..., 0] + boxes.thickness / 2, 0, 1)
    else:
        lo, hi = d[..., 0], d[..., 1]
    k = np.arange(depth)[:, None, None]
    return covered & (k / depth < hi - 1 / 65535) & ((k + 1) / depth > lo + 1 / 65535)


@pytest.mark.parametrize("variant", ["volumetric", "shell", "thick-shell"])
def test_distance_textures_match_a_brute_force_distance(gl, variant):
    tilt = np.array([[-1, -0.5, -0.05], [1, -0.5, 0.05], [1, 0.5, 0.02], [-1, 0.5, -0.08]])
    mesh = quads(tilt[[0, 1, 2, 3]], flat(0.05, half=(0.4, 0.2)))
    boxes = bake_boxes(mesh, variant, epsilon=0.06, texel_size=0.1, thickness=(
        0.25 if variant == "shell" else None))
    for box in boxes.boxes:
        occupied = reference_occupancy(boxes, box)
        assert occupied.any() and not occupied.all()
        assert np.array_equal(box.distance, brute_force_distance(occupied, box.box_to_world))
        assert (box.distance[occupied] == 0).all() and (box.distance[~occupied] > 0).all()


# -- 6, 7: memory, determinism, bad parameters ------------------------------------------

def test_memory_follows_table_2_on_the_tree(gl):
    from reliefkit.scene.assets import make_asset

    mesh = make_asset("tree")
    diagonal = float(np.linalg.norm(np.subtract(*mesh.bounds[::-1])))
    figures = {}
    for variant in ("volumetric", "shell", "thick-shell"):
        boxes = bake_boxes(mesh, variant, texel_size=diagonal / 192)
        memory = boxes.memory_bytes()
        arrays = {"color": 0, "normal": 0, "distance": 0, "displacement": 0}
        for box in boxes.boxes:
            for name in arrays:
                value = getattr(box, name)
                arrays[name] += 0 if value is None else value.nbytes
        assert {k: memory[k] for k in arrays} == arrays
        assert memory["billboard_cloud"] == sum(boxes.cloud.memory_bytes().values())
        figures[variant] = sum(arrays.values())
        figures["bbc"] = memory["billboard_cloud"]
    print("tree at diagonal/192, bytes:", figures)
    assert figures["volumetric"] > 4 * figures["shell"]
    assert figures["thick-shell"] > figures["shell"] > figures["bbc"]


def test_two_bakes_are_equal(gl):
    mesh = stacked()
    a = bake_boxes(mesh, "thick-shell", epsilon=0.05, texel_size=0.05, surfaces="outside")
    b = bake_boxes(mesh, "thick-shell", epsilon=0.05, texel_size=0.05, surfaces="outside")
    for x, y in zip(a.boxes, b.boxes, strict=True):
        for name in ("box_to_world", "color", "normal", "distance", "displacement"):
            assert np.array_equal(getattr(x, name), getattr(y, name))
    assert a.params["generation"]["planes"] == b.params["generation"]["planes"]


@pytest.mark.parametrize("kwargs, message", [
    ({"variant": "voxels"}, "variant must be one of"),
    ({"variant": "shell", "thickness": 0.0}, "thickness must be"),
    ({"variant": "shell", "thickness": 1.5}, "thickness must be"),
    ({"variant": "shell", "thickness": True}, "thickness must be"),
    ({"variant": "volumetric", "thickness": 0.5}, "only to the shell"),
    ({"surfaces": "inside"}, "surfaces must be one of"),
])
def test_bad_parameters_are_one_line_usage_errors(kwargs, message):
    with pytest.raises(UsageError, match=message) as error:
        bake_boxes(quads(flat(0.0)), **kwargs)
    assert "\n" not in str(error.value)


def test_too_many_voxels_are_refused_before_baking(gl):
    calls = []
    with pytest.raises(UsageError, match="larger --texel-size") as error:
        bake_boxes(quads(flat(0.0)), epsilon=0.2, texel_size=0.002,
                   progress=lambda done, total: calls.append((done, total)))
    assert "\n" not in str(error.value)
    assert all(done <= 2 for done, _ in calls)  # only the plane generation ran
