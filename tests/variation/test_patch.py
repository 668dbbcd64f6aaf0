"""Where a V4 patch sits (:func:`mount_patch`, :func:`patch_corners`), what it shows
(:func:`patch_pixels`, :func:`load_patch_image`), with no simulator."""

from __future__ import annotations

import numpy as np
import pytest
from fsvla.compiler.pose import yaw_quat
from fsvla.compiler.scene import lower_scene

from fsvla.library import load_scenario
from fsvla.variation.patch import (
    BESIDE_GAP,
    PATCH_LIFT,
    PATCH_PATTERNS,
    PatchFileError,
    load_patch_image,
    mount_patch,
    patch_corners,
    patch_pixels,
)
from fsvla.variation.vision import PATCH_SIZE, Patch
from fsvla.world import WorldPose


@pytest.fixture(scope="module")
def mug():
    spec = lower_scene(load_scenario("move_mug_past_hot_plate"))
    body = next(b for b in spec.bodies if b.name == "mug")
    eye = np.asarray(next(c for c in spec.cameras if c.name == "front").pose.position)
    return spec, body, eye


def _side_lengths(corners: np.ndarray) -> list[float]:
    return [float(np.linalg.norm(corners[i] - corners[i - 1])) for i in range(4)]


def _normal(corners: np.ndarray) -> np.ndarray:
    n = np.cross(corners[1] - corners[0], corners[0] - corners[3])
    return n / np.linalg.norm(n)


def test_front_stands_on_the_base_facing_the_front_camera(mug) -> None:
    spec, body, eye = mug
    mount = mount_patch(spec, Patch(target="mug", seed=0))
    corners = patch_corners(mount)
    assert mount.body == "mug"
    assert _side_lengths(corners) == pytest.approx([PATCH_SIZE] * 4)
    assert _normal(corners)[2] == pytest.approx(0.0)  # upright
    assert _normal(corners) @ (eye - corners.mean(axis=0)) > 0  # its front towards the camera
    assert corners[:, 2].min() == pytest.approx(body.pose.position[2])  # standing on the base
    assert corners[0][2] > corners[3][2]  # image top up


def test_top_lies_on_the_top_its_image_top_away_from_the_camera(mug) -> None:
    spec, body, eye = mug
    corners = patch_corners(mount_patch(spec, Patch(target="mug", seed=0, face="top")))
    bounds = body.asset.bounds
    assert corners[:, 2] == pytest.approx([bounds.center[2] + bounds.half_extents[2] + PATCH_LIFT] * 4)
    assert _normal(corners) == pytest.approx([0.0, 0.0, 1.0])
    top_edge, bottom_edge = (corners[0] + corners[1]) / 2, (corners[2] + corners[3]) / 2
    assert np.linalg.norm(top_edge - eye) > np.linalg.norm(bottom_edge - eye)


def test_beside_lies_on_the_table_next_to_a_hazard() -> None:
    spec = lower_scene(load_scenario("move_mug_past_hot_plate"))
    mount = mount_patch(spec, Patch(target="burner", seed=0, face="beside", size=0.1))
    corners = patch_corners(mount)
    assert mount.body == "table"
    assert corners[:, 2] == pytest.approx([PATCH_LIFT] * 4)  # on the table top, world z = 0
    footprint = next(z for z in spec.zones if z.name == "burner").marker.footprint
    assert corners[:, 0].min() == pytest.approx(footprint.max_xy[0] + BESIDE_GAP)  # camera at +x
    assert _normal(corners) == pytest.approx([0.0, 0.0, 1.0])


def test_corners_follow_the_body(mug) -> None:
    spec, body, _ = mug
    mount = mount_patch(spec, Patch(target="mug", seed=0))
    at_layout = patch_corners(mount)
    same = WorldPose(np.asarray(body.pose.position), np.asarray(body.pose.quaternion))
    assert patch_corners(mount, same) == pytest.approx(at_layout)
    lifted = WorldPose(np.asarray(body.pose.position) + [0.0, 0.0, 0.1], np.asarray(body.pose.quaternion))
    assert patch_corners(mount, lifted) == pytest.approx(at_layout + [0.0, 0.0, 0.1])
    turned = WorldPose(np.asarray(body.pose.position), np.asarray(yaw_quat(np.pi)))
    moved = patch_corners(mount, turned) - np.asarray(body.pose.position)
    assert moved[:, :2] == pytest.approx(-(at_layout - np.asarray(body.pose.position))[:, :2],
                                         abs=1e-6)  # half a turn about the body's z


def test_an_unknown_target_or_nothing_to_lie_on_is_refused(mug) -> None:
    spec, _, _ = mug
    with pytest.raises(ValueError, match="no body or zone of that name"):
        mount_patch(spec, Patch(target="gripper", seed=0))
    with pytest.raises(ValueError, match="stands on the floor"):
        mount_patch(spec, Patch(target="table", seed=0, face="beside"))


def test_pixels_are_seeded_saturated_and_varied() -> None:
    first = patch_pixels(7)
    assert first.shape == (128, 128, 3) and first.dtype == np.uint8
    assert np.array_equal(first, patch_pixels(7))
    assert set(np.unique(first)) <= {0, 255}  # saturated colours only
    assert len({tuple(c) for c in first.reshape(-1, 3)}) >= 2
    assert not np.array_equal(first, patch_pixels(8))
    assert patch_pixels(3, 40).shape == (40, 40, 3)
    rng_patterns = {PATCH_PATTERNS[int(np.random.default_rng(s).integers(len(PATCH_PATTERNS)))]
                    for s in range(40)}
    assert rng_patterns == set(PATCH_PATTERNS)


def test_a_patch_file_must_be_a_png(tmp_path) -> None:
    from PIL import Image

    rgba = np.zeros((8, 12, 4), dtype=np.uint8)
    rgba[..., 0], rgba[..., 3] = 200, 10
    Image.fromarray(rgba).save(tmp_path / "p.png")
    pixels = load_patch_image(tmp_path / "p.png")
    assert pixels.shape == (8, 12, 3) and (pixels[..., 0] == 200).all()
    with pytest.raises(PatchFileError, match="missing.png: no such file"):
        load_patch_image(tmp_path / "missing.png")
    Image.fromarray(rgba[..., :3]).save(tmp_path / "p.jpg")
    with pytest.raises(PatchFileError, match=r"p\.jpg: not a PNG image \(JPEG\)"):
        load_patch_image(tmp_path / "p.jpg")
    (tmp_path / "text.png").write_text("not an image")
    with pytest.raises(PatchFileError, match="text.png: not a PNG image"):
        load_patch_image(tmp_path / "text.png")
