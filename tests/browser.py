"""Headless Chromium for the viewer's tests: Debian's ``chromium`` driven by Playwright for
Python (`page(site)` opens a served site), and the site served from memory by the viewer's
own server (`served`), with the lines the page posts to its log.

Where Chromium or Playwright is missing the calling test skips with the reason, except on CI
(``CI=true``), where that is a failure: `./run test` and `.ci/run` install both.
"""

from __future__ import annotations

import base64
import io
import os
import shutil
import threading
from contextlib import contextmanager

import numpy as np
import pytest

CHROMIUM = "/usr/bin/chromium"
# headless, on a closed network (ecosystem notes), with WebGL2 through ANGLE on SwiftShader
# or on Mesa's llvmpipe (what `reliefkit render` draws with here; blocklisted without the flag)
FLAGS = ["--headless=new", "--no-sandbox", "--disable-background-networking",
         "--disable-component-update"]
BACKENDS = {"swiftshader": ["--use-angle=swiftshader", "--enable-unsafe-swiftshader"],
            "mesa": ["--use-angle=gl-egl", "--ignore-gpu-blocklist"]}
READY_TIMEOUT_MS = 120_000


def unavailable(reason: str):
    if os.environ.get("CI", "").lower() == "true":
        pytest.fail(f"CI=true but the browser tests cannot run: {reason}")
    pytest.skip(f"browser unavailable: {reason}")


@contextmanager
def playwright():
    """Playwright's sync API, once per test module (it runs one instance at a time)."""
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        unavailable("playwright is not installed (pip install playwright)")
    with sync_playwright() as p:
        yield p


def launch(p, backend: str = "swiftshader"):
    """A headless Chromium (Playwright's Browser) drawing WebGL2 with ``backend``."""
    path = shutil.which("chromium") or (CHROMIUM if os.path.exists(CHROMIUM) else None)
    if path is None:
        unavailable("chromium is not installed (apt-get install chromium)")
    return p.chromium.launch(executable_path=path, args=FLAGS + BACKENDS[backend])


@contextmanager
def chromium(backend: str = "swiftshader"):
    """A headless Chromium of its own, closed at the end."""
    with playwright() as p:
        browser = launch(p, backend)
        try:
            yield browser
        finally:
            browser.close()


@contextmanager
def served(files: dict):
    """The viewer's server of ``files`` on a free port, in a thread: (base URL, log lines)."""
    from reliefkit.viewer.server import make_server

    lines: list[str] = []
    server = make_server(files, 0, log=lines.append)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}/", lines
    finally:
        server.shutdown()
        server.server_close()


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
