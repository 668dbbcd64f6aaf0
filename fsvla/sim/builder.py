"""Build a SAPIEN scene from a :class:`~fsvla.compiler.scene.SceneSpec`.

``build(spec)`` makes a scene with:

- the floor (a static plane) at ``spec.ground_z``;
- every :class:`SceneBody`: rigid assets as one entity each (PhysX shapes with the
  asset's material, mass, centre of mass and principal inertia; static when
  ``is_static``), articulated assets through SAPIEN's URDF loader (fixed base when
  ``is_static``, scaled, root at the body pose, joints at 0 with a little damping);
- every zone: its marker as a visual-only static entity, corridor walls as static
  collision;
- the embodiment's robots (``fsvla.sim.robot.load_robot``) at their mounts, at home;
- when rendering: visuals, the spec's cameras (world or on an arm's ee link) and lights.

Physics: the spec's gravity and timestep; every dynamic body gets
:data:`SOLVER_ITERATIONS`. :meth:`BuiltScene.step` feeds the robots' passive forces
forward before each physics step, so a robot holds its drive targets.
"""

from __future__ import annotations

import contextlib
import tempfile
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from fsvla.compiler.assets.model import Appearance, ArticulatedAsset, RigidAsset, ZoneAsset
from fsvla.compiler.scene import PhysicsSpec, SceneBody, SceneSpec, SceneZone
from fsvla.world import WorldPose

from .appearance import SapienAppearance
from .kinematics import ArmKinematics
from .render import (
    DEFAULT_SHADER,
    RenderUnavailable,
    add_lights,
    check_shader,
    create_render_system,
    mount_camera,
    picture_rgb,
)
from .robot import LoadedRobot, load_robot
from .shapes import collision_shapes, physx_material, sapien_pose, shapes_of_sapien, visual_shapes
from .urdf import prepare_urdf

if TYPE_CHECKING:
    from fsvla.compiler.assets.model import Shape
    from fsvla.monitor.contacts import ContactFilter

    from .probe import Probe

#: PhysX solver iterations (position, velocity) of each free rigid body: SAPIEN's
#: defaults, set per body so that a changed global body config cannot alter a scene.
SOLVER_ITERATIONS = (10, 1)
#: Viscous damping (N·s/m or N·m·s/rad) of an articulated asset's passive joints.
PASSIVE_JOINT_DAMPING = 0.5
#: Floor colour (RGBA) when rendering.
FLOOR_COLOR = (0.55, 0.55, 0.52, 1.0)


@dataclass
class BuiltScene:
    """A SceneSpec built in SAPIEN; names are the spec's. It is the SAPIEN back-end's
    :class:`fsvla.world.MonitoredScene` and :class:`fsvla.world.SceneState`, and
    :meth:`appearance` its :class:`fsvla.world.SceneAppearance`."""

    spec: SceneSpec
    scene: Any  # sapien.Scene
    bodies: dict[str, Any]  # rigid SceneBodies: name -> sapien.Entity
    articulations: dict[str, Any]  # articulated SceneBodies: name -> PhysxArticulation
    robot: LoadedRobot
    cameras: dict[str, Any] = field(default_factory=dict)  # name -> RenderCameraComponent
    zones: dict[str, Any] = field(default_factory=dict)  # zone name -> marker/walls entity
    ground: Any = None
    _frame_components: dict[str, Any] = field(default_factory=dict, init=False, repr=False,
                                              compare=False)

    @property
    def renders(self) -> bool:
        """Whether the scene has a render system."""
        return _has_render(self.scene)

    def reset(self) -> None:
        """Bodies back to their spec poses at rest, articulated joints at their start, robots home."""
        for body in self.spec.bodies:
            if body.name in self.bodies:
                entity = self.bodies[body.name]
                entity.pose = sapien_pose(body.pose)
                rigid = _rigid_component(entity)
                if not body.is_static and rigid is not None:
                    rigid.linear_velocity = np.zeros(3)
                    rigid.angular_velocity = np.zeros(3)
            else:
                articulation = self.articulations[body.name]
                articulation.set_root_pose(sapien_pose(body.pose))
                articulation.set_qpos(start_qpos(articulation, body.asset))
                articulation.set_qvel(np.zeros(articulation.dof, dtype=np.float32))
                if not body.is_static:
                    articulation.set_root_linear_velocity(np.zeros(3))
                    articulation.set_root_angular_velocity(np.zeros(3))
        _place_robots(self.robot, self.spec)
        self.robot.reset_home()

    def step(self, n: int = 1) -> None:
        """``n`` physics steps, each after the robots' gravity feed-forward."""
        if n < 0:
            raise ValueError(f"expected a non-negative number of steps, got {n}")
        for _ in range(n):
            self.robot.compensate_gravity()
            self.scene.step()

    def render_views(self, names: Sequence[str] | None = None) -> dict[str, NDArray[np.uint8]]:
        """HWC uint8 RGB pictures of the named cameras (all when None)."""
        if not self.renders:
            raise RenderUnavailable("the scene was built without a render system (render=False)")
        chosen = list(self.cameras) if names is None else list(names)
        unknown = [n for n in chosen if n not in self.cameras]
        if unknown:
            raise KeyError(f"no camera {', '.join(map(repr, unknown))}; cameras: "
                           f"{', '.join(self.cameras) or 'none'}")
        self.scene.update_render()
        views = {}
        for name in chosen:
            self.cameras[name].take_picture()
            views[name] = picture_rgb(self.cameras[name])
        return views

    def state(self) -> NDArray[np.float64]:
        """Poses and velocities of every body, articulation and robot, as one vector
        (for determinism checks)."""
        parts: list[NDArray[np.float64]] = []
        for entity in self.bodies.values():
            pose = entity.pose
            parts += [np.asarray(pose.p, dtype=np.float64), np.asarray(pose.q, dtype=np.float64)]
        for articulation in [*self.articulations.values(), *self.robot.articulations.values()]:
            parts += [np.asarray(articulation.get_qpos(), dtype=np.float64),
                      np.asarray(articulation.get_qvel(), dtype=np.float64)]
        return np.concatenate(parts) if parts else np.zeros(0)

    # --- fsvla.world.SceneState: what the experts read ------------------------------------
    def body_pose(self, body: str) -> WorldPose:
        pose = (self.bodies[body].pose if body in self.bodies
                else self.articulations[body].get_root_pose())
        return WorldPose(pose.p, pose.q)

    def link_pose(self, body: str, link: str) -> WorldPose:
        found = next(lk for lk in self.articulations[body].get_links() if lk.name == link)
        pose = found.entity_pose
        return WorldPose(pose.p, pose.q)

    def joint_position(self, body: str, joint: str) -> float:
        articulation = self.articulations[body]
        index = [j.name for j in articulation.get_active_joints()].index(joint)
        return float(articulation.get_qpos()[index])

    def arm_joints(self, arm: str) -> NDArray[np.float64]:
        return self.robot.arm(arm).qpos()

    def gripper_opening(self, arm: str) -> float:
        return self.robot.arm(arm).gripper_opening()

    def tcp_pose(self, arm: str) -> WorldPose:
        pose = self.robot.arm(arm).tcp_pose()
        return WorldPose(pose.p, pose.q)

    def robot_link_pose(self, arm: str, link: str) -> WorldPose:
        found = next(lk for lk in self.robot.arm(arm).articulation.links if lk.name == link)
        pose = found.entity_pose
        return WorldPose(pose.p, pose.q)

    def arm_model(self, arm: str) -> ArmKinematics:
        return ArmKinematics(self.robot.arm(arm))

    def contact_force(self, arm: str, links: Sequence[str], other: str | None = None) -> float:
        mine = {link: link.name for link in self.robot.arm(arm).articulation.links
                if link.name in links}
        robot = {link for articulation in self.robot.articulations.values()
                 for link in articulation.links}
        source = self._components_of(other)
        totals: dict[str, NDArray[np.float64]] = {}
        for contact in self.scene.get_contacts():
            b0, b1 = contact.bodies
            for link, far, sign in ((b0, b1, 1.0), (b1, b0, -1.0)):  # impulses act on b0
                if link in mine and far not in robot and (source is None or far in source):
                    total = totals.setdefault(mine[link], np.zeros(3))
                    for point in contact.points:
                        total += sign * np.asarray(point.impulse, dtype=np.float64)
        inv_dt = 1.0 / self.spec.physics.timestep
        return max((float(np.linalg.norm(t)) * inv_dt for t in totals.values()), default=0.0)

    def contact_gap(self, arm: str, links: Sequence[str], other: str) -> float | None:
        mine = {link for link in self.robot.arm(arm).articulation.links if link.name in links}
        source = self._components_of(other) or set()
        gaps = [float(point.separation) for contact in self.scene.get_contacts()
                if (contact.bodies[0] in mine and contact.bodies[1] in source)
                or (contact.bodies[1] in mine and contact.bodies[0] in source)
                for point in contact.points]
        return min(gaps, default=None)

    def _components_of(self, body: str | None) -> set[Any] | None:
        """The physics components of the scene body or articulation ``body`` (None: any)."""
        if body in self.bodies:
            return {_rigid_component(self.bodies[body])}
        if body is not None:
            return set(self.articulations[body].links)
        return None

    # --- fsvla.world.MonitoredScene: what the safety monitor reads -------------------------
    def frames(self) -> list[str]:
        return list(self._components())

    def frame_shapes(self, frame: str) -> list[Shape]:
        return shapes_of_sapien(self._components()[frame])

    def probe(self, timestep: float, *, pose_frames: Sequence[str], free_bodies: Sequence[str],
              torque_frames: Sequence[str], scan: ContactFilter, last: ContactFilter,
              joints: Mapping[str, tuple[str, str]],
              gravity: tuple[float, float, float]) -> Probe:
        from .probe import Probe

        indices = {}  # state name -> (articulation, index in its qpos)
        for name, (body, joint) in joints.items():
            articulation = self.articulations.get(body)
            names = [j.name for j in articulation.active_joints] if articulation is not None else []
            if joint in names:
                indices[name] = (articulation, names.index(joint))
        return Probe(self.scene, timestep, self._components(), pose_frames=pose_frames,
                     free_bodies=free_bodies, torque_frames=torque_frames, scan=scan, last=last,
                     joints=indices, gravity=gravity)

    def _components(self) -> dict[str, Any]:
        """Frame name -> SAPIEN rigid component or link (made once: the parts are fixed)."""
        if not self._frame_components:
            from .probe import components_of

            self._frame_components = components_of(self.bodies, self.articulations,
                                                   self.robot.articulations)
        return self._frame_components

    # --- fsvla.world.SceneAppearance: what the visual variation changes ---------------------
    def appearance(self) -> SapienAppearance:
        """The scene's look (``ValueError`` for a scene built without rendering)."""
        return SapienAppearance(self)


def build(spec: SceneSpec, *, render: bool | None = None, shader: str = DEFAULT_SHADER,
          shadows: bool | None = None) -> BuiltScene:
    """Build ``spec`` in a new SAPIEN scene.

    ``render`` None: with a render system when a Vulkan device exists, physics only
    otherwise; False: physics only; True: rendering, or :class:`RenderUnavailable`.
    ``shader`` is the cameras' shader (``minimal``, ``default``, ``rt``). ``shadows``
    None keeps the lights' shadow flags except with ``minimal`` (a shadow pass costs
    about 3x the frame time on lavapipe); False drops them, True keeps them."""
    check_shader(shader)
    scene = _new_scene(spec.physics, render)
    renders = _has_render(scene)
    with _shape_config(spec.physics):  # every collision shape is made in here
        ground = scene.add_ground(spec.ground_z, render=renders,
                                  render_material=_floor_material() if renders else None)
        bodies: dict[str, Any] = {}
        articulations: dict[str, Any] = {}
        with tempfile.TemporaryDirectory(prefix="fsvla-scene-") as tmp:
            for body in spec.bodies:
                if isinstance(body.asset, RigidAsset):
                    bodies[body.name] = _build_rigid(scene, body, body.asset, renders)
                else:
                    articulations[body.name] = _build_articulated(scene, body, body.asset,
                                                                  Path(tmp), renders)
        zones = {zone.name: entity for zone in spec.zones
                 if (entity := _build_zone(scene, zone, zone.marker, renders)) is not None}
        robot = load_robot(scene, spec.embodiment)
    _place_robots(robot, spec)
    robot.reset_home()
    cameras: dict[str, Any] = {}
    if renders:
        add_lights(scene, spec.lights,
                   shadows=shader != "minimal" if shadows is None else shadows)
        links = {name: arm.ee_link for name, arm in robot.arms.items()}
        cameras = {c.name: mount_camera(scene, c, shader, links) for c in spec.cameras}
    return BuiltScene(spec=spec, scene=scene, bodies=bodies, articulations=articulations,
                      robot=robot, cameras=cameras, zones=zones, ground=ground)


# --- the scene ------------------------------------------------------------------------------


@contextlib.contextmanager
def _global_config(get: Callable[[], Any], put: Callable[[Any], None],
                   **values: Any) -> Iterator[None]:
    """SAPIEN reads some settings from global configs when it makes a thing: set
    ``values`` on the config ``get`` returns for that time, then ``put`` back the previous."""
    previous, config = get(), get()
    for name, value in values.items():
        setattr(config, name, value)
    put(config)
    try:
        yield
    finally:
        put(previous)


def _scene_config(physics: PhysicsSpec) -> contextlib.AbstractContextManager[None]:
    """Gravity, read from the global scene config when a PhysX system is made."""
    import sapien

    return _global_config(sapien.physx.get_scene_config, sapien.physx.set_scene_config,
                          gravity=np.asarray(physics.gravity, dtype=np.float32))


def _shape_config(physics: PhysicsSpec) -> contextlib.AbstractContextManager[None]:
    """The contact offset, read from the global shape config when a collision shape is made."""
    import sapien

    return _global_config(sapien.physx.get_shape_config, sapien.physx.set_shape_config,
                          contact_offset=physics.contact_offset)


def _new_scene(physics: PhysicsSpec, render: bool | None) -> Any:
    import sapien

    render_system = None
    if render is not False:
        try:
            render_system = create_render_system()
        except RenderUnavailable:
            if render:
                raise
    with _scene_config(physics):
        systems = [sapien.physx.PhysxCpuSystem()]
    if render_system is not None:
        systems.append(render_system)
    scene = sapien.Scene(systems)
    scene.set_timestep(physics.timestep)
    return scene


def _has_render(scene: Any) -> bool:
    try:
        scene.get_system("render")
    except (RuntimeError, KeyError, IndexError):
        return False
    return True


def _floor_material() -> Any:
    import sapien

    return sapien.render.RenderMaterial(base_color=list(FLOOR_COLOR), roughness=0.9)


def _rigid_component(entity: Any) -> Any:
    import sapien

    return next((c for c in entity.components
                 if isinstance(c, sapien.physx.PhysxRigidDynamicComponent)), None)


# --- bodies ---------------------------------------------------------------------------------


def _build_rigid(scene: Any, body: SceneBody, asset: RigidAsset, renders: bool) -> Any:
    import sapien

    physx = sapien.physx
    component = (physx.PhysxRigidStaticComponent() if body.is_static
                 else physx.PhysxRigidDynamicComponent())
    for shape in collision_shapes(asset.collision, physx_material(asset.material)):
        component.attach(shape)
    if not body.is_static:
        component.mass = asset.mass
        component.cmass_local_pose = sapien.Pose(list(asset.center_of_mass),
                                                 list(asset.inertia_frame))
        component.inertia = np.asarray(asset.inertia, dtype=np.float32)
        component.solver_position_iterations = SOLVER_ITERATIONS[0]
        component.solver_velocity_iterations = SOLVER_ITERATIONS[1]
    component.name = body.name
    entity = sapien.Entity()
    entity.name = body.name
    if renders and asset.visuals:
        entity.add_component(_render_body(body.name, visual_shapes(asset.visuals, asset.material)))
    entity.add_component(component)
    entity.pose = sapien_pose(body.pose)
    scene.add_entity(entity)
    return entity


def _render_body(name: str, shapes: Sequence[Any]) -> Any:
    import sapien

    component = sapien.render.RenderBodyComponent()
    for shape in shapes:
        component.attach(shape)
    component.name = name
    return component


def _build_articulated(scene: Any, body: SceneBody, asset: ArticulatedAsset, tmp: Path,
                       renders: bool) -> Any:
    if asset.urdf is not None:
        source = tmp / f"{body.name}.urdf"
        source.write_text(asset.urdf, encoding="utf-8")
    else:
        source = Path(str(asset.urdf_path))
    folder = tmp / body.name
    folder.mkdir()
    urdf = prepare_urdf(source, folder, keep_visuals=renders)
    loader = scene.create_urdf_loader()
    loader.fix_root_link = body.is_static
    loader.scale = asset.scale
    material = asset.material
    loader.set_material(material.static_friction, material.dynamic_friction,
                        material.restitution)
    builder = loader.load_file_as_articulation_builder(str(urdf))
    pose = sapien_pose(body.pose)
    builder.initial_pose = pose
    articulation = builder.build(fix_root_link=body.is_static)
    articulation.name = body.name
    articulation.set_root_pose(pose)
    for joint in articulation.active_joints:
        joint.set_drive_properties(0.0, PASSIVE_JOINT_DAMPING, np.inf, "force")
        joint.set_drive_target(0.0)
    articulation.set_qpos(start_qpos(articulation, asset))
    return articulation


def start_qpos(articulation: Any, asset: ArticulatedAsset) -> np.ndarray:
    """The articulation's joint positions at the start (:meth:`ArticulatedAsset.start_positions`:
    the asset's joints are already scaled), in its active joints' order."""
    start = asset.start_positions()
    qpos = np.zeros(articulation.dof, dtype=np.float32)
    for index, joint in enumerate(articulation.active_joints):
        if joint.name in start:
            qpos[index] = start[joint.name]
    return qpos


def _build_zone(scene: Any, zone: SceneZone, marker: ZoneAsset, renders: bool) -> Any | None:
    """The zone's marker (visual only) and walls (static collision) as one static entity;
    None when it has neither here (a physics-only scene and no walls)."""
    import sapien

    if not marker.collision and not (renders and marker.visuals):
        return None
    entity = sapien.Entity()
    entity.name = f"zone_{zone.name}"
    if renders and marker.visuals:
        shapes = visual_shapes(marker.visuals, _ZONE_LOOK)
        entity.add_component(_render_body(entity.name, shapes))
    if marker.collision:
        walls = sapien.physx.PhysxRigidStaticComponent()
        material = sapien.physx.PhysxMaterial(0.5, 0.4, 0.1)
        for shape in collision_shapes(marker.collision, material):
            walls.attach(shape)
        walls.name = entity.name
        entity.add_component(walls)
    entity.pose = sapien_pose(zone.pose)
    scene.add_entity(entity)
    return entity


def _place_robots(robot: LoadedRobot, spec: SceneSpec) -> None:
    """Each robot's root at its spec mount (a variant may move a mount)."""
    for mount in spec.mounts:
        if mount.robot in robot.articulations:
            robot.articulations[mount.robot].set_root_pose(sapien_pose(mount.pose))


#: How a zone marker part without an appearance looks.
_ZONE_LOOK = Appearance(base_color=(0.8, 0.2, 0.2, 1.0), roughness=0.8)

__all__ = ["PASSIVE_JOINT_DAMPING", "SOLVER_ITERATIONS", "BuiltScene", "build"]
