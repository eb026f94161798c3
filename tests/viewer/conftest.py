"""The viewer tests' headless Chromium: one Playwright instance and browser per test module
(Playwright's sync API runs one instance at a time), on SwiftShader, and on Mesa's llvmpipe
through ANGLE for the kinds compared there."""

from __future__ import annotations

import pytest
from browser import launch, playwright


@pytest.fixture(scope="module")
def pw():
    with playwright() as p:
        yield p


@pytest.fixture(scope="module")
def browser(pw):
    b = launch(pw)
    yield b
    b.close()


@pytest.fixture(scope="module")
def mesa_browser(pw):
    b = launch(pw, "mesa")
    yield b
    b.close()
