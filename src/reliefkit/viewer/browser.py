"""Headless Chromium for `reliefkit bench viewer` and the viewer's tests: Debian's
``chromium`` driven by Playwright for Python (its own browser download is not needed, and is
not reachable on a closed network), with WebGL2 on one of `BACKENDS`.

What is missing (Playwright, the browser) is a `UsageError` that says what to install, before
anything starts.
"""

from __future__ import annotations

import os
import shutil
from contextlib import contextmanager

from ..errors import UsageError

#: The browser's path: this variable, else ``chromium`` on the PATH, else Debian's.
CHROMIUM_VARIABLE = "RELIEFKIT_CHROMIUM"
DEBIAN_CHROMIUM = "/usr/bin/chromium"
# headless, on a closed network (ecosystem notes)
FLAGS = ("--headless=new", "--no-sandbox", "--disable-background-networking",
         "--disable-component-update")
#: WebGL2 through ANGLE on SwiftShader (any machine), or on the EGL driver: Mesa's llvmpipe
#: here (what `reliefkit render` draws with; blocklisted without the flag), an NVIDIA GPU
#: where glvnd picks NVIDIA's (__EGL_VENDOR_LIBRARY_FILENAMES, as tools/device/ sets it).
#: ``mesa`` and ``gpu`` are the same flags, named for what the report expects to see; its
#: WebGL renderer string says which one drew.
_EGL = ("--use-angle=gl-egl", "--ignore-gpu-blocklist")
BACKENDS = {"swiftshader": ("--use-angle=swiftshader", "--enable-unsafe-swiftshader"),
            "mesa": _EGL, "gpu": _EGL}
INSTALL_PLAYWRIGHT = "pip install 'reliefkit[viewer]'"
INSTALL_CHROMIUM = "apt-get install chromium"


def chromium_path() -> str:
    """The Chromium to launch, or a `UsageError` saying how to get one."""
    named = os.environ.get(CHROMIUM_VARIABLE)
    if named:
        if not (os.path.isfile(named) and os.access(named, os.X_OK)):
            raise UsageError(f"{CHROMIUM_VARIABLE}={named}: no executable browser there")
        return named
    path = shutil.which("chromium") or (DEBIAN_CHROMIUM if os.path.exists(DEBIAN_CHROMIUM)
                                        else None)
    if path is None:
        raise UsageError(f"chromium is not installed ({INSTALL_CHROMIUM}, or set "
                         f"{CHROMIUM_VARIABLE} to a Chromium)")
    return path


def require_playwright() -> None:
    """A `UsageError` saying what to install where Playwright for Python is missing."""
    try:
        import playwright.sync_api  # noqa: F401
    except ImportError:
        raise UsageError(f"playwright is not installed ({INSTALL_PLAYWRIGHT})") from None


@contextmanager
def playwright():
    """Playwright's sync API (one instance at a time in a process)."""
    require_playwright()
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        yield p


def launch(p, backend: str = "swiftshader"):
    """A headless Chromium (Playwright's Browser) drawing WebGL2 with ``backend``."""
    if backend not in BACKENDS:
        raise UsageError(f"unknown browser backend {backend!r} (choose from "
                         f"{', '.join(BACKENDS)})")
    return p.chromium.launch(executable_path=chromium_path(),
                             args=[*FLAGS, *BACKENDS[backend]])


@contextmanager
def chromium(backend: str = "swiftshader"):
    """A headless Chromium of its own, closed at the end (the browser is found before
    Playwright starts)."""
    chromium_path()
    require_playwright()
    with playwright() as p:
        browser = launch(p, backend)
        try:
            yield browser
        finally:
            browser.close()
