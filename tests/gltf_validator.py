"""The Khronos glTF validator for tests: `validate(path)` runs tools/gltf/validate.mjs (npm
``gltf-validator``, pinned in package.json / package-lock.json) and returns its JSON report.

Where node or the installed validator (``npm ci`` in the repository root) is missing the
calling test skips with the reason, except on CI (``CI=true``), where that is a failure: CI
must always validate.
"""

from __future__ import annotations

import json
import subprocess

from node_tools import ROOT, node_or_skip

SCRIPT = ROOT / "tools" / "gltf" / "validate.mjs"
PACKAGE = ROOT / "node_modules" / "gltf-validator"
TIMEOUT_S = 120


def validate(path) -> dict:
    """The validator's report for ``path`` (``report["issues"]["numErrors"]`` etc.)."""
    node = node_or_skip("the glTF validator", PACKAGE)
    done = subprocess.run([node, str(SCRIPT), str(path)], capture_output=True, text=True,
                          timeout=TIMEOUT_S, cwd=ROOT)
    if done.returncode:
        raise AssertionError(f"the validator failed on {path}: {done.stderr.strip()}")
    return json.loads(done.stdout)


def problems(report: dict) -> list[str]:
    """The report's errors and warnings (severity 0 and 1), one line each."""
    return [f"{m['code']} at {m.get('pointer', '?')}: {m['message']}"
            for m in report["issues"]["messages"] if m["severity"] <= 1]
