"""The local executor through `reliefkit.batch.batch`: real worker processes (spawned), the
toy and misbehaving kinds registered in each by `batch_kinds.setup`. A worker that crashes,
runs past --timeout or over --max-memory is replaced and only its asset fails."""

from __future__ import annotations

import json
import subprocess
import sys

import batch_kinds
import pytest
from helpers import write_tetrahedron

import reliefkit
from reliefkit.batch import batch
from reliefkit.batch.key import file_cache_key
from reliefkit.batch.local import cores
from reliefkit.io import rk


@pytest.fixture(autouse=True)
def _kinds_unregistered_after():
    """The driver (this process) registers the test kinds through ``setup``: not for long."""
    yield
    batch_kinds.teardown()


@pytest.fixture
def library(tmp_path):
    root = tmp_path / "lib"
    for k, name in enumerate(("a.obj", "b.obj", "c.obj")):
        write_tetrahedron(root / name, scale=1.0 + k)
    return root


def run(inputs, kind, out, **options):
    return batch(inputs, kind, out, setup=batch_kinds.setup, progress=False, **options)


def lines(out):
    return [json.loads(line) for line in (out / "batch.jsonl").read_text().splitlines()]


def manifest(root, kinds: dict) -> str:
    path = root / "m.jsonl"
    path.write_text("".join(json.dumps({"input": name, "kind": kind}) + "\n"
                            for name, kind in kinds.items()))
    return str(path)


def test_a_crashing_worker_is_replaced_and_only_its_asset_fails(library, tmp_path):
    out = tmp_path / "out"
    spec = manifest(library, {"a.obj": "toy-quad", "b.obj": "crash", "c.obj": "toy-quad"})
    report = run([spec], "toy-quad", out, workers=1)  # c runs on the replacement
    status = {r.output: r.status for r in report.records}
    assert status == {"a.rk": "ok", "b.rk": "failed", "c.rk": "ok"}
    assert report.exit_status == 1
    (failed,) = report.failed
    assert "b.obj" in failed.error and "died (exit status 7)" in failed.error
    assert failed.seconds >= 0  # never -0.0 in the summary
    assert not (out / "b.rk").exists()
    for name in ("a", "c"):  # the toy bake: the mesh's bounding rectangle
        quad = rk.load(out / f"{name}.rk")
        assert quad.corners[1][0] == pytest.approx(1.0 + "abc".index(name))
    assert [r["status"] for r in lines(out)] == [r.status for r in report.records]


def test_timeout_stops_the_asset_and_the_batch_goes_on(library, tmp_path):
    spec = library / "m.csv"  # a CSV manifest this time
    spec.write_text("input,kind\na.obj,hang\nb.obj,\n")
    report = run([spec], "toy-quad", tmp_path / "out", workers=1, timeout=3.0)
    status = {r.output: (r.status, r.error) for r in report.records}
    assert status["b.rk"] == ("ok", None)  # on the worker that replaced the stopped one
    assert status["a.rk"][0] == "failed" and "longer than --timeout 3 s" in status["a.rk"][1]


def test_max_memory_stops_the_worker_over_it(library, tmp_path):
    spec = manifest(library, {"a.obj": "hog", "b.obj": "toy-quad"})
    limit = 400 << 20  # a worker holds about 200 MiB after baking a relief
    report = run([spec], "toy-quad", tmp_path / "out", workers=1, max_memory=limit)
    status = {r.output: (r.status, r.error) for r in report.records}
    assert status["b.rk"] == ("ok", None)
    assert status["a.rk"][0] == "failed" and "over --max-memory 400 MiB" in status["a.rk"][1]


def test_two_workers_bake_every_asset_once(library, tmp_path):
    out = tmp_path / "out"
    report = run([library], "toy-quad", out, workers=2)
    assert sorted(r.output for r in report.ok) == ["a.rk", "b.rk", "c.rk"]
    assert report.exit_status == 0
    again = run([library], "toy-quad", out, workers=2)
    assert [r.status for r in again.records] == ["skipped"] * 3
    assert [r["status"] for r in lines(out)] == ["ok"] * 3 + ["skipped"] * 3


def test_a_broken_mesh_fails_with_its_line_and_the_rest_succeed(library, tmp_path):
    (library / "broken.obj").write_text("v 0 0 0\nv 1 1 1\nv 2 2 2\nf 1 2 3\n")
    (library / "empty.ply").write_bytes(b"")
    report = run([library], "toy-quad", tmp_path / "out", workers=2)
    assert sorted(r.output for r in report.ok) == ["a.rk", "b.rk", "c.rk"]
    errors = {r.output: r.error for r in report.failed}
    assert set(errors) == {"broken.rk", "empty.rk"}
    assert errors["broken.rk"].startswith(str(library / "broken.obj") + ": ")
    assert "no triangle with a visible area" in errors["broken.rk"]
    assert "empty" in errors["empty.rk"]
    assert all("\n" not in e and "reliefkit-mesh-" not in e for e in errors.values())


@pytest.mark.parametrize("workers", [1, 2])
def test_workers_times_mesa_threads_stay_within_the_cores(library, tmp_path, workers):
    report = run([library], "threads", tmp_path / "out", workers=workers)
    expected = max(1, cores() // workers)
    for record in report.ok:
        params = rk.read_manifest(tmp_path / "out" / record.output)["params"]
        assert params == {"LP_NUM_THREADS": str(expected), "llvmpipe_threads": expected}
    assert len(report.ok) == 3


def test_the_public_api_bakes_with_the_built_ins(library, tmp_path):
    out = tmp_path / "out"
    report = reliefkit.batch(library / "a.obj", "relief", out, workers=1, depth_res=10,
                             progress=False)
    assert [(r.output, r.status) for r in report.records] == [("a.rk", "ok")]
    manifest = rk.read_manifest(out / "a.rk")
    assert manifest["cache_key"] == file_cache_key(library / "a.obj", "relief",
                                                   {"depth_res": 10})
    assert manifest["source_hash"] == rk.file_sha256(library / "a.obj")


def test_a_script_without_the_main_guard_is_told_so(library, tmp_path):
    """Workers are spawned: each imports the script, which called batch again there; every
    worker died in ~450 lines of Python's error, and each asset was failed as "died"."""
    script = tmp_path / "bake_all.py"
    script.write_text("import reliefkit\n"
                      f"reliefkit.batch({str(library)!r}, 'relief', {str(tmp_path / 'out')!r}, "
                      "workers=2, depth_res=10, progress=False)\n")
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                          timeout=300, cwd=tmp_path)
    assert done.returncode == 1
    assert done.stderr.splitlines()[-1] == (
        "reliefkit.errors.UsageError: batch ran again in each worker process as it started: a "
        "worker imports the script that calls it, so call batch under `if __name__ == "
        "\"__main__\":` (Python's rule for scripts that start processes)")
    assert "died" not in done.stderr and "bootstrapping" not in done.stderr
    assert not (tmp_path / "out" / "batch.jsonl").exists()  # no asset recorded


def test_a_bake_s_python_warnings_go_to_its_record_not_the_terminal(library, tmp_path,
                                                                     capfd):
    report = run([library / "a.obj"], "warns", tmp_path / "out", workers=1)
    assert [r.warnings for r in report.records] == [("warning: the toy quad is flat",)]
    assert "toy quad is flat" not in capfd.readouterr().err  # the workers' stderr too
