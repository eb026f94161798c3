"""The Ray executor on a real local Ray cluster (2 CPUs, 1 GPU as Ray counts them) that this
module starts once and shares: each worker's EGL device is its task's GPU, with its share
of the cores; the same bytes as the local executor and single `reliefkit bake` runs, a
broken mesh and a crashing worker failing only their assets, --timeout, skips on a rerun,
a CLI run that starts its own cluster stopped by Ctrl-C and finished on this one
(--address HOST:PORT), and ray://HOST:PORT through a Ray Client server. Without Ray they
skip saying why; on CI (``CI=true``) that is a failure: `./run test` and `.ci/run` install
the ``ray`` extra."""

from __future__ import annotations

import json
import logging
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest
import worker_kinds
from helpers import write_tetrahedron

from reliefkit import cli
from reliefkit.batch import batch
from reliefkit.batch.local import cores
from reliefkit.io import rk

TESTS = Path(__file__).resolve().parents[1]
RELIEF = ["--as", "relief", "--depth-res", "10"]


@pytest.fixture(scope="module")
def ray_module():
    """Ray, imported; without it the test skips saying why (on CI it fails)."""
    try:
        import ray
    except ImportError:
        reason = "Ray is not installed (pip install 'reliefkit[ray]')"
        if os.environ.get("CI", "").lower() == "true":
            pytest.fail(f"CI=true but the Ray tests cannot run: {reason}")
        pytest.skip(reason)
    return ray


@pytest.fixture(scope="module")
def cluster(ray_module):
    """A local Ray cluster for this module; its workers import the tests' kinds."""
    ray = ray_module
    path = os.pathsep.join([str(TESTS), os.environ.get("PYTHONPATH", "")])
    # one GPU as Ray counts them (none is needed: EGL device 0 is Mesa's llvmpipe here), so
    # the tasks ask for a share of it and their workers make their context on its device
    ray.init(num_cpus=2, num_gpus=1, include_dashboard=False, logging_level=logging.ERROR,
             log_to_driver=False, runtime_env={"env_vars": {"PYTHONPATH": path}})
    yield ray.get_runtime_context().gcs_address
    ray.shutdown()


@pytest.fixture(autouse=True)
def _kinds_unregistered_after():
    yield
    worker_kinds.teardown()


@pytest.fixture
def library(tmp_path):
    root = tmp_path / "lib"
    write_tetrahedron(root / "chairs" / "a.obj", name_texture="a.png")
    from PIL import Image
    Image.new("RGB", (4, 4), (200, 30, 30)).save(root / "chairs" / "a.png")
    for k, name in enumerate(("b.obj", "c.obj")):
        write_tetrahedron(root / name, scale=2.0 + k)
    return root


def on_ray(inputs, kind, out, **options):
    return batch(inputs, kind, out, "ray", setup=worker_kinds.setup, progress=False, **options)


def statuses(out) -> list[tuple[str, str]]:
    return [(r["output"], r["status"])
            for r in map(json.loads, (out / "batch.jsonl").read_text().splitlines())]


def manifest(root, kinds: dict) -> Path:
    path = root / "m.jsonl"
    path.write_text("".join(json.dumps({"input": name, "kind": kind}) + "\n"
                            for name, kind in kinds.items()))
    return path


def test_the_bytes_of_the_local_executor_and_of_single_bakes(cluster, library, tmp_path):
    (library / "broken.obj").write_text("v 0 0 0\nv 0 0 0\nf 1 2 1\n")
    out, local = tmp_path / "ray", tmp_path / "local"
    report = on_ray([library], "relief", out, workers=2, depth_res=10)
    assert report.exit_status == 1
    assert sorted(statuses(out)) == [("b.rk", "ok"), ("broken.rk", "failed"),
                                     ("c.rk", "ok"), ("chairs/a.rk", "ok")]
    (broken,) = report.failed
    assert broken.error.startswith(f"{library / 'broken.obj'}: has no triangle with a "
                                   "visible area")
    assert batch([library], "relief", local, workers=2, depth_res=10,
                 setup=worker_kinds.setup, progress=False).exit_status == 1
    for name in ("chairs/a", "b", "c"):
        single = tmp_path / "single.rk"
        assert cli.main(["bake", str(library / f"{name}.obj"), *RELIEF, "-o", str(single)]) == 0
        baked = (out / f"{name}.rk").read_bytes()
        assert baked == single.read_bytes() == (local / f"{name}.rk").read_bytes(), name

    again = on_ray([library], "relief", out, workers=2, depth_res=10)  # a rerun skips
    assert sorted((r.output, r.status) for r in again.records) == [
        ("b.rk", "skipped"), ("broken.rk", "failed"), ("c.rk", "skipped"),
        ("chairs/a.rk", "skipped")]


def test_a_worker_that_dies_fails_only_its_asset(cluster, library, tmp_path):
    spec = manifest(library, {"b.obj": "crash", "c.obj": "toy-quad", "chairs/a.obj": "toy-quad"})
    out = tmp_path / "out"
    report = on_ray([spec], "toy-quad", out, workers=1)
    status = {r.output: (r.status, r.error) for r in report.records}
    assert status["c.rk"] == status["chairs/a.rk"] == ("ok", None)
    assert status["b.rk"][0] == "failed"
    assert status["b.rk"][1] == f"{spec}:1 (b.obj): the Ray worker baking it died; " \
                                "Ray replaced it"
    assert not (out / "b.rk").exists()
    assert rk.load(out / "c.rk").corners[1][0] == pytest.approx(3.0)  # the toy: its extent


def test_timeout_cancels_the_task_and_the_batch_goes_on(cluster, library, tmp_path):
    spec = manifest(library, {"b.obj": "hang", "c.obj": "toy-quad"})
    started = time.monotonic()
    report = on_ray([spec], "toy-quad", tmp_path / "out", workers=1, timeout=3.0)
    status = {r.output: (r.status, r.error) for r in report.records}
    assert status["c.rk"] == ("ok", None)  # on the worker that replaced the cancelled one
    assert status["b.rk"][0] == "failed"
    assert "took longer than --timeout 3 s; its Ray task was cancelled" in status["b.rk"][1]
    assert time.monotonic() - started < 300  # not the hang's 600 s


def test_max_memory_an_unreachable_address_and_a_missing_ray_are_one_line(
        library, tmp_path, capsys, monkeypatch):
    args = ["batch", str(library), *RELIEF, "--out", str(tmp_path / "out"), "--executor", "ray"]
    assert cli.main([*args, "--max-memory", "1GB"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: --max-memory is not available with --executor ray: ")
    assert err.count("\n") == 1
    assert cli.main([*args, "--address", "127.0.0.1:1"]) == 1  # nothing listens there
    assert capsys.readouterr().err == "error: --executor ray: nothing answers at 127.0.0.1:1 " \
                                      "(Connection refused); is the Ray cluster running?\n"
    assert cli.main([*args, "--address", "head"]) == 2
    assert capsys.readouterr().err == "error: --address takes auto, HOST:PORT or " \
                                      "ray://HOST:PORT, got 'head'\n"
    monkeypatch.setitem(sys.modules, "ray", None)  # as where Ray is not installed
    assert cli.main(args) == 2
    assert capsys.readouterr().err == \
        "error: --executor ray needs Ray: pip install 'reliefkit[ray]'\n"
    assert not (tmp_path / "out").exists()


def test_ctrl_c_on_its_own_cluster_then_the_rest_on_an_address(cluster, tmp_path):
    """No --address: the run starts a local cluster; Ctrl-C leaves whole files and exit
    130; the rerun on the test's cluster (--address) bakes only what is missing."""
    library = tmp_path / "lib"
    names = [f"m{k}.obj" for k in range(6)]
    for k, name in enumerate(names):
        write_tetrahedron(library / name, scale=1.0 + k / 8)
    out = tmp_path / "out"
    args = ["batch", str(library), "--as", "relief", "--depth-res", "48", "--out", str(out),
            "--workers", "1", "--executor", "ray"]
    process = subprocess.Popen([sys.executable, "-m", "reliefkit.cli", *args],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 180
    while not (out / "batch.jsonl").exists() or \
            '"ok"' not in (out / "batch.jsonl").read_text():
        assert process.poll() is None and time.monotonic() < deadline
        time.sleep(0.02)
    process.send_signal(signal.SIGINT)
    printed, err = process.communicate(timeout=120)
    assert process.returncode == 130, err
    assert "error: interrupted after" in err and "Traceback" not in err
    assert all(line.startswith(("batch: ", "error: ")) for line in err.splitlines())  # no Ray's
    assert printed == ""
    first = statuses(out)
    assert 1 <= len(first) < len(names)
    assert not list(out.glob("**/*.tmp")) and not list(out.glob("**/.*"))
    for path in out.glob("*.rk"):
        rk.load(path)

    rerun = subprocess.run([sys.executable, "-m", "reliefkit.cli", *args, "--address", cluster],
                           capture_output=True, text=True, timeout=180)
    assert rerun.returncode == 0, rerun.stderr
    assert f"{len(names)} of {len(names)} assets" in rerun.stdout
    baked = [output for output, status in statuses(out) if status == "ok"]
    assert sorted(baked) == sorted(n.replace(".obj", ".rk") for n in names)  # once each


def test_ray_client_address(cluster, library, tmp_path):
    """--address ray://HOST:PORT: through a Ray Client server in front of this cluster."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    server = subprocess.Popen([sys.executable, "-m", "ray.util.client.server", "--address",
                               cluster, "--host", "127.0.0.1", "--port", str(port), "--mode",
                               "legacy"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:  # until the server listens
            with socket.socket() as probe:
                if probe.connect_ex(("127.0.0.1", port)) == 0:
                    break
            time.sleep(0.2)
        out = tmp_path / "out"
        done = subprocess.run([sys.executable, "-m", "reliefkit.cli", "batch", str(library),
                               *RELIEF, "--out", str(out), "--executor", "ray", "--address",
                               f"ray://127.0.0.1:{port}"], capture_output=True, text=True,
                              timeout=180)
    finally:
        server.kill()
        server.wait()
    assert done.returncode == 0, done.stderr
    for name in ("chairs/a", "b"):
        single = tmp_path / "single.rk"
        assert cli.main(["bake", str(library / f"{name}.obj"), *RELIEF, "-o", str(single)]) == 0
        assert (out / f"{name}.rk").read_bytes() == single.read_bytes(), name


TOKEN_CLUSTER = """
import sys, ray
ray.init(num_cpus=1, include_dashboard=False, _temp_dir=sys.argv[1])
print(ray.get_runtime_context().gcs_address, flush=True)
sys.stdin.read()
ray.shutdown()
"""


def test_a_cluster_with_token_authentication_is_one_line_that_says_so(
        ray_module, library, tmp_path):
    """A cluster started with Ray's token authentication, reached without the token: Ray's
    core logged 21 lines of retries and then an error that did not name the cause."""
    token = "7f" * 32
    plain = {k: v for k, v in os.environ.items() if not k.startswith("RAY_AUTH")}
    plain["HOME"] = str(tmp_path)  # no ~/.ray/auth_token
    plain["RAY_NUM_REDIS_GET_RETRIES"] = "2"  # Ray retries the connection for 2 s, not 20
    secured = {**plain, "RAY_AUTH_MODE": "token", "RAY_AUTH_TOKEN": token}
    temp = tempfile.mkdtemp(prefix="rk-ray-", dir="/tmp")  # its sockets: short paths
    head = subprocess.Popen([sys.executable, "-c", TOKEN_CLUSTER, temp], env=secured,
                            stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                            stderr=subprocess.DEVNULL, text=True)
    try:
        address = head.stdout.readline().strip()
        assert address, "the token cluster did not start"
        args = [sys.executable, "-m", "reliefkit.cli", "batch", str(library / "b.obj"), *RELIEF,
                "--out", str(tmp_path / "out"), "--executor", "ray", "--address", address]
        refused = subprocess.run(args, env=plain, capture_output=True, text=True, timeout=180)
        assert refused.returncode == 1
        assert refused.stderr == (f"error: --executor ray: the Ray cluster at {address} asks "
                                  "for Ray's token authentication and this process has no "
                                  "token it accepts: run with RAY_AUTH_MODE=token and the "
                                  "cluster's token in ~/.ray/auth_token (or "
                                  "RAY_AUTH_TOKEN_PATH, or RAY_AUTH_TOKEN)\n")
        # --address auto: the line names the cluster Ray found (it said "at auto")
        found = subprocess.run(args[:-1] + ["auto"], env={**plain, "RAY_ADDRESS": address},
                               capture_output=True, text=True, timeout=180)
        assert found.returncode == 1
        assert found.stderr.startswith("error: --executor ray: the Ray cluster --address auto "
                                       f"found at {address} asks for Ray's token "
                                       "authentication"), found.stderr
        accepted = subprocess.run(args, env=secured, capture_output=True, text=True,
                                  timeout=180)
        assert accepted.returncode == 0, accepted.stderr
        assert statuses(tmp_path / "out") == [("b.rk", "ok")]
    finally:
        head.communicate(input="", timeout=60)
        shutil.rmtree(temp, ignore_errors=True)


def test_a_worker_makes_its_context_on_its_ray_gpu_with_its_share_of_the_cores(
        cluster, library, tmp_path):
    out = tmp_path / "out"
    report = on_ray([library], "worker", out, workers=2)
    assert len(report.ok) == 3
    share = max(1, cores() // 2)  # the node's 2 CPU slots
    for record in report.ok:
        params = rk.read_manifest(out / record.output)["params"]
        assert params["ray_gpu_ids"] == [0]  # asked for a share of the cluster's one GPU
        assert params["GLCONTEXT_DEVICE_INDEX"] == "0"
        assert params["renderer"].startswith("llvmpipe")
        assert (params["LP_NUM_THREADS"], params["numba_threads"]) == (str(share), share)
