"""Shared fixtures: one GL probe per session (in a subprocess with a timeout), seeded RNG."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

from reliefkit.builtins import registry

sys.path.insert(0, os.path.dirname(__file__))  # `import helpers` from any test folder

registry()  # the composition root, as every public entry point runs it: tests use the layers

PROBE = ("from reliefkit.gl.context import create_context; "
         "print(create_context().info['GL_RENDERER'])")
_probe_result: tuple[bool, str] | None = None


def _probe_gl() -> tuple[bool, str]:
    """Can this machine make a GL 4.3 context? Probed once, in a child process."""
    global _probe_result
    if _probe_result is None:
        try:
            out = subprocess.run([sys.executable, "-c", PROBE], capture_output=True, text=True,
                                 timeout=60)
            ok = out.returncode == 0
            _probe_result = (ok, out.stdout.strip() if ok else out.stderr.strip()[-300:])
        except subprocess.TimeoutExpired:
            _probe_result = (False, "creating a GL context timed out after 60 s")
    return _probe_result


def pytest_sessionstart(session):
    ok, detail = _probe_gl()
    if not ok and os.environ.get("RELIEFKIT_REQUIRE_GL"):
        pytest.exit(f"RELIEFKIT_REQUIRE_GL is set but no OpenGL context could be made: {detail}",
                    returncode=3)


def pytest_report_header(config):
    ok, detail = _probe_gl()
    return f"reliefkit GL: {detail if ok else 'unavailable (' + detail + ')'}"


@pytest.fixture(scope="session")
def gl():
    """The shared moderngl context; GPU tests skip with the reason when none can be made."""
    ok, detail = _probe_gl()
    if not ok:
        pytest.skip(f"no OpenGL context: {detail}")
    from reliefkit.gl.context import get_context

    return get_context()


@pytest.fixture
def rng():
    return np.random.default_rng(0)


@pytest.fixture(autouse=True)
def _strict_numpy():
    with np.errstate(all="raise"):
        yield


@pytest.fixture(scope="module")
def toy_registered():
    """The toy technique in the registry for a module's tests (`technique_samples` lists its
    kind): ``pytestmark = pytest.mark.usefixtures("toy_registered")``."""
    from helpers import toy_technique

    with toy_technique():
        yield
