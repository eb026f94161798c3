"""VTK's cell-centre depth sort as a peer of `order.visibility_order` (skipped without VTK)."""

from __future__ import annotations

import sys

import numpy as np
import pytest
from shell_scenes import torus_mesh

from reliefkit.scene.camera import Camera
from reliefkit.techniques.shellvolume.order import centroid_depths, visibility_order
from reliefkit.techniques.shellvolume.order_check import ordering_violations
from reliefkit.techniques.shellvolume.peers import PeerOrder, vtk_available, vtk_depth_sort
from reliefkit.techniques.shellvolume.shell import build_shell

AVAILABLE, REASON = vtk_available()
needs_vtk = pytest.mark.skipif(not AVAILABLE, reason=REASON or "vtk unavailable")


@pytest.fixture(scope="module")
def torus_shell():
    return build_shell(torus_mesh(), 0.08)


def cameras():
    return [Camera.orbit((0, 0, 0), az, el, 4.5, size=(64, 64), ortho_height=half)
            for az, el, half in ((0, 0, None), (35, 20, None), (120, -40, None),
                                 (10, 3, 1.8), (80, 25, 1.8))]


def test_missing_vtk_is_reported_not_raised(torus_shell, monkeypatch):
    for name in [m for m in sys.modules if m == "vtkmodules" or m.startswith("vtkmodules.")]:
        monkeypatch.setitem(sys.modules, name, None)  # None: "import halted"
    monkeypatch.setitem(sys.modules, "vtkmodules", None)
    peer = vtk_depth_sort(torus_shell, cameras()[0])
    assert not peer.available and len(peer.order) == 0
    assert peer.reason and "\n" not in peer.reason and "vtk" in peer.reason


@needs_vtk
def test_vtk_order_is_a_front_to_back_permutation_like_the_centroid_sort(torus_shell):
    count = len(torus_shell.tets)
    vtk_bad, centroid_bad = [], []
    for camera in cameras():
        peer = vtk_depth_sort(torus_shell, camera)
        assert isinstance(peer, PeerOrder) and peer.available and peer.reason == ""
        assert peer.order.dtype == np.int32
        assert np.array_equal(np.sort(peer.order), np.arange(count))
        assert peer.seconds >= 0
        depth = centroid_depths(torus_shell, camera)
        tenth = count // 10
        assert depth[peer.order[:tenth]].mean() < depth[peer.order[-tenth:]].mean()
        vtk_bad.append(ordering_violations(torus_shell, camera, peer.order).violations)
        ce = visibility_order(torus_shell, camera, method="centroid")
        centroid_bad.append(ordering_violations(torus_shell, camera, ce.order).violations)
        print(f"{camera.eye} ortho={camera.orthographic}: vtk {vtk_bad[-1]} violated, "
              f"centroid {centroid_bad[-1]}, vtk sort {peer.seconds * 1e3:.2f} ms")
    assert sum(vtk_bad) > 0
    # the same approximation (cell centres' depth): within a factor of two of ours
    assert 0.5 * sum(centroid_bad) <= sum(vtk_bad) <= 2.0 * sum(centroid_bad)
