"""The command line starts light: ``--help`` and ``info`` import none of the heavy libraries
(numba, trimesh, scipy, ...), which only baking, drawing and the benches need. Checked in a
fresh interpreter by what it imported, not by a time."""

from __future__ import annotations

import json
import subprocess
import sys

from reliefkit.builtins import registry
from reliefkit.io import rk
from reliefkit.scene.assets import make_asset

# moderngl is not among them: importing it takes about 16 ms and makes no context (the
# executor's module imports it; `render()` makes the context when it first draws)
HEAVY = ("numba", "trimesh", "scipy", "networkx", "matplotlib", "fast_simplification",
         "open3d", "vtk", "imageio")

RUN = """
import contextlib, io, json, sys
from reliefkit.cli import main
for argv in json.loads(sys.argv[1]):
    with contextlib.redirect_stdout(io.StringIO()) as out:
        try:
            status = main(argv)
        except SystemExit as exit:  # argparse, after printing the help
            status = exit.code
    assert status == 0, (argv, status, out.getvalue())
print(" ".join(m for m in {heavy} if m in sys.modules))
"""


def heavy_modules_after(*commands: list[str]) -> list[str]:
    """The heavy libraries a fresh interpreter has imported after running ``commands``."""
    out = subprocess.run([sys.executable, "-c", RUN.format(heavy=HEAVY), json.dumps(commands)],
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    return out.stdout.split()


def test_help_imports_no_heavy_library():
    commands = [["--help"], *([name, "--help"] for name in
                              ("render", "bake", "batch", "compare", "bench", "demo",
                               "info"))]
    assert heavy_modules_after(*commands) == []


def test_info_imports_no_heavy_library(tmp_path):
    """Every built-in kind: the file's codec is all ``info`` needs. A DMBBC's distance
    textures are checked on reading against scipy's exact distance transform."""
    checked_with_scipy = {"dmbbc"}
    paths = {"mesh": rk.save(tmp_path / "mesh.rk", make_asset("cup"))}
    for tech in registry().techniques():
        paths |= {kind: rk.save(tmp_path / f"{kind}.rk", rep)
                  for kind, rep in tech.samples().items()}
    assert checked_with_scipy <= set(paths)
    light = [["info", str(path)] for kind, path in paths.items() if kind not in checked_with_scipy]
    assert heavy_modules_after(*light) == []
    for kind in checked_with_scipy:
        assert heavy_modules_after(["info", str(paths[kind])]) == ["scipy"]
