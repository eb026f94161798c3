"""Relief texture rendering on analytic scenes: planes, depth modes, camera inside the box."""

import numpy as np
import pytest
import trimesh
from helpers import BOX, make_relief

from reliefkit.render import render
from reliefkit.scene.camera import Camera
from reliefkit.scene.mesh import RenderMesh, vertex_normals

METHODS = ["binary", "exact", "robust", "maxmip", "cone"]
#: robust walks short rays exactly (the small test fields would never jump): off here
OPTIONS = {"robust": {"exact_field": 0}}


def flat(level, n=32):
    h = np.full((n, n), level, np.float32)
    h[0, :] = h[-1, :] = h[:, 0] = h[:, -1] = 0.0
    return h


def plane_hits(camera, y):
    origins, dirs = camera.pixel_rays()
    t = (y - origins[..., 1]) / dirs[..., 1]
    return origins + t[..., None] * dirs, t


@pytest.mark.parametrize("method", METHODS)
def test_flat_surface_positions_lie_on_the_plane(gl, method):
    relief = make_relief(flat(0.5))
    camera = Camera.orbit((0, 0.5, 0), 30, 40, 3.5, size=(64, 64))
    frame = render(relief, camera, method=method, **OPTIONS.get(method, {}))
    hits, _ = plane_hits(camera, 0.5)
    inner = (np.abs(hits[..., 0]) < 0.85) & (np.abs(hits[..., 2]) < 0.85)
    assert inner.sum() > 500 and frame.mask[inner].all()
    # 2 texels of 1/16 each: the border ring ramps from 0.5 down to 0 there
    assert not frame.mask[(np.abs(hits[..., 0]) > 1.1) & (np.abs(hits[..., 2]) > 1.1)].any()
    err = np.linalg.norm(frame.position[inner] - hits[inner], axis=-1)
    assert err.max() < 1e-3
    core = (np.abs(hits[..., 0]) < 0.7) & (np.abs(hits[..., 2]) < 0.7)  # normals off the rim
    np.testing.assert_allclose(frame.normal[core], np.tile([0, 1.0, 0], (core.sum(), 1)),
                               atol=1e-4)


def _sphere(center, radius, rgb=(0.9, 0.1, 0.1)):
    s = trimesh.creation.icosphere(subdivisions=4, radius=radius)
    p = (s.vertices + center).astype(np.float32)
    return RenderMesh(p, s.faces, vertex_normals(p, s.faces), np.tile([*rgb, 1.0], (len(p), 1)))


@pytest.mark.parametrize("method", METHODS)
def test_penetrating_object_is_hidden_correctly_only_in_exact_depth_mode(gl, method):
    relief = make_relief(flat(0.5))
    center, radius = np.array([0.0, 0.5, 0.0]), 0.3
    sphere = _sphere(center, radius)
    camera = Camera.orbit((0, 0.5, 0), 10, 35, 3.0, size=(64, 64))
    origins, dirs = camera.pixel_rays()
    to_c = center - origins
    b = (to_c * dirs).sum(-1)
    disc = b**2 - (to_c**2).sum(-1) + radius**2
    t_sphere = np.where(disc > 0, b - np.sqrt(np.maximum(disc, 0)), np.inf)
    hits, t_plane = plane_hits(camera, 0.5)
    on_plane = (np.abs(hits[..., 0]) < 0.85) & (np.abs(hits[..., 2]) < 0.85)
    # pixels whose first hit is clearly the sphere's upper cap, or clearly the plane
    sphere_first = (disc > 0.02) & (t_sphere < t_plane - 0.05)
    plane_first = on_plane & (t_plane < t_sphere - 0.05)
    assert sphere_first.sum() > 50 and plane_first.sum() > 20
    for order in ([relief, sphere], [sphere, relief]):
        exact = render(order, camera, method=method, depth_mode="exact",
                       **OPTIONS.get(method, {}))
        red = exact.color[..., 0] > 2 * exact.color[..., 1]
        assert red[sphere_first].all() and not red[plane_first].any()
        conservative = render(order, camera, method=method, depth_mode="conservative",
                              **OPTIONS.get(method, {}))
        red = conservative.color[..., 0] > 2 * conservative.color[..., 1]
        assert not red[sphere_first].any()  # the box's front faces hide the cap


@pytest.mark.parametrize("method", METHODS)
def test_camera_inside_the_box(gl, method):
    tall = BOX @ np.diag([1.0, 1.0, 4.0, 1.0])  # box height 4: the camera fits inside
    relief = make_relief(flat(0.125), tall)  # surface at y = 0.5
    camera = Camera(eye=(0.1, 2.0, 0.2), target=(0.3, 0.5, -0.2), size=(48, 48), fov_deg=60,
                    near=0.01, far=10.0)
    frame = render(relief, camera, method=method, **OPTIONS.get(method, {}))
    hits, t = plane_hits(camera, 0.5)
    inner = (np.abs(hits[..., 0]) < 0.85) & (np.abs(hits[..., 2]) < 0.85) & (t > 0)
    assert inner.mean() > 0.5 and frame.mask[inner].all()
    assert np.linalg.norm(frame.position[inner] - hits[inner], axis=-1).max() < 1e-3


@pytest.mark.parametrize("method", METHODS)
def test_a_box_reaching_past_both_clip_planes_keeps_the_surface_between_them(gl, method):
    # the box reaches in front of the near plane (so its back faces are drawn) and behind
    # the far plane, as a reverse frustum baked without clipping does: the surface between
    # the planes must be drawn whole, not cut where the back faces lie beyond far
    relief = make_relief(flat(0.125))  # surface at y = 0.125 over x, z in [-1, 1]
    camera = Camera(eye=(0.0, 1.5, 3.0), target=(0.0, 0.0, 0.0), size=(64, 64), fov_deg=50,
                    near=2.2, far=3.6)
    frame = render(relief, camera, method=method, **OPTIONS.get(method, {}))
    hits, t = plane_hits(camera, 0.125)
    depth = -(hits @ np.asarray(camera.view)[2, :3] + camera.view[2, 3])
    inner = ((np.abs(hits[..., 0]) < 0.9) & (np.abs(hits[..., 2]) < 0.9) & (t > 0)
             & (depth > camera.near * 1.01) & (depth < camera.far * 0.99))
    assert inner.mean() > 0.1 and frame.mask[inner].all()
    assert np.linalg.norm(frame.position[inner] - hits[inner], axis=-1).max() < 1e-2


def test_robust_needs_safety_radii_only_when_it_jumps(gl):
    from reliefkit.errors import UsageError

    relief = make_relief(flat(0.5))
    relief.safety = None
    camera = Camera.orbit((0, 0, 0), 0, 30, 3.0, size=(8, 8))
    with pytest.raises(UsageError, match="no safety radii.*maxmip"):
        render(relief, camera, method="robust", exact_field=0)
    # a field small enough to be drawn with the exact walk's program needs no radii
    small = render(relief, camera, method="robust")
    exact = render(relief, camera, method="exact")
    assert small.mask.any() and np.array_equal(small.mask, exact.mask)


@pytest.mark.parametrize("octants", [False, True], ids=["single", "octants"])
@pytest.mark.parametrize("axis", ["+x", "-x", "+y", "-y"])
def test_robust_jumps_by_the_radius_of_the_texel_holding_the_walk_position(gl, axis, octants):
    """The radius a jump takes is that of the texel holding the walk position (safety.py's
    contract), read at the end of an exact walk and of a jump alike. Walls in columns 40 and
    52; odd rows have radius 0 (walked exactly: they meet the first wall); even rows have
    radius 2 in column 39 (a jump over the first wall) and 0 after it (they meet the second
    wall). Odd rows' radius 30 in column 41 would carry an even row over the second wall
    too. The radii are deliberately unsafe: a radius read from any neighbouring texel
    changes which wall a ray meets."""
    n = 64
    height = flat(0.1, n)
    height[:, 40] = height[:, 52] = 0.9
    odd = (np.arange(n) % 2 == 1)[:, None]
    safety = np.zeros((n, n), np.uint8)
    safety[:, 39] = np.where(odd[:, 0], 0, 2)
    safety[:, 41] = np.where(odd[:, 0], 30, 0)
    no_first_wall = height.copy()
    no_first_wall[:, 40] = 0.1
    # the rays travel along +u, -u, +v or -v: flip and transpose the field to match
    fields = [height, no_first_wall, safety]
    if axis[0] == "-":
        fields = [np.flip(f, axis=1) for f in fields]
    if axis[1] == "y":
        fields = [f.T for f in fields]
    height, no_first_wall, safety = (np.ascontiguousarray(f) for f in fields)
    relief = make_relief(height, safety=np.stack([safety] * 8) if octants else safety)
    # orthographic along the axis: each ray stays on one row (column) of the field
    azimuth = {"+x": -90, "-x": 90, "+y": 0, "-y": 180}[axis]
    camera = Camera.orbit((0, 0.4, 0), azimuth, 15, 3.0, size=(256, 48), ortho_height=1.2)
    robust = render(relief, camera, method="robust", exact_field=0)
    exact = render(relief, camera, method="exact")
    second = render(make_relief(no_first_wall), camera, method="exact")
    origins, _ = camera.pixel_rays()
    u, v = (origins[..., 0] + 1) / 2 * n, (1 - origins[..., 2]) / 2 * n  # texel coordinates
    minor = v if axis[1] == "x" else u
    clear = np.abs(minor - np.round(minor)) > 0.02  # off the row boundaries
    row_odd = np.floor(minor) % 2 == 1
    # rays that meet the first wall high up (so the second one is in their way too)
    hit = np.nan_to_num(exact.position)
    major = (hit[..., 0] + 1) / 2 * n if axis[1] == "x" else (1 - hit[..., 2]) / 2 * n
    wall = 40.5 if axis[0] == "+" else n - 40.5
    first = exact.mask & clear & (np.abs(major - wall) < 1.0) & (hit[..., 1] > 0.3)
    assert (first & row_odd).sum() > 60 and (first & ~row_odd).sum() > 60
    for rows, expected in ((first & row_odd, exact), (first & ~row_odd, second)):
        assert robust.mask[rows].all() and expected.mask[rows].all()
        np.testing.assert_allclose(robust.position[rows], expected.position[rows], atol=1e-4)


def test_unknown_option_and_method_are_errors(gl):
    from reliefkit.errors import UsageError

    relief = make_relief(flat(0.5))
    camera = Camera.orbit((0, 0, 0), 0, 30, 3.0, size=(8, 8))
    with pytest.raises(UsageError, match="method must be one of binary, exact, robust"):
        render(relief, camera, method="magic")
    with pytest.raises(UsageError, match="unknown render option"):
        render(relief, camera, colour="red")


def test_shadows_darken_the_lee_of_a_wall(gl):
    from reliefkit.scene.light import DirectionalLight

    h = flat(0.1, 64)
    h[8:56, 30:34] = 0.9  # a wall across the field
    relief = make_relief(h)
    light = DirectionalLight(direction=(-1.0, 1.0, 0.0), specular=0.0)  # from -x, 45 deg up
    camera = Camera(eye=(0, 3.0, 0.001), target=(0, 0, 0), size=(64, 64), fov_deg=45)
    lit = render(relief, camera, method="exact", light=light)
    shaded = render(relief, camera, method="exact", light=light, shadows=True)
    x = shaded.position[..., 0]
    floor = shaded.mask & (shaded.position[..., 1] < 0.15) & (np.abs(shaded.position[..., 2])
                                                               < 0.5)
    lee = floor & (x > 0.15) & (x < 0.6)      # within the wall's shadow (length 0.8)
    open_side = floor & (x < -0.2)
    assert lee.sum() > 20 and open_side.sum() > 20
    ratio = shaded.color[..., 1][lee].mean() / lit.color[..., 1][lee].mean()
    assert ratio < 0.5
    np.testing.assert_allclose(shaded.color[open_side], lit.color[open_side], atol=1e-5)


def _box_on_the_ground():
    """A 1 x 0.5 x 1 box standing on a 2 x 2 ground slab, flat-shaded."""
    box = trimesh.creation.box((1.0, 0.5, 1.0))
    box.apply_translation((0, 0.25, 0))
    ground = trimesh.creation.box((2.0, 0.02, 2.0))
    ground.apply_translation((0, -0.01, 0))
    both = trimesh.util.concatenate([box, ground])
    pos = both.vertices[both.faces].reshape(-1, 3).astype(np.float32)  # a vertex per corner
    faces = np.arange(len(pos), dtype=np.uint32).reshape(-1, 3)
    colors = np.tile([0.7, 0.7, 0.7, 1.0], (len(pos), 1)).astype(np.float32)
    return RenderMesh(pos, faces, vertex_normals(pos, faces), colors, name="box")


@pytest.mark.parametrize("method", METHODS)
def test_wall_hits_have_wall_normals_at_every_pixel(gl, method):
    """The bake sees a box's top and the ground, never its sides: the walls that the
    heightfield builds between them have no normal of their own in the map, which gave
    every wall pixel the top's normal (up), or a blend of it with a steep texel's (bright
    dots). Every hit on a wall, away from the box's vertical edges, faces out of its face."""
    from reliefkit.techniques.relief.bake import bake_relief

    relief = bake_relief(_box_on_the_ground(), depth_res=48, safety=method == "robust")
    texel = float(np.linalg.norm(relief.box_to_world[:3, 0])) / relief.height.shape[1]
    camera = Camera.orbit((0, 0.25, 0), azimuth_deg=20, elevation_deg=15, distance=4.0,
                          size=(96, 96))
    frame = render(relief, camera, method=method, **OPTIONS.get(method, {}))
    x, y, z = (frame.position[..., k] for k in range(3))
    ax, az = np.abs(x), np.abs(z)
    wall = (frame.mask & (y > 0.1) & (y < 0.4) & (np.maximum(ax, az) < 0.5 + 1.5 * texel)
            & (np.minimum(ax, az) < 0.5 - 2 * texel))
    outward = np.where((ax > az)[..., None], np.stack([np.sign(x), 0 * x, 0 * x], -1),
                       np.stack([0 * z, 0 * z, np.sign(z)], -1))
    facing = (frame.normal * outward).sum(-1)[wall]
    assert wall.sum() > 200 and facing.min() > 0.95, (wall.sum(), facing.min())


def _checker_relief(height, square=4):
    relief = make_relief(height)
    n = height.shape[0]
    rows, cols = np.mgrid[0:n, 0:n]
    red = ((rows // square + cols // square) % 2).astype(bool)
    relief.color[..., 0] = np.where(red, 255, 0)
    relief.color[..., 1] = np.where(red, 0, 255)
    relief.color[..., 2] = 0
    return relief


@pytest.mark.parametrize("method", ["exact", "maxmip", "robust"])
def test_colour_along_depth_edges_is_the_hit_texels_not_a_blurred_mip(gl, method):
    """A magnified red/green checker on two terraces and a ridge: every pixel whose hit lies
    a texel inside a square is pure red or green (a coarser mip would blend them). Hardware
    derivatives, taken across the quad's other surfaces or discarded fragments, picked
    blended mips along the edges."""
    from reliefkit.scene.light import DirectionalLight

    n, square = 32, 4
    h = flat(0.3, n)
    h[1:-1, n // 2:-1] = 0.7
    h[12:20, 4:8] = 0.95
    relief = _checker_relief(h, square)
    light = DirectionalLight(specular=0.0)
    for az, el in [(75, 25), (200, 40), (300, 35)]:  # magnified: the finest level
        camera = Camera.orbit((0, 0.5, 0), az, el, 3.0, size=(128, 128))
        frame = render(relief, camera, method=method, light=light, **OPTIONS.get(method, {}))
        p = frame.position
        texel = np.stack([(p[..., 0] + 1) / 2 * n, (1 - p[..., 2]) / 2 * n], axis=-1)
        inside = ((texel % square > 1) & (texel % square < square - 1)).all(-1)
        inside &= frame.mask & (texel > 1).all(-1) & (texel < n - 1).all(-1)
        r, g = frame.color[..., 0][inside], frame.color[..., 1][inside]
        mixed = np.minimum(r, g) > 0.05 * np.maximum(r, g)
        assert inside.sum() > 1500
        assert mixed.sum() == 0, f"view {az},{el}: {mixed.sum()} pixels of blended colour"


def test_methods_that_find_the_same_hits_give_the_same_colours(gl):
    from scipy.ndimage import gaussian_filter

    from reliefkit.techniques.relief.safety import safety_radii

    rng = np.random.default_rng(0)
    h = gaussian_filter(rng.random((64, 64)), 2)
    h = ((h - h.min()) / np.ptp(h) * 0.8 + 0.1).astype(np.float32)
    relief = _checker_relief(h, 2)
    relief.safety = safety_radii(h)
    for az, el in [(30, 7), (200, 20)]:
        camera = Camera.orbit((0, 0.5, 0), az, el, 3.0, size=(128, 128))
        frames = {m: render(relief, camera, method=m) for m in ["exact", "maxmip", "robust"]}
        for m in ["maxmip", "robust"]:
            same = frames["exact"].mask & frames[m].mask & (np.linalg.norm(
                frames["exact"].position - frames[m].position, axis=-1) < 1e-5)
            assert same.sum() > 5000
            diff = np.abs(frames["exact"].color - frames[m].color)[same].max()
            assert diff < 1e-3, f"{m} at {az},{el}"
