"""Asset geometry (``fsvla.compiler.assets.model``) to SAPIEN collision and render shapes,
and SAPIEN collision shapes back to asset shapes (:func:`shapes_of_sapien`: robot links,
for the monitor's geometry).

Frames: an asset's cylinders and capsules have their axis along local z, SAPIEN's along
local x, so each gets the rotation :data:`Z_TO_X` appended to its pose (and
:data:`X_TO_Z` on the way back). Inline meshes
become SAPIEN shapes directly (no files); file meshes are loaded by SAPIEN from their
path, scaled.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np

from fsvla.compiler.assets.model import (
    Appearance,
    BoxShape,
    CapsuleShape,
    ConvexMeshShape,
    CylinderShape,
    InlineMesh,
    Material,
    MeshFile,
    Pose,
    Shape,
    SphereShape,
    VisualPart,
)
from fsvla.compiler.pose import quat_mul

#: (w, x, y, z) of the rotation that takes SAPIEN's cylinder/capsule axis (+x) onto +z.
Z_TO_X = (0.7071067811865476, 0.0, -0.7071067811865476, 0.0)
#: Its inverse: appended to a SAPIEN cylinder's or capsule's pose, its axis lies along +z.
X_TO_Z = (0.7071067811865476, 0.0, 0.7071067811865476, 0.0)

#: Visual normals are split where faces meet at more than this angle (rad).
SMOOTH_ANGLE = np.radians(35.0)


def sapien_pose(pose: Pose) -> Any:
    """A ``sapien.Pose`` from an asset :class:`Pose` (both use (w, x, y, z))."""
    import sapien

    return sapien.Pose(list(pose.position), list(pose.quaternion))


def physx_material(material: Material) -> Any:
    import sapien

    return sapien.physx.PhysxMaterial(
        material.static_friction, material.dynamic_friction, material.restitution
    )


def collision_shapes(shapes: Iterable[Any], material: Any) -> list[Any]:
    """PhysX collision shapes for asset :data:`Shape` s, each at its pose."""
    import sapien

    physx = sapien.physx
    along_z = sapien.Pose([0.0, 0.0, 0.0], list(Z_TO_X))
    out = []
    for shape in shapes:
        local = sapien_pose(shape.pose)
        if shape.type == "box":
            built = physx.PhysxCollisionShapeBox(half_size=list(shape.half_size), material=material)
        elif shape.type == "cylinder":
            built = physx.PhysxCollisionShapeCylinder(
                radius=shape.radius, half_length=shape.half_length, material=material
            )
            local = local * along_z
        elif shape.type == "capsule":
            built = physx.PhysxCollisionShapeCapsule(
                radius=shape.radius, half_length=shape.half_length, material=material
            )
            local = local * along_z
        elif shape.type == "sphere":
            built = physx.PhysxCollisionShapeSphere(radius=shape.radius, material=material)
        elif shape.type == "convex_mesh":
            built = _convex(shape.mesh, material)
        else:  # pragma: no cover - the Shape union is closed
            raise ValueError(f"unknown collision shape type {shape.type!r}")
        built.local_pose = local
        out.append(built)
    return out


def _convex(mesh: InlineMesh | MeshFile, material: Any) -> Any:
    import sapien

    cls = sapien.physx.PhysxCollisionShapeConvexMesh
    if mesh.type == "inline":
        vertices = np.asarray(mesh.vertices, dtype=np.float32)
        return cls(vertices=vertices, scale=np.ones(3, dtype=np.float32), material=material)
    return cls(filename=mesh.path, scale=np.asarray(mesh.scale, dtype=np.float32),
               material=material)


def render_material(look: Appearance | Material, *, alpha: float | None = None) -> Any:
    """A SAPIEN render material from an appearance (or a body material's default look).

    ``emission`` is (r, g, b, strength) in both fsvla and SAPIEN."""
    import sapien

    color = list(look.base_color)
    if alpha is not None:
        color[3] = alpha
    emission = list(look.emission) if look.emission is not None else [0.0, 0.0, 0.0, 0.0]
    return sapien.render.RenderMaterial(
        base_color=color, emission=emission, roughness=look.roughness, metallic=look.metallic
    )


def triangle_mesh_shape(vertices: Sequence[Sequence[float]], faces: Sequence[Sequence[int]],
                        material: Any) -> Any:
    """A SAPIEN render mesh for triangles, normals smoothed below :data:`SMOOTH_ANGLE`."""
    import sapien
    import trimesh

    mesh = trimesh.Trimesh(np.asarray(vertices, dtype=np.float64),
                           np.asarray(faces, dtype=np.int64), process=False)
    mesh = trimesh.graph.smooth_shade(mesh, angle=SMOOTH_ANGLE)
    v = np.asarray(mesh.vertices, dtype=np.float32)
    return sapien.render.RenderShapeTriangleMesh(
        vertices=v,
        triangles=np.asarray(mesh.faces, dtype=np.uint32),
        normals=np.asarray(mesh.vertex_normals, dtype=np.float32),
        uvs=np.zeros((len(v), 2), dtype=np.float32),
        material=material,
    )


def visual_shapes(visuals: Iterable[VisualPart], default_look: Appearance | Material) -> list[Any]:
    """SAPIEN render shapes for an asset's visual parts, each at its pose."""
    import sapien

    out = []
    for part in visuals:
        material = render_material(part.appearance or default_look)
        if part.mesh.type == "inline":
            shape = triangle_mesh_shape(part.mesh.vertices, part.mesh.faces, material)
        else:
            shape = sapien.render.RenderShapeTriangleMesh(
                part.mesh.path, np.asarray(part.mesh.scale, dtype=np.float32), material
            )
        shape.local_pose = sapien_pose(part.pose)
        shape.name = part.name
        out.append(shape)
    return out


def shapes_of_sapien(component: Any) -> list[Shape]:
    """Asset shapes for the collision shapes of a SAPIEN rigid component or link."""
    import sapien

    physx = sapien.physx
    shapes: list[Shape] = []
    for sh in component.collision_shapes:
        local = sh.local_pose
        p, q = tuple(float(v) for v in local.p), tuple(float(v) for v in local.q)
        if isinstance(sh, physx.PhysxCollisionShapeBox):
            shapes.append(BoxShape(pose=Pose(position=p, quaternion=q),
                                   half_size=tuple(float(v) for v in sh.half_size)))
        elif isinstance(sh, physx.PhysxCollisionShapeSphere):
            shapes.append(SphereShape(pose=Pose(position=p, quaternion=q), radius=float(sh.radius)))
        elif isinstance(sh, physx.PhysxCollisionShapeCapsule):
            shapes.append(CapsuleShape(pose=Pose(position=p, quaternion=quat_mul(q, X_TO_Z)),
                                       radius=float(sh.radius), half_length=float(sh.half_length)))
        elif isinstance(sh, physx.PhysxCollisionShapeCylinder):
            shapes.append(CylinderShape(pose=Pose(position=p, quaternion=quat_mul(q, X_TO_Z)),
                                        radius=float(sh.radius), half_length=float(sh.half_length)))
        elif isinstance(sh, physx.PhysxCollisionShapeConvexMesh):
            vertices = np.asarray(sh.vertices, dtype=np.float64) * np.asarray(sh.scale, dtype=np.float64)
            faces = np.asarray(sh.get_triangles(), dtype=np.int64)
            shapes.append(ConvexMeshShape(pose=Pose(position=p, quaternion=q), mesh=InlineMesh(
                vertices=[tuple(v) for v in vertices.tolist()], faces=[tuple(f) for f in faces.tolist()])))
        # planes and triangle meshes are not monitored (the floor; never a robot link)
    return shapes


__all__ = [
    "X_TO_Z", "Z_TO_X", "collision_shapes", "physx_material", "render_material", "sapien_pose",
    "shapes_of_sapien", "triangle_mesh_shape", "visual_shapes",
]
