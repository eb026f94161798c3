"""The octahedral maps: encode and decode invert each other, and the three frames around a
direction and their weights are the ones an impostor blends."""

from __future__ import annotations

import numpy as np
import pytest

from reliefkit.techniques.impostor import octahedral


def _directions(rng, count: int, upper: bool = False) -> np.ndarray:
    d = rng.normal(size=(count, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    if upper:
        d[:, 1] = np.abs(d[:, 1])
    return d


@pytest.mark.parametrize("hemi", [False, True])
def test_encode_and_decode_round_trip(rng, hemi):
    d = _directions(rng, 2000, upper=hemi)
    d = np.concatenate([d, np.eye(3), -np.eye(3) if not hemi else np.eye(3)])
    p = octahedral.encode(d, hemi)
    assert (np.abs(p) <= 1 + 1e-12).all()
    np.testing.assert_allclose(octahedral.decode(p, hemi), d, atol=1e-12)


def test_the_full_map_puts_up_in_the_middle_and_down_at_the_corners():
    np.testing.assert_allclose(octahedral.encode([0.0, 1.0, 0.0], False), [0.0, 0.0])
    for corner in ([1, 1], [-1, 1], [1, -1], [-1, -1]):
        np.testing.assert_allclose(octahedral.decode(corner, False), [0, -1, 0], atol=1e-12)


def test_the_hemi_map_clamps_views_from_below_to_the_horizon():
    below = np.array([0.6, -0.8, 0.0])
    np.testing.assert_allclose(octahedral.decode(octahedral.encode(below, True), True),
                               [1.0, 0.0, 0.0], atol=1e-12)


@pytest.mark.parametrize("hemi,grid", [(False, 12), (True, 8), (False, 3), (True, 2)])
def test_three_frames_around_a_direction_with_barycentric_weights(rng, hemi, grid):
    d = _directions(rng, 3000, upper=hemi)
    frames, weights = octahedral.blend_frames(d, grid, hemi)
    assert frames.shape == (3000, 3, 2) and weights.shape == (3000, 3)
    np.testing.assert_allclose(weights.sum(axis=1), 1.0, atol=1e-12)
    assert (weights >= -1e-12).all() and (frames >= 0).all() and (frames < grid).all()
    # the three frames are a half of one grid cell, and the weights interpolate the point
    assert (np.ptp(frames, axis=1) == 1).all()
    g = (octahedral.encode(d, hemi) + 1) * 0.5 * (grid - 1)
    np.testing.assert_allclose(np.einsum("nk,nkc->nc", weights, frames), g, atol=1e-9)


@pytest.mark.parametrize("hemi", [False, True])
def test_a_view_exactly_on_a_frame_gives_that_frame_weight_one(hemi):
    grid = 7
    directions = octahedral.frame_directions(grid, hemi)
    for j in range(grid):
        for i in range(grid):
            frames, weights = octahedral.blend_frames(directions[j, i], grid, hemi)
            k = int(np.argmax(weights))
            assert weights[k] == pytest.approx(1.0, abs=1e-9)
            # the frame itself, or (on the full map's fold) a border frame that mirrors it
            np.testing.assert_allclose(directions[frames[k][1], frames[k][0]],
                                       directions[j, i], atol=1e-9)


def test_frame_axes_are_a_right_handed_basis_looking_along_minus_d(rng):
    d = np.concatenate([_directions(rng, 200), [[0, 1, 0], [0, -1, 0]]])
    right, up = octahedral.frame_basis(d)
    for a, b in ((right, up), (right, d), (up, d)):
        np.testing.assert_allclose(np.einsum("nc,nc->n", a, b), 0.0, atol=1e-12)
    np.testing.assert_allclose(np.cross(right, up), d, atol=1e-12)
