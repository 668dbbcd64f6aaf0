"""Prepare a URDF for SAPIEN's loader: absolute mesh paths and, for a physics-only
scene, no visual elements (SAPIEN builds render bodies for visuals and fails without
a render device). The installed file is never modified; a copy is written instead."""

from __future__ import annotations

import xml.etree.ElementTree as ET
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


def prepare_urdf(urdf: Path, out_dir: Path, keep_visuals: bool) -> Path:
    """Write a loader-ready copy of ``urdf`` into ``out_dir`` and return its path."""
    root = ET.parse(urdf).getroot()
    urdf_dir = urdf.resolve().parent
    if not keep_visuals:
        for link in root.iter("link"):
            for visual in link.findall("visual"):
                link.remove(visual)
    for element in root.iter():
        if element.tag in ("mesh", "texture") and element.get("filename"):
            element.set("filename", resolve_uri(element.get("filename", ""), urdf_dir))
    out = out_dir / urdf.name
    if out.exists():
        out = out_dir / f"{urdf.stem}_{len(list(out_dir.iterdir()))}{urdf.suffix}"
    ET.ElementTree(root).write(out, encoding="utf-8", xml_declaration=True)
    return out


__all__ = ["prepare_urdf", "resolve_uri"]
