"""`reliefkit bench loading`: the one mesh it writes in four formats is the same mesh in
each, and a measurement reports the load of that file (not of the warm-up)."""

from __future__ import annotations

import numpy as np

from reliefkit.bench.loading import FORMATS, measure, tiled_spheres, write_meshes
from reliefkit.io.meshes import load_mesh


def test_every_format_holds_the_same_triangles(tmp_path):
    vertices, faces = tiled_spheres(2, subdivisions=1)
    paths = write_meshes(tmp_path, 2, subdivisions=1)
    assert sorted(paths) == sorted(FORMATS)
    expected = np.sort(vertices[faces].reshape(-1, 9), axis=0)
    for fmt, path in paths.items():
        mesh = load_mesh(path)
        corners = mesh.world_positions[mesh.indices].reshape(-1, 9)
        assert mesh.triangle_count == len(faces), fmt
        np.testing.assert_allclose(np.sort(corners, axis=0), expected, atol=1e-6, err_msg=fmt)


def test_a_measurement_is_of_the_file_it_names(tmp_path):
    small = write_meshes(tmp_path / "small", 1, subdivisions=1)
    large = write_meshes(tmp_path / "large", 2, subdivisions=3)
    row = measure(large["stl"], small["stl"])
    assert row["triangles"] == 2 * 1280 and row["format"] == "stl"
    assert row["file_bytes"] == large["stl"].stat().st_size
    assert row["peak_bytes"] >= row["baseline_bytes"] > 0
    assert row["ratio"] == row["load_bytes"] / row["file_bytes"]
