"""The viewer page in headless Chromium (SwiftShader's WebGL2) against `reliefkit render`:
the same picture for every kind the page draws, at three views; a drag and the arrow keys
orbit, and the URL follows; several inputs share one camera; a bad view in the URL, what it
cannot draw, a broken file and a shader that does not compile show a message in the page
that also reaches the server's log."""

from __future__ import annotations

import struct
from urllib.parse import parse_qs, urlsplit

import numpy as np
import pytest
from browser import (
    SIZE,
    agreement,
    canvas_rgba,
    messages,
    open_page,
    rendered,
    served,
    state,
)
from helpers import sample
from mesh_scenes import sampler_mesh

from reliefkit import save
from reliefkit.compact.compact import CompressOptions, compress
from reliefkit.io.gltf.glb import glb_bytes, read_glb
from reliefkit.scene.views import framing_bounds
from reliefkit.viewer.site import Input, load_inputs, make_input, site_files

VIEWS = ("30,25", "-100,10", "160,50")
#: the scenes: a demo asset, a technique's sample, or a mesh of the test's own (saved as a
#: mesh .rk)
SCENES = {"mesh": "demo:vehicle", "mesh-materials": sampler_mesh,
          "relief": ("relief", "relief"), "relief-object": ("relief", "relief-object"),
          "billboard-cloud": ("billboard", "billboard-cloud"),
          "dmbbc": ("billboard", "dmbbc"),
          "shell-volume": ("shellvolume", "shell-volume"),
          "depth-object": ("slicing", "depth-object"),
          "visual-hull": ("slicing", "visual-hull"),
          "displacement": ("slicing", "displacement"),
          "octahedral-impostor": ("impostor", "octahedral-impostor"),
          "octahedral-impostor-bc": ("impostor", "octahedral-impostor", "bc"),
          "relief-object-bc": ("relief", "relief-object", "bc")}
#: every kind with its default plans (view hooks run in JavaScript), and on which backend:
#: kinds that sample 3D textures or count slices on Mesa's llvmpipe through ANGLE (what
#: render draws with); on SwiftShader their 3D textures' filtering picks a few samples
#: differently (98-99.4% of pixels within 4/255, docs/viewer.md)
DRAWN = (("mesh", "swiftshader"), ("mesh-materials", "swiftshader"),
         ("relief", "swiftshader"), ("relief-object", "swiftshader"),
         ("billboard-cloud", "swiftshader"), ("dmbbc", "swiftshader"),
         ("shell-volume", "mesa"), ("depth-object", "swiftshader"),
         ("visual-hull", "swiftshader"), ("displacement", "mesa"),
         ("octahedral-impostor", "swiftshader"),
         ("octahedral-impostor-bc", "swiftshader"), ("relief-object-bc", "swiftshader"))


@pytest.fixture(scope="module")
def specs(tmp_path_factory):
    """Each scene as an input spec: the demo mesh, the techniques' samples as .rk."""
    folder = tmp_path_factory.mktemp("inputs")
    out = {}
    for kind, source in SCENES.items():
        if isinstance(source, str):
            out[kind] = source
            continue
        made = source() if callable(source) else sample(*source[:2])
        if not callable(source) and len(source) == 3:  # block-compressed (--compress bc)
            made = compress(made, CompressOptions(compress=source[2]))
        out[kind] = str(folder / f"{kind}.rk")
        save(out[kind], made)
    return out


def url(base: str, view: str) -> str:
    return f"{base}?view={view}&size={SIZE[0]}x{SIZE[1]}"


@pytest.mark.parametrize("kind, backend", DRAWN, ids=[k for k, _ in DRAWN])
def test_the_page_draws_what_render_draws(gl, browser, mesa_browser, specs, kind, backend):
    browser = mesa_browser if backend == "mesa" else browser
    files = site_files(load_inputs([specs[kind]]))
    with served(files) as (base, log):
        for view in VIEWS:
            page = open_page(browser, url(base, view))
            seen = state(page)
            assert seen["ready"] and seen["errors"] == [], seen
            iou, within = agreement(canvas_rgba(page), rendered(specs[kind], view))
            print(f"{kind} {view}: mask IoU {iou:.4f}, {within:.2%} within 4/255")
            assert iou >= 0.99 and within >= 0.99, (kind, view, iou, within)
            page.close()
        assert log == []


@pytest.mark.parametrize("kind, options, backend", [
    ("octahedral-impostor", {"parallax_steps": 0}, "swiftshader"),  # frames on their planes
    ("mesh", {"shadows": True}, "swiftshader"),                      # the shadow-map kind
    ("octahedral-impostor", {"shadows": True}, "swiftshader"),
    # an opaque shell on SwiftShader: IoU 0.998-0.999 but 98.5-99.4% within 4/255, isolated
    # pixels where its 3D textures' filtering decides the first dense sample differently;
    # on Mesa's llvmpipe (what render draws with) every pixel is within 1/255
    ("shell-volume", {"composite": "opaque"}, "mesa"),
    ("shell-volume", {"composite": "opaque", "shadows": True}, "mesa"),  # depth sampler, culled
    ("shell-volume", {"sort": "peel"}, "mesa"),  # transparent, by depth peeling: no hook
    ("shell-volume", {"half_opacity": False}, "mesa"),  # the opaque-depth multi-pass kind
    # the depth object's screen slices counted in a stencil buffer
    ("depth-object", {"passes": "stencil", "slicing": "screen"}, "mesa")])
def test_render_options_make_the_plans(gl, browser, mesa_browser, specs, kind, options,
                                       backend):
    from reliefkit.io.inputs import load_input

    spec = specs[kind]
    browser = mesa_browser if backend == "mesa" else browser
    with served(site_files([make_input(spec, load_input(spec), options)])) as (base, _):
        for view in VIEWS:
            page = open_page(browser, url(base, view))
            assert state(page)["errors"] == []
            got = canvas_rgba(page)
            iou, within = agreement(got, rendered(spec, view, **options))
            print(f"{kind} {options} {view}: mask IoU {iou:.4f}, {within:.2%} within 4/255")
            assert iou >= 0.99 and within >= 0.99, (view, iou, within)
            page.close()
    # nearer the options' picture than the defaults' (where the two differ)
    optioned, default = rendered(spec, view, **options), rendered(spec, view)
    if not np.array_equal(optioned, default):
        assert _mean_difference(got, optioned) < _mean_difference(got, default)


def _mean_difference(page: np.ndarray, reference: np.ndarray) -> float:
    both = (page[..., 3] > 0) & (reference[..., 3] > 0)
    return float(np.abs(page[..., :3].astype(int) - reference[..., :3].astype(int))[both].mean())


def test_several_inputs_side_by_side_share_one_camera(gl, browser, specs):
    from reliefkit.io.inputs import load_input

    both = [specs["mesh-materials"], specs["mesh"]]
    boxes = np.array([framing_bounds(load_input(spec)) for spec in both])
    union = np.stack([boxes[:, 0].min(axis=0), boxes[:, 1].max(axis=0)])
    with served(site_files(load_inputs(both))) as (base, _):
        page = open_page(browser, url(base, "-100,10"))
        assert state(page)["errors"] == []
        for index, spec in enumerate(both):
            iou, within = agreement(canvas_rgba(page, index), rendered(spec, "-100,10", union))
            assert iou >= 0.99 and within >= 0.99, (spec, iou, within)


def test_a_drag_orbits(gl, browser, specs):
    with served(site_files(load_inputs([specs["mesh"]]))) as (base, _):
        page = open_page(browser, url(base, "30,25"))
        before, first = canvas_rgba(page), state(page)
        box = page.locator("canvas").bounding_box()
        x, y = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
        page.mouse.move(x, y)
        page.mouse.down()
        page.mouse.move(x + 60, y + 20, steps=4)
        page.mouse.up()
        page.wait_for_function(f"window.reliefkit.frames > {first['frames']}")
        az, el, dist = state(page)["view"]
        assert az < 30 and el > 25
        assert (canvas_rgba(page) != before).any()
        query = parse_qs(urlsplit(page.url).query)  # the view stays in the URL (the fitted
        assert np.allclose([float(x) for x in query["view"][0].split(",")], [az, el],  # distance
                           atol=1e-3) and query["size"] == ["128x128"]  # left out: refitted)
        page.locator("canvas").press("-")  # zoomed: the distance joins, to 10 digits
        page.wait_for_function(f"window.reliefkit.view[2] > {dist}")
        view = [float(x) for x in parse_qs(urlsplit(page.url).query)["view"][0].split(",")]
        assert view[2] == pytest.approx(state(page)["view"][2], rel=1e-9)
        el = state(page)["view"][1]
        page.locator("canvas").press("ArrowUp")
        page.wait_for_function(f"window.reliefkit.view[1] > {el}")
        if page.evaluate("!!document.querySelector('canvas').getContext('webgl2')"
                         ".getExtension('EXT_disjoint_timer_query_webgl2')"):
            page.wait_for_function("window.reliefkit.gpuMs > 0")  # the readout's GPU time


def test_a_right_drag_pans_and_the_url_reopens_it(gl, browser, specs):
    """Panning moves the orbited point in the picture's plane: the page draws what render
    draws from a camera orbiting that point; the URL carries it, and 0 goes back."""
    from reliefkit.io.inputs import load_input
    from reliefkit.render import render
    from reliefkit.scene.camera import Camera
    from reliefkit.scene.light import DEFAULT_LIGHT_ANGLES, DirectionalLight

    spec = specs["mesh"]
    with served(site_files(load_inputs([spec]))) as (base, _):
        page = open_page(browser, url(base, "30,25"))
        first = state(page)
        box = page.locator("canvas").bounding_box()
        x, y = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
        page.mouse.move(x, y)
        page.mouse.down(button="right")
        page.mouse.move(x + 30, y - 10, steps=3)
        page.mouse.up(button="right")
        page.wait_for_function(f"window.reliefkit.frames > {first['frames']}")
        panned = state(page)
        assert panned["view"] == first["view"]  # a pan does not orbit
        target = np.array(panned["target"])
        centre = framing_bounds(load_input(spec)).mean(axis=0)
        assert np.linalg.norm(target - np.array(first["target"])) > 0
        # the reference: render's camera orbiting the panned point, near/far around the box
        box3 = framing_bounds(load_input(spec))
        radius = float(np.linalg.norm(box3[1] - box3[0]) / 2)
        az, el, dist = panned["view"]
        probe = Camera.orbit(tuple(target), az, el, dist * radius, size=SIZE)
        to_centre = float(np.linalg.norm(centre - np.asarray(probe.eye)))
        camera = Camera.orbit(tuple(target), az, el, dist * radius, size=SIZE,
                              near=max(to_centre - 1.05 * radius, 0.005 * dist * radius),
                              far=to_centre + 1.05 * radius)
        light = DirectionalLight.from_angles(*DEFAULT_LIGHT_ANGLES)
        want = render(load_input(spec), camera, light=light).rgba8()
        iou, within = agreement(canvas_rgba(page), want)
        assert iou >= 0.99 and within >= 0.99, (iou, within)
        query = parse_qs(urlsplit(page.url).query)
        assert np.allclose([float(v) for v in query["target"][0].split(",")], target, rtol=1e-5)
        again = open_page(browser, page.url)  # the URL opens on the panned view
        assert np.allclose(state(again)["target"], target, rtol=1e-5)
        assert agreement(canvas_rgba(again), want)[0] >= 0.99
        frames = state(page)["frames"]
        page.locator("canvas").press("0")  # back to the opening view: the box's centre
        page.wait_for_function(f"window.reliefkit.frames > {frames}")
        assert np.allclose(state(page)["target"], centre) and state(page)["view"] == first["view"]
        assert "target" not in parse_qs(urlsplit(page.url).query)


def test_a_bad_url_is_said_and_the_page_opens_on_the_defaults(gl, browser, specs):
    with served(site_files(load_inputs([specs["mesh"]]))) as (base, log):
        page = open_page(browser, f"{base}?view=30&light=10,200&bogus=1&size=128x128")
        shown, opened = messages(page), state(page)
        huge = open_page(browser, f"{base}?size=5000x5000")  # 5000² x 132 bytes of targets
        refused, never = messages(huge), state(huge)
    assert shown == [
        "error: the URL's bogus=1 is no parameter of this page (view, size, light, target, "
        "debug) and no render option of its inputs (shadows): ignored",
        "error: light must be AZ,EL in degrees with an elevation within [-90, 90] (e.g. -60,30), "
        "got '10,200'; showing the default",
        "error: view must be AZ,EL or AZ,EL,DIST with |EL| < 90 (e.g. 30,25,2.6), got '30'; "
        "showing the default"]
    assert {"page: " + line for line in shown + refused} == set(log)  # posted as they came
    assert opened["ready"] and opened["view"][:2] == [30, 25]  # render's default view
    assert agreement(canvas_rgba(page), rendered(specs["mesh"], "30,25"))[0] >= 0.99
    assert "bogus" not in parse_qs(urlsplit(page.url).query)
    # nothing can be drawn: said, and never ready (a screenshot script must not take it)
    assert len(refused) == 1 and "a 5000x5000 frame needs 3148 MiB" in refused[0], refused
    assert never["loaded"] and not never["ready"]


def test_a_plan_it_cannot_draw_is_said(gl, browser, tmp_path):
    """A view hook the page has no port of (a newer reliefkit's, say): said, never blank."""
    made = sample("relief", "relief")
    save(tmp_path / "relief.rk", made)
    (shown_input,) = load_inputs([str(tmp_path / "relief.rk")])
    (tmp_path / "x.glb").write_bytes(shown_input.glb)
    glb = read_glb(tmp_path / "x.glb")
    (draw,) = [ext["draw"] for node in glb.document["nodes"]
               for ext in node.get("extensions", {}).values()]
    for plan in draw["plans"]:
        plan["per_view"]["tuple"][0] = "reliefkit.elsewhere:newer_hook"
    forged = Input(shown_input.name, shown_input.kind, glb_bytes(glb.document, glb.binary),
                   shown_input.bounds)
    with served(site_files([forged])) as (base, log):
        page = open_page(browser, base)
        shown = messages(page)
    assert shown and all("reliefkit.elsewhere:newer_hook is not supported by the viewer yet"
                         in line for line in shown), shown
    assert any("not supported by the viewer yet" in line for line in log)


def _glb_of_json(text: bytes) -> bytes:
    body = text + b" " * (-len(text) % 4)
    return struct.pack("<III", 0x46546C67, 2, 20 + len(body)) + \
        struct.pack("<II", len(body), 0x4E4F534A) + body


@pytest.mark.parametrize("data, message", [
    (b"this is no GLB file at all", "broken.glb is not a GLB file"),
    (_glb_of_json(b'{"asset": '), "broken.glb: its JSON chunk does not parse"),
    (_glb_of_json(b'{"asset": {"version": "2.0"}}'),
     "broken.glb: no RELIEFKIT_ extension (not exported by reliefkit)")])
def test_a_broken_file_shows_its_message(gl, browser, data, message):
    files = site_files([Input("broken.glb", "mesh", data, [[0, 0, 0], [1, 1, 1]])])
    with served(files) as (base, log):
        page = open_page(browser, base)
        shown = messages(page)
    assert len(shown) == 1 and shown[0].startswith(f"broken.glb: {message}"), shown
    assert log == ["page: " + " ".join(shown[0].split())]


def test_a_shader_that_does_not_compile_shows_its_message(gl, browser, specs, tmp_path):
    (good,) = load_inputs([specs["mesh"]])
    (tmp_path / "good.glb").write_bytes(good.glb)
    glb = read_glb(tmp_path / "good.glb")
    for node in glb.document["nodes"]:
        for ext in node.get("extensions", {}).values():
            for program in ext["draw"]["programs"]:
                version, rest = program["fragment"].split("\n", 1)
                program["fragment"] = f"{version}\n#error forced by the test\n{rest}"
    broken = Input("forced.glb", "mesh", glb_bytes(glb.document, glb.binary), good.bounds)
    with served(site_files([broken])) as (base, log):
        page = open_page(browser, base)
        shown = messages(page)
    assert len(shown) == 1 and "fragment shader of core:mesh.glsl does not compile" in shown[0]
    assert "forced by the test" in shown[0]
    assert log == ["page: " + " ".join(shown[0].split())]
