"""Apply a :class:`~fsvla.variation.vision.VisionPerturbation` to a rendering scene's look.

:class:`VisionApplier` works through :class:`fsvla.world.SceneAppearance` (``fsvla.sim``
implements it for SAPIEN: ``BuiltScene.appearance()``). It remembers how the scene looked
when it was made (ambient and light colours, the lights' poses, materials' base colours,
world-camera poses) so that each episode starts from V0 and applies its own perturbation:
``apply(p)`` restores, then changes the lights, repaints or textures materials, moves the
world-mounted cameras, adds visual-only occluders, and fixes the V4 patches to their
bodies as render-only quads (:mod:`fsvla.variation.patch` places them;
:attr:`VisionApplier.mounts` says where they are). The appearance touches no physics, so
an episode's state trace is the same at every V level.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from fsvla.compiler.pose import (
    look_along_quat,
    transform_points,
)
from fsvla.compiler.scene import SceneSpec
from fsvla.world import (
    Camera,
    Color,
    Light,
    Material,
    PoseReading,
    SceneAppearance,
    Undo,
    WorldPose,
)

from .patch import PatchMount, load_patch_image, mount_patch, patch_pixels
from .vision import CameraShift, Patch, VisionPerturbation

#: Pattern texture resolution (pixels per side) and world size of one repeat (m).
TEXTURE_PIXELS = 128
TEXTURE_PERIOD = 0.4
#: Where an occluder stands on the ray from the camera to its target (share of the way).
OCCLUDER_DEPTH = 0.35
#: An occluder's colour (RGBA) and thickness (m, along the camera's ray).
OCCLUDER_COLOR = (0.35, 0.33, 0.3, 1.0)
OCCLUDER_THICKNESS = 0.004


@dataclass
class _Original:
    ambient: Color
    lights: list[tuple[Light, Color, PoseReading]]
    materials: list[tuple[Material, Color]]
    cameras: list[tuple[Camera, PoseReading]]  # the world-mounted ones


class VisionApplier:
    """Applies perturbations to one scene's look; ``apply`` always starts from V0."""

    def __init__(self, appearance: SceneAppearance, spec: SceneSpec) -> None:
        self.appearance = appearance
        self.spec = spec
        cameras = [appearance.camera(c.name) for c in spec.cameras if c.parent == "world"]
        self._original = _Original(
            ambient=appearance.ambient,
            lights=[(light, light.color, light.pose) for light in appearance.lights()],
            materials=[(m, m.base_color) for name in appearance.names()
                       for m in appearance.materials(name)],
            cameras=[(camera, camera.pose) for camera in cameras],
        )
        self._undo: list[Undo] = []  # textures, occluders and patches, in the order added
        self.current = VisionPerturbation()
        #: Where the current perturbation's patches sit (one per patch, in its order).
        self.mounts: tuple[PatchMount, ...] = ()

    # ------------------------------------------------------------------ public
    def apply(self, perturbation: VisionPerturbation) -> None:
        self.restore()
        self._check_targets(perturbation)
        if perturbation.lighting is not None:
            self._light(perturbation)
        for recolor in perturbation.recolors:
            for material in self.appearance.materials(recolor.target):
                material.base_color = (*recolor.color, material.base_color[3])
        for texture in perturbation.textures:
            self._undo.append(self.appearance.paint(
                texture.target, pattern_image(texture.pattern, TEXTURE_PIXELS), TEXTURE_PERIOD))
        if perturbation.camera is not None:
            self._move_cameras(perturbation.camera)
        for occluder in perturbation.occluders:
            self._occlude(occluder.target, occluder.coverage)
        self.mounts = tuple(self._fix(patch) for patch in perturbation.patches)
        self.current = perturbation

    def restore(self) -> None:
        """Back to how the scene was made (V0)."""
        original = self._original
        self.appearance.ambient = original.ambient
        for light, color, pose in original.lights:
            light.color = color
            light.pose = pose
        for material, color in original.materials:
            material.base_color = color
        for camera, pose in original.cameras:
            camera.pose = pose
        for undo in reversed(self._undo):
            undo()
        self._undo = []
        self.current = VisionPerturbation()
        self.mounts = ()

    # ------------------------------------------------------------------ pieces
    def _check_targets(self, perturbation: VisionPerturbation) -> None:
        names = set(self.appearance.names())
        targets = [t.target for t in (*perturbation.recolors, *perturbation.textures,
                                      *perturbation.occluders, *perturbation.patches)]
        unknown = sorted({t for t in targets if t not in names})
        if unknown:
            raise ValueError(f"visual variation names {', '.join(unknown)}, which the scene "
                             f"{self.spec.scenario!r} does not have")

    def _light(self, perturbation: VisionPerturbation) -> None:
        lighting = perturbation.lighting
        assert lighting is not None
        factor = np.asarray(lighting.color) * lighting.intensity
        self.appearance.ambient = tuple(np.asarray(self._original.ambient) * factor)
        key_done = False
        for light, color, _ in self._original.lights:
            light.color = tuple(np.asarray(color) * factor)
            if lighting.direction is not None and not key_done and light.directional:
                light.pose = _facing(lighting.direction)
                key_done = True

    def _move_cameras(self, shift: CameraShift) -> None:
        """Each world camera, at its V0 pose, shifted by the offset and turned by the yaw
        and the pitch in its own frame."""
        for camera, _ in self._original.cameras:
            camera.move(shift.offset, shift.yaw, shift.pitch)

    def _occlude(self, target: str, coverage: float) -> None:
        centre, radius = self._extent(target)
        for camera, _ in self._original.cameras:
            eye = np.asarray(camera.pose.p)
            ray = centre - eye
            distance = float(np.linalg.norm(ray))
            if distance < 1e-6:
                continue
            at = eye + OCCLUDER_DEPTH * ray
            side = 2.0 * radius * OCCLUDER_DEPTH * math.sqrt(coverage)
            self._undo.append(self.appearance.add_occluder(
                target, _facing(ray, at), (OCCLUDER_THICKNESS / 2, side / 2, side / 2),
                OCCLUDER_COLOR))

    def _extent(self, target: str) -> tuple[NDArray[np.float64], float]:
        """World centre and radius of the target's bounds (at its spec pose)."""
        body = next((b for b in self.spec.bodies if b.name == target), None)
        if body is not None:
            bounds = body.asset.bounds
            centre = transform_points([bounds.center], body.pose.position, body.pose.quaternion)[0]
            return centre, float(np.linalg.norm(bounds.half_extents))
        zone = self.spec.zone(target)
        lo, hi = np.asarray(zone.region_bounds.min), np.asarray(zone.region_bounds.max)
        return (lo + hi) / 2.0, float(np.linalg.norm(hi - lo) / 2.0)

    def _fix(self, patch: Patch) -> PatchMount:
        mount = mount_patch(self.spec, patch)
        pixels = (load_patch_image(patch.image) if patch.image is not None
                  else patch_pixels(patch.seed))
        self._undo.append(self.appearance.add_patch(mount.body, np.asarray(mount.corners),
                                                    pixels))
        return mount


def pattern_image(pattern: str, size: int) -> NDArray[np.uint8]:
    """An RGBA texture of ``pattern`` (wood, checker, marble, noise, stripes), deterministic."""
    y, x = np.mgrid[0:size, 0:size].astype(np.float64) / size
    rng = np.random.default_rng(size)
    if pattern == "checker":
        value = ((np.floor(x * 4) + np.floor(y * 4)) % 2)
        rgb = np.stack([0.15 + 0.7 * value] * 3, axis=-1)
    elif pattern == "stripes":
        value = (np.floor(x * 8) % 2)
        rgb = np.stack([0.2 + 0.6 * value, 0.2 + 0.3 * value, 0.2 + 0.1 * value], axis=-1)
    elif pattern == "wood":
        grain = 0.5 + 0.5 * np.sin(2 * np.pi * (y * 5 + 0.3 * np.sin(2 * np.pi * x * 3)))
        rgb = np.stack([0.45 + 0.25 * grain, 0.28 + 0.15 * grain, 0.12 + 0.06 * grain], axis=-1)
    elif pattern == "marble":
        vein = 0.5 + 0.5 * np.sin(2 * np.pi * (x * 3 + 2 * y) + 3 * rng.random((size, size)))
        rgb = np.stack([0.75 + 0.2 * vein] * 3, axis=-1)
    elif pattern == "noise":
        rgb = rng.random((size, size, 3))
    else:
        raise ValueError(f"unknown pattern {pattern!r}")
    alpha = np.ones((size, size, 1))
    return (np.concatenate([rgb, alpha], axis=-1) * 255).astype(np.uint8)


def _facing(direction: Sequence[float], at: Sequence[float] = (0.0, 0.0, 0.0)) -> WorldPose:
    """The pose at ``at`` whose +x points along ``direction`` (a directional light's, an
    occluder's), its +z as near up as it can be (+x when ``direction`` is near vertical)."""
    d = np.asarray(direction, dtype=np.float64)
    d = d / (np.linalg.norm(d) or 1.0)
    up = (0.0, 0.0, 1.0) if abs(d[2]) < 0.99 else (1.0, 0.0, 0.0)
    return WorldPose(np.asarray(at, dtype=np.float64), np.asarray(look_along_quat(d, up)))


__all__ = ["VisionApplier", "pattern_image"]
