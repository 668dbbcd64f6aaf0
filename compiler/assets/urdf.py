"""Reading URDF text into the asset models: links, collision shapes, joints.

Used for both the generated (template) URDFs and user URDF files, so an
`ArticulatedAsset`'s structure always comes from the URDF it carries. Parsing uses
``xml.etree`` only; mesh references are resolved by a caller-supplied function
(which guards paths) and each collision mesh is taken as its convex hull, as a
simulator's URDF loader does by default.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import trimesh

from ..pose import axis_angle_matrix, pose_matrix, rpy_quat
from .geometry import inline_mesh, shape_aabb, union_aabb
from .model import (
    BoxShape,
    ConvexMeshShape,
    CylinderShape,
    Joint,
    Link,
    Pose,
    Shape,
    SphereShape,
)

MeshResolver = Callable[[str], Path]
MOVABLE_JOINTS = ("revolute", "prismatic", "continuous")
_KNOWN_JOINTS = ("revolute", "prismatic", "continuous", "fixed")


class UrdfError(ValueError):
    """A URDF that does not parse or whose links and joints do not form a tree."""


@dataclass(frozen=True)
class UrdfStructure:
    name: str
    root_link: str
    links: list[Link]
    joints: list[Joint]

    def rest_aabb(self, positions: Mapping[str, float] | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Bounds of every collision shape with all joints at zero (or at ``positions``:
        joint name -> rad or m, the others at zero), in the root frame."""
        transforms = link_transforms_at_rest(self, positions)
        boxes = []
        for link in self.links:
            for shape in link.collision:
                corners = _corners(*shape_aabb(shape))
                world = corners @ transforms[link.name][:3, :3].T + transforms[link.name][:3, 3]
                boxes.append((world.min(axis=0), world.max(axis=0)))
        if not boxes:
            raise UrdfError(f"URDF {self.name!r} has no collision geometry")
        return union_aabb(boxes)


def parse_urdf(
    text: str, *, scale: float = 1.0, resolve_mesh: MeshResolver | None = None
) -> UrdfStructure:
    """Parse and check a URDF; lengths are multiplied by ``scale``."""
    if "<!DOCTYPE" in text or "<!ENTITY" in text:
        raise UrdfError("URDF must not declare a DOCTYPE or entities")
    try:
        robot = ET.fromstring(text)
    except ET.ParseError as error:
        raise UrdfError(f"URDF is not well-formed XML: {error}") from None
    if robot.tag != "robot":
        raise UrdfError(f"URDF root element must be <robot>, got <{robot.tag}>")
    links = [_link(element, scale, resolve_mesh) for element in robot.findall("link")]
    joints = [_joint(element, scale) for element in robot.findall("joint")]
    structure = UrdfStructure(
        name=robot.get("name", ""), root_link=_check_tree(links, joints), links=links, joints=joints
    )
    return structure


def link_transforms_at_rest(structure: UrdfStructure,
                            positions: Mapping[str, float] | None = None) -> dict[str, np.ndarray]:
    """4×4 transform of every link in the root link's frame, all joints at zero (or at
    ``positions``, joint name -> rad for a revolute joint, m for a prismatic one)."""
    transforms = {structure.root_link: np.eye(4)}
    pending = list(structure.joints)
    positions = positions or {}
    while pending:
        ready = [j for j in pending if j.parent in transforms]
        for joint in ready:
            transforms[joint.child] = (transforms[joint.parent] @ pose_matrix(joint.origin)
                                       @ _joint_motion(joint, positions.get(joint.name, 0.0)))
            pending.remove(joint)
        if not ready:  # pragma: no cover - _check_tree rules this out
            raise UrdfError("URDF joints do not connect every link to the root")
    return transforms


def _joint_motion(joint: Joint, position: float) -> np.ndarray:
    """The 4×4 motion of a joint's child frame at ``position`` about or along its axis."""
    motion = np.eye(4)
    if position == 0.0 or joint.type == "fixed":
        return motion
    axis = np.asarray(joint.axis, dtype=np.float64)
    axis = axis / np.linalg.norm(axis)
    if joint.type == "prismatic":
        motion[:3, 3] = axis * position
    else:
        motion[:3, :3] = axis_angle_matrix(axis, position)
    return motion


# --- elements -----------------------------------------------------------------------------


def _link(element: ET.Element, scale: float, resolve_mesh: MeshResolver | None) -> Link:
    name = _required(element, "name", "link")
    shapes = [
        _collision(c, f"{name}_{i}", scale, resolve_mesh)
        for i, c in enumerate(element.findall("collision"))
    ]
    mass_element = element.find("inertial/mass")
    mass = float(mass_element.get("value", "0")) if mass_element is not None else 0.0
    return Link(name=name, collision=shapes, mass=mass * scale**3)


def _collision(
    element: ET.Element, default_name: str, scale: float, resolve_mesh: MeshResolver | None
) -> Shape:
    name = element.get("name") or default_name
    pose = _origin(element.find("origin"), scale)
    geometry = element.find("geometry")
    if geometry is None or len(geometry) != 1:
        raise UrdfError(f"collision {name!r} needs exactly one <geometry> child")
    shape = geometry[0]
    if shape.tag == "box":
        size = _floats(_required(shape, "size", "box"), 3)
        return BoxShape(name=name, pose=pose, half_size=tuple(s * scale / 2.0 for s in size))
    if shape.tag == "cylinder":
        return CylinderShape(
            name=name,
            pose=pose,
            radius=float(_required(shape, "radius", "cylinder")) * scale,
            half_length=float(_required(shape, "length", "cylinder")) * scale / 2.0,
        )
    if shape.tag == "sphere":
        return SphereShape(
            name=name, pose=pose, radius=float(_required(shape, "radius", "sphere")) * scale
        )
    if shape.tag == "mesh":
        if resolve_mesh is None:
            raise UrdfError(f"collision {name!r}: mesh geometry is not allowed here")
        path = resolve_mesh(_required(shape, "filename", "mesh"))
        mesh_scale = np.asarray(_floats(shape.get("scale", "1 1 1"), 3)) * scale
        hull = trimesh.load(path, force="mesh").apply_scale(mesh_scale).convex_hull
        return ConvexMeshShape(name=name, pose=pose, mesh=inline_mesh(hull))
    raise UrdfError(f"collision {name!r}: unsupported geometry <{shape.tag}>")


def _joint(element: ET.Element, scale: float) -> Joint:
    name = _required(element, "name", "joint")
    kind = _required(element, "type", f"joint {name!r}")
    if kind not in _KNOWN_JOINTS:
        raise UrdfError(
            f"joint {name!r}: unsupported type {kind!r} (supported: {', '.join(_KNOWN_JOINTS)})"
        )
    parent, child = element.find("parent"), element.find("child")
    if parent is None or child is None:
        raise UrdfError(f"joint {name!r} needs <parent> and <child>")
    axis_element = element.find("axis")
    axis = (
        _floats(axis_element.get("xyz", "1 0 0"), 3)
        if axis_element is not None
        else (1.0, 0.0, 0.0)
    )
    lower = upper = 0.0
    if kind in ("revolute", "prismatic"):
        limit = element.find("limit")
        if limit is None:
            raise UrdfError(f"{kind} joint {name!r} needs a <limit>")
        lower, upper = float(limit.get("lower", "0")), float(limit.get("upper", "0"))
        if lower > upper:
            raise UrdfError(f"joint {name!r}: lower limit {lower} exceeds upper limit {upper}")
        if kind == "prismatic":
            lower, upper = lower * scale, upper * scale
    return Joint(
        name=name,
        type=kind,
        parent=_required(parent, "link", "parent"),
        child=_required(child, "link", "child"),
        origin=_origin(element.find("origin"), scale),
        axis=axis,
        lower=lower,
        upper=upper,
        friction=_friction(element, name),
    )


def _friction(element: ET.Element, joint: str) -> float:
    """A joint's ``<dynamics friction>`` (0 without one)."""
    dynamics = element.find("dynamics")
    text = "0" if dynamics is None else dynamics.get("friction", "0")
    try:
        value = float(text)
    except ValueError:
        raise UrdfError(f"joint {joint!r}: <dynamics friction={text!r}> is not a number") from None
    if value < 0.0:
        raise UrdfError(f"joint {joint!r}: <dynamics friction> must not be negative (got {value})")
    return value


def _check_tree(links: list[Link], joints: list[Joint]) -> str:
    names = [link.name for link in links]
    _unique(names, "link")
    _unique([j.name for j in joints], "joint")
    children: set[str] = set()
    for joint in joints:
        for role, link in (("parent", joint.parent), ("child", joint.child)):
            if link not in names:
                raise UrdfError(f"joint {joint.name!r}: {role} link {link!r} is not defined")
        if joint.child in children:
            raise UrdfError(f"link {joint.child!r} is the child of more than one joint")
        children.add(joint.child)
    roots = [n for n in names if n not in children]
    if len(roots) != 1:
        raise UrdfError(f"URDF must have exactly one root link, found {roots or 'none (a cycle)'}")
    reached, frontier = {roots[0]}, [roots[0]]
    while frontier:
        current = frontier.pop()
        for joint in joints:
            if joint.parent == current and joint.child not in reached:
                reached.add(joint.child)
                frontier.append(joint.child)
    if reached != set(names):
        raise UrdfError(
            f"links not connected to the root {roots[0]!r}: {sorted(set(names) - reached)}"
        )
    return roots[0]


def _origin(element: ET.Element | None, scale: float) -> Pose:
    if element is None:
        return Pose()
    xyz = np.asarray(_floats(element.get("xyz", "0 0 0"), 3)) * scale
    rpy = _floats(element.get("rpy", "0 0 0"), 3)
    if not any(rpy):
        return Pose(position=xyz)
    return Pose(position=xyz, quaternion=rpy_quat(rpy))


def _floats(text: str, count: int) -> tuple[float, ...]:
    try:
        values = tuple(float(v) for v in text.split())
    except ValueError:
        raise UrdfError(f"expected {count} numbers, got {text!r}") from None
    if len(values) != count:
        raise UrdfError(f"expected {count} numbers, got {text!r}")
    return values


def _required(element: ET.Element, attribute: str, what: str) -> str:
    value = element.get(attribute)
    if value is None:
        raise UrdfError(f"{what} is missing its `{attribute}` attribute")
    return value


def _unique(names: list[str], what: str) -> None:
    seen: set[str] = set()
    for name in names:
        if name in seen:
            raise UrdfError(f"{what} name {name!r} is used twice")
        seen.add(name)


def _corners(lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
    return np.array(
        [
            [x, y, z]
            for x in (lower[0], upper[0])
            for y in (lower[1], upper[1])
            for z in (lower[2], upper[2])
        ]
    )
