"""Apply a :class:`~fsvla.variation.vision.VisionPerturbation` to a built, rendering scene.

:class:`VisionApplier` remembers how the scene looked when it was made (light colours,
the key light's pose, materials, head-camera poses) so that each episode starts from
V0 and applies its own perturbation: ``apply(p)`` restores, then changes the lights,
repaints or textures materials, moves the world-mounted cameras, and adds visual-only
occluders. Nothing here touches a physics component, so an episode's state trace is the
same at every V level. :meth:`VisionApplier.composite` pastes the V4 patches onto the
images a policy receives.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from fsvla.compiler.pose import axis_angle_quat, look_along_quat, yaw_quat
from fsvla.sim.builder import BuiltScene

from .vision import CameraShift, Patch, VisionPerturbation

#: Pattern texture resolution (pixels per side) and world size of one repeat (m).
TEXTURE_PIXELS = 128
TEXTURE_PERIOD = 0.4
#: Where an occluder stands on the ray from the camera to its target (share of the way).
OCCLUDER_DEPTH = 0.35


@dataclass
class _Original:
    ambient: tuple[float, ...]
    lights: list[tuple[Any, tuple[float, ...], Any]]  # component, colour, entity pose
    materials: list[tuple[Any, tuple[float, ...], Any]]  # material, base colour, texture
    cameras: list[tuple[Any, Any]]  # world camera entity, pose
    uvs: dict[int, NDArray[np.float32]] = field(default_factory=dict)


class VisionApplier:
    """Applies perturbations to one built scene; ``apply`` always starts from V0."""

    def __init__(self, built: BuiltScene) -> None:
        import sapien

        if not built.renders:
            raise ValueError("visual variation needs a scene built with rendering")
        self.built = built
        self._sapien = sapien
        scene = built.scene
        lights = [c for e in scene.entities for c in e.components
                  if isinstance(c, sapien.render.RenderLightComponent)]
        self._original = _Original(
            ambient=tuple(scene.ambient_light),
            lights=[(c, tuple(c.color), c.entity.pose) for c in lights],
            materials=[(m, tuple(m.base_color), m.base_color_texture)
                       for name in self._named_entities() for m in self._materials(name)],
            cameras=[(built.cameras[c.name].entity, built.cameras[c.name].entity.pose)
                     for c in built.spec.cameras if c.parent == "world" and c.name in built.cameras],
        )
        self._occluders: list[Any] = []
        self._swapped: list[tuple[Any, Any, Any]] = []  # entity, original, textured body
        self.current = VisionPerturbation()

    # ------------------------------------------------------------------ public
    def apply(self, perturbation: VisionPerturbation) -> None:
        self.restore()
        self._check_targets(perturbation)
        if perturbation.lighting is not None:
            self._light(perturbation)
        for recolor in perturbation.recolors:
            for material in self._materials(recolor.target):
                material.base_color = [*recolor.color, material.base_color[3]]
        for texture in perturbation.textures:
            self._texture(texture.target, texture.pattern)
        if perturbation.camera is not None:
            self._move_cameras(perturbation.camera)
        for occluder in perturbation.occluders:
            self._occlude(occluder.target, occluder.coverage)
        self.current = perturbation

    def restore(self) -> None:
        """Back to how the scene was built (V0)."""
        original = self._original
        self.built.scene.ambient_light = list(original.ambient)
        for component, color, pose in original.lights:
            component.color = list(color)
            component.entity.pose = pose
        for material, color, texture in original.materials:
            material.base_color = list(color)
            material.base_color_texture = texture
        for entity, pose in original.cameras:
            entity.pose = pose
        for entity in self._occluders:
            self.built.scene.remove_entity(entity)
        self._occluders = []
        for entity, original, textured in reversed(self._swapped):
            entity.remove_component(textured)
            entity.add_component(original)
        self._swapped = []
        self.current = VisionPerturbation()

    def composite(self, images: dict[str, NDArray[np.uint8]]) -> dict[str, NDArray[np.uint8]]:
        """``images`` with the current perturbation's patches pasted in (copies)."""
        if not self.current.patches:
            return images
        out = {}
        for name, image in images.items():
            picture = image.copy()
            for patch in self.current.patches:
                self._paste(picture, self.built.cameras[name], patch)
            out[name] = picture
        return out

    # ------------------------------------------------------------------ pieces
    def _named_entities(self) -> list[str]:
        return [*self.built.bodies, *self.built.articulations, *self.built.zones]

    def _entities_of(self, name: str) -> list[Any]:
        if name in self.built.bodies:
            return [self.built.bodies[name]]
        if name in self.built.articulations:
            return [link.entity for link in self.built.articulations[name].links]
        zone = self.built.zones.get(name)
        return [zone] if zone is not None else []

    def _materials(self, name: str) -> list[Any]:
        sapien = self._sapien
        found = []
        for entity in self._entities_of(name):
            for component in entity.components:
                if not isinstance(component, sapien.render.RenderBodyComponent):
                    continue
                for shape in component.render_shapes:
                    if isinstance(shape, sapien.render.RenderShapeTriangleMesh):
                        found += [part.material for part in shape.parts]
                    else:
                        found.append(shape.material)
        return found

    def _check_targets(self, perturbation: VisionPerturbation) -> None:
        names = set(self._named_entities())
        targets = [t.target for t in (*perturbation.recolors, *perturbation.textures,
                                      *perturbation.occluders, *perturbation.patches)]
        unknown = sorted({t for t in targets if t not in names})
        if unknown:
            raise ValueError(f"visual variation names {', '.join(unknown)}, which the scene "
                             f"{self.built.spec.scenario!r} does not have")

    def _light(self, perturbation: VisionPerturbation) -> None:
        lighting = perturbation.lighting
        assert lighting is not None
        factor = np.asarray(lighting.color) * lighting.intensity
        self.built.scene.ambient_light = list(np.asarray(self._original.ambient) * factor)
        key_done = False
        for component, color, _ in self._original.lights:
            component.color = list(np.asarray(color) * factor)
            if (lighting.direction is not None and not key_done
                    and isinstance(component, self._sapien.render.RenderDirectionalLightComponent)):
                component.entity.pose = _facing(self._sapien, lighting.direction)
                key_done = True

    def _texture(self, target: str, pattern: str) -> None:
        """Swap the target's render body for a copy whose meshes carry planar UVs and the
        pattern texture (uploaded meshes cannot take new UVs); ``restore`` swaps back."""
        sapien = self._sapien
        pixels = pattern_image(pattern, TEXTURE_PIXELS)
        texture = sapien.render.RenderTexture2D(pixels, "R8G8B8A8Unorm", srgb=True)
        for entity in self._entities_of(target):
            for component in list(entity.components):
                if not isinstance(component, sapien.render.RenderBodyComponent):
                    continue
                textured = sapien.render.RenderBodyComponent()
                for shape in component.render_shapes:
                    for copy in _textured_copies(sapien, shape, texture):
                        textured.attach(copy)
                textured.name = component.name
                entity.remove_component(component)
                entity.add_component(textured)
                self._swapped.append((entity, component, textured))

    def _move_cameras(self, shift: CameraShift) -> None:
        sapien = self._sapien
        turn = (sapien.Pose(q=list(yaw_quat(shift.yaw)))
                * sapien.Pose(q=list(axis_angle_quat((0.0, 1.0, 0.0), shift.pitch))))
        for entity, pose in self._original.cameras:
            moved = sapien.Pose(np.asarray(pose.p) + np.asarray(shift.offset), pose.q)
            entity.pose = moved * turn

    def _occlude(self, target: str, coverage: float) -> None:
        sapien = self._sapien
        centre, radius = self._extent(target)
        for entity, _ in self._original.cameras:
            eye = np.asarray(entity.pose.p)
            ray = centre - eye
            distance = float(np.linalg.norm(ray))
            if distance < 1e-6:
                continue
            at = eye + OCCLUDER_DEPTH * ray
            side = 2.0 * radius * OCCLUDER_DEPTH * math.sqrt(coverage)
            builder = self.built.scene.create_actor_builder()
            material = sapien.render.RenderMaterial(base_color=[0.35, 0.33, 0.3, 1.0], roughness=0.9)
            builder.add_box_visual(half_size=[0.002, side / 2, side / 2], material=material)
            occluder = builder.build_kinematic(name=f"occluder_{target}")
            # Kinematic bodies still collide: make it visual-only by dropping its physics.
            for component in list(occluder.components):
                if isinstance(component, sapien.physx.PhysxRigidBaseComponent):
                    occluder.remove_component(component)
            occluder.pose = _facing(sapien, ray, at)
            self._occluders.append(occluder)

    def _extent(self, target: str) -> tuple[NDArray[np.float64], float]:
        """World centre and radius of the target's bounds."""
        spec = self.built.spec
        body = next((b for b in spec.bodies if b.name == target), None)
        if body is not None:
            bounds = body.asset.bounds
            pose = self._sapien.Pose(list(body.pose.position), list(body.pose.quaternion))
            centre = np.asarray((pose * self._sapien.Pose(list(bounds.center))).p)
            return centre, float(np.linalg.norm(bounds.half_extents))
        zone = spec.zone(target)
        lo, hi = np.asarray(zone.region_bounds.min), np.asarray(zone.region_bounds.max)
        return (lo + hi) / 2.0, float(np.linalg.norm(hi - lo) / 2.0)

    def _paste(self, picture: NDArray[np.uint8], camera: Any, patch: Patch) -> None:
        centre, _ = self._extent(patch.target)
        extrinsic = np.asarray(camera.get_extrinsic_matrix(), dtype=np.float64)
        intrinsic = np.asarray(camera.get_intrinsic_matrix(), dtype=np.float64)
        point = extrinsic @ np.append(centre, 1.0)
        if point[2] <= 1e-6:
            return  # behind the camera
        u, v, _ = intrinsic @ (point / point[2])
        half = max(1, int(round(patch.size * intrinsic[0, 0] / point[2] / 2.0)))
        height, width = picture.shape[:2]
        x0, x1 = int(round(u)) - half, int(round(u)) + half
        y0, y1 = int(round(v)) - half, int(round(v)) + half
        cx0, cx1, cy0, cy1 = max(x0, 0), min(x1, width), max(y0, 0), min(y1, height)
        if cx0 >= cx1 or cy0 >= cy1:
            return
        pixels = patch_pixels(patch.seed, 2 * half)
        picture[cy0:cy1, cx0:cx1] = pixels[cy0 - y0:cy1 - y0, cx0 - x0:cx1 - x0]


def _textured_copies(sapien: Any, shape: Any, texture: Any) -> list[Any]:
    """Render meshes like ``shape``'s parts, with top-down planar UVs and ``texture``."""
    if not isinstance(shape, sapien.render.RenderShapeTriangleMesh):
        return [shape.clone()] if hasattr(shape, "clone") else []
    copies = []
    for part in shape.parts:
        vertices = np.asarray(part.vertices, dtype=np.float32)
        old = part.material
        material = sapien.render.RenderMaterial(
            base_color=[1.0, 1.0, 1.0, old.base_color[3]], roughness=old.roughness,
            metallic=old.metallic, emission=list(old.emission))
        material.base_color_texture = texture
        copy = sapien.render.RenderShapeTriangleMesh(
            vertices=vertices, triangles=np.asarray(part.triangles, dtype=np.uint32),
            normals=np.asarray(part.get_vertex_normal(), dtype=np.float32),
            uvs=(vertices[:, :2] / TEXTURE_PERIOD).astype(np.float32), material=material)
        copy.local_pose = shape.local_pose
        copy.name = shape.name
        copies.append(copy)
    return copies


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


def patch_pixels(seed: int, size: int) -> NDArray[np.uint8]:
    """A high-contrast square of random saturated blocks: the V4 patch."""
    rng = np.random.default_rng(seed)
    blocks = rng.integers(0, 2, size=(8, 8, 3)).astype(np.uint8) * 255
    repeat = max(1, -(-size // 8))
    return np.kron(blocks, np.ones((repeat, repeat, 1), dtype=np.uint8))[:size, :size]


def _facing(sapien: Any, direction: Sequence[float], at: Sequence[float] = (0.0, 0.0, 0.0)) -> Any:
    """The pose at ``at`` whose +x points along ``direction`` (a directional light's, an
    occluder's), its +z as near up as it can be (+x when ``direction`` is near vertical)."""
    d = np.asarray(direction, dtype=np.float64)
    d = d / (np.linalg.norm(d) or 1.0)
    up = (0.0, 0.0, 1.0) if abs(d[2]) < 0.99 else (1.0, 0.0, 0.0)
    return sapien.Pose(np.asarray(at, dtype=np.float64), list(look_along_quat(d, up)))


__all__ = ["VisionApplier", "patch_pixels", "pattern_image"]
