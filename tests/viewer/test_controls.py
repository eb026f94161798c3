"""The page's controls in headless Chromium: a render option switched in the page (or asked
for in the URL) gives the picture `reliefkit render` gives with that option, and the URL
carries it; a bad value is said and the picture stays; the light sliders and `light=` give
`render --light`; a static export shows its options disabled and says a URL option it
cannot apply. Switching plans frees the old GL objects."""

from __future__ import annotations

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

from reliefkit import save
from reliefkit.io.inputs import load_input
from reliefkit.render import render
from reliefkit.scene.light import DEFAULT_LIGHT_ANGLES, DirectionalLight
from reliefkit.scene.views import framing_bounds, orbit_bounds, parse_view
from reliefkit.viewer.site import load_inputs, make_input, site_files
from reliefkit.viewer.variants import Variants

VIEW = "30,25"
#: every GL object the page makes and deletes, counted (WebGL cannot list the live ones);
#: not timer queries, which live from one frame until the browser has their result
COUNT_GL_OBJECTS = """
(() => {
  const live = new Set();
  window.__glLive = () => live.size;
  const proto = WebGL2RenderingContext.prototype;
  for (const kind of ['Texture', 'Buffer', 'Framebuffer', 'Renderbuffer', 'VertexArray',
                      'Program', 'Shader']) {
    const [make, free] = [proto['create' + kind], proto['delete' + kind]];
    proto['create' + kind] = function (...a) {
      const made = make.apply(this, a);
      live.add(made);
      return made;
    };
    proto['delete' + kind] = function (o) { live.delete(o); return free.call(this, o); };
  }
})();
"""


@pytest.fixture(scope="module")
def specs(tmp_path_factory):
    folder = tmp_path_factory.mktemp("inputs")
    out = {}
    for technique, kind in (("impostor", "octahedral-impostor"), ("relief", "relief")):
        out[kind] = str(folder / f"{kind}.rk")
        save(out[kind], sample(technique, kind))
    return out


def live_site(specs: list[str]):
    inputs = load_inputs(specs)
    return site_files(inputs, live=True), Variants(inputs)


def page_at(browser, base: str, query: str = ""):
    """The page at VIEW, 128x128, and ``query``, once its options are applied and drawn."""
    page = open_page(browser, f"{base}?view={VIEW}&size={SIZE[0]}x{SIZE[1]}{query}",
                     COUNT_GL_OBJECTS)
    settle(page)
    return page


def settle(page):
    """Wait for the option switch under way to end and its frame to be drawn."""
    page.wait_for_function("window.reliefkit.ready", timeout=120_000)


def url_options(page) -> dict:
    return {k: v[0] for k, v in parse_qs(urlsplit(page.url).query).items()}


def assert_agrees(page, reference):
    iou, within = agreement(canvas_rgba(page), reference)
    assert iou >= 0.99 and within >= 0.99, (iou, within)


def test_switching_an_option_in_the_page_draws_what_render_draws(gl, browser, specs):
    spec = specs["octahedral-impostor"]
    before_ref, after_ref = rendered(spec, VIEW), rendered(spec, VIEW, parallax_steps=0)
    assert not np.array_equal(before_ref, after_ref)
    with served(*live_site([spec])) as (base, log):
        page = page_at(browser, base)
        field = page.locator("#option-parallax-steps")
        assert field.input_value() == "8" and field.is_enabled()
        assert_agrees(page, before_ref)
        assert "parallax-steps" not in url_options(page)  # the default is not in the URL
        field.fill("0")
        field.press("Enter")
        settle(page)
        assert_agrees(page, after_ref)
        assert url_options(page)["parallax-steps"] == "0"
        live = page.evaluate("window.__glLive()")
        for value in ["8", "0"] * 10:  # 20 switches: the old plans' GL objects are freed
            field.fill(value)
            field.press("Enter")
            settle(page)
        assert page.evaluate("window.__glLive()") == live
        assert_agrees(page, after_ref)
        assert state(page)["errors"] == [] and log == []


def test_a_url_with_options_opens_with_them_and_a_select_switches_the_method(gl, browser,
                                                                               specs):
    spec = specs["relief"]
    # binary search with two linear steps and one bisection: visibly coarser than robust
    coarse = {"method": "binary", "linear_steps": 2, "binary_steps": 1}
    coarse_ref, robust_ref = rendered(spec, VIEW, **coarse), rendered(spec, VIEW)
    assert agreement(coarse_ref, robust_ref)[1] < 0.99  # the check below can tell them apart
    with served(*live_site([spec])) as (base, _):
        page = page_at(browser, base, "&method=binary&linear-steps=2&binary-steps=1")
        assert page.locator("#option-method").input_value() == "binary"
        assert_agrees(page, coarse_ref)
        page.locator("#option-method").select_option("robust")
        settle(page)
        assert_agrees(page, robust_ref)
        assert "method" not in url_options(page)
        assert url_options(page)["linear-steps"] == "2"
        assert state(page)["errors"] == []
    # `reliefkit view relief.rk --method binary ...`: the page opens so, and its URL says it
    inputs = [make_input(spec, load_input(spec), coarse)]
    with served(site_files(inputs, live=True), Variants(inputs)) as (base, _):
        page = page_at(browser, base)
        assert page.locator("#option-method").input_value() == "binary"
        assert url_options(page)["method"] == "binary"
        assert_agrees(page, coarse_ref)


def test_the_iteration_heat_map_follows_an_option_switch(gl, browser, specs):
    """The counting plans come from the GLB made with the new options: the page's counts are
    render's with them."""
    spec = specs["relief"]
    coarse = {"method": "binary", "linear_steps": 2, "binary_steps": 1}
    counted = {name: rendered_counts(spec, **options)
               for name, options in (("robust", {}), ("binary", coarse))}
    assert counted["robust"]["iterations_max"] != counted["binary"]["iterations_max"]
    with served(*live_site([spec])) as (base, _):
        page = page_at(browser, base, "&debug=iterations&linear-steps=2&binary-steps=1")
        for method in ("robust", "binary"):
            if page.locator("#option-method").input_value() != method:
                page.locator("#option-method").select_option(method)
                settle(page)
            got = state(page)["debug"]["iterations"][0]
            assert got["max"] == counted[method]["iterations_max"], method
            assert got["mean"] == pytest.approx(counted[method]["iterations_mean"], rel=0.01)
        assert state(page)["errors"] == []


def rendered_counts(spec: str, **options) -> dict:
    """`render --stats`'s iteration counts of ``spec`` at VIEW, 128x128."""
    obj = load_input(spec)
    camera = orbit_bounds(framing_bounds(obj), *parse_view(VIEW), SIZE)
    light = DirectionalLight.from_angles(*DEFAULT_LIGHT_ANGLES)
    return render(obj, camera, light=light, count_iterations=True, **options).stats


def test_a_bad_value_is_said_and_the_picture_stays(gl, browser, specs):
    spec = specs["octahedral-impostor"]
    with served(*live_site([spec])) as (base, log):
        page = page_at(browser, base)
        before = canvas_rgba(page)
        field = page.locator("#option-parallax-steps")
        field.fill("99")
        field.press("Enter")
        settle(page)
        shown = messages(page)
        after = canvas_rgba(page)
        value = field.input_value()
    message = (f"error: --parallax-steps must be within [0, 16], got 99 ({spec}, an "
               "octahedral-impostor .rk)")
    assert shown == [message]
    assert log == ["page: " + message]
    assert np.array_equal(before, after) and value == "8"


def test_the_light_sliders_and_the_url_give_render_s_light(gl, browser, specs):
    spec = specs["relief"]
    lit = rendered(spec, VIEW, light_angles=(120, 40))
    assert agreement(lit, rendered(spec, VIEW))[1] < 0.99
    with served(*live_site([spec])) as (base, _):
        page = page_at(browser, base, "&light=120,40")
        assert_agrees(page, lit)
        page.close()
        page = page_at(browser, base)
        move_light(page, 120, 40)
        assert_agrees(page, lit)
        assert url_options(page)["light"] == "120,40"


def test_a_shadow_map_follows_the_light(gl, browser, specs):
    """Drawn again for the new light, the old one freed."""
    spec = specs["octahedral-impostor"]
    lit = rendered(spec, VIEW, light_angles=(120, 40), shadows=True)
    with served(*live_site([spec])) as (base, _):
        page = page_at(browser, base, "&shadows=true")
        move_light(page, 0, 60)
        live = page.evaluate("window.__glLive()")
        for azimuth in (30, 60, 90, 120):
            move_light(page, azimuth, 40)
        assert page.evaluate("window.__glLive()") == live
        assert_agrees(page, lit)


def move_light(page, azimuth: float, elevation: float):
    """The light sliders moved as a user does, and the frame drawn."""
    frames = state(page)["frames"]
    page.evaluate("""([az, el]) => {
      for (const [id, v] of [['light-azimuth', az], ['light-elevation', el]]) {
        const slider = document.getElementById(id);
        slider.value = String(v);
        slider.dispatchEvent(new Event('input'));
      }
    }""", [azimuth, elevation])
    page.wait_for_function(f"window.reliefkit.frames > {frames}")


def test_a_static_export_shows_its_options_disabled_and_says_a_url_option(gl, browser, specs):
    spec = specs["octahedral-impostor"]
    with served(site_files(load_inputs([spec]))) as (base, _):  # no Python behind it
        page = page_at(browser, base, "&parallax-steps=0")
        field = page.locator("#option-parallax-steps")
        assert field.is_disabled() and field.input_value() == "8"
        assert "this static export holds the plans made with these options" in \
            page.locator("#options .why").inner_text().lower()
        assert messages(page) == [
            "the URL asks for parallax-steps=0, but this static export holds the plans made with "
            "parallax-steps=8 (export again with --parallax-steps 0 to see them)"]
        assert_agrees(page, rendered(spec, VIEW))
