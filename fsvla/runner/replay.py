"""Replay one recorded episode and check that it comes out identical (``fsvla replay``).

The episode's spec (scenario, level, layout seed, W and V with their seeds) and the run's
configuration (modes, embodiment, termination) rebuild its environment from scratch;
the layout digest, the instruction and the perturbation are compared with the recorded
ones. Then either the recorded actions are stepped through again (the default: no policy
needed) or the run's policy plays the episode again (``with_policy``: meaningful for
deterministic policies), and the new per-step record is compared with the stored trace,
every float bit for bit. A faulted episode replays the steps that ran.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from fsvla.results import ResultStore, layout_digest
from fsvla.runner.episode import Fault, play
from fsvla.runner.worker import load_run_policy, make_env

#: Trace keys holding per-step numbers (compared bit for bit, step by step).
_ARRAYS = ("actions", "margins", "costs", "step_costs", "success_values")


class ReplayInputError(ValueError):
    """A replay that cannot start: no run there, no such episode, nothing recorded.
    ``argument`` names the argument at fault."""

    def __init__(self, argument: str, message: str) -> None:
        self.argument = argument
        super().__init__(message)


@dataclass
class ReplayResult:
    episode_id: str
    mode: str  # "actions" or "policy"
    recorded_steps: int
    replayed_steps: int
    recorded_fault: str | None  # the episode's failure_reason
    replay_fault: str | None = None  # a fault while replaying (with_policy: should match)
    differences: list[str] = field(default_factory=list)
    video: Path | None = None
    video_note: str | None = None

    @property
    def identical(self) -> bool:
        return not self.differences


def replay_episode(run_dir: Path, episode_id: str, *, with_policy: bool = False,
           video: Path | None = None) -> ReplayResult:
    """Replay ``episode_id`` of the run in ``run_dir`` (see the module doc)."""
    run_dir = Path(run_dir)
    try:
        store = ResultStore.open(run_dir, readonly=True)
    except (FileNotFoundError, ValueError) as err:
        raise ReplayInputError("RUN_DIR", str(err)) from None
    with store:
        try:
            row = store.episode(episode_id)
        except KeyError:
            raise ReplayInputError("EPISODE_ID", _unknown(episode_id, store)) from None
        config = store.config
        recorded = store.trace(episode_id)
    if recorded is None:
        raise ReplayInputError("EPISODE_ID", f"episode {episode_id} has no trace: it faulted "
                               f"before a step ran ({row.failure_reason}: {row.failure_detail})")
    spec = row.spec()
    frames: list[np.ndarray] | None = [] if video is not None else None
    env, note = _environment(spec, config, frames is not None)
    result = ReplayResult(episode_id=episode_id, mode="policy" if with_policy else "actions",
                          recorded_steps=len(recorded["actions"]), replayed_steps=0,
                          recorded_fault=row.failure_reason, video_note=note)
    if note is not None:
        frames = None
    result.differences += _setup_differences(env, row)

    def on_frame(observation: dict[str, Any]) -> None:
        if frames is not None:
            images = observation.get("images")
            frames.append(_tile(images) if images else env.render())

    if with_policy:
        try:
            play(env, load_run_policy(config), spec, timeout=config.policy_timeout_s,
                 on_frame=on_frame, replan_steps=config.replan_steps)
        except Fault as fault:
            result.replay_fault = fault.reason
        if result.replay_fault != row.failure_reason:
            result.differences.append(f"the episode ended with {row.failure_reason or 'no fault'} "
                                      f"when recorded, {result.replay_fault or 'no fault'} now")
    else:
        result.differences += _step_actions(env, recorded["actions"], row.status == "completed",
                                            on_frame)
    replayed = env.episode_record().to_dict()
    result.replayed_steps = len(replayed["actions"])
    result.differences += compare_traces(recorded, replayed)
    if frames:
        from fsvla.runner.video import write_video

        result.video, result.video_note = write_video(frames, video, 1.0 / env.control_dt)  # type: ignore[arg-type]
    env.close()
    return result


def compare_traces(recorded: dict[str, Any], replayed: dict[str, Any]) -> list[str]:
    """Where two ``EpisodeRecord.to_dict()`` differ (empty when identical, floats bit for
    bit); per-step values name the first step that differs."""
    differences = []
    if len(recorded["actions"]) != len(replayed["actions"]):
        differences.append(f"{len(recorded['actions'])} steps recorded, "
                           f"{len(replayed['actions'])} replayed")
    for key in sorted(set(recorded) | set(replayed)):
        old, new = recorded.get(key), replayed.get(key)
        if key in _ARRAYS or key == "states":
            step = _first_difference(old, new, numeric=key != "states")
            if step is not None:
                differences.append(f"{key} differ from step {step} on")
        elif old != new:
            differences.append(f"{key}: {old!r} recorded, {new!r} replayed")
    return differences


def _first_difference(old: Any, new: Any, *, numeric: bool) -> int | None:
    old, new = list(old or []), list(new or [])
    for index in range(max(len(old), len(new))):
        if index >= len(old) or index >= len(new):
            return index + 1
        if numeric:
            a = np.asarray(old[index], dtype=np.float64)
            b = np.asarray(new[index], dtype=np.float64)
            if a.shape != b.shape or a.tobytes() != b.tobytes():
                return index + 1
        elif old[index] != new[index]:
            return index + 1
    return None


def _environment(spec: Any, config: Any, render: bool) -> tuple[Any, str | None]:
    """The episode's environment; with rendering for a video when possible."""
    from fsvla.sim.render import RenderUnavailable

    wants = render and config.obs_mode != "rgb"  # rgb episodes render their observations
    try:
        return make_env(spec, config, render=wants), None
    except RenderUnavailable as err:
        if not wants:
            raise
        return make_env(spec, config), f"no video: {err}"


def _setup_differences(env: Any, row: Any) -> list[str]:
    found = []
    digest = layout_digest(env.scene_spec)
    if row.layout_digest is not None and digest != row.layout_digest:
        found.append(f"the layout differs (digest {digest[:12]}, recorded "
                     f"{row.layout_digest[:12]}): the scenario file or the compiler changed")
    if row.instruction is not None and env.language.text != row.instruction:
        found.append(f"the instruction differs: {env.language.text!r} now, "
                     f"{row.instruction!r} recorded")
    if row.perturbation is not None and env.vision != row.perturbation:
        found.append("the vision perturbation differs from the recorded one")
    return found


def _step_actions(env: Any, actions: list[list[float]], completed: bool,
                  on_frame: Any) -> list[str]:
    observation, _ = env.reset()
    on_frame(observation)
    ended = False
    for step, action in enumerate(actions, start=1):
        observation, _, terminated, truncated, _ = env.step(np.asarray(action, dtype=np.float64))
        on_frame(observation)
        ended = terminated or truncated
        if ended and step < len(actions):
            return [f"the replay ended at step {step}, the recording ran {len(actions)} steps"]
    if completed and not ended:
        return [f"the recording ended at step {len(actions)}, the replay did not"]
    return []


def _tile(images: dict[str, np.ndarray]) -> np.ndarray:
    from fsvla.runner.video import tile

    return tile(images)


def _unknown(episode_id: str, store: ResultStore) -> str:
    import difflib

    ids = sorted(store.recorded_ids())
    near = difflib.get_close_matches(episode_id, ids, n=1, cutoff=0.6)
    hint = f"; did you mean {near[0]}?" if near else ""
    return f"no episode {episode_id!r} recorded in {store.run_dir} ({len(ids)} recorded){hint}"


__all__ = ["ReplayInputError", "ReplayResult", "compare_traces", "replay_episode"]
