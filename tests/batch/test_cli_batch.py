"""`reliefkit batch` from the command line: the same bytes as single `reliefkit bake` runs,
a broken mesh reported with its line (exit 1), Ctrl-C and a rerun baking each asset once
in total, skips and rebakes by the cache key, bad input in one line."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time

import pytest
from helpers import write_tetrahedron

from reliefkit import cli
from reliefkit.io import rk

RELIEF = ["--as", "relief", "--depth-res", "10"]


@pytest.fixture
def library(tmp_path):
    root = tmp_path / "lib"
    write_tetrahedron(root / "chairs" / "a.obj", name_texture="a.png")
    from PIL import Image
    Image.new("RGB", (4, 4), (200, 30, 30)).save(root / "chairs" / "a.png")
    write_tetrahedron(root / "b.obj", scale=2.0)
    return root


def statuses(out) -> list[tuple[str, str]]:
    return [(r["output"], r["status"])
            for r in map(json.loads, (out / "batch.jsonl").read_text().splitlines())]


def test_outputs_are_the_bytes_of_single_bakes_and_a_broken_mesh_is_reported(
        library, tmp_path, capsys):
    (library / "broken.obj").write_text("v 0 0 0\nv 0 0 0\nf 1 2 1\n")
    out = tmp_path / "out"
    status = cli.main(["batch", str(library), *RELIEF, "--out", str(out), "--workers", "2",
                       "--export", "glb"])
    printed = capsys.readouterr()
    assert status == 1
    assert sorted(statuses(out)) == [("b.rk", "ok"), ("broken.rk", "failed"),
                                     ("chairs/a.rk", "ok")]
    assert f"failed: {library / 'broken.obj'}: has no triangle with a visible area" in \
        printed.out
    assert "Traceback" not in printed.err
    for name in ("chairs/a", "b"):
        single = tmp_path / "single.rk"
        assert cli.main(["bake", str(library / f"{name}.obj"), *RELIEF, "-o", str(single)]) == 0
        assert (out / f"{name}.rk").read_bytes() == single.read_bytes(), name
        glb = tmp_path / "single.glb"
        assert cli.main(["export", str(single), "-o", str(glb)]) == 0
        assert (out / f"{name}.glb").read_bytes() == glb.read_bytes(), name
    capsys.readouterr()
    # a folder baked by hand is skipped by a batch: same key, same bytes
    hand = tmp_path / "by-hand"
    hand.mkdir()
    assert cli.main(["bake", str(library / "b.obj"), *RELIEF, "--safety-tolerance", "0.01",
                     "-o", str(hand / "b.rk")]) == 0
    assert cli.main(["batch", str(library / "b.obj"), *RELIEF, "--out", str(hand)]) == 0
    assert statuses(hand) == [("b.rk", "skipped")]


def test_interrupted_then_rerun_bakes_each_asset_once(tmp_path, capsys):
    library = tmp_path / "lib"
    names = [f"m{k}.obj" for k in range(8)]
    for k, name in enumerate(names):
        write_tetrahedron(library / name, scale=1.0 + k / 8)
    out = tmp_path / "out"
    args = ["batch", str(library), "--as", "relief", "--depth-res", "48", "--out", str(out),
            "--workers", "1"]
    process = subprocess.Popen([sys.executable, "-m", "reliefkit.cli", *args],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while not (out / "batch.jsonl").exists() or \
            '"ok"' not in (out / "batch.jsonl").read_text():
        assert process.poll() is None and time.monotonic() < deadline
        time.sleep(0.02)
    process.send_signal(signal.SIGINT)
    _, err = process.communicate(timeout=60)
    assert process.returncode == 130, err
    assert "error: interrupted after" in err and "rerun the same command" in err
    first = statuses(out)
    assert 1 <= len(first) < len(names)  # stopped part way
    assert not list(out.glob("**/*.tmp")) and not list(out.glob("**/.*"))
    for path in out.glob("*.rk"):  # whole files only
        rk.load(path)

    assert cli.main(args) == 0
    baked = [output for output, status in statuses(out) if status == "ok"]
    assert sorted(baked) == sorted(n.replace(".obj", ".rk") for n in names)  # once each

    assert cli.main(args) == 0  # all up to date
    assert [status for _, status in statuses(out)[-len(names):]] == ["skipped"] * len(names)
    assert cli.main(args[:-2] + ["--depth-res", "32"]) == 0  # another option: rebaked
    assert [status for _, status in statuses(out)[-len(names):]] == ["ok"] * len(names)
    assert "8 of 8 assets" in capsys.readouterr().out


def test_force_rebakes_what_is_up_to_date(library, tmp_path):
    out = tmp_path / "out"
    assert cli.main(["batch", str(library / "b.obj"), *RELIEF, "--out", str(out)]) == 0
    assert cli.main(["batch", str(library / "b.obj"), *RELIEF, "--out", str(out),
                     "--force"]) == 0
    assert statuses(out) == [("b.rk", "ok"), ("b.rk", "ok")]


@pytest.mark.parametrize("extra, words", [
    (["--executor", "ray", "--max-memory", "1GB"], "--max-memory is not available with"),
    (["--max-memory", "lots"], "--max-memory takes a byte count"),
    (["--max-memory", "1"], "--max-memory 1 is below 256 MiB"),  # failed assets by the clock
    (["--workers", "0"], "--workers must be at least 1"),
    (["--timeout", "0"], "--timeout must be a positive"),
    (["--epsilon", "0.1"], "--epsilon does not apply to"),
    (["--address", "auto"], "--address names a Ray cluster"),
])
def test_bad_arguments_are_one_line(library, tmp_path, capsys, extra, words):
    status = cli.main(["batch", str(library), *RELIEF, "--out", str(tmp_path / "o"), *extra])
    err = capsys.readouterr().err
    assert status == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and words in lines[0], err
    assert not (tmp_path / "o").exists()  # refused before anything was made


def test_the_api_takes_max_memory_as_text_and_refuses_what_the_cli_refuses(library, tmp_path):
    """max_memory="1GB" (the CLI's form) was a TypeError after the workers started, and -5
    failed every asset "over --max-memory -0 MiB"."""
    from reliefkit import batch
    from reliefkit.errors import UsageError

    report = batch(library / "b.obj", "relief", tmp_path / "out", depth_res=10,
                   max_memory="1GB", progress=False)
    assert [r.status for r in report.records] == ["ok"]
    for bad in (-5, "-5MB", 0, 1.5, "lots"):
        with pytest.raises(UsageError, match="--max-memory takes a byte count"):
            batch(library / "b.obj", "relief", tmp_path / "o2", max_memory=bad, progress=False)
    assert not (tmp_path / "o2").exists()


def test_an_output_over_an_input_is_refused(library, tmp_path, capsys):
    """--export glb of a .glb baked into its own folder replaced the user's mesh."""
    import trimesh

    source = library / "c.glb"
    trimesh.load(library / "b.obj", force="mesh").export(source)
    before = source.read_bytes()
    status = cli.main(["batch", str(source), *RELIEF, "--out", str(library), "--export", "glb"])
    err = capsys.readouterr().err
    assert status == 2 and err.count("\n") == 1, err
    assert f"{library / 'c.glb'} would be written over the input {source}" in err
    assert source.read_bytes() == before and not (library / "c.rk").exists()


def test_an_input_that_names_nothing_is_one_line(tmp_path, capsys):
    status = cli.main(["batch", str(tmp_path / "nothing"), "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert status == 2 and err.count("\n") == 1 and "nothing: no such file or folder" in err


def test_a_stale_export_or_thumbnail_is_made_again(library, tmp_path):
    """A .glb and thumbnails left from a bake of other options, beside an .rk rebaked without
    them, were counted as up to date: a rerun with --export glb --sheet skipped forever."""
    from reliefkit.batch.sheet import thumbnail_key
    from reliefkit.io.gltf import representation as gltf

    out, source = tmp_path / "out", str(library / "b.obj")
    assert cli.main(["batch", source, *RELIEF, "--out", str(out), "--export", "glb",
                     "--sheet"]) == 0
    assert cli.main(["batch", source, "--as", "relief", "--depth-res", "12",
                     "--out", str(out)]) == 0
    key = rk.read_manifest(out / "b.rk")["cache_key"]
    assert gltf.stored_cache_key(out / "b.glb") != key  # the earlier bake's export
    assert cli.main(["batch", source, "--as", "relief", "--depth-res", "12", "--out", str(out),
                     "--export", "glb", "--sheet"]) == 0
    assert cli.main(["batch", source, "--as", "relief", "--depth-res", "12", "--out", str(out),
                     "--export", "glb", "--sheet"]) == 0
    assert statuses(out) == [("b.rk", "ok")] * 3 + [("b.rk", "skipped")]
    assert gltf.read_manifest(out / "b.glb")["cache_key"] == key
    assert [thumbnail_key(p) for p in sorted((out / "thumbnails").glob("b*.png"))] == [key] * 2


def test_an_out_that_cannot_be_made_is_a_usage_error(library, capsys):
    """Root passes the access check under /proc, and making the folder failed with exit 1."""
    status = cli.main(["batch", str(library), *RELIEF, "--out", "/proc/reliefkit-batch-out"])
    err = capsys.readouterr().err
    assert status == 2 and err.count("\n") == 1 and "/proc/reliefkit-batch-out" in err, err


def test_a_rebake_without_the_export_removes_the_stale_one(library, tmp_path, capsys):
    """A rerun of other options without --export glb --sheet left the earlier bake's .glb
    and thumbnails beside the new .rk (and the sheet showing the old kind) silently."""
    out, source = tmp_path / "out", str(library / "b.obj")
    assert cli.main(["batch", source, *RELIEF, "--out", str(out), "--export", "glb",
                     "--sheet"]) == 0
    (out / "mine.glb").write_bytes((out / "b.glb").read_bytes())  # not beside an asset
    capsys.readouterr()
    assert cli.main(["batch", source, "--as", "relief", "--depth-res", "12",
                     "--out", str(out)]) == 0
    printed = capsys.readouterr()
    assert not (out / "b.glb").exists() and not list((out / "thumbnails").glob("*.png"))
    assert (out / "mine.glb").exists() and (out / "sheet.png").exists()
    assert "removed 3 file(s) an earlier bake left beside assets baked now" in printed.out
    assert f"\nwarning: {out / 'sheet.png'} and index.html are from an earlier run" in printed.err
    # a skip removes nothing, and a file reliefkit did not key stays
    (out / "b.glb").write_bytes(b"not reliefkit's")
    assert cli.main(["batch", source, "--as", "relief", "--depth-res", "12", "--out", str(out),
                     "--force"]) == 0
    assert (out / "b.glb").read_bytes() == b"not reliefkit's"
