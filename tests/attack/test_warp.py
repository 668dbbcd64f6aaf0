"""Where a patch lands in a picture: the homography takes the corners where they project,
an upright square pastes pixel for pixel, and numpy's sampling is torch's grid_sample."""

from __future__ import annotations

import numpy as np
import pytest

from fsvla.attack.warp import composite, footprint, homography, project, sample


def test_the_homography_takes_each_corner_to_its_image() -> None:
    source = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    target = np.array([[10.0, 12.0], [40.0, 9.0], [44.0, 35.0], [8.0, 30.0]])
    h = homography(source, target)
    mapped = np.c_[source, np.ones(4)] @ h.T
    assert np.allclose(mapped[:, :2] / mapped[:, 2:], target)


def test_an_upright_square_is_pasted_pixel_for_pixel() -> None:
    patch = np.random.default_rng(0).random((4, 4, 3))
    frame = np.full((20, 30, 3), 7, dtype=np.uint8)
    where = footprint(np.array([[10.0, 5.0], [14.0, 5.0], [14.0, 9.0], [10.0, 9.0]]), (20, 30))
    assert where is not None and where.pixels == 16
    out = composite(frame, patch, where)
    assert np.array_equal(out[5:9, 10:14], (patch * 255).round().astype(np.uint8))
    out[5:9, 10:14] = 7
    assert (out == 7).all()  # nothing else changed


def test_a_patch_outside_the_picture_has_no_footprint() -> None:
    assert footprint(np.array([[50.0, 5.0], [60.0, 5.0], [60.0, 9.0], [50.0, 9.0]]), (20, 30)) is None


def test_projection_follows_the_opencv_camera() -> None:
    intrinsic = np.array([[100.0, 0, 50], [0, 100.0, 40], [0, 0, 1]])
    extrinsic = np.c_[np.eye(3), [0.0, 0.0, 2.0]]
    pixels, depth = project(np.array([[0.2, -0.1, 0.0]]), intrinsic, extrinsic)
    assert np.allclose(pixels, [[60.0, 35.0]]) and np.allclose(depth, [2.0])


def test_numpy_sampling_matches_grid_sample() -> None:
    torch = pytest.importorskip("torch")
    patch = np.random.default_rng(1).random((8, 8, 3))
    corners = np.array([[3.3, 2.1], [20.7, 4.0], [19.2, 18.8], [2.0, 15.5]])
    where = footprint(corners, (24, 24))
    assert where is not None
    ours = sample(patch, where.grid)
    theirs = torch.nn.functional.grid_sample(
        torch.as_tensor(patch).permute(2, 0, 1)[None], torch.as_tensor(where.grid, dtype=torch.float64)[None],
        mode="bilinear", padding_mode="border", align_corners=False)[0].permute(1, 2, 0).numpy()
    assert np.allclose(ours, theirs, atol=1e-5)
