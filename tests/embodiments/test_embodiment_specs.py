"""Embodiment specs as data: the built-in TOML files, the loader, validation errors.

No simulator is needed here.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from fsvla.dsl import catalog
from pydantic import ValidationError

from fsvla.embodiments import (
    EmbodimentSpec,
    UnknownEmbodimentError,
    builtin_embodiments,
    load_embodiment,
)

BUILTINS = ("baxter", "dual_panda", "panda", "so101", "z1")

USER_TOML = """
name = "my_arm"
description = "a user's own panda, next to its own copy of the URDF"

[[robots]]
name = "mine"
urdf = "robot.urdf"
mount = { position = [-0.5, 0.1, 0.0], yaw = 0.3 }

[[robots.arms]]
name = "arm"
base_link = "panda_link0"
joints = ["panda_joint1"]
home = [0.0]
ee_link = "panda_hand_tcp"
workspace = { center = [0.0, 0.0, 0.15], size = [0.2, 0.2, 0.1] }

[robots.arms.gripper]
joints = ["panda_finger_joint1"]
open = [0.04]
closed = [0.0]
finger_links = ["panda_leftfinger"]

[[cameras]]
name = "front"
position = [0.6, 0.0, 0.5]
look_at = [0.0, 0.0, 0.1]
"""


def test_builtin_names() -> None:
    assert builtin_embodiments() == BUILTINS


@pytest.mark.parametrize("name", BUILTINS)
def test_builtin_validates(name: str) -> None:
    spec = load_embodiment(name)
    assert isinstance(spec, EmbodimentSpec)
    assert spec.name == name
    for arm in spec.arms:
        assert len(arm.home) == len(arm.joints)
        assert arm.workspace.size[0] >= 0.08 and arm.workspace.size[1] >= 0.16
    for cam in spec.cameras:
        assert (cam.width, cam.height) == (320, 240)
        assert np.isclose(np.linalg.norm(cam.orientation()), 1.0)


@pytest.mark.parametrize("name", BUILTINS)
def test_builtin_arms_match_the_language_catalog(name: str) -> None:
    assert load_embodiment(name).arm_names == catalog.EMBODIMENTS[name]


def test_each_builtin_has_a_world_camera_and_a_wrist_camera_per_arm() -> None:
    for name in BUILTINS:
        spec = load_embodiment(name)
        parents = [c.parent for c in spec.cameras]
        assert "world" in parents
        assert sorted(p for p in parents if p != "world") == sorted(spec.arm_names)


def test_unknown_name_suggests_the_closest() -> None:
    with pytest.raises(UnknownEmbodimentError) as info:
        load_embodiment("pandas")
    message = str(info.value)
    assert "did you mean `panda`?" in message
    for name in BUILTINS:
        assert name in message


def test_missing_toml_path() -> None:
    with pytest.raises(FileNotFoundError):
        load_embodiment("/nonexistent/robot.toml")


def test_user_toml_with_a_local_urdf(tmp_path: Path) -> None:
    (tmp_path / "robot.urdf").write_text("<robot name='r'/>")
    path = tmp_path / "mine.toml"
    path.write_text(USER_TOML)
    spec = load_embodiment(path)
    assert spec.name == "my_arm"
    assert spec.robots[0].urdf == str(tmp_path / "robot.urdf")  # anchored to the TOML file
    assert spec.arm("arm").gripper.home == "open"


def test_user_toml_urdf_falls_back_to_robot_data(tmp_path: Path) -> None:
    path = tmp_path / "mine.toml"
    path.write_text(USER_TOML.replace('"robot.urdf"', '"panda_description/urdf/panda.urdf"'))
    assert load_embodiment(str(path)).robots[0].urdf == "panda_description/urdf/panda.urdf"


def _user_data() -> dict:
    import tomllib

    return tomllib.loads(USER_TOML)


def _errors(data: dict) -> str:
    with pytest.raises(ValidationError) as info:
        EmbodimentSpec.model_validate(data)
    return str(info.value)


def test_unknown_key_is_rejected() -> None:
    data = _user_data()
    data["robots"][0]["arms"][0]["ee_lnk"] = "x"
    assert "ee_lnk" in _errors(data)


def test_home_length_must_match_joints() -> None:
    data = _user_data()
    data["robots"][0]["arms"][0]["home"] = [0.0, 1.0]
    assert "`home` has 2 values for 1 joints" in _errors(data)


def test_gripper_targets_must_match_joints() -> None:
    data = _user_data()
    data["robots"][0]["arms"][0]["gripper"]["open"] = [0.04, 0.04]
    assert "gripper `open` has 2 values for 1 joints" in _errors(data)


def test_pad_friction_must_be_a_friction() -> None:
    data = _user_data()
    data["robots"][0]["arms"][0]["gripper"]["pad_friction"] = -0.5
    assert "pad_friction" in _errors(data)
    data["robots"][0]["arms"][0]["gripper"]["pad_friction"] = 0.9
    EmbodimentSpec.model_validate(data)


def test_camera_parent_must_be_world_or_an_arm() -> None:
    data = _user_data()
    data["cameras"][0]["parent"] = "left"
    assert "neither `world` nor an arm" in _errors(data)


def test_camera_needs_exactly_one_orientation() -> None:
    data = _user_data()
    data["cameras"][0]["quat"] = [1.0, 0.0, 0.0, 0.0]
    assert "exactly one of `look_at` or `quat`" in _errors(data)


def test_camera_looking_straight_along_up_is_rejected() -> None:
    data = _user_data()
    data["cameras"][0].update(position=[0.0, 0.0, 1.0], look_at=[0.0, 0.0, 0.0])
    assert "parallel to up" in _errors(data)


def test_duplicate_arm_names_are_rejected() -> None:
    data = _user_data()
    data["robots"].append({**data["robots"][0], "name": "other"})
    assert "arm `arm` is listed twice" in _errors(data)


def test_importing_fsvla_does_not_import_sapien() -> None:
    code = (
        "import sys, fsvla, fsvla.embodiments, fsvla.sim, fsvla.sim.robot, fsvla.sim.kinematics;"
        "fsvla.embodiments.load_embodiment('baxter');"
        "assert 'sapien' not in sys.modules, 'sapien imported'"
    )
    subprocess.run([sys.executable, "-c", code], check=True)


@pytest.mark.parametrize("name", builtin_embodiments())
def test_builtin_collision_pieces_are_shipped(name: str) -> None:
    from fsvla.sim.urdf import convex_piece_files

    for robot in load_embodiment(name).robots:
        for mesh, folder in robot.collision_pieces.items():
            assert Path(folder).is_absolute(), (mesh, folder)
            assert len(convex_piece_files(Path(folder))) >= 2, mesh


def test_user_toml_collision_pieces_are_anchored_to_its_folder(tmp_path: Path) -> None:
    path = tmp_path / "mine.toml"
    path.write_text(USER_TOML.replace(
        'urdf = "robot.urdf"', 'urdf = "robot.urdf"\ncollision_pieces = { "jaw.stl" = "pieces/jaw" }'))
    (tmp_path / "robot.urdf").write_text("<robot name='r'/>")
    assert load_embodiment(path).robots[0].collision_pieces == {"jaw.stl": str(tmp_path / "pieces/jaw")}
