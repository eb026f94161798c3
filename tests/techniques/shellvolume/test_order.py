"""Visibility order of shell tetrahedra against a brute-force ray reference
(`order_check.ordering_violations`): on every pixel ray, the tetrahedra it crosses, by exact
float64 entry distance, must come in that order."""

from __future__ import annotations

import time

import numpy as np
import pytest
from shell_scenes import sphere_mesh, torus_mesh

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
from reliefkit.techniques.shellvolume.order_check import OrderCheck, ordering_violations
from reliefkit.techniques.shellvolume.shell import build_shell


def dented_sphere_mesh(subdivisions=2, direction=(0.3, 0.5, 0.8), cap_deg=55.0, depth=0.6):
    """The unit sphere with a smooth crater around `direction` (a concave region: rays
    across the crater leave the shell and re-enter it)."""
    sphere = sphere_mesh(subdivisions)
    unit, faces = np.asarray(sphere.positions, dtype=np.float64), np.asarray(sphere.indices)
    axis = np.asarray(direction, dtype=np.float64) / np.linalg.norm(direction)
    cap = np.cos(np.radians(cap_deg))
    s = np.clip((unit @ axis - cap) / (1.0 - cap), 0.0, 1.0)
    p = unit * (1.0 - depth * s * s * (3.0 - 2.0 * s))[:, None]  # smoothstep push inwards
    return RenderMesh(p, faces, vertex_normals(p, faces), np.ones((len(p), 4)), sphere.uvs)


def two_spheres_mesh(subdivisions=1):
    """Two separate spheres along z (one behind the other seen from near the z axis)."""
    sphere = sphere_mesh(subdivisions)
    unit, faces = np.asarray(sphere.positions, dtype=np.float64), np.asarray(sphere.indices)
    p = np.vstack([unit * 0.6 + [0.0, 0.0, 1.0], unit * 0.45 + [0.15, 0.1, -1.0]])
    return RenderMesh(p, np.vstack([faces, faces + len(unit)]), np.vstack([unit, unit]),
                      np.ones((len(p), 4)), np.vstack([sphere.uvs, sphere.uvs]))


@pytest.fixture(scope="module")
def sphere_shell():
    return build_shell(sphere_mesh(), 0.15)


@pytest.fixture(scope="module")
def torus_shell():
    return build_shell(torus_mesh(), 0.08)


def violations(shell, camera, order):
    """(violated, total) consecutive-crossing constraints of `camera`'s pixel rays."""
    check = ordering_violations(shell, camera, order)
    return check.violations, check.pairs


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
    order, broken, _ = topological_order(by_depth(depth), (src, dst))
    assert full_permutation(order, 5)
    assert broken == 1
    pos = np.argsort(order)
    kept = [(s, d) for s, d in zip(src, dst, strict=True) if pos[s] < pos[d]]
    assert len(kept) == 3
    assert pos[2] < pos[3]
    assert np.array_equal(order, topological_order(by_depth(depth), (src, dst))[0])


def test_acyclic_graph_keeps_every_relation():
    rng = np.random.default_rng(1)
    n = 200
    src = rng.integers(0, n, 800)
    dst = rng.integers(0, n, 800)
    keep = src < dst  # acyclic by construction
    order, broken, _ = topological_order(by_depth(rng.random(n)), (src[keep], dst[keep]))
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
    src, dst = adjacent_relations(torus_shell, camera)
    adjacency_only, _, _ = topological_order(by_depth(worst), (src, dst))
    bad, _ = violations(torus_shell, camera, adjacency_only)
    assert bad > 0
    for resolution in (64, 512):
        src, dst = abuffer_relations(torus_shell, camera, resolution)
        a_src, a_dst = adjacent_relations(torus_shell, camera)
        order, broken, _ = topological_order(by_depth(worst), (a_src, a_dst), (src, dst))
        fixed, _ = violations(torus_shell, camera, order)
        print(f"adversarial ties: adjacency only {bad}, with A-buffer {resolution}: {fixed}")
        assert fixed == 0 and broken == 0


def test_checker_counts_each_consecutive_pair_once(torus_shell):
    camera = views(distance=4.5)[1]
    order = visibility_order(torus_shell, camera, method="centroid").order
    check = ordering_violations(torus_shell, camera, order)
    reverse = ordering_violations(torus_shell, camera, order[::-1].copy())
    assert isinstance(check, OrderCheck) and check.seconds >= 0
    # ranks are distinct: every consecutive pair is inverted by exactly one of the two
    assert check.violations + reverse.violations == check.pairs == reverse.pairs
    assert reverse.bad_rays == reverse.rays == check.rays > 0
    assert 0 < check.bad_rays <= check.rays <= check.pairs and check.violations > 0
    small = ordering_violations(torus_shell, camera, order, size=(16, 16))
    assert 0 < small.rays <= 16 * 16 and small.pairs < check.pairs
    with pytest.raises(UsageError):
        ordering_violations(torus_shell, camera, order[:-1])
    with pytest.raises(UsageError):
        ordering_violations(torus_shell, camera, order, size=(0, 16))


def test_checker_speed():
    shell = build_shell(sphere_mesh(subdivisions=4), 0.03)  # 15360 tetrahedra
    camera = Camera.orbit((0, 0, 0), 30, 20, 4.0, size=(256, 256))
    order = visibility_order(shell, camera).order
    ordering_violations(shell, camera, order)  # compile / load the cache
    check = ordering_violations(shell, camera, order)
    print(f"checker: {len(shell.tets)} tetrahedra, 256x256 rays, {check.rays} crossing 2+, "
          f"{check.pairs} pairs in {check.seconds * 1e3:.1f} ms")
    assert check.violations == 0 and check.rays > 10000
    assert check.seconds < 1.0


#: Pixel rays per random view (and SXMPVO's A-buffer resolution, see below).
RAYS = 48

#: name -> (mesh builder, shell thickness, rough radius of the shape around the origin)
SHAPES = {"torus": (torus_mesh, 0.08, 1.5), "dented sphere": (dented_sphere_mesh, 0.06, 1.1),
          "two spheres": (two_spheres_mesh, 0.1, 1.8)}


def random_views(rng, count, reach):
    """Random orbits around a point near the origin, the eye outside the shape: perspective
    with a random field of view, a quarter orthographic."""
    cameras = []
    for _ in range(count):
        target = tuple(rng.uniform(-0.3, 0.3, 3))
        distance = rng.uniform(2.2, 7.0) * reach / 1.5
        kind = {"ortho_height": rng.uniform(0.6, 1.2) * reach} if rng.random() < 0.25 \
            else {"fov_deg": rng.uniform(15.0, 80.0)}
        cameras.append(Camera.orbit(target, rng.uniform(0, 360), rng.uniform(-85, 85),
                                    distance, size=(RAYS, RAYS), **kind))
    return cameras


@pytest.mark.parametrize("name", list(SHAPES))
def test_random_views_sxmpvo_exact_centroid_not(name):
    """SXMPVO is exact on the rays its A-buffer samples (module docstring of `order`), so
    the A-buffer is the checked ray grid itself (`resolution=RAYS`: the same pixel rays).
    Over 1000 random views nothing may be violated; the centroid sort, on the same views,
    is reported and must fail somewhere."""
    build, thickness, reach = SHAPES[name]
    shell = build_shell(build(), thickness)
    rng = np.random.default_rng(sum(map(ord, name)))
    sx_bad = sx_cycles = ce_bad = pairs = bad_views = 0
    for camera in random_views(rng, 1000, reach):
        sx = visibility_order(shell, camera, resolution=RAYS)
        ce = visibility_order(shell, camera, method="centroid")
        check = ordering_violations(shell, camera, sx.order)
        sx_bad += check.violations
        sx_cycles += sx.cycles
        bad_views += check.violations > 0
        pairs += check.pairs
        ce_bad += ordering_violations(shell, camera, ce.order).violations
    print(f"{name}: {len(shell.tets)} tetrahedra, 1000 views at {RAYS}x{RAYS}, {pairs} "
          f"constraints: sxmpvo {sx_bad} violated ({bad_views} views, {sx_cycles} cycles), "
          f"centroid {ce_bad} violated")
    assert pairs > 0
    assert sx_bad == 0 and sx_cycles == 0
    assert ce_bad > 0


def by_depth(depth):
    """The visiting order `topological_order` takes: nearest first, ties by index."""
    return np.argsort(depth, kind="stable")


def reference_order(count, src, dst, depth):
    """The previous implementation's traversal, in plain numpy and Python: relations made
    distinct with np.unique, successors by lexsort (nearest last), roots farthest first."""
    src, dst = np.asarray(src, np.int64), np.asarray(dst, np.int64)
    keep = src != dst
    key = np.unique(src[keep] * count + dst[keep])
    src, dst = key // count, key % count
    rank = np.empty(count, np.int64)
    rank[np.argsort(depth, kind="stable")] = np.arange(count)
    by = np.lexsort((-rank[dst], src))
    src, dst = src[by], dst[by]
    offsets = np.concatenate([[0], np.cumsum(np.bincount(src, minlength=count))])
    state, post, broken = np.zeros(count, np.int8), [], 0
    for root in np.argsort(-rank, kind="stable"):
        if state[root]:
            continue
        stack, state[root] = [[root, offsets[root]]], 1
        while stack:
            v, k = stack[-1]
            if k < offsets[v + 1]:
                stack[-1][1] += 1
                u = dst[k]
                if state[u] == 0:
                    state[u] = 1
                    stack.append([u, offsets[u]])
                else:
                    broken += state[u] == 1
            else:
                state[v] = 2
                post.append(v)
                stack.pop()
    return np.array(post[::-1], np.int32), broken, len(key)


def test_fast_pipeline_matches_the_reference_traversal(torus_shell):
    """The fused, threaded path of `visibility_order` (rank-space CSR graph, deduplicated
    in place) gives exactly the order of the straightforward pipeline: the public stages
    and the previous implementation's unique/lexsort/DFS."""
    cameras = views(distance=4.5) + [Camera.orbit((0, 0, 0), 80, 25, 4.5, size=(64, 64),
                                                  ortho_height=1.8)]
    for camera, resolution in zip(cameras, (64, 48, 96, 64, 200, 33), strict=True):
        fast = visibility_order(torus_shell, camera, resolution=resolution)
        a_src, a_dst = adjacent_relations(torus_shell, camera)
        g_src, g_dst = abuffer_relations(torus_shell, camera, resolution)
        order, broken, edges = reference_order(
            len(torus_shell.tets), np.concatenate([a_src, g_src]),
            np.concatenate([a_dst, g_dst]), centroid_depths(torus_shell, camera))
        assert np.array_equal(fast.order, order)
        assert (fast.cycles, fast.edges) == (broken, edges)


def test_topological_order_matches_the_reference_with_cycles():
    rng = np.random.default_rng(7)
    for n, m in ((50, 400), (300, 1500), (40, 40)):
        src, dst = rng.integers(0, n, m), rng.integers(0, n, m)
        depth = rng.integers(0, 5, n).astype(float)  # many ties: broken by index
        order, broken, edges = topological_order(by_depth(depth), (src, dst))
        ref, ref_broken, ref_edges = reference_order(n, src, dst, depth)
        assert np.array_equal(order, ref) and broken == ref_broken and broken > 0
        assert edges == ref_edges


def test_the_checker_counts_the_same_at_any_scale():
    """The torus scaled by 1e-12 (every segment shorter than an absolute 1e-9) and its
    camera likewise: the same rays, pairs and violations of the centroid order."""
    counts = []
    for scale in (1.0, 1e-12):
        mesh = torus_mesh()
        small = RenderMesh(mesh.world_positions * scale, mesh.indices, mesh.normals,
                           mesh.colors, mesh.uvs)
        shell = build_shell(small, 0.1 * scale)
        camera = Camera.orbit((0, 0, 0), 30.0, 20.0, 4.5 * scale, size=(48, 48),
                              near=0.5 * scale, far=10.0 * scale)
        order = visibility_order(shell, camera, method="centroid").order
        check = ordering_violations(shell, camera, order)
        counts.append((check.rays, check.pairs, check.violations))
    assert counts[0][1] > 100 and counts[0][2] > 0
    assert counts[1] == counts[0]
