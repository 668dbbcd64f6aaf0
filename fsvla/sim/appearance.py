"""The look of a built SAPIEN scene: :class:`SapienAppearance` implements
:class:`fsvla.world.SceneAppearance` over a :class:`~fsvla.sim.builder.BuiltScene` that
renders.

Lights, materials and cameras are wrapped as they are asked for; a change is written to
SAPIEN at once. :meth:`SapienAppearance.paint` swaps a body's render components for
copies whose meshes carry planar UVs and the texture (an uploaded mesh cannot take new
UVs), :meth:`SapienAppearance.add_occluder` adds an entity with a box visual and no
physics component, and :meth:`SapienAppearance.add_patch` adds a render component holding
one textured quad to the body's own entity (so it moves with the body; its front shows the
image, its back :data:`PATCH_BACK_COLOR`); each returns the function that takes its change
back. Nothing here touches a physics component. ``materials`` and ``paint`` leave a
patch's component alone.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from fsvla.compiler.pose import axis_angle_quat, yaw_quat
from fsvla.world import Color, PoseReading, Undo, WorldPose

if TYPE_CHECKING:
    from .builder import BuiltScene

#: An occluder's surface: matte, so that it hides what lies behind it without a highlight.
OCCLUDER_ROUGHNESS = 0.9
#: The name of a patch's render component, and the colour (RGBA) of the quad's back.
PATCH_COMPONENT = "fsvla_patch"
PATCH_BACK_COLOR = (0.85, 0.85, 0.85, 1.0)


def _pose(value: PoseReading) -> Any:
    import sapien

    return sapien.Pose(value.p, value.q)


class SapienLight:
    """A light component (directional or point)."""

    def __init__(self, component: Any) -> None:
        import sapien

        self._component = component
        self.directional = isinstance(component, sapien.render.RenderDirectionalLightComponent)

    @property
    def color(self) -> Color:
        return tuple(self._component.color)

    @color.setter
    def color(self, value: Color) -> None:
        self._component.color = list(value)

    @property
    def pose(self) -> PoseReading:
        pose = self._component.entity.pose
        return WorldPose(pose.p, pose.q)

    @pose.setter
    def pose(self, value: PoseReading) -> None:
        self._component.entity.pose = _pose(value)


class SapienMaterial:
    """A render material."""

    def __init__(self, material: Any) -> None:
        self._material = material

    @property
    def base_color(self) -> Color:
        return tuple(self._material.base_color)

    @base_color.setter
    def base_color(self, value: Color) -> None:
        self._material.base_color = list(value)


class SapienCamera:
    """A camera component; only one on its own entity (a world camera) can be moved."""

    def __init__(self, component: Any, on_world: bool) -> None:
        self._component = component
        self._on_world = on_world

    @property
    def pose(self) -> PoseReading:
        pose = self._component.entity.pose if self._on_world else self._component.global_pose
        return WorldPose(pose.p, pose.q)

    @pose.setter
    def pose(self, value: PoseReading) -> None:
        if not self._on_world:
            raise ValueError(f"camera {self._component.name!r} rides on an arm: it cannot be moved")
        self._component.entity.pose = _pose(value)

    def move(self, offset: Sequence[float], yaw: float, pitch: float) -> None:
        import sapien

        if not self._on_world:
            raise ValueError(f"camera {self._component.name!r} rides on an arm: it cannot be moved")
        turn = (sapien.Pose(q=list(yaw_quat(yaw)))
                * sapien.Pose(q=list(axis_angle_quat((0.0, 1.0, 0.0), pitch))))
        entity = self._component.entity
        pose = entity.pose
        entity.pose = sapien.Pose(np.asarray(pose.p) + np.asarray(offset), pose.q) * turn

    def intrinsic(self) -> NDArray[np.float64]:
        return np.asarray(self._component.get_intrinsic_matrix(), dtype=np.float64)

    def extrinsic(self) -> NDArray[np.float64]:
        return np.asarray(self._component.get_extrinsic_matrix(), dtype=np.float64)


class SapienAppearance:
    """:class:`fsvla.world.SceneAppearance` of a built scene (see the module doc)."""

    def __init__(self, built: BuiltScene) -> None:
        if not built.renders:
            raise ValueError("changing a scene's look needs a scene built with rendering")
        self.built = built

    @property
    def ambient(self) -> Color:
        return tuple(self.built.scene.ambient_light)

    @ambient.setter
    def ambient(self, value: Color) -> None:
        self.built.scene.ambient_light = list(value)

    def names(self) -> list[str]:
        return [*self.built.bodies, *self.built.articulations, *self.built.zones]

    def lights(self) -> list[SapienLight]:
        import sapien

        return [SapienLight(c) for e in self.built.scene.entities for c in e.components
                if isinstance(c, sapien.render.RenderLightComponent)]

    def materials(self, name: str) -> list[SapienMaterial]:
        import sapien

        found = []
        for entity in self._entities_of(name):
            for component in entity.components:
                if not _own(component):
                    continue
                for shape in component.render_shapes:
                    if isinstance(shape, sapien.render.RenderShapeTriangleMesh):
                        found += [SapienMaterial(part.material) for part in shape.parts]
                    else:
                        found.append(SapienMaterial(shape.material))
        return found

    def camera(self, name: str) -> SapienCamera:
        spec = next((c for c in self.built.spec.cameras if c.name == name), None)
        if spec is None or name not in self.built.cameras:
            raise KeyError(f"no camera {name!r}; cameras: {', '.join(self.built.cameras) or 'none'}")
        return SapienCamera(self.built.cameras[name], spec.parent == "world")

    def paint(self, name: str, texture: NDArray[np.uint8], period: float) -> Undo:
        import sapien

        image = sapien.render.RenderTexture2D(texture, "R8G8B8A8Unorm", srgb=True)
        swapped: list[tuple[Any, Any, Any]] = []  # entity, original, textured body
        for entity in self._entities_of(name):
            for component in list(entity.components):
                if not _own(component):
                    continue
                textured = sapien.render.RenderBodyComponent()
                for shape in component.render_shapes:
                    for copy in _textured_copies(shape, image, period):
                        textured.attach(copy)
                textured.name = component.name
                entity.remove_component(component)
                entity.add_component(textured)
                swapped.append((entity, component, textured))

        def undo() -> None:
            for entity, original, textured in reversed(swapped):
                entity.remove_component(textured)
                entity.add_component(original)
        return undo

    def add_occluder(self, name: str, pose: PoseReading, half_size: Sequence[float],
                     color: Color) -> Undo:
        import sapien

        scene = self.built.scene
        builder = scene.create_actor_builder()
        material = sapien.render.RenderMaterial(base_color=list(color), roughness=OCCLUDER_ROUGHNESS)
        builder.add_box_visual(half_size=list(half_size), material=material)
        occluder = builder.build_kinematic(name=f"occluder_{name}")
        # Kinematic bodies still collide: make it visual-only by dropping its physics.
        for component in list(occluder.components):
            if isinstance(component, sapien.physx.PhysxRigidBaseComponent):
                occluder.remove_component(component)
        occluder.pose = _pose(pose)
        return lambda: scene.remove_entity(occluder)

    def add_patch(self, name: str, corners: NDArray[np.floating],
                  image: NDArray[np.uint8]) -> Undo:
        import sapien

        entities = self._entities_of(name, root=True)
        if not entities:
            raise KeyError(f"no body or zone {name!r} to fix a patch to")
        entity = entities[0]
        c = np.asarray(corners, dtype=np.float32).reshape(4, 3)
        normal = np.cross(c[1] - c[0], c[0] - c[3])
        normal = normal / np.linalg.norm(normal)
        pixels = np.asarray(image, dtype=np.uint8)
        if pixels.shape[-1] == 3:
            pixels = np.concatenate([pixels, np.full((*pixels.shape[:2], 1), 255, np.uint8)], -1)
        front = sapien.render.RenderMaterial(base_color=[1.0, 1.0, 1.0, 1.0],
                                             roughness=OCCLUDER_ROUGHNESS)
        front.base_color_texture = sapien.render.RenderTexture2D(
            np.ascontiguousarray(pixels), "R8G8B8A8Unorm", srgb=True, address_mode="edge")
        back = sapien.render.RenderMaterial(base_color=list(PATCH_BACK_COLOR),
                                            roughness=OCCLUDER_ROUGHNESS)
        uvs = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=np.float32)
        component = sapien.render.RenderBodyComponent()
        component.name = PATCH_COMPONENT
        for triangles, n, material in (([[3, 2, 1], [3, 1, 0]], normal, front),
                                       ([[3, 1, 2], [3, 0, 1]], -normal, back)):
            component.attach(sapien.render.RenderShapeTriangleMesh(
                vertices=c, triangles=np.asarray(triangles, dtype=np.uint32),
                normals=np.tile(n, (4, 1)).astype(np.float32), uvs=uvs, material=material))
        entity.add_component(component)
        return lambda: entity.remove_component(component)

    def _entities_of(self, name: str, root: bool = False) -> list[Any]:
        built = self.built
        if name in built.bodies:
            return [built.bodies[name]]
        if name in built.articulations:
            articulation = built.articulations[name]
            return [link.entity for link in ([articulation.root] if root else articulation.links)]
        zone = built.zones.get(name)
        return [zone] if zone is not None else []


def _own(component: Any) -> bool:
    """Whether ``component`` is one of the scene's own visuals (a render body that is not a
    patch)."""
    import sapien

    return (isinstance(component, sapien.render.RenderBodyComponent)
            and component.name != PATCH_COMPONENT)


def _textured_copies(shape: Any, texture: Any, period: float) -> list[Any]:
    """Render meshes like ``shape``'s parts, with top-down planar UVs (one repeat per
    ``period`` metres) and ``texture``."""
    import sapien

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
            uvs=(vertices[:, :2] / period).astype(np.float32), material=material)
        copy.local_pose = shape.local_pose
        copy.name = shape.name
        copies.append(copy)
    return copies


__all__ = ["OCCLUDER_ROUGHNESS", "PATCH_BACK_COLOR", "PATCH_COMPONENT", "SapienAppearance",
           "SapienCamera", "SapienLight", "SapienMaterial"]
