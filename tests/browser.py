"""Headless Chromium for the viewer's tests (launched by `reliefkit.viewer.browser`: Debian's
``chromium`` driven by Playwright for Python; `open_page` opens a served site), and the site
served from memory by the viewer's own server (`served`), with the lines the page posts to
its log.

Where Chromium or Playwright is missing the calling test skips with the reason, except on CI
(``CI=true``), where that is a failure: `./run test` and `.ci/run` install both.
"""

from __future__ import annotations

import base64
import io
import os
from contextlib import contextmanager

import numpy as np
import pytest

from reliefkit.errors import UsageError
from reliefkit.viewer import browser
from reliefkit.viewer.server import serving

READY_TIMEOUT_MS = 120_000
SIZE = (128, 128)  # the pages the tests compare with `reliefkit render`


def unavailable(reason: str):
    if os.environ.get("CI", "").lower() == "true":
        pytest.fail(f"CI=true but the browser tests cannot run: {reason}")
    pytest.skip(f"browser unavailable: {reason}")


@contextmanager
def playwright():
    """Playwright's sync API, once per test module (it runs one instance at a time)."""
    try:
        browser.require_playwright()
    except UsageError as exc:
        unavailable(str(exc))
    with browser.playwright() as p:
        yield p


def launch(p, backend: str = "swiftshader"):
    """A headless Chromium (Playwright's Browser) drawing WebGL2 with ``backend``."""
    try:
        browser.chromium_path()
    except UsageError as exc:
        unavailable(str(exc))
    return browser.launch(p, backend)


@contextmanager
def chromium(backend: str = "swiftshader"):
    """A headless Chromium of its own, closed at the end."""
    with playwright() as p:
        b = launch(p, backend)
        try:
            yield b
        finally:
            b.close()


@contextmanager
def served(files: dict, variants=None):
    """The viewer's server of ``files`` (and ``variants``: the GLBs made with other render
    options) on a free port, in a thread: (base URL, log lines)."""
    lines: list[str] = []
    with serving(files, lines.append, variants) as url:
        yield url, lines


def open_page(browser, url: str, init_script: str | None = None):
    """A new page at ``url`` (``init_script`` run before the page's own), waited on until its
    first frame is complete or it gave up."""
    page = browser.new_page()
    if init_script:
        page.add_init_script(init_script)
    page.goto(url)
    page.wait_for_function("window.reliefkit && window.reliefkit.loaded",
                           timeout=READY_TIMEOUT_MS)
    return page


def state(page) -> dict:
    return page.evaluate("() => JSON.parse(JSON.stringify(window.reliefkit))")


def canvas_rgba(page, index: int = 0) -> np.ndarray:
    """The pixels of the page's ``index``-th canvas, (H, W, 4) uint8, row 0 at the top."""
    from PIL import Image

    url = page.evaluate(f"document.querySelectorAll('canvas')[{index}].toDataURL('image/png')")
    data = base64.b64decode(url.split(",", 1)[1])
    return np.asarray(Image.open(io.BytesIO(data)).convert("RGBA"))


def messages(page) -> list[str]:
    """The error lines the page shows."""
    return page.locator("#messages .error").all_inner_texts()


def rendered(spec: str, view: str, bounds=None, light_angles=None, **options) -> np.ndarray:
    """What `reliefkit render SPEC --view VIEW --size 128x128 [--light AZ,EL] [OPTIONS]`
    writes, as RGBA8 (framed by ``bounds`` instead of the input's own)."""
    from reliefkit.io.inputs import load_input
    from reliefkit.render import render
    from reliefkit.scene.light import DEFAULT_LIGHT_ANGLES, DirectionalLight
    from reliefkit.scene.views import framing_bounds, orbit_bounds, parse_view

    obj = load_input(spec)
    box = framing_bounds(obj) if bounds is None else bounds
    camera = orbit_bounds(box, *parse_view(view), SIZE)
    light = DirectionalLight.from_angles(*(light_angles or DEFAULT_LIGHT_ANGLES))
    return render(obj, camera, light=light, **options).rgba8()


def agreement(page: np.ndarray, reference: np.ndarray) -> tuple[float, float]:
    """Mask IoU, and the fraction of pixels both cover whose channels are within 4/255."""
    a, b = page[..., 3] > 0, reference[..., 3] > 0
    iou = (a & b).sum() / max((a | b).sum(), 1)
    both = a & b
    diff = np.abs(page[..., :3].astype(int) - reference[..., :3].astype(int)).max(-1)[both]
    return float(iou), float((diff <= 4).mean()) if diff.size else 0.0
