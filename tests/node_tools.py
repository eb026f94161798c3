"""Node for tests that run the project's JavaScript (the glTF validator, the viewer's view
hooks): `node_or_skip(what)` is the node executable, or the calling test skips with the
reason; on CI (``CI=true``) a missing node or package is a failure: CI must always run them.
"""

from __future__ import annotations

import base64
import json
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
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


class NodeScript:
    """A node script that answers one JSON request a line with one JSON answer a line
    (tools/viewer/run_*.mjs), in one process; an ``{"error": ...}`` answer fails the test."""

    def __init__(self, what: str, script: Path):
        node = node_or_skip(what)
        self.script = script
        self.process = subprocess.Popen([node, str(script)], stdin=subprocess.PIPE,
                                        stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                        text=True, cwd=ROOT)

    def ask(self, request: dict) -> dict:
        try:
            self.process.stdin.write(json.dumps(request) + "\n")
            self.process.stdin.flush()
            line = self.process.stdout.readline()
        except BrokenPipeError:
            line = ""
        if not line:
            raise AssertionError(f"{self.script.name} exited: {self.process.stderr.read()[-2000:]}")
        answer = json.loads(line)
        if "error" in answer:
            raise AssertionError(f"{self.script.name} failed: {answer['error']}")
        return answer

    def close(self):
        self.process.stdin.close()
        self.process.wait(timeout=30)


def wire(array: np.ndarray) -> dict:
    """An array as the node scripts take it: dtype, shape and its little-endian bytes."""
    a = np.ascontiguousarray(array)
    return {"dtype": a.dtype.name, "shape": list(a.shape),
            "b64": base64.b64encode(a.astype(a.dtype.newbyteorder("<")).tobytes()).decode()}


def unwire(value):
    """`wire`'s inverse, through lists and dicts."""
    if isinstance(value, list):
        return [unwire(v) for v in value]
    if not isinstance(value, dict):
        return value
    if "b64" in value:
        data = np.frombuffer(base64.b64decode(value["b64"]),
                             np.dtype(value["dtype"]).newbyteorder("<"))
        return data.reshape(value["shape"])
    return {k: unwire(v) for k, v in value.items()}
