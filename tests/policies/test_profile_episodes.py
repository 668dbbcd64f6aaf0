"""Whole episodes through ``fsvla run --policy ws://... --policy-profile P``: a server of
each openpi example (tests/policies/openpi_examples.py) plays the one-second scenario
with no fault, and what it sees next shows the robot moved as its actions said."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

pytest.importorskip("openpi_client")
pytest.importorskip("pyarrow")
from fsvla.cli import run
from fsvla.results import ResultStore

from .openpi_examples import JOINT_DELTA_PROFILE, Aloha, Droid, JointDelta, Libero, serving

pytestmark = pytest.mark.sim


def _play(uri: str, scenario: Path, out: Path, *options: str) -> Any:
    """Run one episode of the server at ``uri``; its stored row."""
    argv = ["run", "--policy", uri, "--scenarios", str(scenario), "--warmup", "0",
            "--workers", "0", "--no-progress", "--out", str(out), *options]
    assert run(argv) == 0
    with ResultStore.open(out, readonly=True) as store:
        (row,) = store.episodes()
    return row


def _no_fault(row: Any, server: Any) -> None:
    assert not server.errors, server.errors[0]
    assert row.failure_reason is None, row.failure_detail
    assert row.steps == 20  # the whole second


@pytest.mark.render
@pytest.mark.slow  # about 15 s: two or three cameras rendered on the CPU
def test_droid_joint_velocities_turn_the_joints(short_scenario: Path, tmp_path: Path,
                                               render_device) -> None:
    with serving(Droid(velocity=(0.1, -0.1, 0, 0, 0, 0, 0))) as (server, uri):
        row = _play(uri, short_scenario, tmp_path / "droid", "--policy-profile", "droid")
    _no_fault(row, server)
    assert len(server.requests) == 3  # every 8 steps: at steps 0, 8 and 16
    joints = np.array([r["observation/joint_position"] for r in server.requests])
    moved = joints[2] - joints[0]  # 16 steps at 0.1 × 3 rad/s: 0.24 rad
    assert moved[:2] == pytest.approx([0.24, -0.24], abs=0.02)
    assert np.abs(moved[2:]).max() < 0.01
    assert server.requests[2]["observation/gripper_position"][0] < 0.05  # still open


@pytest.mark.render
@pytest.mark.slow  # about 15 s: two or three cameras rendered on the CPU
def test_libero_deltas_lift_the_tool(short_scenario: Path, tmp_path: Path,
                                     render_device) -> None:
    with serving(Libero(delta=(0, 0, 0.2, 0, 0, 0))) as (server, uri):
        row = _play(uri, short_scenario, tmp_path / "libero", "--policy-profile", "libero")
    _no_fault(row, server)
    assert len(server.requests) == 4  # every 5 steps
    states = np.array([r["observation/state"] for r in server.requests])
    rise = np.diff(states[:, 2])
    assert (rise > 0.005).all() and states[-1, 2] - states[0, 2] > 0.02  # up, 1 cm a step asked
    assert np.abs(states[-1, :2] - states[0, :2]).max() < 0.01
    assert states[-1, 6] == pytest.approx(0.04, abs=0.002)  # fingers still open


@pytest.mark.render
@pytest.mark.slow  # about 15 s: two or three cameras rendered on the CPU
def test_aloha_absolute_joints_reach_their_targets(short_scenario: Path, tmp_path: Path,
                                                   render_device) -> None:
    with serving(Aloha(arms=2, joints=7, offset=0.2)) as (server, uri):
        row = _play(uri, short_scenario, tmp_path / "aloha", "--policy-profile", "aloha",
                    "--embodiment", "dual_panda", "--replan-steps", "5")
    _no_fault(row, server)
    assert len(server.requests) == 4  # --replan-steps 5 over the profile's 25
    assert set(server.requests[0]["images"]) == {"cam_high", "cam_left_wrist",
                                                 "cam_right_wrist"}
    first, last = (np.asarray(server.requests[i]["state"]) for i in (0, -1))
    assert (last - first)[[0, 8]] == pytest.approx([0.2, 0.2], abs=0.02)
    assert last[[7, 15]] == pytest.approx([1.0, 1.0], abs=0.02)  # grippers open


def test_a_profile_file_runs_a_state_only_episode(short_scenario: Path, tmp_path: Path) -> None:
    profile = tmp_path / "joint_delta_server.toml"
    profile.write_text(JOINT_DELTA_PROFILE, encoding="utf-8")
    with serving(JointDelta()) as (server, uri):
        row = _play(uri, short_scenario, tmp_path / "mine", "--policy-profile", str(profile))
        assert run(["run", "--out", str(tmp_path / "mine"), "--workers", "0"]) == 0  # resumes
    _no_fault(row, server)
    with ResultStore.open(tmp_path / "mine", readonly=True) as store:
        config = store.config
    assert (config.control_mode, config.replan_steps, config.obs_mode) == ("joint_delta", 4,
                                                                             "state")
    assert len(server.requests) == 5
    joints = np.array([r["qpos"] for r in server.requests])
    assert (np.diff(joints[:, 0]) > 0.004).all()  # +0.01 rad asked per step
    assert np.abs(joints[-1, 1:7] - joints[0, 1:7]).max() < 0.01
