"""File assets: a mesh or URDF file next to the scenario (`AssetClass.FILE`).

Paths are resolved relative to the scenario's folder (``base_dir``) and must stay
inside one of the allowed roots (``base_dir`` itself when none are given): a path
that resolves (symbolic links followed) outside them is rejected, and so is every
file a URDF refers to (meshes, textures). Loading never runs code from a file.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import trimesh

from .decomposition import Method, convex_pieces
from .geometry import bounds_of, inline_mesh, mass_properties, shape_aabb, union_aabb
from .materials import Substance, physics_material
from .model import (
    ArticulatedAsset,
    ConvexMeshShape,
    MeshFile,
    ParamValue,
    Part,
    Pose,
    RigidAsset,
    VisualPart,
)
from .urdf import MOVABLE_JOINTS, UrdfError, parse_urdf

MESH_SUFFIXES = (".obj", ".stl", ".ply", ".glb")
URDF_SUFFIXES = (".urdf",)
# A user's mesh of unknown material: the density of water unless `mass` is given.
GENERIC = Substance("generic", 1000.0, (0.7, 0.7, 0.7, 1.0), friction=0.6)


class AssetPathError(ValueError):
    """A file asset's path that is missing, of the wrong type, or outside the allowed roots."""


def resolve_asset_path(
    path: str | Path,
    *,
    base_dir: Path | None,
    allowed_roots: Sequence[Path] = (),
    suffixes: Sequence[str] = (),
) -> Path:
    """The resolved path of a file asset, checked against the allowed roots."""
    candidate = Path(path)
    if not candidate.is_absolute():
        if base_dir is None:
            raise AssetPathError(
                f"relative asset path {str(path)!r} needs the scenario's folder (base_dir)"
            )
        candidate = Path(base_dir) / candidate
    resolved = candidate.resolve()
    roots = [Path(root).resolve() for root in allowed_roots]
    if not roots and base_dir is not None:
        roots = [Path(base_dir).resolve()]
    if not any(resolved.is_relative_to(root) for root in roots):
        allowed = ", ".join(str(root) for root in roots) or "none"
        raise AssetPathError(
            f"asset path {str(path)!r} resolves to {resolved}, "
            f"outside the allowed roots ({allowed})"
        )
    if suffixes and resolved.suffix.lower() not in suffixes:
        raise AssetPathError(f"asset file {str(path)!r} must end in one of {', '.join(suffixes)}")
    if not resolved.is_file():
        raise AssetPathError(f"asset file {str(path)!r} not found (looked at {resolved})")
    return resolved


def load_mesh_asset(
    params: Mapping[str, ParamValue],
    *,
    base_dir: Path | None,
    allowed_roots: Sequence[Path] = (),
    method: Method = "auto",
) -> RigidAsset:
    """A rigid body from a mesh file: its convex hull, or convex pieces when it is not convex.

    The body frame is the mesh's own, shifted so that its origin is at the centre of the
    bottom of its bounding box (the convention of every asset)."""
    path = resolve_asset_path(
        str(params["path"]), base_dir=base_dir, allowed_roots=allowed_roots, suffixes=MESH_SUFFIXES
    )
    scale = float(params.get("scale", 1.0))
    mesh = trimesh.load(path, force="mesh")
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        raise AssetPathError(f"mesh file {str(params['path'])!r} holds no triangles")
    mesh.apply_scale(scale)
    lower, upper = mesh.bounds
    offset = np.array([(lower[0] + upper[0]) / 2.0, (lower[1] + upper[1]) / 2.0, lower[2]])
    mesh.apply_translation(-offset)
    pieces, method_used = convex_pieces(mesh, method=method)
    collision = [
        ConvexMeshShape(name=f"{method_used}_{i}", mesh=inline_mesh(piece))
        for i, piece in enumerate(pieces)
    ]
    props = mass_properties([(shape, GENERIC.density) for shape in collision])
    factor = 1.0 if params.get("mass") is None else float(params["mass"]) / props.mass
    visual = VisualPart(
        name="mesh",
        mesh=MeshFile(path=str(path), scale=(scale, scale, scale)),
        pose=Pose(position=-offset),
    )
    bounds, footprint = bounds_of(
        *union_aabb([shape_aabb(s) for s in collision] + [tuple(mesh.bounds)])
    )
    return RigidAsset(
        kind="mesh",
        params=dict(params),
        collision=collision,
        visuals=[visual],
        mass=props.mass * factor,
        center_of_mass=props.center_of_mass,
        inertia=tuple(m * factor for m in props.principal_moments),
        inertia_frame=props.principal_frame,
        material=physics_material(GENERIC, params.get("friction"), GENERIC.density * factor),
        is_static=False,
        bounds=bounds,
        footprint=footprint,
    )


def load_urdf_asset(
    params: Mapping[str, ParamValue], *, base_dir: Path | None, allowed_roots: Sequence[Path] = ()
) -> ArticulatedAsset:
    """An articulated body from a URDF file; every file it refers to must be inside the roots.

    Each movable joint's child link becomes a part named after the link."""
    path = resolve_asset_path(
        str(params["path"]), base_dir=base_dir, allowed_roots=allowed_roots, suffixes=URDF_SUFFIXES
    )
    roots = list(allowed_roots) or [path.parent if base_dir is None else Path(base_dir)]
    text = path.read_text(encoding="utf-8")

    def resolve_reference(reference: str) -> Path:
        return _resolve_reference(reference, urdf_dir=path.parent, roots=roots)

    if "<!DOCTYPE" in text or "<!ENTITY" in text:
        raise UrdfError(f"{path.name}: a URDF must not declare a DOCTYPE or entities")
    try:
        for element in ET.fromstring(text).iter():
            if "filename" in element.attrib:
                resolve_reference(element.attrib["filename"])
    except ET.ParseError as error:
        raise UrdfError(f"{path.name}: not well-formed XML: {error}") from None
    scale = float(params.get("scale", 1.0))
    structure = parse_urdf(text, scale=scale, resolve_mesh=resolve_reference)
    parts = [
        Part(name=j.child, link=j.child, joint=j.name)
        for j in structure.joints
        if j.type in MOVABLE_JOINTS
    ]
    bounds, footprint = bounds_of(*structure.rest_aabb())
    return ArticulatedAsset(
        kind="urdf",
        params=dict(params),
        urdf_path=str(path),
        scale=scale,
        root_link=structure.root_link,
        links=structure.links,
        joints=structure.joints,
        parts=parts,
        material=physics_material(GENERIC, None, GENERIC.density),
        bounds=bounds,
        footprint=footprint,
    )


def _resolve_reference(reference: str, *, urdf_dir: Path, roots: Sequence[Path]) -> Path:
    """A file a URDF names: plain or ``file://`` paths relative to the URDF's folder."""
    if reference.startswith("file://"):
        reference = reference[len("file://") :]
    elif "://" in reference:
        raise AssetPathError(
            f"URDF reference {reference!r}: only paths relative to the URDF (or file://) "
            "are allowed in scenario assets, not package:// or other URIs"
        )
    return resolve_asset_path(reference, base_dir=urdf_dir, allowed_roots=roots)
