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
def served(files: dict):
    """The viewer's server of ``files`` on a free port, in a thread: (base URL, log lines)."""
    lines: list[str] = []
    with serving(files, lines.append) as url:
        yield url, lines


def open_page(browser, url: str):
    """A new page at ``url``, waited on until its first frame is complete or it gave up."""
    page = browser.new_page()
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
