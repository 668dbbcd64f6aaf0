"""Record the careful expert's safe, successful episodes of a scenario as demonstrations.

Each attempt is one episode at the requested level with the next layout seed: the careful
expert (``fsvla.experts``) runs it through the gymnasium environment, and the episode is
kept only if the task succeeded and no safety channel was ever violated. Kept episodes
go to a LeRobot dataset (``fsvla.collect.lerobot``): per frame the observation the
policy saw (multi-view images, joint state, tool poses), the action it then took, and
the instruction as the task. ``meta/fsvla_collect.json`` records the attempts, so a
collection that is interrupted resumes at the next seed and never repeats one.
"""

from __future__ import annotations

import json
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from fsvla.library import ScenarioRef, load_scenario

from .lerobot import Frame, LeRobotWriter, features

PROGRESS_FILE = "fsvla_collect.json"


@dataclass
class CollectProgress:
    """Where a collection stands; saved after every attempt."""

    scenario: str
    level: str
    next_seed: int = 0
    attempts: int = 0
    kept: int = 0
    rejected: dict[str, int] = field(default_factory=dict)  # reason -> attempts

    def to_json(self) -> str:
        return json.dumps(self.__dict__, indent=2)


def collect(scenario: ScenarioRef, out: Path, episodes: int, *, level: str = "L0",
            images: bool = True, max_attempts: int | None = None,
            cameras: Sequence[str] | None = None, resolution: str | None = None,
            on_attempt: Callable[[CollectProgress], None] | None = None) -> CollectProgress:
    """Collect until ``out`` holds ``episodes`` kept episodes or ``max_attempts`` (default
    three per wanted episode) attempts have been made in all; returns the progress.
    ``cameras`` (names; None: all) and ``resolution`` (``"WIDTHxHEIGHT"``; None: each
    camera's own) choose the pictures recorded."""
    from fsvla.env import make
    from fsvla.experts import make_expert

    source = load_scenario(scenario)
    out = Path(out)
    progress = _load_progress(out, source.name, level)
    limit = max_attempts if max_attempts is not None else 3 * episodes
    writer: LeRobotWriter | None = None
    obs_mode = "rgb" if images else "state"
    while progress.kept < episodes and progress.attempts < limit:
        env = make(source, level=level, seed=progress.next_seed, obs_mode=obs_mode,
                   cameras=cameras, resolution=resolution)
        if writer is None:
            writer = _writer(out, env)
            progress.kept = writer.episodes
            if progress.kept >= episodes:
                break
        frames, reason = _attempt(env, make_expert(env, "careful"))
        if reason is None:
            writer.add_episode(frames, env.instruction)
            progress.kept = writer.episodes
        else:
            progress.rejected[reason] = progress.rejected.get(reason, 0) + 1
        progress.attempts += 1
        progress.next_seed += 1
        _save_progress(out, progress)
        if on_attempt is not None:
            on_attempt(progress)
    return progress


def _attempt(env, expert) -> tuple[list[Frame], str | None]:
    """Run one episode; its frames, and why it is rejected (None: kept)."""
    obs, _ = env.reset()
    expert.reset(None)  # scripted experts plan from the bound env, not from EpisodeInfo
    frames: list[Frame] = []
    done = False
    while not done:
        for action in np.atleast_2d(expert.act(obs)):
            agent = obs["agent"]
            frames.append(Frame(
                state=np.concatenate([agent["qpos"], agent["gripper"]]).astype(np.float32),
                tcp_pose=np.asarray(agent["tcp_pose"], dtype=np.float32),
                action=np.asarray(action, dtype=np.float32),
                images=dict(obs.get("images", {}))))
            obs, _, terminated, truncated, _ = env.step(action)
            if terminated or truncated:
                done = True
                break
    record = env.episode_record()
    if (record.margins < 0).any():
        return frames, "violation"
    if not record.success:
        return frames, "no success"
    return frames, None


def _writer(out: Path, env) -> LeRobotWriter:
    codec = env.codec
    arms = [arm.name for arm in codec.arms]
    state = [f"{a.name}.{j}" for a in codec.arms for j in a.joints] + [f"{a}.gripper" for a in arms]
    tcp = [f"{a}.{c}" for a in arms for c in ("x", "y", "z", "qw", "qx", "qy", "qz")]
    cameras = ({c.name: (c.height, c.width) for c in env.render_spec.cameras}
               if env.config.obs_mode == "rgb" else {})
    fps = 1.0 / env.control_dt
    return LeRobotWriter(out, fps=fps, robot_type=env.config.embodiment,
                         features=features(state, tcp, codec.labels, cameras, fps))


def _load_progress(out: Path, scenario: str, level: str) -> CollectProgress:
    path = out / "meta" / PROGRESS_FILE
    if not path.exists():
        return CollectProgress(scenario=scenario, level=level)
    saved = CollectProgress(**json.loads(path.read_text(encoding="utf-8")))
    if (saved.scenario, saved.level) != (scenario, level):
        raise ValueError(f"{out} holds demonstrations of {saved.scenario} at {saved.level}, not "
                         f"{scenario} at {level}; collect into another folder")
    return saved


def _save_progress(out: Path, progress: CollectProgress) -> None:
    path = out / "meta" / PROGRESS_FILE
    temporary = path.with_suffix(".json.tmp")
    temporary.write_text(progress.to_json(), encoding="utf-8")
    os.replace(temporary, path)


__all__ = ["PROGRESS_FILE", "CollectProgress", "collect"]
