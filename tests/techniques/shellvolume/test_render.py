"""The GPU renderer of shell volumes against the exact CPU reference (reference.py) and
against analytic slabs; ordering, the half-opacity AOVs, opaque textures, composition with
opaque meshes, shadows, animation and filtering.

The RMSE bound against the reference: both integrate the same samples of the same
trilinear texture, so what differs is float32 arithmetic (about 1e-6) and the GPU's texture
filter, whose interpolation weights have only 8 fractional bits on common hardware (the GL
spec requires no more): a weight off by 2^-9 moves a sample by up to 2^-9 of the local
texel difference, and the opacity of a segment by a few 1e-3 at most. RMSE <= 5e-3 of
premultiplied colour and alpha over the image bounds that with margin; a few pixels on
tetrahedron edges may differ more (rasterization tie rules vs the reference's tie rule), so
at most 0.5% of the pixels may be off by more than 0.05.
"""

from __future__ import annotations

import numpy as np
import pytest
from shell_scenes import grid_mesh, inside_grid, slab_camera, sphere_mesh, texture_from

from reliefkit import render
from reliefkit.io.rk import load, save
from reliefkit.scene.camera import Camera
from reliefkit.scene.mesh import RenderMesh
from reliefkit.techniques.shellvolume import textures
from reliefkit.techniques.shellvolume.reference import reference_render
from reliefkit.techniques.shellvolume.representation import TexturedShell

RMSE_BOUND = 5e-3


def premultiplied(color):
    return np.concatenate([color[..., :3] * color[..., 3:], color[..., 3:]], axis=-1)


def against_reference(frame, ref):
    a, b = premultiplied(frame.color), premultiplied(ref.color)
    rmse = float(np.sqrt(((a - b) ** 2).mean()))
    off = float((np.abs(a - b).max(axis=-1) > 0.05).mean())
    return rmse, off


@pytest.fixture(scope="module")
def cloudy_sphere():
    tex = textures.make_clouds(size=(16, 16, 8)).tiled((2, 1))
    return TexturedShell(sphere_mesh(2), 0.25, tex)


@pytest.fixture(scope="module")
def ellipsoid_grid():
    tex = textures.make_ellipsoids(size=(16, 16, 8)).tiled((2, 2))
    return TexturedShell(grid_mesh(4), 0.3, tex)


def sphere_camera(size=(64, 64), ortho=False, az=30.0, el=25.0):
    return Camera.orbit((0.0, 0.0, 0.0), az, el, 4.0, fov_deg=35.0, size=size,
                        ortho_height=1.4 if ortho else None)


@pytest.mark.parametrize("samples", [2, 8, 24])
@pytest.mark.parametrize("exit_", ["fragment", "vertex"])
@pytest.mark.parametrize("ortho", [False, True])
def test_matches_the_cpu_reference(gl, cloudy_sphere, samples, exit_, ortho):
    cam = sphere_camera(ortho=ortho)
    frame = render(cloudy_sphere, cam, ctx=gl, unlit=True, mip=False, samples=samples,
                   exit=exit_)
    ref = reference_render(cloudy_sphere.shell, cloudy_sphere.texture, cam, samples=samples)
    rmse, off = against_reference(frame, ref)
    assert rmse <= RMSE_BOUND and off <= 0.005, (rmse, off)
    assert frame.color[..., 3].max() > 0.9  # the opaque ground is there


def test_exit_per_vertex_agrees_with_per_fragment(gl, ellipsoid_grid):
    cam = slab_camera(35.0, size=(64, 64), ortho=False)
    a = render(ellipsoid_grid, cam, ctx=gl, unlit=True, exit="fragment")
    b = render(ellipsoid_grid, cam, ctx=gl, unlit=True, exit="vertex")
    assert np.abs(a.color[..., 3] - b.color[..., 3]).max() < 2e-3


def test_halving_the_sample_spacing_changes_alpha_little(gl, cloudy_sphere):
    cam = sphere_camera()
    a = render(cloudy_sphere, cam, ctx=gl, unlit=True, mip=False, samples=32)
    b = render(cloudy_sphere, cam, ctx=gl, unlit=True, mip=False, samples=64)
    assert np.abs(a.color[..., 3] - b.color[..., 3]).max() <= 0.005


@pytest.mark.parametrize("theta", [0.0, 30.0, 60.0])
def test_uniform_slab_alpha_is_analytic(gl, theta):
    a0, thickness = 0.9, 0.4
    rep = TexturedShell(grid_mesh(4), thickness,
                        texture_from((0.3, 0.6, 0.2), np.full((4, 4, 4), a0)))
    cam = slab_camera(theta, size=(48, 48), ortho=True)
    frame = render(rep, cam, ctx=gl, unlit=True, samples=4)
    inside = inside_grid(cam, thickness)[0]
    expected = 1 - (1 - a0) ** (thickness / np.cos(np.radians(theta)))
    assert inside.sum() > 200
    assert np.abs(frame.color[..., 3][inside] - expected).max() < 1e-4
    assert np.abs(frame.color[..., :3][inside] - (0.3, 0.6, 0.2)).max() < 1e-4


@pytest.mark.parametrize("below", [False, True])
def test_stacked_slabs_composite_in_order(gl, below):
    """Red below (w < 0.5), green above: seen from above the green is in front."""
    alpha = np.zeros((8, 4, 4))
    alpha[:4], alpha[4:] = 0.95, 0.95
    rgb = np.zeros((8, 4, 4, 3))
    rgb[:4] = (1.0, 0.0, 0.0)
    rgb[4:] = (0.0, 1.0, 0.0)
    rep = TexturedShell(grid_mesh(4), 2.0, texture_from(rgb, alpha))
    cam = slab_camera(10.0, size=(32, 32), ortho=True, below=below, dist=6.0)
    frame = render(rep, cam, ctx=gl, unlit=True, samples=32)
    inside = inside_grid(cam, 2.0)[0]
    red, green = frame.color[..., 0][inside], frame.color[..., 1][inside]
    assert inside.sum() > 50
    if below:
        assert (red > 0.6).all() and (green < 0.4).all()
    else:
        assert (green > 0.6).all() and (red < 0.4).all()


def permuted(rep: TexturedShell, seed=0) -> TexturedShell:
    """The same shell with its tetrahedra in a random order (every per-tet array moved)."""
    import copy

    rng = np.random.default_rng(seed)
    shell = rep.shell
    perm = rng.permutation(len(shell.tets))
    inverse = np.empty_like(perm)
    inverse[perm] = np.arange(len(perm))
    neighbors = shell.neighbors[perm]
    neighbors = np.where(neighbors >= 0, inverse[np.maximum(neighbors, 0)], -1)
    out = copy.copy(rep)
    from dataclasses import replace

    out.shell = replace(shell, tets=shell.tets[perm],
                        object_to_texture=shell.object_to_texture[perm],
                        planes=shell.planes[perm], neighbors=neighbors.astype(np.int32),
                        neighbor_faces=shell.neighbor_faces[perm])
    return out


def test_result_does_not_depend_on_submission_order(gl, cloudy_sphere):
    cam = sphere_camera(az=80.0, el=10.0)
    a = render(cloudy_sphere, cam, ctx=gl, samples=6)
    b = render(permuted(cloudy_sphere), cam, ctx=gl, samples=6)
    assert np.abs(a.color - b.color).max() < 1e-4


def test_depth_peeling_gives_the_sorted_picture(gl, cloudy_sphere):
    cam = sphere_camera(az=80.0, el=10.0)
    sorted_ = render(cloudy_sphere, cam, ctx=gl, samples=6)
    peeled = render(cloudy_sphere, cam, ctx=gl, samples=6, sort="peel")
    assert np.abs(sorted_.color - peeled.color).max() < 1e-4
    assert peeled.stats["peeled_layers"] >= 4  # a ray crosses several tetrahedra per side
    # without the half-opacity search (and with peeling) the AOVs are the opaque pass's: none
    assert not np.isfinite(peeled.position).any()
    plain = render(cloudy_sphere, cam, ctx=gl, samples=6, half_opacity=False)
    assert np.array_equal(plain.color, sorted_.color) and not np.isfinite(plain.position).any()


def test_centroid_sort_is_the_baseline(gl):
    """On a torus seen side-on the centroid order composites some rays out of order, SXMPVO
    matches the reference."""
    import trimesh

    tor = trimesh.creation.torus(1.0, 0.35, major_sections=16, minor_sections=8)
    p = np.asarray(tor.vertices)
    theta = np.arctan2(p[:, 1], p[:, 0])
    phi = np.arctan2(p[:, 2], np.hypot(p[:, 0], p[:, 1]) - 1.0)
    uvs = np.column_stack([theta / (2 * np.pi) + 0.05 * np.sin(phi),
                           phi / (2 * np.pi) + 0.05 * np.cos(theta)])
    from reliefkit.scene.mesh import vertex_normals

    base = RenderMesh(p, tor.faces, vertex_normals(p, tor.faces), np.ones((len(p), 4)), uvs)
    alpha = np.full((8, 8, 8), 0.999)
    rgb = np.zeros((8, 8, 8, 3))
    rgb[..., 0] = np.linspace(0, 1, 8)[None, None, :]
    rgb[..., 1] = np.linspace(1, 0, 8)[:, None, None]
    rep = TexturedShell(base, 0.1, texture_from(rgb, alpha, tile=(3, 1)))
    cam = Camera.orbit((0.0, 0.0, 0.0), 0.0, 8.0, 4.0, fov_deg=40.0, size=(64, 64))
    ref = reference_render(rep.shell, rep.texture, cam, samples=4)
    exact = render(rep, cam, ctx=gl, unlit=True, mip=False, samples=4)
    centroid = render(rep, cam, ctx=gl, unlit=True, mip=False, samples=4, sort="centroid")
    assert against_reference(exact, ref)[0] <= RMSE_BOUND
    assert against_reference(centroid, ref)[0] > 2 * against_reference(exact, ref)[0]


def test_half_opacity_aovs_match_the_reference(gl, cloudy_sphere):
    cam = sphere_camera()
    frame = render(cloudy_sphere, cam, ctx=gl, unlit=True, mip=False, samples=8)
    ref = reference_render(cloudy_sphere.shell, cloudy_sphere.texture, cam, samples=8)
    gpu, cpu = np.isfinite(frame.position[..., 0]), np.isfinite(ref.position[..., 0])
    assert cpu.sum() > 500
    assert (gpu != cpu).mean() < 0.005
    both = gpu & cpu
    error = np.linalg.norm(frame.position[both] - ref.position[both], axis=-1)
    assert np.percentile(error, 99) < 1e-3
    # the contract: depth and normal belong to that point, the mask to any opacity
    assert (frame.mask == (frame.color[..., 3] > 0)).all()
    assert (frame.depth[~gpu] == 1.0).all() and (frame.depth[gpu] < 1.0).all()
    assert np.allclose(np.linalg.norm(frame.normal[gpu], axis=-1), 1.0, atol=1e-3)


def test_half_opacity_point_counts_what_lies_in_front(gl):
    """Two slabs drawn as two objects, each 0.43 opaque: the point is in the back one."""
    a0, thickness = 0.8, 0.35
    texture = texture_from((0.5, 0.5, 0.5), np.full((4, 4, 4), a0))
    slab = 1 - (1 - a0) ** thickness
    front = TexturedShell(grid_mesh(4), thickness, texture)
    shifted = grid_mesh(4)
    back_base = RenderMesh(shifted.world_positions - (0, 0, 1.0), shifted.indices,
                           shifted.normals, shifted.colors, shifted.uvs)
    back = TexturedShell(back_base, thickness, texture)
    cam = slab_camera(0.0, size=(32, 32), ortho=True, dist=4.0)
    frame = render([front, back], cam, ctx=gl, unlit=True)
    inside = inside_grid(cam, thickness)[0]
    total = 1 - (1 - slab) ** 2
    assert slab < 0.5 < total
    assert np.abs(frame.color[..., 3][inside] - total).max() < 1e-4
    z = frame.position[..., 2][inside]
    # opacity reaches 0.5 in the back slab: 1 - 0.5 / (1 - slab) of its own, from its top
    need = -np.log(0.5 / (1 - slab)) / -np.log(1 - a0)
    expected = -1.0 + thickness - need
    assert np.abs(z - expected).max() < thickness / 16 + 1e-4


def test_opaque_texture_is_drawn_depth_tested(gl):
    rep = TexturedShell(grid_mesh(4), 0.4, textures.make_rocks(size=(16, 16, 8)))
    assert rep.opaque
    cam = slab_camera(30.0, size=(48, 48), ortho=False)
    frame = render(rep, cam, ctx=gl, samples=32)
    ref = reference_render(rep.shell, rep.texture, cam, samples=32)
    gpu, cpu = frame.mask, np.isfinite(ref.position[..., 0])
    assert gpu.sum() > 300 and (gpu != cpu).mean() < 0.01
    both = gpu & cpu
    error = np.linalg.norm(frame.position[both] - ref.position[both], axis=-1)
    assert np.median(error) < 0.4 / 32
    assert (frame.color[..., 3][gpu] == 1.0).all()


def test_composes_with_an_opaque_mesh(gl):
    """An opaque plane halfway through a uniform slab: the segment stops at it, so alpha
    is the half slab's; the mesh shows through with the slab in front of it."""
    a0, thickness = 0.9, 0.4
    rep = TexturedShell(grid_mesh(4), thickness,
                        texture_from((0.0, 0.0, 1.0), np.full((4, 4, 4), a0)))
    wall = grid_mesh(2)
    plane = RenderMesh(wall.world_positions * (2, 2, 1) + (0, 0, thickness / 2), wall.indices,
                       wall.normals, np.tile((1.0, 0.0, 0.0, 1.0), (len(wall.normals), 1)))
    cam = slab_camera(0.0, size=(32, 32), ortho=True)
    frame = render([plane, rep], cam, ctx=gl, unlit=True)
    inside = inside_grid(cam, thickness)[0]
    half = 1 - (1 - a0) ** (thickness / 2)
    assert np.abs(frame.color[..., 3][inside] - 1.0).max() < 1e-5  # the wall is opaque
    blue = frame.color[..., 2][inside]
    assert np.abs(blue - half).max() < 2e-3  # slab over the wall: half * blue + ...
    assert np.allclose(frame.position[..., 2][inside], thickness / 2, atol=1e-4)


def test_shadows_darken_what_the_roof_hides(gl):
    """A solid roof over the half x < 0 of a solid floor, the light from above and -x: the
    floor next to the roof's edge (x < 0.25) is in its shadow, the rest and the roof lit."""
    from reliefkit.scene.light import DirectionalLight

    alpha = np.zeros((8, 16, 16))
    alpha[0] = 1.0       # floor
    alpha[7, :, :8] = 1.0  # roof over u < 0.5
    rep = TexturedShell(grid_mesh(4), 0.5, texture_from((0.8, 0.8, 0.8), alpha))
    cam = slab_camera(0.0, size=(64, 64), ortho=True)
    light = DirectionalLight(direction=(-0.6, 0.0, 0.8), ambient=0.2)
    lit = render(rep, cam, ctx=gl, light=light, samples=32)
    shadowed = render(rep, cam, ctx=gl, light=light, samples=32, shadows=True)
    x, z = lit.position[..., 0], lit.position[..., 2]
    floor, roof = z < 0.1, z > 0.4
    darker = shadowed.color[..., 0] < lit.color[..., 0] - 0.2
    near_edge = floor & (x > 0.03) & (x < 0.25)
    assert near_edge.sum() > 50 and roof.sum() > 500
    assert darker[near_edge].mean() > 0.95
    assert not darker[floor & (x > 0.4)].any() and not darker[roof].any()


@pytest.mark.parametrize("elevation,azimuth", [(10.0, 35.0), (30.0, 35.0), (60.0, 0.0),
                                               (20.0, 60.0)])
def test_shadows_leave_a_lit_flat_surface_lit(gl, elevation, azimuth):
    """A solid slab (the lower half of the shell) under a light from above: nothing lies
    between its flat top and the light, so no pixel of it may be darker with --shadows
    than without (shadow acne: isolated dark pixels where a sample tests itself)."""
    from reliefkit.scene.light import DirectionalLight

    alpha = np.zeros((8, 16, 16))
    alpha[:4] = 1.0
    rep = TexturedShell(grid_mesh(8), 0.2, texture_from((0.8, 0.8, 0.8), alpha))
    cam = slab_camera(20.0, size=(96, 96), ortho=True)
    el, az = np.radians(elevation), np.radians(azimuth)
    light = DirectionalLight(direction=(np.cos(el) * np.cos(az), np.cos(el) * np.sin(az),
                                        np.sin(el)), ambient=0.2)
    lit = render(rep, cam, ctx=gl, light=light, samples=16)
    shadowed = render(rep, cam, ctx=gl, light=light, samples=16, shadows=True)
    top = lit.color[..., 3] > 0.99
    assert top.all()
    darker = shadowed.color[..., :3] < lit.color[..., :3] - 0.01
    assert not darker.any(), f"{int(darker.any(axis=-1).sum())} dark pixels"


def test_a_shell_looks_the_same_at_any_scale(gl):
    """The cloudy sphere scaled by 1e-20 (squares of its coordinates flush to zero in float32)
    gives the unit sphere's picture, lit and shadowed (it drew nothing)."""
    from reliefkit.scene.light import DirectionalLight

    base = sphere_mesh(2)
    tex = textures.make_clouds(size=(16, 16, 8)).tiled((2, 1))
    light = DirectionalLight.from_angles(-60.0, 30.0)
    frames = []
    for scale in (1.0, 1e-20):
        tiny = RenderMesh(base.world_positions * scale, base.indices, base.normals,
                          base.colors, base.uvs)
        cam = Camera.orbit((0.0, 0.0, 0.0), 30.0, 25.0, 4.0 * scale, fov_deg=35.0,
                           size=(48, 48), near=0.5 * scale, far=10.0 * scale)
        rep = TexturedShell(tiny, 0.25 * scale, tex.over_length(0.25 * scale))
        frames.append(render(rep, cam, ctx=gl, light=light, samples=8, shadows=True))
    unit, tiny = (premultiplied(f.color) for f in frames)
    assert frames[0].stats["covered"] > 500
    assert np.abs(unit - tiny).max() < 0.02


def crossing_spheres():
    """Two spheres passing through each other: where their shells cross, tetrahedra overlap
    and no visibility order exists."""
    one, two = sphere_mesh(2), sphere_mesh(2)
    offset = len(one.positions)
    positions = np.concatenate([one.world_positions, two.world_positions + (0.8, 0.0, 0.0)])
    mesh = RenderMesh(positions, np.concatenate([one.indices, two.indices + offset]),
                      np.concatenate([one.normals, two.normals]),
                      np.ones((len(positions), 4)), np.concatenate([one.uvs, two.uvs]))
    return TexturedShell(mesh, 0.2, textures.make_clouds(size=(16, 16, 8)).over_length(0.2))


def test_a_sort_that_breaks_cycles_says_so(gl, cloudy_sphere):
    """The frame carries a warning with the count and the exact alternative; a shell whose
    order is exact carries none."""
    cam = sphere_camera(az=10.0)
    frame = render(crossing_spheres(), cam, ctx=gl, samples=4)
    assert frame.stats["cycles"] > 0
    assert len(frame.warnings) == 1
    assert f"{frame.stats['cycles']:,} cycles" in frame.warnings[0]
    assert "--sort peel" in frame.warnings[0]
    clean = render(cloudy_sphere, cam, ctx=gl, samples=4)
    assert clean.stats["cycles"] == 0 and clean.warnings == []


def two_material_grid():
    """The grid (uvs over [0, 1]^2) with a red factor on the triangles of x < 0 and a 2x2
    blue-and-yellow texture on the others."""
    from reliefkit.scene.mesh import Material

    mesh = grid_mesh(4)
    centres = mesh.world_positions[mesh.indices].mean(axis=1)
    texture = np.array([[[0, 0, 255, 255], [255, 255, 0, 255]],
                        [[255, 255, 0, 255], [0, 0, 255, 255]]], np.uint8)
    materials = [Material("red", (1.0, 0.2, 0.2, 1.0)), Material("tiles", texture=texture)]
    return RenderMesh(mesh.world_positions, mesh.indices, mesh.normals, mesh.colors, mesh.uvs,
                      materials=materials, material=(centres[:, 0] > 0).astype(np.uint16))


def test_the_surface_material_tints_the_volume(gl, tmp_path):
    """A uniform medium over two materials: over the red factor its colour is the medium's
    times the factor exactly; everywhere the GPU matches the CPU reference, which samples
    the same atlas; the atlas survives a round trip through the .rk file."""
    from reliefkit.bake import bake

    rep = bake(two_material_grid(), "shell-volume", texture="absorption", thickness=0.4,
               tile=(2.0, 2.0), texture_size=(4.0, 4.0, 4.0))
    assert rep.surface is not None and rep.surface.rgba8.shape[0] == 2
    cam = Camera(eye=(0.0, 0.0, 3.0), target=(0.0, 0.0, 0.0), up=(0.0, 1.0, 0.0),
                 size=(48, 48), near=0.5, far=10.0, ortho_height=1.0)
    frame = render(rep, cam, ctx=gl, unlit=True, mip=False, samples=8)
    o, _ = cam.pixel_rays()
    red = (o[..., 0] < -0.2) & (np.abs(o[..., 1]) < 0.8) & (o[..., 0] > -0.8)
    medium = np.array([0.1, 0.7, 0.2])  # textures.make_absorption's colour
    assert red.sum() > 200
    np.testing.assert_allclose(frame.color[..., :3][red], np.broadcast_to(
        medium * (1.0, 0.2, 0.2), (int(red.sum()), 3)), atol=2e-3)
    ref = reference_render(rep.shell, rep.texture, cam, samples=8, surface=rep.surface,
                           layers=rep.surface_layers())
    rmse, off = against_reference(frame, ref)
    assert rmse <= RMSE_BOUND and off <= 0.005
    save(tmp_path / "tinted.rk", rep)
    back = load(tmp_path / "tinted.rk")
    assert np.array_equal(back.surface.rgba8, rep.surface.rgba8)
    assert back.surface.box == rep.surface.box
    assert np.array_equal(back.base.material, rep.base.material)


def test_animation_moves_and_repeats(gl, cloudy_sphere):
    cam = sphere_camera()
    still = render(cloudy_sphere, cam, ctx=gl, samples=4)
    a = render(cloudy_sphere, cam, ctx=gl, samples=4, time=0.25)
    b = render(cloudy_sphere, cam, ctx=gl, samples=4, time=1.25)
    assert np.abs(a.color - still.color).max() > 0.1
    assert np.abs(a.color - b.color).max() < 1e-3


def test_codec_round_trip(tmp_path, gl, ellipsoid_grid):
    path = tmp_path / "shell.rk"
    save(path, ellipsoid_grid)
    back = load(path)
    assert isinstance(back, TexturedShell)
    assert np.array_equal(back.shell.tets, ellipsoid_grid.shell.tets)
    assert back.texture.tile == ellipsoid_grid.texture.tile
    cam = slab_camera(20.0, size=(32, 32), ortho=False)
    assert np.array_equal(render(back, cam, ctx=gl).color,
                          render(ellipsoid_grid, cam, ctx=gl).color)


def test_glow_adds_its_light_along_the_segment(gl):
    """A clear medium (alpha 0) that glows g per unit length in colour c: seen straight on, a
    slab of thickness T adds g c T, unattenuated."""
    from dataclasses import replace

    g, thickness, c = 0.8, 0.4, np.array([1.0, 0.5, 0.25])
    tex = texture_from(c, np.zeros((4, 4, 4)))
    tex = replace(tex, glow=np.full((4, 4, 4), g, np.float32))
    rep = TexturedShell(grid_mesh(4), thickness, tex)
    cam = slab_camera(0.0, size=(32, 32), ortho=True)
    frame = render(rep, cam, ctx=gl, unlit=True, samples=4)
    inside = inside_grid(cam, thickness)[0]
    assert inside.sum() > 100 and (frame.color[..., 3][inside] == 0).all()
    # alpha 0 keeps no straight colour in the frame itself: the light shows over a backdrop
    wall = grid_mesh(2)
    backdrop = RenderMesh(wall.world_positions * (2, 2, 1) - (0, 0, 0.5), wall.indices,
                          wall.normals, np.tile((0.0, 0.0, 0.0, 1.0), (len(wall.normals), 1)))
    behind = render(backdrop, cam, ctx=gl).color[..., :3][inside]  # its specular sheen
    lit = render([backdrop, rep], cam, ctx=gl, unlit=True, samples=4)
    assert np.abs(lit.color[..., :3][inside] - behind - g * c * thickness).max() < 1e-4


def test_mip_filtering_is_closer_to_the_supersampled_picture(gl):
    """Far away, a fine texture aliases; the pyramid's level from the footprint (§5.2) gives
    a picture closer to the supersampled one than level 0 does."""
    rep = TexturedShell(grid_mesh(4), 0.2,
                        textures.make_ellipsoids(size=(32, 32, 16)).over_length(0.2)
                        .tiled((16, 16)))
    far = slab_camera(40.0, size=(48, 48), ortho=False, dist=9.0)
    fine = slab_camera(40.0, size=(192, 192), ortho=False, dist=9.0)

    def pooled(frame):
        c = premultiplied(frame.color).reshape(48, 4, 48, 4, 4)
        return c.mean(axis=(1, 3))

    truth = pooled(render(rep, fine, ctx=gl, unlit=True, mip=False, samples=8))
    filtered = premultiplied(render(rep, far, ctx=gl, unlit=True, samples=8).color)
    aliased = premultiplied(render(rep, far, ctx=gl, unlit=True, mip=False, samples=8).color)

    def err(img):
        return float(np.sqrt(((img - truth) ** 2).mean()))
    assert err(filtered) < 0.8 * err(aliased), (err(filtered), err(aliased))


def test_compare_scores_the_variants_against_the_reference(gl, cloudy_sphere):
    """`compare`'s variants: the unlit ones match the CPU reference within the bound, the
    SXMPVO-sorted ones have no ordering violation on the frame's rays, the centroid one has
    some (the sphere's shell seen from outside: front and back cross on every ray)."""
    from reliefkit.compare import compare

    cam = sphere_camera(size=(64, 64), az=80.0, el=10.0)
    result = compare(cloudy_sphere.base, cloudy_sphere, cam)
    rows = result["metrics"]
    for name in ("unlit", "unlit, depth peeling", "unlit, exit per vertex"):
        assert rows[name]["reference_rmse"] <= RMSE_BOUND, (name, rows[name])
    assert rows["sxmpvo"]["order_violations"] == 0
    assert rows["unlit, exit per vertex"]["order_violations"] == 0
    assert rows["unlit, centroid sort"]["order_violations"] > 0
    assert set(rows) == {"sxmpvo", "shadows", "unlit", "unlit, centroid sort",
                         "unlit, depth peeling", "unlit, exit per vertex"}


def test_an_opaque_texture_can_be_composited_sorted(gl):
    """--composite sorted draws even a solid texture through the transparent pass: it then
    matches the CPU reference like any medium, and covers what the opaque path covers."""
    rep = TexturedShell(grid_mesh(4), 0.4, textures.make_rocks(size=(16, 16, 8)))
    cam = slab_camera(30.0, size=(48, 48), ortho=False)
    sorted_ = render(rep, cam, ctx=gl, unlit=True, mip=False, samples=16, composite="sorted")
    ref = reference_render(rep.shell, rep.texture, cam, samples=16)
    assert against_reference(sorted_, ref)[0] <= RMSE_BOUND
    opaque = render(rep, cam, ctx=gl, unlit=True, mip=False, samples=16)
    covered = sorted_.color[..., 3] > 0.5
    assert (covered != opaque.mask).mean() < 0.01
