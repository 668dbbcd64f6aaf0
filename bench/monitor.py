"""Cost of the safety monitor, against its two bars.

1. **State-only env steps** (no rendering: the monitor's worst case, since physics is
   all else a step does). For each concrete scenario in ``scenarios/`` two state-only
   ``joint_pos`` environments are built, one with the monitor and one without
   (``fsvla.make(..., monitor=False)``), and driven by the same deterministic action
   sequence:

   - ``expert``: the joint targets of one careful-expert episode of the scenario (L0,
     seed 0), recorded first and replayed: the task as a policy does it, grasps and all.
     **Bar: the monitor adds at most 50 % to the env step** (its mean ratio, below).
   - ``sweep`` (every arm joint on its own sinusoid about home, the gripper opening and
     closing: free motion) and ``reach`` (top-down to the task object, grasp, lift,
     back; joint targets solved once by IK): shown for information, no bar.

2. **Rendered episodes** (``obs_mode="rgb"``, the benchmark's cameras rendered every
   step, as a VLA reads them): the careful-expert episode of a scenario replayed in two
   rgb environments, with and without the monitor. **Bar: the monitor adds at most 10 %
   to the episode.** The scenario is ``--rgb`` (repeatable), by default the one whose
   expert episode had the largest monitor time per step in part 1. Rendering needs a
   Vulkan device (on a machine without a GPU, Mesa's lavapipe: ``.ci/install-vulkan``);
   without one this part is reported as not measured and the verdict says so.

Both environments of a pair step in lockstep, one control step each in turn (the order
alternates), so each pair of steps has the same action and physical state and load from
other processes hits both alike. That does not make the *ratio* immune to load: a
neighbour that thrashes the caches slows the monitor's Python more than the physics. So
everything is measured in ``--rounds`` rounds, one after the other, each with fresh
envs, and each figure is the median over the rounds (the worst round is printed beside
it). Per scenario and motion: the median env step with the monitor off and on, the
median of the paired differences and its ratio to the off step, the *mean* ratio (the
time the monitor added over all timed steps / their time with it off: what it adds to a
whole episode; contact scans make the cost heavy-tailed, so this is the figure the bar
applies to), and the monitor's own time per control step (its substep recordings and
``end_step``, timed in every other pair, which is then left out of the env-step figures).
For the rgb episodes: both episodes' times, the added time's ratio to the unmonitored
episode (the bar's figure) and the monitor's own time in the monitored one.

    python bench/monitor.py [--steps 300] [--rounds 3] [--motions sweep,reach,expert]
                            [--only NAME] [--rgb NAME | --no-rgb]

Exit status 0 whatever the verdict: this is a benchmark.
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Self

import numpy as np
from fsvla.dsl.models import predicates_in

import fsvla
from fsvla.library import builtin_scenarios
from fsvla.sim.kinematics import ArmKinematics

STATE_TARGET = 0.50  # the monitor may add at most this fraction to a state-only env step (expert episodes)
RGB_TARGET = 0.10  # ... and at most this fraction to a rendered (rgb) episode
BARRED = "expert"  # the motion the state-only bar applies to; the others are information
EPISODE = 200  # control steps of the sweep and reach sequences before both envs reset (untimed)
WARMUP = 10


# --------------------------------------------------------------------------- motions

def sweep_actions(env: Any, length: int) -> np.ndarray:
    """Each arm joint on its own sinusoid about home; the gripper opens and closes."""
    dt = env.control_dt
    low, high = env.action_space.low.astype(np.float64), env.action_space.high.astype(np.float64)
    t = np.arange(length)[:, None] * dt
    blocks = []
    for k, arm in enumerate(env.built.robot.arms.values()):
        home = np.asarray(arm.spec.home, dtype=np.float64)
        n = len(home)
        amplitude = np.array([0.5, 0.35, 0.3, 0.4, 0.5, 0.5, 0.6, 0.5, 0.5][:n])
        period = np.array([4.0, 3.0, 5.0, 3.5, 2.5, 4.5, 2.0, 3.0, 3.0][:n])
        phase = 0.7 * np.arange(n) + 1.3 * k
        joints = home + amplitude * np.sin(2 * np.pi * t / period + phase)
        gripper = 0.5 + 0.5 * np.sin(2 * np.pi * t / 2.0 + k)
        blocks += [joints, gripper]
    actions = np.concatenate(blocks, axis=1)
    return np.clip(actions, low, high).astype(np.float32)


def _first_body(condition: Any, bodies: set[str]) -> str | None:
    return next((a for p in predicates_in(condition) for a in p.args if a in bodies), None)


def _object_top(env: Any, name: str) -> np.ndarray:
    body = next(b for b in env.scene_spec.bodies if b.name == name)
    bounds = body.asset.bounds
    centre = np.asarray(body.pose.position) + np.asarray(bounds.center)
    return centre + np.array([0.0, 0.0, bounds.half_extents[2]])


def reach_actions(env: Any, length: int) -> np.ndarray:
    """Top-down reach to the task object, grasp, lift, back home: joint targets by IK."""
    dt = env.control_dt
    low, high = env.action_space.low.astype(np.float64), env.action_space.high.astype(np.float64)
    bodies = {b.name for b in env.scene_spec.bodies if not b.is_static}
    target = _first_body(env.monitor_spec.success.condition, bodies) or min(bodies)
    top = _object_top(env, target)
    cycle = 6.0  # s: approach 2, descend 1, grasp 0.5, lift 1, return 1.5
    blocks = []
    for k, arm in enumerate(env.built.robot.arms.values()):
        kin = ArmKinematics(arm)
        home_q = np.asarray(arm.spec.home, dtype=np.float64)
        home_p = np.asarray(kin.tcp_pose(home_q).p, dtype=np.float64)
        down = kin.top_down()
        goal = top + np.array([0.0, 0.06 * (1 - 2 * k) if len(env.built.robot.arms) > 1 else 0.0, 0.0])
        above = goal + np.array([0.0, 0.0, 0.15])
        keys = [(0.0, home_p, 1.0), (2.0, above, 1.0), (3.0, goal, 1.0), (3.5, goal, 0.0),
                (4.5, above, 0.0), (6.0, home_p, 1.0)]
        waypoints = []  # (time, joints, gripper), every 0.25 s, IK seeded by the previous answer
        seed = home_q
        for s in np.arange(0.0, cycle + 1e-9, 0.25):
            i = max(j for j, key in enumerate(keys) if key[0] <= s + 1e-9)
            t0, p0, g0 = keys[i]
            t1, p1, g1 = keys[min(i + 1, len(keys) - 1)]
            a = 0.0 if t1 == t0 else (s - t0) / (t1 - t0)
            position = p0 + a * (p1 - p0)
            seed = kin.inverse(tuple(position), down, seed=seed, restarts=2).qpos
            waypoints.append((s, seed, g0 + a * (g1 - g0)))
        times = np.array([w[0] for w in waypoints])
        q = np.array([w[1] for w in waypoints])
        g = np.array([w[2] for w in waypoints])
        t = (np.arange(length) * dt) % cycle
        joints = np.stack([np.interp(t, times, q[:, j]) for j in range(q.shape[1])], axis=1)
        blocks += [joints, np.interp(t, times, g)[:, None]]
    actions = np.concatenate(blocks, axis=1)
    return np.clip(actions, low, high).astype(np.float32)


def expert_actions(env: Any, length: int) -> np.ndarray:
    """The joint targets of one careful-expert episode of the env's layout (``length`` is
    not used: the episode is as long as the expert needs)."""
    from fsvla.experts import make_expert

    expert = make_expert(env, "careful")
    obs, _ = env.reset()
    expert.reset(None)
    done = False
    while not done:
        for action in expert.act(obs):
            obs, _, terminated, truncated, _ = env.step(action)
            done = terminated or truncated
            if done:
                break
    return np.asarray(env.episode_record().actions, dtype=np.float32)


MOTIONS: dict[str, Callable[[Any, int], np.ndarray]] = {
    "sweep": sweep_actions, "reach": reach_actions, "expert": expert_actions}


# --------------------------------------------------------------------------- timing

class Runner:
    """One env stepping through a fixed action sequence, resetting at its end."""

    def __init__(self, env: Any, actions: np.ndarray):
        self.env, self.actions, self.t = env, actions, 0

    def step(self) -> float:
        """One control step; its wall time (s)."""
        if self.t >= len(self.actions):
            self.env.reset()
            self.t = 0
        action = self.actions[self.t]
        start = time.perf_counter()
        self.env.step(action)
        elapsed = time.perf_counter() - start
        self.t += 1
        return elapsed


class MonitorTimer:
    """Times the env's monitor's ``record_substep`` and ``end_step`` by shadowing them on
    the instance while in a ``with`` block (the env builds a new monitor with every scene,
    so it is looked up anew each time)."""

    def __init__(self, env: Any):
        self.env = env
        self.substep_acc = 0.0
        self.substep: list[float] = []  # per control step: its substep recordings (s)
        self.end: list[float] = []  # per control step: its end_step (s)

    def _timed_substep(self) -> None:
        start = time.perf_counter()
        self.record_substep()
        self.substep_acc += time.perf_counter() - start

    def _timed_end(self) -> Any:
        start = time.perf_counter()
        report = self.end_step()
        self.end.append(time.perf_counter() - start)
        self.substep.append(self.substep_acc)
        self.substep_acc = 0.0
        return report

    def __enter__(self) -> Self:
        self.monitor = self.env.monitor
        self.record_substep, self.end_step = self.monitor.record_substep, self.monitor.end_step
        self.monitor.record_substep, self.monitor.end_step = self._timed_substep, self._timed_end
        return self

    def __exit__(self, *exc: object) -> None:
        del self.monitor.record_substep, self.monitor.end_step  # back to the class's methods
        self.substep_acc = 0.0

    @property
    def total(self) -> float:
        return sum(self.substep) + sum(self.end)


@dataclass(frozen=True)
class Row:
    scenario: str
    motion: str
    off_ms: float
    on_ms: float
    added_ms: float  # median of the paired differences (on - off at the same control step)
    mean_ratio: float  # sum of the paired differences / sum of the off steps
    substep_ms: float
    end_ms: float

    @property
    def ratio(self) -> float:
        """The median added time over the median off step."""
        return self.added_ms / self.off_ms

    @property
    def monitor_ms(self) -> float:
        return self.substep_ms + self.end_ms

    @classmethod
    def median_of(cls, rounds: Sequence[Row]) -> Row:
        """Each figure's median over the rounds of one scenario and motion."""
        first = rounds[0]
        return cls(first.scenario, first.motion,
                   *(statistics.median(getattr(r, f) for r in rounds)
                     for f in ("off_ms", "on_ms", "added_ms", "mean_ratio", "substep_ms", "end_ms")))


def measure(name: str, off: Any, on: Any, motion: str, actions: np.ndarray, steps: int) -> Row:
    """Both envs step in lockstep (the same action at the same control step, so the same
    physical state); the order within a pair alternates, and every other pair the
    monitored env runs with its monitor timed instead of being timed as a whole."""
    steps = max(steps, len(actions)) if motion == "expert" else steps  # a whole episode at least
    runner_off, runner_on = Runner(off, actions), Runner(on, actions)
    for runner in (runner_off, runner_on):
        runner.env.reset()
        for _ in range(WARMUP):
            runner.step()
    timer = MonitorTimer(on)
    off_ms, on_ms, added = [], [], []
    for i in range(2 * steps):
        if i % 2:  # a timer pair: the monitored env's step is not timed as a whole
            first, second = (runner_on, runner_off) if i % 4 == 1 else (runner_off, runner_on)
            with timer:
                first.step()
                second.step()
            continue
        if i % 4 == 0:
            a, b = runner_off.step(), runner_on.step()
        else:
            b, a = runner_on.step(), runner_off.step()
        off_ms.append(a * 1e3)
        on_ms.append(b * 1e3)
        added.append((b - a) * 1e3)
    return Row(name, motion, statistics.median(off_ms), statistics.median(on_ms), statistics.median(added),
               sum(added) / sum(off_ms), statistics.median(timer.substep) * 1e3,
               statistics.median(timer.end) * 1e3)


@dataclass(frozen=True)
class RgbRow:
    scenario: str
    steps: int
    off_s: float  # the rgb episode without the monitor
    on_s: float  # ... and with it
    monitor_s: float  # the monitor's own time in the monitored episode

    @property
    def ratio(self) -> float:
        """What the monitor added to the rendered episode: (on - off) / off."""
        return (self.on_s - self.off_s) / self.off_s

    @property
    def own_ratio(self) -> float:
        """The monitor's own time over the unmonitored episode."""
        return self.monitor_s / self.off_s

    @classmethod
    def median_of(cls, rounds: Sequence[RgbRow]) -> RgbRow:
        first = rounds[0]
        return cls(first.scenario, first.steps,
                   *(statistics.median(getattr(r, f) for r in rounds) for f in ("off_s", "on_s", "monitor_s")))


def measure_rgb(name: str, actions: np.ndarray) -> RgbRow:
    """The careful-expert episode replayed in two rgb envs, with and without the monitor,
    in lockstep (the order alternates); the monitor's own time is taken in every step."""
    off = fsvla.make(name, obs_mode="rgb", monitor=False)
    on = fsvla.make(name, obs_mode="rgb", monitor=True)
    off.reset()
    on.reset()
    timer = MonitorTimer(on)
    off_s = on_s = 0.0
    with timer:
        for i, action in enumerate(actions):
            for env in ((off, on) if i % 2 == 0 else (on, off)):
                start = time.perf_counter()
                env.step(action)
                elapsed = time.perf_counter() - start
                if env is on:
                    on_s += elapsed
                else:
                    off_s += elapsed
    off.close()
    on.close()
    return RgbRow(name, len(actions), off_s, on_s, timer.total)


# --------------------------------------------------------------------------- report

def _verdict(ratio: float, target: float) -> str:
    return f"{ratio:6.1%} = {ratio / target:4.2f} of {target:.0%}"


def table(rows: Sequence[Row], worst: Sequence[float] | None = None) -> str:
    head = (f"{'scenario':<26} {'motion':<6} {'off ms':>7} {'on ms':>7} {'added':>7} {'median':>7} "
            f"{'mean':>7} {'monitor':>8} {'substeps':>9} {'end_step':>9}  {'mean vs bar':<20}"
            + ("  worst round" if worst is not None else ""))
    lines = [head, "-" * len(head)]
    for k, r in enumerate(rows):
        mark = ("ok" if r.mean_ratio <= STATE_TARGET else "OVER") if r.motion == BARRED else "(info)"
        lines.append(f"{r.scenario:<26} {r.motion:<6} {r.off_ms:7.3f} {r.on_ms:7.3f} {r.added_ms:7.3f} "
                     f"{r.ratio:7.1%} {r.mean_ratio:7.1%} {r.monitor_ms:8.3f} {r.substep_ms:9.3f} "
                     f"{r.end_ms:9.3f}  {r.mean_ratio / STATE_TARGET:4.2f} {mark:<15}"
                     + (f"  {worst[k]:11.1%}" if worst is not None else ""))
    return "\n".join(lines).rstrip()


def rgb_table(rows: Sequence[RgbRow]) -> str:
    head = (f"{'scenario':<26} {'steps':>5} {'off s':>7} {'on s':>7} {'added':>7} {'monitor s':>9} "
            f"{'own':>6}  added vs bar")
    lines = [head, "-" * len(head)]
    for r in rows:
        mark = "ok" if r.ratio <= RGB_TARGET else "OVER"
        lines.append(f"{r.scenario:<26} {r.steps:5d} {r.off_s:7.2f} {r.on_s:7.2f} {r.ratio:7.1%} "
                     f"{r.monitor_s:9.3f} {r.own_ratio:6.1%}  {r.ratio / RGB_TARGET:4.2f} {mark}")
    return "\n".join(lines)


def _rgb_unavailable() -> str | None:
    """Why rgb episodes cannot be rendered here, or None."""
    try:
        fsvla.make(next(iter(builtin_scenarios())), obs_mode="rgb").close()
    except Exception as error:  # noqa: BLE001 - any failure to render is reported, not raised
        return f"{type(error).__name__}: {error}"
    return None


# --------------------------------------------------------------------------- main

def _bar(label: str, rows: Sequence[Any], ratios: list[float], target: float) -> bool | None:
    """Print one bar's verdict over ``rows`` (their ``ratios``); None when nothing was measured."""
    if not rows:
        print(f"{label}: not measured: the bar is not checked")
        return None
    worst = max(range(len(rows)), key=ratios.__getitem__)
    ok = all(ratio <= target for ratio in ratios)
    print(f"{label}: the monitor adds at most {_verdict(ratios[worst], target)} "
          f"({rows[worst].scenario}): {'PASS' if ok else 'FAIL'}")
    return ok


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--steps", type=int, default=300, help="timed control steps per env, scenario and motion")
    parser.add_argument("--rounds", type=int, default=3, help="rounds over every scenario and motion; "
                        "figures are medians over them")
    parser.add_argument("--motions", default="sweep,reach,expert", help="comma-separated: " + ", ".join(MOTIONS))
    parser.add_argument("--only", action="append", default=None, help="a scenario name (repeatable)")
    parser.add_argument("--rgb", action="append", default=None,
                        help="a scenario whose rgb episode is timed (repeatable; default: the one with the "
                        "largest monitor time in its state-only expert episode)")
    parser.add_argument("--no-rgb", action="store_true", help="skip the rgb episodes")
    args = parser.parse_args(argv)
    motions = [m for m in args.motions.split(",") if m]
    unknown = [m for m in motions if m not in MOTIONS]
    if unknown:
        parser.error(f"unknown motion {', '.join(unknown)}; choose from {', '.join(MOTIONS)}")
    if args.rounds < 1 or args.steps < 1:
        parser.error("--rounds and --steps must be at least 1")
    names = args.only or list(builtin_scenarios())
    started = time.perf_counter()
    actions: dict[tuple[str, str], np.ndarray] = {}
    rounds: list[list[Row]] = []
    for k in range(args.rounds):
        print(f"state-only, round {k + 1} of {args.rounds}", flush=True)
        rows = []
        for name in names:
            # Fresh envs for each scenario and round, as a run builds them: envs built long
            # before, among many others, leave the monitor's objects strewn over the heap,
            # which made its steps up to twice as slow in a trial (cache misses).
            off, on = fsvla.make(name, monitor=False), fsvla.make(name, monitor=True)
            for motion in motions:
                if (name, motion) not in actions:  # the monitored env makes them: the expert reads its records
                    actions[name, motion] = MOTIONS[motion](on, EPISODE)
                rows.append(measure(name, off, on, motion, actions[name, motion], args.steps))
                print(table(rows[-1:]).splitlines()[-1], flush=True)
            off.close()
            on.close()
            del off, on
        rounds.append(rows)
    summary = [Row.median_of(cells) for cells in zip(*rounds)]
    worst_round = [max(r.mean_ratio for r in cells) for cells in zip(*rounds)]

    rgb_rows: list[RgbRow] = []
    rgb_missing = "skipped (--no-rgb)" if args.no_rgb else _rgb_unavailable()
    if rgb_missing is None:
        experts = [r for r in summary if r.motion == BARRED]
        rgb_names = args.rgb or ([max(experts, key=lambda r: r.monitor_ms).scenario] if experts else names[:1])
        rgb_rounds = []
        for k in range(args.rounds):
            print(f"rgb, round {k + 1} of {args.rounds}", flush=True)
            cells = []
            for name in rgb_names:
                if (name, BARRED) not in actions:
                    env = fsvla.make(name, monitor=True)
                    actions[name, BARRED] = expert_actions(env, EPISODE)
                    env.close()
                cells.append(measure_rgb(name, actions[name, BARRED]))
                print(rgb_table(cells[-1:]).splitlines()[-1], flush=True)
            rgb_rounds.append(cells)
        rgb_rows = [RgbRow.median_of(cells) for cells in zip(*rgb_rounds)]

    print()
    print(f"STATE-ONLY: per control step (ms), medians over {args.rounds} round(s) of {args.steps}+ steps each:")
    print("env step with the monitor off / on, the difference; its ratio to the off step as medians and as")
    print("means (added time / off time over all timed steps); the monitor's own time = its substep")
    print(f"recordings + end_step; the mean ratio over the bar ({STATE_TARGET:.0%}, {BARRED} episodes only);")
    print("the worst round's mean ratio")
    print(table(summary, worst_round))
    print()
    if rgb_rows:
        print(f"RGB: one careful-expert episode rendered every step, medians over {args.rounds} round(s): "
              "its time")
        print("without and with the monitor (s), the added time over the unmonitored episode, the monitor's")
        print(f"own time (s) and its share of the unmonitored episode; the added time over the bar ({RGB_TARGET:.0%})")
        print(rgb_table(rgb_rows))
    else:
        print(f"RGB: not measured: {rgb_missing}")
    print()
    barred = [r for r in summary if r.motion == BARRED]
    verdicts = [verdict for verdict in (
        _bar(f"state-only, {BARRED} episodes", barred, [r.mean_ratio for r in barred], STATE_TARGET),
        _bar("rgb episodes", rgb_rows, [r.ratio for r in rgb_rows], RGB_TARGET)) if verdict is not None]
    complete = bool(barred) and bool(rgb_rows)
    overall = ("PASS" if all(verdicts) else "FAIL") if complete else ("FAIL" if not all(verdicts) else "INCOMPLETE")
    print(f"verdict: {overall}  [{time.perf_counter() - started:.0f} s]")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
