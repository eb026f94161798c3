"""compare's reports: metrics.md and metrics.json name each measured column once, and a score
with nothing to measure reads n/a (null in JSON), never nan."""

import json
import math

import pytest

from reliefkit import bake
from reliefkit.compare import compare, metrics_json, metrics_markdown
from reliefkit.scene.assets import make_asset
from reliefkit.scene.views import orbit_bounds


def table(markdown: str) -> tuple[list[str], list[list[str]]]:
    """The header's columns and each row's cells of the one table in ``markdown``."""
    rows = [[c.strip() for c in line.strip("|").split("|")]
            for line in markdown.splitlines() if line.startswith("|")]
    return rows[0], rows[2:]


def test_columns_of_a_part_are_the_compared_kinds_once(gl):
    """The slicing technique declares depth-object and displacement columns; comparing a
    displacement map shows its own (reference_wrong once) and no empty column."""
    mesh = make_asset("blob")
    rep = bake(mesh, "displacement", res=16)
    camera = orbit_bounds(mesh.bounds, 30.0, 25.0, None, (32, 32), 40.0)
    header, rows = table(metrics_markdown(compare(mesh, rep, camera), "blob"))
    assert len(header) == len(set(header)), header
    assert "reference_wrong" in header and "reference_iou" not in header
    for k, column in enumerate(header[1:], start=1):
        assert any(row[k] not in ("", "n/a") for row in rows), f"{column} is empty"


def test_a_score_without_a_measure_is_na_and_null():
    """Depth peeling's frame has no positions: its position error is NaN, which the table
    shows as n/a and the JSON as null (strict JSON: no NaN token)."""
    result = {"columns": ("psnr", "position_mean_rel", "bytes"),
              "bytes": {"mesh": 10, "representation": 20},
              "metrics": {"sorted": {"psnr": 20.5, "position_mean_rel": 0.01, "bytes": 20},
                          "peeling": {"psnr": 20.5, "position_mean_rel": math.nan,
                                      "bytes": 20}}}
    header, rows = table(metrics_markdown(result, "shell"))
    peeling = dict(zip(header, rows[1], strict=True))
    assert peeling["position_mean_rel"] == "n/a"
    assert "nan" not in metrics_markdown(result, "shell").lower()

    def refuse(token):
        pytest.fail(f"metrics.json holds {token}")

    parsed = json.loads(metrics_json(result, "shell"), parse_constant=refuse)
    assert parsed["variants"]["peeling"]["position_mean_rel"] is None
    assert parsed["variants"]["sorted"]["position_mean_rel"] == 0.01


def test_an_infinite_score_is_inf_in_the_table_and_null_in_the_json():
    """Identical pictures have an infinite PSNR: the table says so, strict JSON cannot."""
    result = {"columns": ("psnr", "bytes"), "bytes": {"mesh": 10, "representation": 20},
              "metrics": {"same": {"psnr": math.inf, "bytes": 20}}}
    header, rows = table(metrics_markdown(result, "x"))
    assert dict(zip(header, rows[0], strict=True))["psnr"] == "inf"

    def refuse(token):
        pytest.fail(f"metrics.json holds {token}")

    parsed = json.loads(metrics_json(result, "x"), parse_constant=refuse)
    assert parsed["variants"]["same"]["psnr"] is None


def test_a_shadowed_variant_is_scored_against_the_mesh_with_shadows(gl):
    """The shell volume's "shadows" variant is held to the mesh rendered with --shadows,
    every other variant to the plain mesh (one render per distinct set of options)."""
    import numpy as np
    import trimesh

    from reliefkit.compare import mesh_references
    from reliefkit.core.technique import technique
    from reliefkit.render import render
    from reliefkit.scene.light import DirectionalLight
    from reliefkit.scene.mesh import RenderMesh, vertex_normals

    cube = trimesh.creation.box(extents=(0.5, 0.5, 0.5))
    cube.apply_translation((0.0, 0.75, 0.0))
    plane = trimesh.creation.box(extents=(4.0, 0.02, 4.0))
    both = trimesh.util.concatenate([cube, plane])
    positions = np.asarray(both.vertices, np.float32)
    mesh = RenderMesh(positions, both.faces, vertex_normals(positions, both.faces),
                      np.ones((len(positions), 4)))
    camera = orbit_bounds(mesh.bounds, 30.0, 50.0, None, (48, 48), 40.0)
    light = DirectionalLight.from_angles(-60.0, 45.0)
    variants = technique("shellvolume").compare_variants
    references = mesh_references(mesh, camera, light, variants)
    shadowed = render(mesh, camera, light=light, shadows=True).color
    plain = render(mesh, camera, light=light).color
    assert not np.array_equal(shadowed, plain)
    for variant in variants:
        expected = shadowed if variant.options.get("shadows") else plain
        np.testing.assert_array_equal(references[variant.name].color, expected, variant.name)
    assert any(v.options.get("shadows") for v in variants)
    assert len({id(frame) for frame in references.values()}) == 2
