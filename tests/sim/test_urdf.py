"""Preparing a URDF for the loader: a collision mesh swapped for its convex pieces."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from fsvla.sim.urdf import convex_piece_files, prepare_urdf

URDF = """<?xml version="1.0"?>
<robot name="r">
  <link name="hand">
    <visual><geometry><mesh filename="jaw.stl"/></geometry></visual>
    <collision><origin xyz="0 0 0.1"/><geometry><mesh filename="meshes/jaw.stl" scale="2 2 2"/></geometry></collision>
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>
  </link>
  <link name="other">
    <collision><geometry><mesh filename="meshes/base.stl"/></geometry></collision>
  </link>
</robot>
"""


def _prepared(tmp_path: Path, pieces: dict[str, Path] | None) -> ET.Element:
    source = tmp_path / "robot.urdf"
    source.write_text(URDF, encoding="utf-8")
    out = tmp_path / "out"
    out.mkdir()
    return ET.parse(prepare_urdf(source, out, keep_visuals=False, pieces=pieces)).getroot()


def test_a_collision_mesh_becomes_one_element_per_piece_at_its_origin(tmp_path: Path) -> None:
    folder = tmp_path / "jaw"
    folder.mkdir()
    for name in ("piece_01.obj", "piece_00.obj"):
        (folder / name).write_text("v 0 0 0\n", encoding="utf-8")
    root = _prepared(tmp_path, {"jaw.stl": folder})
    hand = root.find("link[@name='hand']")
    assert hand is not None
    collisions = hand.findall("collision")
    meshes = [c.find("geometry/mesh") for c in collisions[:2]]
    assert [Path(m.get("filename")).name for m in meshes] == ["piece_00.obj", "piece_01.obj"]
    assert all(m.get("scale") == "2 2 2" for m in meshes)
    assert all(c.find("origin").get("xyz") == "0 0 0.1" for c in collisions[:2])
    assert collisions[2].find("geometry/box") is not None  # other shapes stay, in order
    assert hand.find("visual") is None
    other = root.find("link[@name='other']/collision/geometry/mesh")
    assert other.get("filename").endswith("meshes/base.stl")  # not named: untouched


def test_no_pieces_leaves_the_collision_meshes(tmp_path: Path) -> None:
    root = _prepared(tmp_path, None)
    assert len(root.findall("link[@name='hand']/collision")) == 2


def test_an_empty_pieces_folder_is_a_clear_error(tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError, match="no convex pieces"):
        convex_piece_files(tmp_path)
