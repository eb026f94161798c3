"""Visibility order of shell tetrahedra against a brute-force ray reference: on every pixel
ray, the tetrahedra it crosses, by exact float64 entry distance, must come in that order."""

from __future__ import annotations

import time

import numpy as np
import pytest
import trimesh

from reliefkit.errors import UsageError
from reliefkit.scene.camera import Camera
from reliefkit.scene.mesh import RenderMesh, vertex_normals
from reliefkit.techniques.shellvolume.order import (
    abuffer_relations,
    adjacent_relations,
    centroid_depths,
    topological_order,
    visibility_order,
)
from reliefkit.techniques.shellvolume.shell import build_shell


def sphere_mesh(subdivisions=2):
    """trimesh's icosphere, radial normals, a tilted spherical mapping (as test_shell)."""
    ico = trimesh.creation.icosphere(subdivisions=subdivisions, radius=1.0)
    p = np.asarray(ico.vertices, dtype=np.float64)
    unit = p / np.linalg.norm(p, axis=1, keepdims=True)
    u = np.arctan2(unit[:, 1], unit[:, 0]) / (2 * np.pi) + 0.5
    v = np.arccos(np.clip(unit[:, 2], -1, 1)) / np.pi
    uvs = np.column_stack([u + 0.05 * unit[:, 2], v + 0.05 * unit[:, 0]])
    return RenderMesh(p, np.asarray(ico.faces), unit, np.ones((len(p), 4)), uvs)


def torus_mesh():
    """A torus (non-convex: side-on rays leave the shell and re-enter it)."""
    tor = trimesh.creation.torus(1.0, 0.35, major_sections=20, minor_sections=10)
    p = np.asarray(tor.vertices, dtype=np.float64)
    faces = np.asarray(tor.faces)
    theta = np.arctan2(p[:, 1], p[:, 0])
    phi = np.arctan2(p[:, 2], np.hypot(p[:, 0], p[:, 1]) - 1.0)
    uvs = np.column_stack([theta / (2 * np.pi) + 0.05 * np.sin(phi),
                           phi / (2 * np.pi) + 0.05 * np.cos(theta)])
    return RenderMesh(p, faces, vertex_normals(p, faces), np.ones((len(p), 4)), uvs)


@pytest.fixture(scope="module")
def sphere_shell():
    return build_shell(sphere_mesh(), 0.15)


@pytest.fixture(scope="module")
def torus_shell():
    return build_shell(torus_mesh(), 0.08)


def crossings(shell, origins, dirs, chunk=256):
    """Per ray, the tetrahedra it crosses (positive length) sorted by entry distance."""
    normals, offsets = shell.planes[..., :3], shell.planes[..., 3]
    tol = 1e-9
    out = []
    for lo in range(0, len(origins), chunk):
        o, d = origins[lo:lo + chunk], dirs[lo:lo + chunk]
        num = np.einsum("tfi,ri->rtf", normals, o) + offsets  # > 0: outside that plane
        den = np.einsum("tfi,ri->rtf", normals, d)
        with np.errstate(divide="ignore", invalid="ignore"):
            t = -num / den
        enter = np.where(den < 0, t, -np.inf).max(axis=2)
        leave = np.where(den > 0, t, np.inf).min(axis=2)
        parallel_out = ((den == 0) & (num > 0)).any(axis=2)
        crossed = (leave - enter > tol) & ~parallel_out
        for r in range(len(o)):
            hit = np.nonzero(crossed[r])[0]
            out.append(hit[np.argsort(enter[r, hit], kind="stable")])
    return out


def violations(shell, camera, order):
    """Ray constraints (consecutive crossed tetrahedra) the order breaks, and their total."""
    origins, dirs = (a.reshape(-1, 3) for a in camera.pixel_rays())
    position = np.empty(len(order), np.int64)
    position[order] = np.arange(len(order))
    bad = total = 0
    for hits in crossings(shell, origins, dirs):
        if len(hits) > 1:
            pos = position[hits]
            bad += int((pos[1:] < pos[:-1]).sum())
            total += len(hits) - 1
    return bad, total


def views(distance=4.0, ortho=False):
    half = 1.6 if ortho else None
    return [Camera.orbit((0, 0, 0), az, el, distance, size=(64, 64), ortho_height=half)
            for az, el in ((0, 0), (35, 20), (120, -40), (250, 70), (300, 5))]


def full_permutation(order, count):
    return order.dtype == np.int32 and np.array_equal(np.sort(order), np.arange(count))


@pytest.mark.parametrize("ortho", [False, True])
def test_sphere_shell_from_outside_satisfies_every_ray(sphere_shell, ortho):
    for camera in views(ortho=ortho):
        result = visibility_order(sphere_shell, camera)
        assert full_permutation(result.order, len(sphere_shell.tets))
        bad, total = violations(sphere_shell, camera, result.order)
        print(f"sphere ortho={ortho} {camera.eye}: {bad}/{total} violated, "
              f"{result.edges} edges, {result.cycles} cycles")
        assert total > 0
        assert bad == 0
        assert result.cycles == 0


def test_torus_shell_sxmpvo_exact_centroid_not(torus_shell):
    cameras = views(distance=4.5) + [
        Camera.orbit((0, 0, 0), az, el, 4.5, size=(64, 64), ortho_height=1.8)
        for az, el in ((10, 3), (80, 25))]
    centroid_bad = []
    for camera in cameras:
        sx = visibility_order(torus_shell, camera)
        ce = visibility_order(torus_shell, camera, method="centroid")
        bad, total = violations(torus_shell, camera, sx.order)
        cbad, _ = violations(torus_shell, camera, ce.order)
        print(f"torus {camera.eye} ortho={camera.orthographic}: sxmpvo {bad}/{total}, "
              f"centroid {cbad}/{total}, cycles {sx.cycles}, edges {sx.edges}")
        assert bad == 0
        assert sx.cycles == 0
        centroid_bad.append(cbad)
    assert max(centroid_bad) > 0


def test_deterministic(torus_shell):
    camera = views()[1]
    a, b = visibility_order(torus_shell, camera), visibility_order(torus_shell, camera)
    assert np.array_equal(a.order, b.order) and (a.edges, a.cycles) == (b.edges, b.cycles)
    assert a.method == "sxmpvo" and a.seconds >= 0


def test_topological_sort_breaks_a_cycle_and_counts_it():
    # 0 -> 1 -> 2 -> 0 is a cycle; 2 -> 3 and 4 free
    src = np.array([0, 1, 2, 2])
    dst = np.array([1, 2, 0, 3])
    depth = np.array([0.0, 1.0, 2.0, 3.0, 0.5])
    order, broken = topological_order(5, src, dst, depth)
    assert full_permutation(order, 5)
    assert broken == 1
    pos = np.argsort(order)
    kept = [(s, d) for s, d in zip(src, dst, strict=True) if pos[s] < pos[d]]
    assert len(kept) == 3
    assert pos[2] < pos[3]
    assert np.array_equal(order, topological_order(5, src, dst, depth)[0])


def test_acyclic_graph_keeps_every_relation():
    rng = np.random.default_rng(1)
    n = 200
    src = rng.integers(0, n, 800)
    dst = rng.integers(0, n, 800)
    keep = src < dst  # acyclic by construction
    order, broken = topological_order(n, src[keep], dst[keep], rng.random(n))
    pos = np.argsort(order)
    assert broken == 0 and (pos[src[keep]] < pos[dst[keep]]).all()


def test_bad_arguments(sphere_shell):
    with pytest.raises(UsageError):
        visibility_order(sphere_shell, views()[0], method="bsp")
    with pytest.raises(UsageError):
        visibility_order(sphere_shell, views()[0], resolution=0)


def test_speed_large_icosphere():
    shell = build_shell(sphere_mesh(subdivisions=5), 0.03)
    camera = Camera.orbit((0, 0, 0), 30, 20, 4.0, size=(512, 512))
    visibility_order(shell, camera)  # compile / load the cache
    for method in ("sxmpvo", "centroid"):
        start = time.perf_counter()
        result = visibility_order(shell, camera, method=method)
        wall = time.perf_counter() - start
        print(f"{method}: {len(shell.tets)} tetrahedra in {wall * 1e3:.1f} ms "
              f"({len(shell.tets) / wall:.3g} tets/s), {result.edges} edges, "
              f"{result.cycles} cycles")
        assert full_permutation(result.order, len(shell.tets))


def test_gap_relations_are_needed_when_ties_break_badly(torus_shell):
    """With adversarial tie-breaking (farthest first) the face adjacency alone misorders the
    cells across the torus's gaps; the A-buffer relations restore the order when its samples
    separate them (the reference's own rays at 64, or a fine 512 buffer)."""
    camera = Camera.orbit((0, 0, 0), 35, 20, 4.5, size=(64, 64))
    worst = -centroid_depths(torus_shell, camera)
    count = len(torus_shell.tets)
    src, dst = adjacent_relations(torus_shell, camera)
    adjacency_only, _ = topological_order(count, src, dst, worst)
    bad, _ = violations(torus_shell, camera, adjacency_only)
    assert bad > 0
    for resolution in (64, 512):
        src, dst = abuffer_relations(torus_shell, camera, resolution)
        a_src, a_dst = adjacent_relations(torus_shell, camera)
        order, broken = topological_order(count, np.concatenate([a_src, src]),
                                          np.concatenate([a_dst, dst]), worst)
        fixed, _ = violations(torus_shell, camera, order)
        print(f"adversarial ties: adjacency only {bad}, with A-buffer {resolution}: {fixed}")
        assert fixed == 0 and broken == 0
