"""Every registered kind (and the toy's) has a glTF fallback: `fallback_mesh(triangles)`
returns a RenderMesh with triangles, within the budget where the kind has one, around the
representation's bounds (a camera-facing card may reach past the box, not far). Each
kind's own tests hold its fallback to the source mesh (mask IoU >= 0.9 from three views)."""

from __future__ import annotations

import numpy as np
import pytest
from helpers import sample, sample_ids, technique_samples

from reliefkit.scene.mesh import RenderMesh

pytestmark = pytest.mark.usefixtures("toy_registered")

SAMPLES = technique_samples()
IDS = sample_ids(SAMPLES)



@pytest.mark.parametrize("tech_kind", SAMPLES, ids=IDS)
def test_every_kind_has_a_fallback_mesh_within_its_bounds(gl, tech_kind):
    rep = sample(*tech_kind)
    mesh = rep.fallback_mesh()
    assert isinstance(mesh, RenderMesh) and mesh.triangle_count > 0
    assert mesh.triangle_count <= 20_000
    lo, hi = np.asarray(rep.bounds, float)
    reach = np.linalg.norm(mesh.world_positions - (lo + hi) / 2, axis=1).max()
    assert reach <= 1.5 * np.linalg.norm(hi - lo) / 2
