"""INPUTs into jobs: folders, globs, files and manifests; outputs keep their relative
paths; collisions and bad kinds or options are refused up front, naming the asset."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from helpers import write_tetrahedron

from reliefkit.batch.jobs import check_jobs, expand_inputs
from reliefkit.batch.key import cache_key, read_sources
from reliefkit.errors import UsageError


@pytest.fixture
def library(tmp_path):
    root = tmp_path / "lib"
    for name in ("chairs/a.obj", "chairs/old/b.obj", "tables/c.obj"):
        write_tetrahedron(root / name)
    (root / "notes.txt").write_text("not a mesh")
    return root


def outputs(jobs):
    return sorted(job.output for job in jobs)


def test_a_folder_is_searched_recursively_and_outputs_keep_relative_paths(library, tmp_path):
    jobs = expand_inputs([library], "relief", {}, tmp_path / "out")
    assert outputs(jobs) == ["chairs/a.rk", "chairs/old/b.rk", "tables/c.rk"]
    assert {job.input for job in jobs} == {library / "chairs/a.obj",
                                           library / "chairs/old/b.obj",
                                           library / "tables/c.obj"}


def test_a_glob_keeps_paths_below_its_fixed_part(library, tmp_path):
    jobs = expand_inputs([f"{library}/chairs/**/*.obj"], "relief", {}, tmp_path / "out")
    assert outputs(jobs) == ["a.rk", "old/b.rk"]


def test_a_file_is_written_by_its_name(library, tmp_path):
    jobs = expand_inputs([library / "tables/c.obj"], "relief", {}, tmp_path / "out")
    assert outputs(jobs) == ["c.rk"]


def test_files_under_the_output_folder_are_never_inputs(library):
    write_tetrahedron(library / "out" / "a.obj")  # an earlier --export, say
    jobs = expand_inputs([library], "relief", {}, library / "out")
    assert outputs(jobs) == ["chairs/a.rk", "chairs/old/b.rk", "tables/c.rk"]


@pytest.mark.parametrize("spec, count", [("chairs", 2), ("chairs/*.obj", 1)])
def test_an_out_that_holds_every_input_says_so(library, spec, count):
    """--out the input folder itself said "no mesh files in this folder": they are there."""
    words = rf"its {count} mesh file\(s\) are all inside --out .*chairs, whose files a batch"
    with pytest.raises(UsageError, match=words):
        expand_inputs([f"{library}/{spec}"], "relief", {}, library / "chairs")


def test_the_same_asset_twice_is_one_job(library, tmp_path):
    jobs = expand_inputs([library / "tables/c.obj", library / "tables/../tables/c.obj"],
                         "relief", {}, tmp_path / "out")
    assert outputs(jobs) == ["c.rk"]


def test_two_inputs_writing_one_output_are_refused(library, tmp_path):
    write_tetrahedron(library / "tables" / "c.ply.obj")
    (library / "chairs" / "a.ply").write_text("ply\n")
    with pytest.raises(UsageError, match=r"a\.obj and .*a\.ply would both write chairs/a\.rk"):
        expand_inputs([library], "relief", {}, tmp_path / "out")


@pytest.mark.parametrize("spec, words", [
    ("missing", "no such file or folder"),
    ("lib/notes.txt", "not a mesh file"),
    ("lib/**/*.stl", "matches no mesh file"),
    ("empty", "no mesh files"),
])
def test_inputs_that_name_nothing(library, tmp_path, spec, words):
    (tmp_path / "empty").mkdir()
    with pytest.raises(UsageError, match=words):
        expand_inputs([str(tmp_path / spec)], "relief", {}, tmp_path / "out")


def test_manifests_give_kinds_and_options_per_asset(library, tmp_path):
    (library / "m.csv").write_text('input,kind,options\nchairs/a.obj,relief,"{""depth_res"": 12}"\n'
                                   "tables/c.obj,,\n")
    (library / "m.jsonl").write_text(json.dumps({"input": "chairs/old/b.obj",
                                                 "kind": "relief-cube"}) + "\n\n")
    jobs = expand_inputs([library / "m.csv", library / "m.jsonl"], "billboard-cloud",
                         {"compress": "bc"}, tmp_path / "out")
    got = {job.output: (job.kind, job.options) for job in jobs}
    assert got == {"chairs/a.rk": ("relief", {"compress": "bc", "depth_res": 12}),
                   "tables/c.rk": ("billboard-cloud", {"compress": "bc"}),
                   "chairs/old/b.rk": ("relief-cube", {"compress": "bc"})}
    check_jobs(jobs)


@pytest.mark.parametrize("text, words", [
    ("file,kind\na.obj,relief\n", "header is input,kind,options"),
    ("input,kind,options\nchairs/a.obj,relief,{bad\n", r"m\.csv:2: not valid JSON"),
    ("input,kind,options\nchairs/a.obj,relief,[1]\n", "expected a JSON object"),
    ("input\n../x.obj\n", "inside the manifest's folder"),
    ("input\nchairs/zz.obj\n", r"m\.csv:2: chairs/zz\.obj: no such file"),
])
def test_bad_manifests(library, tmp_path, text, words):
    (library / "m.csv").write_text(text)
    with pytest.raises(UsageError, match=words):
        expand_inputs([library / "m.csv"], "relief", {}, tmp_path / "out")


def test_every_job_is_checked_before_anything_is_baked(library, tmp_path):
    (library / "m.jsonl").write_text(
        json.dumps({"input": "chairs/a.obj", "kind": "relief"}) + "\n"
        + json.dumps({"input": "tables/c.obj", "kind": "billboard-cloud",
                      "options": {"depth_res": 12}}) + "\n")
    jobs = expand_inputs([library / "m.jsonl"], "relief", {}, tmp_path / "out")
    with pytest.raises(UsageError, match=r"--depth-res does not apply to .*m\.jsonl:2 "
                                         r"\(tables/c\.obj\) \(its manifest row's kind "
                                         r"billboard-cloud\)[^;]*$"):
        check_jobs(jobs)  # the row's own option: no word of the command line
    # the command line's option meets a row whose kind does not take it: said so (the
    # line said "(--as billboard-cloud)": the kind came from the row)
    (library / "m.jsonl").write_text(
        json.dumps({"input": "tables/c.obj", "kind": "billboard-cloud"}) + "\n")
    jobs = expand_inputs([library / "m.jsonl"], "relief", {"depth_res": 12}, tmp_path / "out")
    with pytest.raises(UsageError, match=r"\(its manifest row's kind billboard-cloud\).*; the "
                                         r"command line's options go to every row"):
        check_jobs(jobs)
    jobs = expand_inputs([library / "tables"], "relief", {"depth_res": -3}, tmp_path / "out")
    with pytest.raises(UsageError,
                       match=r"--depth-res must be .*got -3 \(.*c\.obj \(--as relief\)\)"):
        check_jobs(jobs)
    jobs = expand_inputs([library / "tables"], "hologram", {}, tmp_path / "out")
    with pytest.raises(UsageError, match=r"c\.obj: unknown representation 'hologram'"):
        check_jobs(jobs)


def test_the_cache_key_fills_defaults_and_follows_every_input(tmp_path):
    mesh = write_tetrahedron(tmp_path / "t.obj", name_texture="t.png")
    (tmp_path / "t.png").write_bytes(b"\x89PNG not really")
    source, files = read_sources(mesh)
    assert set(files) == {"t.mtl", "t.png"}
    key = cache_key("relief", {}, source, files)
    assert cache_key("relief", {"safety_tolerance": 0.01, "compress": "none"}, source,
                     files) == key  # defaults given explicitly
    assert cache_key("relief", {"depth_res": "64"}, source, files) == \
        cache_key("relief", {"depth_res": 64}, source, files)
    changed = [cache_key("relief", {"depth_res": 64}, source, files),
               cache_key("relief-cube", {}, source, files),
               cache_key("relief", {}, source + b"\n", files),
               cache_key("relief", {}, source, {**files, "t.png": b"other"}),
               cache_key("relief", {}, source, {"t.mtl": files["t.mtl"]})]
    assert len({key, *changed}) == len(changed) + 1


def test_a_texture_edit_changes_the_key_on_disk(tmp_path):
    mesh = write_tetrahedron(tmp_path / "t.obj", name_texture="t.png")
    Path(tmp_path / "t.png").write_bytes(b"one")
    before = cache_key("relief", {}, *read_sources(mesh))
    Path(tmp_path / "t.png").write_bytes(b"two")
    assert cache_key("relief", {}, *read_sources(mesh)) != before
