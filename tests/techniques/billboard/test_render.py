"""Drawing billboard clouds, against a CPU ray cast of the rectangles built here: per pixel the
ray meets each rectangle's plane, (s, t) come from the rectangle's parametrization and pick the
atlas texel the representation's docstring says; the nearest covered hit wins."""

from __future__ import annotations

import numpy as np
import pytest

from reliefkit.colorspace import srgb_decode
from reliefkit.core.technique import Technique, drawable_spec, register, unregister
from reliefkit.errors import GPUError
from reliefkit.render import render
from reliefkit.render.frame import window_depth
from reliefkit.scene.camera import Camera
from reliefkit.scene.light import DirectionalLight
from reliefkit.scene.mesh import RenderMesh
from reliefkit.techniques.billboard import render as billboard_render
from reliefkit.techniques.billboard.representation import GUTTER, BillboardCloud

FLAT = DirectionalLight(intensity=0.0, ambient=1.0, specular=0.0)
SIZE = (96, 96)
RED, GREEN, BLUE, WHITE = (230, 40, 30), (30, 200, 60), (40, 60, 220), (240, 240, 240)


@pytest.fixture(scope="module")
def billboard(gl):
    """Renders clouds through `render()`: the package's own registration once it has one,
    else a throwaway technique carrying only this drawable, removed afterwards."""
    probe = one_rectangle(np.full((1, 8, 8, 4), 255, np.uint8))
    if drawable_spec(probe)[1] is not None:
        yield
        return
    register(Technique(name="billboard", summary="test registration",
                       package="reliefkit.techniques.billboard",
                       drawables=(billboard_render.drawable_spec(),),
                       programs=billboard_render.PROGRAMS))
    try:
        yield
    finally:
        unregister("billboard")


# --- scenes ----------------------------------------------------------------------------------

TILT_CORNER = np.array([-1.0, -0.45, 0.2])
TILT_U = np.array([2.0, 0.0, -0.6])  # 2 x 1, tilted about both the x and the y axis
TILT_V = np.cross(np.cross(TILT_U, [0.1, 1.0, 0.5]), TILT_U)
TILT_V = TILT_V / np.linalg.norm(TILT_V)


def encode_normal(n) -> np.ndarray:
    n = np.asarray(n, np.float64)
    return np.round((n / np.linalg.norm(n) + 1.0) / 2.0 * 255.0).astype(np.uint8)


def decode_normal(encoded) -> np.ndarray:
    n = 2.0 * np.asarray(encoded, np.float64) / 255.0 - 1.0
    return n / np.linalg.norm(n)


def one_rectangle(color, normal=None, corner=TILT_CORNER, u=TILT_U, v=TILT_V, rect=None):
    """A cloud of one rectangle whose texels are the whole of page 0 unless ``rect``."""
    layers, h, w = color.shape[:3]
    plane = np.cross(u, v)
    if normal is None:
        normal = np.broadcast_to(encode_normal(plane), (layers, h, w, 3)).copy()
    return BillboardCloud(corners=[corner], u_axes=[u], v_axes=[v],
                          rects=[rect if rect is not None else (0, 0, 0, w, h)],
                          color=color, normal=normal, epsilon=0.01)


def checker_with_hole() -> np.ndarray:
    """32 x 16 texels of 4 x 4 checker cells (red / white), a 6 x 4 hole at texels x 18..23,
    y 4..7."""
    j, i = np.mgrid[:16, :32]
    rgba = np.where(((i // 4 + j // 4) % 2 == 0)[..., None], RED, WHITE)
    alpha = np.full((16, 32, 1), 255)
    alpha[4:8, 18:24] = 0
    return np.concatenate([rgba, alpha], axis=-1).astype(np.uint8)[None]


def cameras(target=(0.0, 0.0, 0.0)):
    target = np.asarray(target, np.float64)
    eye = target + np.array([0.6, 0.5, 3.0])
    return {"perspective": Camera(eye=tuple(eye), target=tuple(target), size=SIZE, fov_deg=45,
                                  near=0.5, far=10.0),
            "orthographic": Camera(eye=tuple(eye), target=tuple(target), size=SIZE,
                                   ortho_height=1.2, near=0.5, far=10.0)}


# --- the reference ---------------------------------------------------------------------------

def trace(cloud: BillboardCloud, camera, jitter=(0.0, 0.0)) -> dict:
    """Nearest covered rectangle per pixel: ``rect`` (-1: none), world ``hit``, RGBA8
    ``texel``. ``jitter`` moves (s, t) by that many texels (for the stability band)."""
    origins, dirs = camera.pixel_rays()
    shape = origins.shape[:2]
    best = np.full(shape, np.inf)
    out = {"rect": np.full(shape, -1), "hit": np.full(shape + (3,), np.nan),
           "texel": np.zeros(shape + (4,), np.uint8)}
    for p in range(cloud.count):
        c, u, v = cloud.corners[p], cloud.u_axes[p], cloud.v_axes[p]
        page, x, y, w, h = (int(k) for k in cloud.rects[p])
        n = np.cross(u, v)
        with np.errstate(divide="ignore", invalid="ignore"):
            dist = ((c - origins) @ n) / (dirs @ n)
        hit = origins + dist[..., None] * dirs
        gram = np.array([[u @ u, u @ v], [u @ v, v @ v]])
        s, t = np.moveaxis(np.linalg.solve(gram, np.stack([(hit - c) @ u, (hit - c) @ v],
                                                           axis=-1)[..., None])[..., 0], -1, 0)
        s, t = s + jitter[0] / w, t + jitter[1] / h
        inside = (s >= 0) & (s < 1) & (t >= 0) & (t < 1) & (dist > 0)
        i = np.clip(np.floor(s * w).astype(int), 0, w - 1)
        j = np.clip(np.floor(t * h).astype(int), 0, h - 1)
        texel = cloud.color[page, y + j, x + i]  # texel (x + i, y + j) holds s = (i + .5) / w
        take = inside & (texel[..., 3] >= 128) & (dist < best)
        best = np.where(take, dist, best)
        out["rect"] = np.where(take, p, out["rect"])
        out["hit"] = np.where(take[..., None], hit, out["hit"])
        out["texel"] = np.where(take[..., None], texel, out["texel"])
    return out


def stable(cloud, camera, ref) -> np.ndarray:
    """Pixels whose answer cannot depend on rasterization or filtering details: the same
    rectangle and texel colour 0.6 texel around the hit and in the 3 x 3 pixel block."""
    key = ref["rect"] * 2**32 + ref["texel"].astype(np.int64) @ (256 ** np.arange(4))
    ok = np.ones(key.shape, bool)
    for jitter in [(a, b) for a in (-0.6, 0.6) for b in (-0.6, 0.6)]:
        moved = trace(cloud, camera, jitter)
        ok &= moved["rect"] * 2**32 + moved["texel"].astype(np.int64) @ (256 ** np.arange(4)) \
            == key
    padded = np.pad(key, 1, mode="edge")
    for dr in (0, 1, 2):
        for dc in (0, 1, 2):
            ok &= padded[dr:dr + key.shape[0], dc:dc + key.shape[1]] == key
    return ok


def linear(texels) -> np.ndarray:
    return srgb_decode(np.asarray(texels)[..., :3] / 255.0)


# --- 1, 2: footprint, hole, colours, positions, depth, orientation ------------------------

@pytest.mark.parametrize("kind", ["perspective", "orthographic"])
def test_footprint_colours_positions_and_depth(billboard, kind):
    cloud = one_rectangle(checker_with_hole())
    camera = cameras()[kind]
    frame = render(cloud, camera, light=FLAT)
    ref = trace(cloud, camera)
    expected = ref["rect"] >= 0
    ok = stable(cloud, camera, ref)
    assert expected.sum() > 2000 and (~expected & ok).sum() > 2000
    assert ok.sum() > 0.8 * ok.size
    assert np.array_equal(frame.mask[ok], expected[ok])
    hole = trace(one_rectangle(np.full_like(cloud.color, 255)), camera)["rect"] >= 0
    assert (hole & ~expected & ok).sum() > 50  # the hole shows, not just the outline
    inside = ok & expected
    assert np.abs(frame.color[inside][:, :3] - linear(ref["texel"][inside])).max() < 3e-3
    assert np.allclose(frame.color[frame.mask][:, 3], 1.0)
    drawn = frame.mask & expected
    assert np.abs(frame.position[drawn] - ref["hit"][drawn]).max() < 1e-4 * 2.0
    depth = window_depth(ref["hit"], camera.view, camera.proj, np.ones(SIZE[::-1]))
    assert np.abs(frame.depth[drawn] - depth[drawn]).max() < 1e-5
    assert (frame.depth[~frame.mask] == 1.0).all()


def test_atlas_orientation_follows_the_st_mapping(billboard):
    """An L in the (s, t) = (0, 0) corner, its arms of different lengths, inside a block
    that is not at the page's origin: a mirrored, transposed or shifted lookup moves it."""
    page = np.zeros((1, 32, 48, 4), np.uint8)
    page[..., :3], page[..., 3] = BLUE, 255
    x, y, w, h = 9, 5, 24, 20
    block = page[0, y:y + h, x:x + w]
    block[..., :3] = GREEN
    block[:14, :4, :3] = RED   # along t (rows), long arm
    block[:4, :9, :3] = RED    # along s (columns), short arm
    cloud = one_rectangle(page, rect=(0, x, y, w, h))
    camera = cameras()["perspective"]
    frame = render(cloud, camera, light=FLAT)
    ref = trace(cloud, camera)
    ok = stable(cloud, camera, ref) & (ref["rect"] >= 0)
    red = (ref["texel"][..., :3] == RED).all(axis=-1)
    assert (ok & red).sum() > 60 and (ok & ~red).sum() > 600
    assert np.abs(frame.color[ok][:, :3] - linear(ref["texel"][ok])).max() < 3e-3
    assert not (ok & (ref["texel"][..., :3] == BLUE).all(axis=-1)).any()


def test_minified_thin_parts_are_not_eroded(billboard):
    """Lines one texel wide every four texels, about four texels to a pixel: the alpha
    test reads the base level, so pixels whose centre falls on a line are covered (about a
    quarter of the footprint); a test on the mipmapped alpha (0.25 there) would drop them."""
    j, i = np.mgrid[:128, :256]
    rgba = np.zeros((1, 128, 256, 4), np.uint8)
    rgba[..., :3] = WHITE
    rgba[0, ..., 3] = np.where((i % 4 == 1) | (j % 4 == 1), 255, 0)
    cloud = one_rectangle(rgba, corner=(-1.0, -0.5, 0.0), u=(2.0, 0.0, 0.0), v=(0.0, 1.0, 0.0))
    camera = Camera(eye=(0.0, 0.0, 3.0), target=(0.0, 0.0, 0.0), size=(72, 72),
                    ortho_height=2.0, near=0.5, far=10.0)
    footprint = trace(one_rectangle(np.full_like(rgba, 255), corner=(-1.0, -0.5, 0.0),
                                    u=(2.0, 0.0, 0.0), v=(0.0, 1.0, 0.0)), camera)["rect"] >= 0
    frame = render(cloud, camera, light=FLAT)
    expected = trace(cloud, camera)["rect"] >= 0  # the texel under each pixel centre
    assert footprint.sum() > 500
    assert frame.mask.sum() > 0.3 * footprint.sum()
    assert (frame.mask & ~footprint).sum() == 0
    assert (frame.mask == expected)[footprint].mean() > 0.9


# --- 3: normal-mapped lighting, two-sided like the mesh ------------------------------------

LIGHT = DirectionalLight(direction=(0.3, 0.6, 1.0), intensity=0.8, ambient=0.2, specular=0.4,
                         shininess=8.0)
STORED = encode_normal(np.cross(TILT_U, TILT_V) / np.linalg.norm(np.cross(TILT_U, TILT_V))
                       + np.array([0.35, -0.2, 0.1]))


def phong(base, n, light, to_eye) -> np.ndarray:
    """shaders/include/shading.glsl's formula, in numpy."""
    to_light = light.unit_direction
    diffuse = max(n @ to_light, 0.0)
    h = (to_light + to_eye) / np.linalg.norm(to_light + to_eye)
    spec = max(n @ h, 0.0) ** light.shininess * light.specular if diffuse > 0 else 0.0
    color = np.asarray(light.color) * light.intensity
    return base * (light.ambient + diffuse * color) + spec * color


def uniform_cloud(color=GREEN):
    rgba = np.zeros((1, 8, 16, 4), np.uint8)
    rgba[..., :3], rgba[..., 3] = color, 255
    return one_rectangle(rgba, normal=np.broadcast_to(STORED, (1, 8, 16, 3)).copy())


def test_stored_normal_lights_as_phong_says(billboard):
    cloud = uniform_cloud()
    camera = cameras()["perspective"]
    frame = render(cloud, camera, light=LIGHT)
    r, c = SIZE[1] // 2, SIZE[0] // 2
    assert frame.mask[r, c]
    hit = trace(cloud, camera)["hit"][r, c]
    to_eye = np.asarray(camera.eye) - hit
    n = decode_normal(STORED)
    expected = phong(linear(np.array(GREEN)), n, LIGHT, to_eye / np.linalg.norm(to_eye))
    flat = phong(linear(np.array(GREEN)), np.cross(TILT_U, TILT_V) /
                 np.linalg.norm(np.cross(TILT_U, TILT_V)), LIGHT, to_eye / np.linalg.norm(to_eye))
    assert np.abs(expected - flat).max() > 0.03  # the tilt matters at this pixel
    assert np.abs(frame.color[r, c, :3] - expected).max() < 3e-3
    assert np.allclose(frame.normal[r, c], n, atol=2e-3)


def quad_mesh(cloud: BillboardCloud) -> RenderMesh:
    """The same rectangle as a two-triangle mesh, wound counter-clockwise about u x v, with
    the stored normal and the texel's linear colour."""
    corners = cloud.rectangle_corners[0].astype(np.float32)
    colour = np.append(linear(cloud.color[0, 0, 0]), 1.0).astype(np.float32)
    return RenderMesh(corners, np.array([[0, 1, 2], [0, 2, 3]], np.uint32),
                      np.tile(decode_normal(STORED), (4, 1)).astype(np.float32),
                      np.tile(colour, (4, 1)))


@pytest.mark.parametrize("side", [1.0, -1.0], ids=["front", "back"])
def test_flat_cloud_looks_like_the_quad_mesh(billboard, side):
    cloud = uniform_cloud()
    plane = np.cross(TILT_U, TILT_V) / np.linalg.norm(np.cross(TILT_U, TILT_V))
    center = cloud.center
    camera = Camera(eye=tuple(center + side * 3.0 * plane + [0.3, 0.2, 0.0]),
                    target=tuple(center), size=SIZE, near=0.5, far=10.0)
    light = DirectionalLight(direction=tuple(side * plane + [0.5, 0.4, 0.0]), intensity=0.8,
                             ambient=0.2, specular=0.4, shininess=8.0)
    bbc, mesh = render(cloud, camera, light=light), render(quad_mesh(cloud), camera, light=light)
    core = bbc.mask & mesh.mask
    assert core.sum() > 1500 and (bbc.mask ^ mesh.mask).sum() <= 2
    assert np.abs(bbc.color[core] - mesh.color[core]).max() < 3e-3
    assert np.abs(bbc.normal[core] - mesh.normal[core]).max() < 3e-3
    assert (bbc.normal[core] @ (side * plane) > 0).all()  # flipped to the viewer at the back


# --- 4: pages, gutters, overlaps --------------------------------------------------------------

def two_page_cloud() -> BillboardCloud:
    """Rectangles A and B side by side on page 0, C on page 1 in front of both; every block
    framed by GUTTER texels of its own colour at alpha 0 (as the baker dilates), B's hard
    against A's, so a lookup that bleeds shows the neighbour's colour."""
    color = np.zeros((2, 32, 32, 4), np.uint8)
    color[..., :3] = (255, 0, 255)  # never visible: outside every block and its gutter
    rects = [(0, GUTTER, GUTTER, 12, 10), (0, 12 + 3 * GUTTER, GUTTER, 12, 10),
             (1, GUTTER + 3, GUTTER + 1, 16, 8)]
    for (page, x, y, w, h), rgb in zip(rects, (RED, GREEN, BLUE), strict=True):
        color[page, y - GUTTER:y + h + GUTTER, x - GUTTER:x + w + GUTTER, :3] = rgb
        color[page, y:y + h, x:x + w, 3] = 255
    normal = np.broadcast_to(encode_normal((0, 0, 1)), (2, 32, 32, 3)).copy()
    corners = [(-1.1, -0.5, 0.0), (0.05, -0.5, 0.0), (-0.8, -0.3, 0.4)]
    u_axes = [(1.0, 0.0, 0.0), (1.0, 0.0, 0.0), (1.6, 0.0, 0.0)]
    v_axes = [(0.0, 1.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.8, 0.0)]
    return BillboardCloud(corners=corners, u_axes=u_axes, v_axes=v_axes, rects=rects,
                          color=color, normal=normal, epsilon=0.01)


def test_pages_gutters_and_the_nearer_rectangle_wins(billboard):
    cloud = two_page_cloud()
    camera = Camera(eye=(0.3, 0.2, 3.0), target=(0.0, 0.0, 0.0), size=SIZE, near=0.5,
                    far=10.0)
    frame = render(cloud, camera, light=FLAT)
    ref = trace(cloud, camera)
    ok = stable(cloud, camera, ref)
    assert {0, 1, 2} <= set(np.unique(ref["rect"][ok & (ref["rect"] >= 0)]))
    assert np.array_equal(frame.mask[ok], (ref["rect"] >= 0)[ok])
    inside = ok & (ref["rect"] >= 0)
    assert np.abs(frame.color[inside][:, :3] - linear(ref["texel"][inside])).max() < 3e-3
    # C (page 1) hides A and B where they overlap: A and B lie behind C's footprint
    behind = trace(BillboardCloud(cloud.corners[:2], cloud.u_axes[:2], cloud.v_axes[:2],
                                  cloud.rects[:2], cloud.color, cloud.normal, 0.01), camera)
    assert (ok & (ref["rect"] == 2) & (behind["rect"] >= 0)).sum() > 300
    # no bleeding across blocks: every drawn pixel, edges included, is one block's colour
    palette = linear(np.array([RED, GREEN, BLUE]))
    drawn = frame.color[frame.mask][:, :3]
    nearest = np.abs(drawn[:, None] - palette[None]).max(axis=-1).min(axis=1)
    assert nearest.max() < 3e-3


# --- 5: far from the origin -------------------------------------------------------------------

def test_far_from_the_origin_renders_the_same_picture(billboard):
    cloud = one_rectangle(checker_with_hole())
    offset = np.array([1e7, -3e6, 2e7])
    far = BillboardCloud(cloud.corners + offset, cloud.u_axes, cloud.v_axes, cloud.rects,
                         cloud.color, cloud.normal, cloud.epsilon)
    for camera, moved in zip(cameras().values(), cameras(offset).values(), strict=True):
        near_frame = render(cloud, camera, light=LIGHT)
        far_frame = render(far, moved, light=LIGHT)
        assert (near_frame.mask != far_frame.mask).sum() <= 2
        both = near_frame.mask & far_frame.mask
        assert np.abs(near_frame.color[both] - far_frame.color[both]).max() < 1e-3
        assert np.abs(far_frame.position[both] - offset - near_frame.position[both]).max() \
            < 1e-4 * 2.0


# --- 6: instrumented pass ---------------------------------------------------------------------

def test_instrumented_pass_draws_the_same_pixels(billboard):
    cloud = two_page_cloud()
    camera = cameras()["perspective"]
    plain = render(cloud, camera, light=LIGHT)
    counted = render(cloud, camera, light=LIGHT, count_iterations=True)
    assert np.array_equal(plain.mask, counted.mask)
    assert np.array_equal(plain.color, counted.color)
    assert counted.stats["fragments"] == counted.stats["covered"] == plain.stats["covered"]
    assert plain.stats["rectangles"] == counted.stats["rectangles"] == 3


# --- 7: GPU limits ----------------------------------------------------------------------------

class LimitedContext:
    """The real context with smaller limits, and no texture array may be allocated."""

    def __init__(self, ctx, **limits):
        self._ctx, self.info = ctx, dict(ctx.info) | limits

    def texture_array(self, *args, **kwargs):
        raise AssertionError("allocated a texture array past the limit")

    def __getattr__(self, name):
        return getattr(self._ctx, name)


@pytest.mark.parametrize("limits, match", [
    ({"GL_MAX_ARRAY_TEXTURE_LAYERS": 1}, "2 texture array layers exceed this GPU's limit of 1"),
    ({"GL_MAX_TEXTURE_SIZE": 16}, "32x32 texture exceeds this GPU's limit of 16x16"),
])
def test_atlases_beyond_the_gpu_limits_are_refused_before_allocation(gl, billboard, limits,
                                                                     match):
    with pytest.raises(GPUError, match=match):
        render(two_page_cloud(), cameras()["perspective"], ctx=LimitedContext(gl, **limits))


@pytest.mark.parametrize("es", [False, True], ids=["glsl330", "es300"])
def test_draw_path_programs_compile(gl, billboard, es):
    """The portability test covers registered techniques; this covers the drawable now."""
    from reliefkit.gl.shaders import program

    for variant in billboard_render.PROGRAMS:
        program(gl, variant.file, variant.defines, es=es)
