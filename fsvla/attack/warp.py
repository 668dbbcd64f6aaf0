"""Where a patch's pixels land in a camera's picture: a homography, and compositing.

A V4 patch is a flat quad, so its image in a pinhole camera is the patch image under a
homography. :func:`project` takes the quad's world corners (from
:func:`fsvla.variation.patch.patch_corners`) to pixel coordinates (a pixel's centre at
``(u + 0.5, v + 0.5)``, as SAPIEN renders), :func:`footprint` inverts the homography once
per view into a sampling grid over the quad's bounding box, and :func:`composite` pastes a
patch through that grid with bilinear sampling. The grid is in
``torch.nn.functional.grid_sample``'s normalised coordinates (``align_corners=False``), so
the gradient attack samples the same places differentiably. Numpy only.

Compositing into frames rendered without the patch is exact for the quad's geometry and
ignores what the renderer would add: shading of the patch (it is drawn unlit, as the
render-only quad's texture is close to), and occlusion of the patch by the robot.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class Footprint:
    """Where a patch shows in one picture: the rows ``top:bottom`` and columns
    ``left:right`` of its bounding box, ``grid`` (h × w × 2: where each of those pixels
    samples the patch, normalised to [-1, 1], x first) and ``mask`` (h × w: inside the
    quad)."""

    top: int
    bottom: int
    left: int
    right: int
    grid: NDArray[np.float32]
    mask: NDArray[np.bool_]

    @property
    def pixels(self) -> int:
        """How many pixels of the picture the patch covers."""
        return int(self.mask.sum())


def project(points: FloatArray, intrinsic: FloatArray, extrinsic: FloatArray
            ) -> tuple[FloatArray, NDArray[np.float64]]:
    """Pixel coordinates (n × 2) of world ``points`` (n × 3) and their depth along the
    camera's axis (OpenCV camera: 3 × 3 ``intrinsic``, 3 × 4 world-to-camera ``extrinsic``)."""
    camera = np.c_[np.asarray(points, dtype=np.float64), np.ones(len(points))] @ np.asarray(extrinsic).T
    uv = camera @ np.asarray(intrinsic).T
    depth = camera[:, 2]
    return uv[:, :2] / np.where(np.abs(uv[:, 2:]) < 1e-12, 1e-12, uv[:, 2:]), depth


def homography(source: FloatArray, target: FloatArray) -> FloatArray:
    """The 3 × 3 homography taking the four ``source`` points (4 × 2) to ``target``."""
    rows, rhs = [], []
    for (x, y), (u, v) in zip(np.asarray(source, dtype=np.float64), np.asarray(target, dtype=np.float64)):
        rows.append([x, y, 1, 0, 0, 0, -u * x, -u * y])
        rows.append([0, 0, 0, x, y, 1, -v * x, -v * y])
        rhs.extend([u, v])
    h = np.linalg.solve(np.asarray(rows), np.asarray(rhs))
    return np.append(h, 1.0).reshape(3, 3)


def footprint(corners_px: FloatArray, frame_shape: tuple[int, int]) -> Footprint | None:
    """Where a patch whose corners (image order TL, TR, BR, BL) project to ``corners_px``
    (4 × 2) shows in a picture of ``frame_shape`` (height, width); None when none of it is
    in the picture."""
    height, width = frame_shape
    corners = np.asarray(corners_px, dtype=np.float64)
    left, top = np.floor(corners.min(axis=0)).astype(int)
    right, bottom = np.ceil(corners.max(axis=0)).astype(int)
    left, top = max(left, 0), max(top, 0)
    right, bottom = min(right, width), min(bottom, height)
    if right <= left or bottom <= top:
        return None
    unit = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])
    inverse = homography(corners, unit)
    v, u = np.mgrid[top:bottom, left:right].astype(np.float64) + 0.5
    mapped = np.stack([u, v, np.ones_like(u)], axis=-1) @ inverse.T
    grid = mapped[..., :2] / mapped[..., 2:]
    mask = (np.abs(grid) <= 1.0).all(axis=-1)
    if not mask.any():
        return None
    return Footprint(int(top), int(bottom), int(left), int(right), grid.astype(np.float32), mask)


def sample(patch: NDArray[np.floating], grid: NDArray[np.float32]) -> NDArray[np.float64]:
    """Bilinear samples (h × w × 3) of ``patch`` (S × S' × 3) at ``grid``'s normalised
    places, as ``grid_sample(..., align_corners=False, padding_mode="border")`` takes them."""
    rows, cols = patch.shape[:2]
    x = np.clip((grid[..., 0] + 1.0) * cols / 2.0 - 0.5, 0.0, cols - 1.0)
    y = np.clip((grid[..., 1] + 1.0) * rows / 2.0 - 0.5, 0.0, rows - 1.0)
    x0, y0 = np.floor(x).astype(int), np.floor(y).astype(int)
    x1, y1 = np.minimum(x0 + 1, cols - 1), np.minimum(y0 + 1, rows - 1)
    fx, fy = (x - x0)[..., None], (y - y0)[..., None]
    p = np.asarray(patch, dtype=np.float64)
    return ((p[y0, x0] * (1 - fx) + p[y0, x1] * fx) * (1 - fy)
            + (p[y1, x0] * (1 - fx) + p[y1, x1] * fx) * fy)


def composite(frame: NDArray[np.uint8], patch: NDArray[np.floating], where: Footprint,
              gain: float = 1.0) -> NDArray[np.uint8]:
    """``frame`` (H × W × 3 uint8) with ``patch`` (S × S × 3, values in [0, 1]) pasted into
    ``where``, the whole picture then scaled by ``gain`` (a change of light)."""
    out = np.asarray(frame, dtype=np.float64).copy()
    box = out[where.top:where.bottom, where.left:where.right]
    box[where.mask] = sample(patch, where.grid)[where.mask] * 255.0
    return np.clip(out * gain, 0.0, 255.0).round().astype(np.uint8)


__all__ = ["Footprint", "composite", "footprint", "homography", "project", "sample"]
