"""The bundle that ships (src/reliefkit/viewer/static/viewer.js) is what web/build.mjs makes
of web/src/ with the pinned esbuild: rebuilding gives the committed bytes. Skips without
node or `npm ci`'s esbuild, except on CI (``CI=true``), where that is a failure."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
BUNDLE = ROOT / "src" / "reliefkit" / "viewer" / "static" / "viewer.js"


def _unavailable(reason: str):
    if os.environ.get("CI", "").lower() == "true":
        pytest.fail(f"CI=true but the viewer bundle cannot be rebuilt: {reason}")
    pytest.skip(reason)


def test_the_committed_bundle_is_built_from_the_sources(tmp_path):
    node = shutil.which("node")
    if node is None:
        _unavailable("node is not installed (apt-get install nodejs npm)")
    if not (ROOT / "node_modules" / "esbuild").is_dir():
        _unavailable(f"esbuild is missing (run `npm ci` in {ROOT})")
    out = tmp_path / "viewer.js"
    done = subprocess.run([node, str(ROOT / "web" / "build.mjs"), str(out)], cwd=ROOT,
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr[-2000:]
    assert out.read_bytes() == BUNDLE.read_bytes(), \
        "viewer.js is stale: run `node web/build.mjs` and commit it"
