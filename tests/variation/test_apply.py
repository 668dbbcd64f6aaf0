"""VisionApplier over the simulator seam: a fake :class:`fsvla.world.SceneAppearance` that
records every change proves what ``apply`` changes and that ``restore`` returns to V0,
with no simulator."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pytest
from fsvla.compiler.pose import axis_angle_quat, quat_mul, quat_to_matrix, yaw_quat
from fsvla.compiler.scene import lower_scene

from fsvla.library import load_scenario
from fsvla.variation.apply import (
    OCCLUDER_DEPTH,
    TEXTURE_PERIOD,
    TEXTURE_PIXELS,
    VisionApplier,
    pattern_image,
)
from fsvla.variation.patch import mount_patch, patch_pixels
from fsvla.variation.vision import perturbation_for
from fsvla.world import Color, PoseReading, Undo, WorldPose


@dataclass
class FakeLight:
    directional: bool
    color: Color
    pose: PoseReading


@dataclass
class FakeMaterial:
    base_color: Color


@dataclass
class FakeCamera:
    pose: PoseReading
    width: int = 320
    height: int = 240
    focal: float = 300.0

    def move(self, offset, yaw: float, pitch: float) -> None:
        turn = quat_mul(yaw_quat(yaw), axis_angle_quat((0.0, 1.0, 0.0), pitch))
        self.pose = WorldPose(np.asarray(self.pose.p) + offset, np.asarray(quat_mul(self.pose.q, turn)))

    def intrinsic(self) -> np.ndarray:
        return np.array([[self.focal, 0.0, self.width / 2], [0.0, self.focal, self.height / 2],
                         [0.0, 0.0, 1.0]])

    def extrinsic(self) -> np.ndarray:
        """World to OpenCV camera (x right, y down, z forward) of a camera looking along +x."""
        R = quat_to_matrix(self.pose.q)
        to_cv = np.array([[0.0, -1.0, 0.0], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0]])
        rotation = to_cv @ R.T
        return np.column_stack([rotation, -rotation @ np.asarray(self.pose.p)])


@dataclass
class FakeAppearance:
    """Lights, materials and cameras as plain values; paint and occluders recorded."""

    body_names: list[str]
    cameras: dict[str, FakeCamera]
    ambient: Color = (0.3, 0.3, 0.3)
    light_list: list[FakeLight] = field(default_factory=lambda: [
        FakeLight(True, (1.0, 1.0, 1.0), WorldPose(np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0]))),
        FakeLight(False, (0.5, 0.5, 0.5), WorldPose(np.array([0.0, 0.0, 2.0]),
                                                    np.array([1.0, 0.0, 0.0, 0.0]))),
    ])
    looks: dict[str, list[FakeMaterial]] = field(default_factory=dict)
    painted: dict[str, tuple[np.ndarray, float]] = field(default_factory=dict)
    occluders: list[tuple[str, PoseReading, tuple[float, ...], Color]] = field(default_factory=list)
    patches: list[tuple[str, np.ndarray, np.ndarray]] = field(default_factory=list)
    calls: list[str] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.looks = {n: [FakeMaterial((0.5, 0.5, 0.5, 1.0)), FakeMaterial((0.2, 0.4, 0.6, 0.8))]
                      for n in self.body_names}

    def names(self) -> list[str]:
        return list(self.body_names)

    def lights(self) -> list[FakeLight]:
        return self.light_list

    def materials(self, name: str) -> list[FakeMaterial]:
        return self.looks[name]

    def camera(self, name: str) -> FakeCamera:
        return self.cameras[name]

    def paint(self, name: str, texture: np.ndarray, period: float) -> Undo:
        self.calls.append(f"paint {name}")
        self.painted[name] = (texture, period)

        def undo() -> None:
            self.calls.append(f"unpaint {name}")
            del self.painted[name]
        return undo

    def add_occluder(self, name: str, pose: PoseReading, half_size, color: Color) -> Undo:
        self.calls.append(f"occlude {name}")
        entry = (name, pose, tuple(half_size), color)
        self.occluders.append(entry)

        def undo() -> None:
            self.calls.append(f"unocclude {name}")
            self.occluders.remove(entry)
        return undo

    def add_patch(self, name: str, corners: np.ndarray, image: np.ndarray) -> Undo:
        self.calls.append(f"patch {name}")
        entry = (name, np.asarray(corners), np.asarray(image))
        self.patches.append(entry)

        def undo() -> None:
            self.calls.append(f"unpatch {name}")
            self.patches.remove(entry)
        return undo

    def snapshot(self) -> tuple:
        """Everything a picture depends on, as plain values."""
        return (tuple(self.ambient),
                [(tuple(lt.color), tuple(lt.pose.p), tuple(lt.pose.q)) for lt in self.light_list],
                {n: [tuple(m.base_color) for m in ms] for n, ms in self.looks.items()},
                {n: (tuple(c.pose.p), tuple(c.pose.q)) for n, c in self.cameras.items()},
                sorted(self.painted),
                [(n, tuple(pose.p), tuple(pose.q), half, color)
                 for n, pose, half, color in self.occluders],
                [(n, c.tobytes(), i.tobytes()) for n, c, i in self.patches])


@pytest.fixture
def stove():
    scenario = load_scenario("lift_pot_beside_stove")
    spec = lower_scene(scenario)
    cameras = {c.name: FakeCamera(WorldPose(np.asarray(c.pose.position, dtype=np.float64),
                                            np.asarray(c.pose.quaternion, dtype=np.float64)))
               for c in spec.cameras}
    names = [b.name for b in spec.bodies] + [z.name for z in spec.zones]
    return scenario, spec, FakeAppearance(names, cameras)


def test_apply_then_restore_returns_to_v0(stove) -> None:
    scenario, spec, look = stove
    applier = VisionApplier(look, spec)
    v0 = look.snapshot()
    applier.apply(perturbation_for(scenario, "V4", 3))
    assert look.snapshot() != v0
    applier.restore()
    assert look.snapshot() == v0
    cameras = len(_world_cameras(spec))
    assert look.calls == ["paint table", *["occlude stove"] * cameras, "patch pot",
                          "unpatch pot", *["unocclude stove"] * cameras, "unpaint table"]


def test_each_apply_starts_from_v0(stove) -> None:
    scenario, spec, look = stove
    applier = VisionApplier(look, spec)
    p = perturbation_for(scenario, "V4", 3)
    applier.apply(p)
    once = look.snapshot()
    applier.apply(p)
    assert look.snapshot() == once  # nothing compounds: no brighter, no second occluder
    applier.apply(perturbation_for(scenario, "V0", 3))
    applier.apply(p)
    assert look.snapshot() == once


def test_what_v4_changes(stove) -> None:
    scenario, spec, look = stove
    applier = VisionApplier(look, spec)
    before = look.snapshot()
    p = perturbation_for(scenario, "V4", 3)
    applier.apply(p)
    factor = np.asarray(p.lighting.color) * p.lighting.intensity
    assert look.ambient == pytest.approx(tuple(np.asarray(before[0]) * factor))
    assert look.light_list[1].color == pytest.approx(tuple(np.asarray(before[1][1][0]) * factor))
    if p.lighting.direction is not None:  # the key light shines along the direction
        key = quat_to_matrix(look.light_list[0].pose.q)[:, 0]
        direction = np.asarray(p.lighting.direction) / np.linalg.norm(p.lighting.direction)
        assert key == pytest.approx(direction)
    for recolor in p.recolors:  # RGB changed, alpha kept
        assert [m.base_color for m in look.looks[recolor.target]] == [
            (*recolor.color, 1.0), (*recolor.color, 0.8)]
    texture, period = look.painted["table"]
    assert np.array_equal(texture, pattern_image("wood", TEXTURE_PIXELS))
    assert period == TEXTURE_PERIOD
    for name in _world_cameras(spec):  # shifted, panned and tilted in its own frame
        (original, q0), moved = before[3][name], look.cameras[name].pose
        assert moved.p == pytest.approx(np.asarray(original) + np.asarray(p.camera.offset))
        turn = quat_to_matrix(q0).T @ quat_to_matrix(moved.q)
        assert turn == pytest.approx(quat_to_matrix(yaw_quat(p.camera.yaw))
                                     @ quat_to_matrix(axis_angle_quat((0, 1, 0), p.camera.pitch)))
    # one occluder per world camera, on its ray to the stove, its thin side along the ray
    assert len(look.occluders) == len(_world_cameras(spec))
    for (target, pose, half, _), name in zip(look.occluders, _world_cameras(spec)):
        eye = np.asarray(look.cameras[name].pose.p)
        assert target == "stove" and half[0] < half[1] == half[2]
        ray = np.asarray(pose.p) - eye
        facing = quat_to_matrix(pose.q)[:, 0]
        assert facing == pytest.approx(ray / np.linalg.norm(ray))
        zone = spec.zone("stove").region_bounds
        centre = (np.asarray(zone.min) + np.asarray(zone.max)) / 2
        assert np.linalg.norm(ray) == pytest.approx(OCCLUDER_DEPTH * np.linalg.norm(centre - eye))


def test_unknown_targets_are_refused(stove) -> None:
    scenario, spec, look = stove
    look.body_names.remove("pot")
    with pytest.raises(ValueError, match="names pot, which the scene"):
        VisionApplier(look, spec).apply(perturbation_for(scenario, "V2", 0))


def test_patches_are_fixed_to_their_body_with_seeded_pixels(stove) -> None:
    scenario, spec, look = stove
    applier = VisionApplier(look, spec)
    p = perturbation_for(scenario, "V4", 3)
    applier.apply(p)
    (patch,) = p.patches
    (mount,) = applier.mounts
    assert mount == mount_patch(spec, patch)
    (name, corners, image), = look.patches
    assert name == mount.body == "pot"
    assert np.array_equal(corners, np.asarray(mount.corners))
    assert np.array_equal(image, patch_pixels(patch.seed))
    applier.restore()
    assert applier.mounts == () and look.patches == []


def test_a_patch_file_gives_the_pixels(stove, tmp_path) -> None:
    from PIL import Image

    scenario, spec, look = stove
    pixels = np.zeros((20, 30, 3), dtype=np.uint8)
    pixels[:, :10] = (255, 0, 0)
    Image.fromarray(pixels).save(tmp_path / "patch.png")
    VisionApplier(look, spec).apply(perturbation_for(scenario, "V4", 3, str(tmp_path / "patch.png")))
    assert np.array_equal(look.patches[0][2], pixels)


def _world_cameras(spec) -> list[str]:
    return [c.name for c in spec.cameras if c.parent == "world"]
