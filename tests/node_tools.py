"""Node for tests that run the project's JavaScript (the glTF validator, the viewer's view
hooks): `node_or_skip(what)` is the node executable, or the calling test skips with the
reason; on CI (``CI=true``) a missing node or package is a failure: CI must always run them.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def unavailable(what: str, reason: str):
    """Skip (or, under ``CI=true``, fail) a test that needs ``what`` for ``reason``."""
    if os.environ.get("CI", "").lower() == "true":
        pytest.fail(f"CI=true but {what} cannot run: {reason}")
    pytest.skip(f"{what} unavailable: {reason}")


def node_or_skip(what: str, package: Path | None = None) -> str:
    """The node executable for running ``what``, with the npm ``package`` folder (under
    node_modules) installed where one is given."""
    node = shutil.which("node")
    if node is None:
        unavailable(what, "node is not installed (apt-get install nodejs npm)")
    if package is not None and not package.is_dir():
        unavailable(what, f"{package.relative_to(ROOT)} is missing (run `npm ci` in {ROOT})")
    return node
