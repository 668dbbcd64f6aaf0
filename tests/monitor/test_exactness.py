"""The optimised monitor against brute force on every built-in scenario.

Each scenario's env is driven along a seeded, smooth random joint trajectory that
dips every arm to the task object and back, then to a distance channel's reference (a
hazard) and back. At every control step each distance
channel's margin is recomputed from scratch: fresh FCL pieces, placed at the poses the
monitor holds at the step's end and at every sampled instant of the step's interpolated
motion (``fsvla.monitor.sweep``), every piece pair (no broad phase, no bound, no memo),
and the step's rule applied to those. Where the design promises exactness (the distance
below limit + ε + EXACT_BAND) the margins agree to 1e-9; beyond it the monitor's margin
is a lower bound that is itself beyond the band.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from fsvla.compiler.collision import signed_distance

import fsvla
from fsvla.monitor import kernels
from fsvla.monitor.channels import EXACT_BAND, TOUCH_DEPTH
from fsvla.monitor.geometry import MAX_DISTANCE, POSE_TOLERANCE
from fsvla.monitor.layout import build_geometry
from fsvla.selectors import named_sets
from fsvla.sim.kinematics import ArmKinematics

#: The paper's diagnostic subset: every per-scenario check here, over each of them (the
#: whole catalogue would grow CI with every scenario added).
DIAGNOSTIC = sorted(named_sets()["diagnostic"].scenarios)

pytestmark = pytest.mark.sim
DISTANCE_METRICS = frozenset({"clearance", "zone_distance", "separation", "untouched", "do_not_disturb"})
STEPS = 80
GJK_TOLERANCE = 1e-6  # m: FCL's distance is found to this (its default GJK tolerance)
DIP_S = 2.0  # s per dip


def _reach_targets(env) -> list[np.ndarray]:
    """5 cm above the first movable body the success condition names (else the first
    one), then 5 cm above the first distance channel's reference that is not a robot part."""
    movable = [b for b in env.scene_spec.bodies if not b.is_static]
    text = str(env.monitor_spec.success.condition)
    body = next((b for b in movable if repr(b.name) in text), movable[0])
    targets = [np.asarray(body.pose.position) + np.asarray(body.asset.bounds.center) + [0.0, 0.0, 0.05]]
    monitor = env.monitor
    for ch in monitor.spec.channels:
        frames = monitor.evaluator.layout.frames(ch.reference) if ch.reference else frozenset()
        bounds = monitor.geometry.bounds(frames) if frames and not any(f.startswith("@") for f in frames) else None
        if ch.metric in DISTANCE_METRICS and bounds is not None:
            lo, hi = bounds
            targets.append(np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, hi[2] + 0.05]))
            break
    return targets


def _actions(env, rng: np.random.Generator) -> np.ndarray:
    """Per arm: a dip from home to the task object and back (joints by IK) every 2 s, plus
    two sinusoids of random phase per joint; the gripper opens and closes. Two arms reach
    for the same object, so they come close to each other."""
    t = np.arange(STEPS)[:, None] * env.control_dt
    dip = 0.5 - 0.5 * np.cos(2 * np.pi * t / DIP_S)
    targets = _reach_targets(env)
    which = (t[:, 0] // DIP_S).astype(int) % len(targets)  # the dip's target
    blocks = []
    for arm in env.built.robot.arms.values():
        kinematics = ArmKinematics(arm)
        home = np.asarray(arm.spec.home, dtype=np.float64)
        reaches = np.array([kinematics.inverse(tuple(p), kinematics.top_down(), restarts=2).qpos
                            for p in targets])
        reach = reaches[which]
        n = len(home)
        amplitude = rng.uniform(0.1, 0.4, n)
        freq = rng.uniform(0.3, 1.0, (2, n))
        phase = rng.uniform(0, 2 * np.pi, (2, n))
        q = home + dip * (reach - home) + amplitude * 0.5 * (np.sin(2 * np.pi * freq[0] * t + phase[0])
                                                          + np.sin(2 * np.pi * freq[1] * t + phase[1]))
        blocks += [q, 0.5 + 0.5 * np.sin(2 * np.pi * 0.7 * t + phase[0, :1])]
    actions = np.concatenate(blocks, axis=1)
    return np.clip(actions, env.action_space.low, env.action_space.high).astype(np.float32)


def _brute_swept(fresh, start: dict, end: dict, samples: int, a: frozenset[str], b: frozenset[str],
                 limit: float, warn: float) -> float:
    """The sweep's rule by brute force: the distance at the step's end, or, where an instant
    of its interpolated motion came below the threshold the end is beyond, the smallest."""
    at_end = _brute_distance(fresh, end.__getitem__, a, b)
    target = warn if at_end >= warn else limit if at_end >= limit else None
    if target is None:
        return at_end
    frames = sorted(a | b)
    first, last = np.array([start[f] for f in frames]), np.array([end[f] for f in frames])
    rows, poses = np.arange(len(frames)), last.copy()
    inside = math.inf
    for k in range(1, samples):  # the monitor's interpolation (test_sweep holds it to scipy's)
        kernels.interpolate_frames(first, last, rows, k / samples, poses)
        inside = min(inside, _brute_distance(fresh, dict(zip(frames, poses)).__getitem__, a, b))
    return inside if inside < target else at_end


def _brute_distance(fresh, poses, a: frozenset[str], b: frozenset[str]) -> float:
    best = MAX_DISTANCE
    for fa in a:
        for pa in fresh.frame_pieces(fa):
            pa.place(poses(fa))
            for fb in b:
                if fb == fa:
                    continue
                for pb in fresh.frame_pieces(fb):
                    pb.place(poses(fb))
                    best = min(best, signed_distance(pa.obj, pb.obj))
    return best


@pytest.mark.parametrize("name", DIAGNOSTIC)
def test_distance_margins_match_brute_force(name):
    env = fsvla.make(name, monitor=True)
    monitor = env.monitor
    layout, geometry = monitor.evaluator.layout, monitor.geometry
    robot_frames = [f for f in geometry.frames if f.startswith("@")]
    fresh = build_geometry(env.scene_spec, layout,
                           {f: env.built.frame_shapes(f) for f in robot_frames})
    states = []
    step = monitor.evaluator.step
    monitor.evaluator.step = lambda state: (states.append(state), step(state))[1]
    channels = [(k, c) for k, c in enumerate(monitor.spec.channels) if c.metric in DISTANCE_METRICS]
    env.reset()
    checked = exact = 0
    end = {f: geometry.pose(f).copy() for f in geometry.frames}
    for action in _actions(env, np.random.default_rng(7)):
        _, _, _, _, info = env.step(action)
        state = states[-1]
        for frame, pose in state.poses.items():  # the monitor's poses are the scene's, to POSE_TOLERANCE
            if geometry.has(frame):
                assert np.abs(geometry.pose(frame) - pose).max() <= POSE_TOLERANCE
        start, end = end, {f: geometry.pose(f).copy() for f in geometry.frames}
        margins = list(info["margins"].values())
        for k, ch in channels:
            reference = layout.frames(ch.reference)
            m = min(_brute_swept(fresh, start, end, monitor.spec.substeps, layout.frames(s), reference, ch.limit,
                                 ch.limit + ch.soft_threshold) for s in ch.subjects)
            if ch.metric == "untouched" and any(state.touching(layout.frames(s), reference) for s in ch.subjects):
                m = min(m, -TOUCH_DEPTH)
            exact_below = ch.limit + ch.soft_threshold + EXACT_BAND
            q = ch.limit - m if ch.comparison == "<=" else m - ch.limit
            checked += 1
            if m < exact_below:
                exact += 1
                assert margins[k] == pytest.approx(q, abs=1e-9), (ch.name, state.step)
            else:
                assert ch.comparison == ">="
                # a box-gap lower bound against FCL's distance: equal up to GJK's tolerance
                assert exact_below - ch.limit - 1e-9 <= margins[k] <= q + GJK_TOLERANCE, (ch.name, state.step)
    assert checked == 0 or exact > 0, "the trajectory never brought a distance into its exact band"
