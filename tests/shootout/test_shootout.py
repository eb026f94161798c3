"""`reliefkit shootout`: budgets met by what the files put on a GPU (counted here from each
file's manifest, by the formats' block sizes), the decimated mesh at every
budget, the same figures twice, recommendations by the stated rule, one-line errors."""

from __future__ import annotations

import json

import numpy as np
import pytest
import trimesh
from helpers import assert_one_line_error, run_cli

from reliefkit.io.rk import read_manifest
from reliefkit.scene.mesh import RenderMesh, vertex_normals
from reliefkit.shootout import parse_budgets, parse_kinds, parse_sizes, shootout
from reliefkit.shootout.report import TIME_FIELDS
from reliefkit.shootout.sizing import KNOB_TOLERANCE, candidates

BUDGETS, SIZES = "2KB,64KB", "32,48"
KINDS = "relief-cube,depth-object,shell-volume"


def lamp() -> RenderMesh:
    """A coloured sphere on a box: small, closed, no uvs."""
    parts = [trimesh.creation.icosphere(3, radius=0.6),
             trimesh.creation.box((1.0, 0.6, 1.0)).apply_translation((0, -0.8, 0))]
    both = trimesh.util.concatenate(parts)
    points = np.asarray(both.vertices, np.float32)
    faces = np.asarray(both.faces, np.uint32)
    colors = np.ones((len(points), 4), np.float32)
    colors[:, :3] = 0.25 + 0.5 * (points - points.min(0)) / np.ptp(points, axis=0)
    return RenderMesh(points, faces, vertex_normals(points, faces), colors, name="lamp")


BLOCK_BYTES = {"bc1": 8, "bc4": 8, "bc5": 16, "bc7": 16}


def gpu_bytes_from_manifest(path) -> int:
    """Bytes a GPU holds for the .rk at ``path``, from its manifest alone: an encoded array's
    blocks (4 x 4 texels, 8 or 16 bytes) or unorm values at every mip level it has, a raw
    array as it is (the shootout compresses every texture that has a role)."""
    total = 0
    for entry in read_manifest(path)["arrays"].values():
        enc = entry.get("encoding")
        if enc is None:
            total += int(np.prod(entry["shape"])) * np.dtype(entry["dtype"]).itemsize
            continue
        shape = enc["shape"]
        layers = shape[0] if enc["layered"] else 1
        h, w = shape[int(enc["layered"]):][:2]
        while True:
            if enc["format"] in BLOCK_BYTES:
                total += layers * -(-h // 4) * -(-w // 4) * BLOCK_BYTES[enc["format"]]
            else:  # u8 / u16: one value a channel
                channels = shape[-1] if len(shape) > 2 + enc["layered"] else 1
                total += layers * h * w * channels * int(enc["format"][1:]) // 8
            if not enc["mipmaps"] or (h, w) == (1, 1):
                break
            h, w = max(h // 2, 1), max(w // 2, 1)
    return total


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """The same shootout twice, into two folders."""
    out = []
    for k in range(2):
        folder = tmp_path_factory.mktemp(f"run{k}")
        results, paths = shootout([lamp()], parse_kinds(KINDS), parse_budgets(BUDGETS),
                                  parse_sizes(SIZES), folder)
        out.append((folder, json.loads((folder / "shootout.json").read_text()), paths))
    return out


def test_every_row_is_there_and_every_file_fits_its_budget(runs):
    folder, data, paths = runs[0]
    rows = data["meshes"][0]["rows"]
    labels = [c.label for c in parse_kinds(KINDS)]
    for budget in parse_budgets(BUDGETS):
        at = {r["label"]: r for r in rows if r["budget"] == budget}
        assert set(at) == {*labels, "decimated mesh"}  # none silently dropped
        for label in labels:
            row = at[label]
            if row["fits"]:
                path = folder / row["file"]
                assert gpu_bytes_from_manifest(path) == row["bytes"] <= budget
                assert path.stat().st_size == row["file_bytes"]
            else:
                assert row["reason"]
    shell = [r for r in rows if r["label"] == "shell-volume"]
    assert all(not r["fits"] and "uvs" in r["reason"] for r in shell)
    tiny = {r["label"]: r for r in rows if r["budget"] == 2048}
    assert not tiny["relief-cube"]["fits"] and "at its smallest" in tiny["relief-cube"]["reason"]
    files = {p.relative_to(folder).as_posix() for p in (folder / "rk").rglob("*.rk")}
    assert files == {r["file"] for r in rows if r.get("file")}
    # the mesh bakers without a sizing are named, not silently left out
    assert "relief-frustum" in data["unsized"]
    assert set(data["unsized"]).isdisjoint(c.kind for c in candidates())
    assert ", ".join(data["unsized"]) in (folder / "shootout.md").read_text()
    for name in ("pareto-32.png", "sheet-32.png", "pareto-48.png", "sheet-48.png"):
        assert (folder / name).stat().st_size > 0


def test_the_knob_is_the_largest_that_fits_within_the_tolerance(runs):
    _, data, _ = runs[0]
    hi = {c.label: c.sizing.hi for c in candidates()}
    for row in data["meshes"][0]["rows"]:
        if not row["fits"] or row["kind"] == "mesh":
            continue
        probes = {n: size for n, size in row["probes"]}
        assert probes[row["n"]] == row["bytes"]
        over = [n for n, size in probes.items() if n > row["n"] and size > row["budget"]]
        assert row["n"] == hi[row["label"]] or \
            min(over) <= max(row["n"] + 1, row["n"] * (1 + KNOB_TOLERANCE))


def test_the_impostor_joins_a_small_budget_with_a_coarser_grid(tmp_path):
    """At 24 KB a grid-12 atlas cannot fit (its smallest, 144², takes 76 KB); the impostor
    takes fewer frames there, and more as the budget grows."""
    small, large = parse_budgets("24KB,256KB")
    shootout([lamp()], parse_kinds("octahedral-impostor"), [small, large], parse_sizes("32"),
             tmp_path)
    data = json.loads((tmp_path / "shootout.json").read_text())
    rows = {r["budget"]: r for r in data["meshes"][0]["rows"]
            if r["label"] == "octahedral-impostor"}
    grids = {}
    for budget, row in rows.items():
        assert row["fits"], row
        path = tmp_path / row["file"]
        assert gpu_bytes_from_manifest(path) == row["bytes"] <= budget
        grids[budget] = read_manifest(path)["params"]["grid"]
    assert 6 <= grids[small] < 12 and grids[small] <= grids[large]


def test_the_decimated_mesh_fits_every_budget_counted_by_hand(runs):
    _, data, _ = runs[0]
    for budget in parse_budgets(BUDGETS):
        row, = (r for r in data["meshes"][0]["rows"]
                if r["budget"] == budget and r["label"] == "decimated mesh")
        assert row["fits"]
        # compact: 8 + 4 bytes a vertex (positions, normal) + 4 for its varying colour,
        # uint16 indices; raw: 12 + 12 + 16 a vertex and uint32 indices
        assert row["bytes"] == row["vertices"] * 16 + row["n"] * 3 * 2 <= budget
        assert row["raw_bytes"] == row["vertices"] * 40 + row["n"] * 3 * 4
    full = lamp()
    big = [r for r in data["meshes"][0]["rows"] if r["label"] == "decimated mesh"][-1]
    assert big["n"] == full.triangle_count  # 64 KB holds the whole mesh


def sheets(parts: int = 4, n: int = 12) -> RenderMesh:
    """``parts`` wavy open sheets of n x n quads: quadric decimation keeps their borders, so
    it stops short of one triangle (as on a CAD model of many open parts)."""
    u, v = (a.ravel() for a in np.meshgrid(np.linspace(0, 1, n + 1), np.linspace(0, 1, n + 1)))
    corner = (np.arange(n)[:, None] * (n + 1) + np.arange(n)[None, :]).ravel()
    quad = np.concatenate([np.column_stack([corner, corner + 1, corner + n + 2]),
                           np.column_stack([corner, corner + n + 2, corner + n + 1])])
    points = np.concatenate([np.column_stack([u + 1.2 * k, v, 0.1 * np.sin(7 * u)])
                             for k in range(parts)]).astype(np.float32)
    faces = np.concatenate([quad + k * len(u) for k in range(parts)]).astype(np.uint32)
    return RenderMesh(points, faces, vertex_normals(points, faces), np.ones((len(points), 4)))


def test_a_budget_below_the_decimation_floor_says_where_decimation_stops():
    from reliefkit.scene.decimate import gpu_bytes, simplified
    from reliefkit.shootout.run import decimated_row

    mesh = sheets()
    floor = simplified(mesh, 1)
    row = decimated_row(mesh, gpu_bytes(floor, compact=True)["total"] - 1)
    assert not row["fits"]
    assert f"stops at {floor.triangle_count:,} triangles" in row["reason"]


def without_times(value):
    if isinstance(value, dict):
        return {k: without_times(v) for k, v in value.items() if k not in TIME_FIELDS}
    if isinstance(value, list):
        return [without_times(v) for v in value]
    return value


def test_two_runs_give_the_same_figures_times_aside(runs):
    (_, first, _), (_, second, _) = runs
    assert without_times(first) == without_times(second)
    assert all(r["bake_s"] is not None for r in first["meshes"][0]["rows"] if r["fits"])


def test_each_recommendation_is_the_best_row_by_ssim_then_iou(runs):
    folder, data, _ = runs[0]
    mesh = data["meshes"][0]
    markdown = (folder / "shootout.md").read_text()
    assert len(mesh["recommendations"]) == 2 * 2
    for rec in mesh["recommendations"]:
        size = str(rec["size"])
        within = [r for r in mesh["rows"] if r["budget"] == rec["budget"] and r["fits"]]
        top = max((r["sizes"][size]["ssim"], r["sizes"][size]["iou"]) for r in within)
        chosen, = (r for r in within if r["label"] == rec["label"])
        assert (chosen["sizes"][size]["ssim"], chosen["sizes"][size]["iou"]) == top
        assert rec["line"].split(": ", 1)[1] in markdown


def test_metrics_are_those_of_the_full_mesh_drawn_from_the_same_views(runs):
    _, data, _ = runs[0]
    whole = next(r for r in data["meshes"][0]["rows"]
                 if r["label"] == "decimated mesh" and r["n"] == lamp().triangle_count)
    for figures in whole["sizes"].values():  # the whole mesh, only quantized: near-exact
        assert figures["iou"] > 0.99 and figures["ssim"] > 0.95
        assert len(figures["views"]) == len(data["views"]) == 6


def test_a_row_is_measured_and_timed_with_its_declared_render_options():
    """A relief cube over 128 texels has no safety radii: drawn (and timed) with its
    declared method, never the robust default, which refuses it."""
    from reliefkit.bake import bake
    from reliefkit.render import render
    from reliefkit.scene.sphere_views import cameras
    from reliefkit.shootout.measure import measure

    mesh = lamp()
    cube, = (c for c in candidates() if c.label == "relief-cube")
    rep = bake(mesh, cube.kind, **cube.sizing.params(140, mesh))
    views = {32: cameras(mesh.bounds, 32)[:2]}
    figures, pictures = measure(rep, mesh, views, {32: render(mesh, views[32])},
                                cube.sizing.render)
    assert figures[32]["iou"] > 0.9 and figures[32]["frame_ratio"] > 0
    assert pictures[32].shape == (32, 32, 4)


@pytest.mark.parametrize(("args", "words"), [
    (["demo:tree", "--budgets", "1MB,lots"], ["--budgets", "lots"]),
    (["demo:tree", "--budgets", "0KB"], ["--budgets", "outside"]),
    (["demo:tree", "--sizes", "64,huge"], ["--sizes", "huge"]),
    (["demo:tree", "--kinds", "relief-cube,teapot"], ["--kinds", "unknown teapot"]),
    (["demo:tree", "--kinds", "relief"], ["--kinds", "relief", "cannot be sized"]),
    (["no_such_mesh.obj"], ["no_such_mesh.obj", "no such file"]),
    (["demo:nothing"], ["nothing"]),
    (["thing.rk"], ["mesh file"]),
])
def test_bad_input_is_one_line_before_any_work(tmp_path, args, words):
    out = tmp_path / "out"
    result = run_cli("shootout", *args, "--out", out, cwd=tmp_path)
    assert_one_line_error(result, *words)
    assert not out.exists() or not any(out.iterdir())
