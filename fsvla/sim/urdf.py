"""Prepare a URDF for SAPIEN's loader: absolute mesh paths; for a physics-only scene, no
visual elements (SAPIEN builds render bodies for visuals and fails without a render
device); and collision meshes swapped for their convex pieces where the embodiment ships
them (the loader takes one convex hull of each collision mesh: a gripper's fixed jaw
printed in one piece with its wrist becomes a wedge). The installed file is never
modified; a copy is written instead."""

from __future__ import annotations

import copy
import xml.etree.ElementTree as ET
from collections.abc import Mapping
from pathlib import Path

from fsvla.embodiments.assets import package_share_root

PACKAGE_SCHEME = "package://"


def resolve_uri(uri: str, urdf_dir: Path) -> str:
    """Absolute path for a mesh or texture ``filename`` attribute of a URDF.

    ``package://pkg/rest`` resolves against example-robot-data's ``share`` folder,
    then against each ancestor of the URDF's folder (as ROS would find ``pkg``);
    a relative path resolves against the URDF's folder. Unresolvable URIs are
    returned unchanged so the loader reports them.
    """
    if uri.startswith(PACKAGE_SCHEME):
        rest = uri[len(PACKAGE_SCHEME):]
        candidates = [package_share_root() / rest]
        candidates += [parent / rest for parent in [urdf_dir, *urdf_dir.parents]]
        for candidate in candidates:
            if candidate.is_file():
                return str(candidate)
        return uri
    if uri.startswith("file://"):
        return uri[len("file://"):]
    path = Path(uri)
    return str(path if path.is_absolute() else (urdf_dir / path).resolve())


def prepare_urdf(urdf: Path, out_dir: Path, keep_visuals: bool,
                 pieces: Mapping[str, Path] | None = None) -> Path:
    """Write a loader-ready copy of ``urdf`` into ``out_dir`` and return its path.

    ``pieces`` maps a collision mesh's file name (without folders, as the URDF names it)
    to a folder of convex pieces (``*.obj``): each collision element of that mesh becomes
    one element per piece, at the same origin and scale."""
    root = ET.parse(urdf).getroot()
    urdf_dir = urdf.resolve().parent
    if not keep_visuals:
        for link in root.iter("link"):
            for visual in link.findall("visual"):
                link.remove(visual)
    if pieces:
        for link in root.iter("link"):
            _swap_for_pieces(link, pieces)
    for element in root.iter():
        if element.tag in ("mesh", "texture") and element.get("filename"):
            element.set("filename", resolve_uri(element.get("filename", ""), urdf_dir))
    out = out_dir / urdf.name
    if out.exists():
        out = out_dir / f"{urdf.stem}_{len(list(out_dir.iterdir()))}{urdf.suffix}"
    ET.ElementTree(root).write(out, encoding="utf-8", xml_declaration=True)
    return out


def convex_piece_files(folder: Path) -> list[Path]:
    """The convex pieces in ``folder`` (``*.obj``, in name order); an error when none."""
    found = sorted(folder.glob("*.obj"))
    if not found:
        raise FileNotFoundError(f"no convex pieces (*.obj) in {folder}")
    return found


def _swap_for_pieces(link: ET.Element, pieces: Mapping[str, Path]) -> None:
    for collision in link.findall("collision"):
        mesh = collision.find("geometry/mesh")
        if mesh is None:
            continue
        name = mesh.get("filename", "").replace("\\", "/").rsplit("/", 1)[-1]
        if name not in pieces:
            continue
        at = list(link).index(collision)
        link.remove(collision)
        for offset, piece in enumerate(convex_piece_files(pieces[name])):
            clone = copy.deepcopy(collision)
            part = clone.find("geometry/mesh")
            assert part is not None
            part.set("filename", str(piece.resolve()))
            link.insert(at + offset, clone)


__all__ = ["convex_piece_files", "prepare_urdf", "resolve_uri"]
