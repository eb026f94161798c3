"""The task function on its own, in this process: plain data in, the .rk bytes or one line
out, never an exception for a bad asset, no file system shared with the driver."""

from __future__ import annotations

import hashlib
import pickle
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest
from helpers import write_tetrahedron
from PIL import Image

from reliefkit.batch.jobs import Job
from reliefkit.batch.task import Result, make_task, prepare_worker, run_task
from reliefkit.builtins import bake, save
from reliefkit.errors import UsageError
from reliefkit.io.meshes import load_mesh
from reliefkit.io.rk import rk_bytes


def test_a_task_carries_its_files_and_bakes_without_them_on_disk(gl, tmp_path):
    mesh = write_tetrahedron(tmp_path / "lib" / "t.obj", name_texture="tex/t.png")
    (tmp_path / "lib" / "tex").mkdir()
    Image.new("RGB", (4, 4), (10, 200, 10)).save(tmp_path / "lib" / "tex" / "t.png")
    task = make_task(Job(mesh, "t.rk", "relief", {"depth_res": "10"}, "t.obj"))
    task = pickle.loads(pickle.dumps(task))  # what crosses to a worker
    assert set(task.files) == {"t.mtl", "tex/t.png"}
    expected = tmp_path / "expected.rk"
    save(expected, bake(load_mesh(mesh), "relief", depth_res=10),
         source_hash=hashlib.sha256(mesh.read_bytes()).hexdigest(), cache_key=task.key)
    shutil.rmtree(tmp_path / "lib")  # the worker needs nothing on disk
    result = pickle.loads(pickle.dumps(run_task(task)))
    assert isinstance(result, Result) and result.status == "ok", result.error
    assert result.rk == expected.read_bytes()
    assert result.warnings == ()  # its texture was found: shipped with the task


@pytest.mark.parametrize("source, words", [
    (b"", "is empty"),
    (b"v 0 0 0\nv 1 1 1\nv 2 2 2\nf 1 2 3\n", "no triangle with a visible area"),
    (b"v 0 0 0\nf 1 2 3\n", "t.obj"),
])
def test_a_bad_asset_is_a_failed_result_with_one_line(gl, tmp_path, source, words):
    mesh = write_tetrahedron(tmp_path / "t.obj")
    task = make_task(Job(mesh, "t.rk", "relief", {"depth_res": 10}, "t.obj"))
    task = type(task)(**{**task.__dict__, "source": source})
    result = run_task(task)
    assert result.status == "failed" and result.rk is None
    assert words in result.error and "\n" not in result.error
    assert "reliefkit-mesh-" not in result.error  # the worker's folder is not named


def test_a_file_name_outside_the_folder_is_refused(gl, tmp_path):
    mesh = write_tetrahedron(tmp_path / "t.obj")
    task = make_task(Job(mesh, "t.rk", "relief", {"depth_res": 10}, "t.obj"))
    name = f"../escape-{tmp_path.name}.png"  # next to the worker's temporary folder
    task = type(task)(**{**task.__dict__, "files": {name: b"x"}})
    result = run_task(task)
    assert result.status == "failed" and "outside its folder" in result.error
    assert not (Path(tempfile.gettempdir()) / name[3:]).exists()


def test_prepare_worker_comes_before_the_gl_context(gl):
    with pytest.raises(UsageError, match="before this process makes its GL context"):
        prepare_worker(threads=1)


WORKER = """
import pickle, sys
from reliefkit.batch.task import prepare_worker, run_task
from reliefkit.builtins import registry
from reliefkit.errors import UsageError
from reliefkit.gl.context import has_context
prepare_worker(registry, threads=1)
result = run_task(pickle.loads(sys.stdin.buffer.read()))
assert not has_context(), "the task made the process-wide context"
try:
    prepare_worker(threads=1)
    raise AssertionError("prepared again after its context was made")
except UsageError:
    pass
sys.stdout.buffer.write(pickle.dumps(result))
"""


def test_a_worker_bakes_on_its_own_context(gl, tmp_path):
    """A worker's tasks bake on the context it made once (`using`), never the process-wide
    one, to the bytes a bake on that one gives; a fresh interpreter: no context yet."""
    mesh = write_tetrahedron(tmp_path / "t.obj")
    task = make_task(Job(mesh, "t.rk", "relief", {"depth_res": 10}, "t.obj"))
    out = subprocess.run([sys.executable, "-c", WORKER], input=pickle.dumps(task),
                         capture_output=True, timeout=300)
    assert out.returncode == 0, out.stderr.decode()[-2000:]
    result = pickle.loads(out.stdout)
    assert result.status == "ok", result.error
    assert result.rk == rk_bytes(bake(load_mesh(mesh), "relief", depth_res=10),
                                 source_hash=hashlib.sha256(mesh.read_bytes()).hexdigest(),
                                 cache_key=task.key)


def test_prepare_worker_picks_the_egl_device_by_index():
    """The device index reaches EGL (which ignores CUDA_VISIBLE_DEVICES): one that does not
    exist is refused by it, the first one draws (a fresh interpreter: no context yet)."""
    script = ("from reliefkit.batch.task import prepare_worker\n"
              "from reliefkit.gl.context import get_context\n"
              "import sys\n"
              "prepare_worker(threads=1, device_index=int(sys.argv[1]))\n"
              "try:\n"
              "    print(get_context().info['GL_RENDERER'])\n"
              "except Exception as exc:\n"
              "    print(exc)\n")
    first, missing = (subprocess.run([sys.executable, "-c", script, str(index)],
                                     capture_output=True, text=True, timeout=120).stdout
                      for index in (0, 999))
    assert "could not create" not in first
    assert "device index 999" in missing
