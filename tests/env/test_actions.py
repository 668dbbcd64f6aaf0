"""The action formats: bounds, labels, and refusal of malformed actions."""

from __future__ import annotations

import math

import numpy as np
import pytest
from fsvla.env.actions import (
    ActionCodec,
    ArmLayout,
    ControlMode,
    InvalidActionError,
    joint_targets,
    tcp_target,
)

LEFT = ArmLayout("left", ("j1", "j2"), (-1.0, -2.0), (1.0, 2.0))
RIGHT = ArmLayout("right", ("j1", "j2"), (-1.0, -math.inf), (1.0, math.inf))


def test_joint_pos_layout_is_joints_then_gripper_per_arm() -> None:
    codec = ActionCodec([LEFT, RIGHT], ControlMode.JOINT_POS)
    assert codec.labels == ("left.j1", "left.j2", "left.gripper",
                            "right.j1", "right.j2", "right.gripper")
    assert codec.low.tolist() == pytest.approx([-1, -2, 0, -1, -math.pi, 0])
    left, right = codec.decode([0.5, -1.0, 1.0, 0.0, 3.0, 0.25])
    assert left.joint_targets.tolist() == [0.5, -1.0] and left.gripper == 1.0
    assert right.joint_targets.tolist() == [0.0, 3.0] and right.gripper == 0.25


def test_ee_pose_layout_normalises_a_nearly_unit_quaternion() -> None:
    codec = ActionCodec([LEFT], "ee_pose")
    assert codec.size == 8
    (command,) = codec.decode([0.1, 0.0, 0.2, 1.005, 0.0, 0.0, 0.0, 0.5])
    assert command.tcp_position.tolist() == [0.1, 0.0, 0.2]
    assert command.tcp_quaternion.tolist() == pytest.approx([1.0, 0.0, 0.0, 0.0])


@pytest.mark.parametrize(
    ("action", "message"),
    [
        ([0.0, 0.0], "invalid action: expected shape (3,) for joint_pos [left.j1, left.j2, "
                     "left.gripper], got shape (2,)"),
        ([[0.0, 0.0, 0.0]], "invalid action: expected shape (3,) for joint_pos [left.j1, "
                            "left.j2, left.gripper], got shape (1, 3)"),
        ([0.0, float("nan"), 0.0], "invalid action: action[1] (left.j2) is nan"),
        ([float("inf"), 0.0, 0.0], "invalid action: action[0] (left.j1) is inf"),
        ([1.5, 0.0, 1.2], "invalid action: action[0] (left.j1) = 1.5 is outside [-1, 1]; "
                          "action[2] (left.gripper) = 1.2 is outside [0, 1]"),
        ("open", "invalid action: expected 3 numbers (joint_pos), got str"),
    ],
)
def test_malformed_actions_are_refused_not_clipped(action, message: str) -> None:
    codec = ActionCodec([LEFT], ControlMode.JOINT_POS)
    with pytest.raises(InvalidActionError) as caught:
        codec.decode(action)
    assert str(caught.value).startswith(message)


def test_a_quaternion_far_from_unit_is_refused() -> None:
    codec = ActionCodec([LEFT], ControlMode.EE_POSE)
    with pytest.raises(InvalidActionError, match="left's target quaternion has length 0.5"):
        codec.decode([0.0, 0.0, 0.2, 0.5, 0.0, 0.0, 0.0, 1.0])


def test_space_matches_the_bounds() -> None:
    codec = ActionCodec([LEFT, RIGHT], ControlMode.JOINT_POS)
    space = codec.space()
    assert space.shape == (6,)
    sample = space.sample()
    codec.decode(sample)  # anything the space samples is accepted
    assert np.all(space.low == codec.low)


def test_joint_delta_and_joint_vel_add_to_the_measured_joints_within_their_limits() -> None:
    delta = ActionCodec([LEFT], ControlMode.JOINT_DELTA)
    assert delta.labels == ("left.j1", "left.j2", "left.gripper")
    assert delta.high.tolist() == pytest.approx([0.5, 0.5, 1.0])
    (command,) = delta.decode([0.1, -0.2, 0.5])
    assert joint_targets(command, LEFT, [0.0, 1.0]).tolist() == pytest.approx([0.1, 0.8])
    assert joint_targets(command, LEFT, [0.95, -1.9]).tolist() == pytest.approx([1.0, -2.0])
    velocity = ActionCodec([LEFT], "joint_vel")
    assert velocity.high.tolist() == pytest.approx([10.0, 10.0, 1.0])
    (command,) = velocity.decode([2.0, -1.0, 1.0])
    assert command.joint_velocity.tolist() == [2.0, -1.0] and command.in_joint_space
    assert joint_targets(command, LEFT, [0.0, 0.0], elapsed=0.05).tolist() == pytest.approx(
        [0.1, -0.05])


def test_ee_delta_moves_the_tool_from_its_measured_pose_in_the_table_frame() -> None:
    codec = ActionCodec([LEFT, RIGHT], ControlMode.EE_DELTA)
    assert codec.labels[:7] == ("left.dx", "left.dy", "left.dz", "left.rx", "left.ry",
                                "left.rz", "left.gripper")
    assert codec.size == 14 and codec.high[:7].tolist() == pytest.approx([0.1] * 3 + [0.5] * 3 + [1])
    turn = [0.0, 0.0, 0.01, 0.0, 0.0, math.pi / 8, 1.0]
    left, right = codec.decode(turn + [0.0] * 6 + [0.0])
    half = math.sqrt(0.5)
    position, quaternion = tcp_target(left, [0.1, 0.2, 0.3], [half, 0.0, 0.0, half])  # yaw 90°
    assert position.tolist() == pytest.approx([0.1, 0.2, 0.31])
    yaw = 2 * math.atan2(quaternion[3], quaternion[0])
    assert yaw == pytest.approx(math.pi / 2 + math.pi / 8)
    assert tcp_target(right, [0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0])[1].tolist() == [1, 0, 0, 0]
    with pytest.raises(InvalidActionError, match=r"action\[5\] \(left.rz\) = 0.6 is outside"):
        codec.decode([0.0] * 5 + [0.6, 1.0] + [0.0] * 7)
