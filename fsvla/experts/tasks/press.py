"""press: press the object from above with closed fingers; the careful expert comes down
until its hand feels the press force (a guarded move), the careless one pushes a
centimetre into the object at full speed."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..motion import Guard, Pose, Segment
from ..skills import (
    DOWN,
    UP,
    Plan,
    attained,
    branch_for_path,
    leaning_frame,
    nearest_arm,
    transit,
)
from ..style import Style
from ..world import World, box_distance
from .common import HAND_HALF_LENGTH, retreat_home

#: Force (N) the careful press stops at where no limit watches the press.
PRESS_FORCE = 10.0
#: The careful press comes down PRESS_STEP (m) at a time, at most PRESS_STEPS times.
PRESS_STEP = 0.001
PRESS_STEPS = 40
#: The least force (N) it presses with: ``pressed`` needs a force a sensor tells from noise.
LEAST_PRESS = 2.0
#: The careful hold after the press: HOLD_STEPS control steps, the command's lead under
#: the hand changed by HOLD_STEP (m) at a time; above PRESS_EASE times the force it eases.
HOLD_STEPS = 20
HOLD_STEP = 0.0001
PRESS_EASE = 1.3


def press_force(world: World, arm: str, obj: str) -> float:
    """The force the careful expert presses ``obj`` with: PRESS_FORCE, or less where a
    contact-force limit watches the object or the hand: half the limit, and out of its
    warning band."""
    allowed = world.force_allowance("gripper", f"{arm}_gripper", obj)
    return max(LEAST_PRESS, PRESS_FORCE if allowed is None else min(PRESS_FORCE, allowed))


def plan_press(world: World, style: Style, roles: dict[str, str]) -> Plan:
    obj = roles["object"]
    lo, hi = world.bounds(obj)
    top = np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, hi[2] + 0.005])
    arm = nearest_arm(world, top)
    R = _press_frame(world, style, arm, obj, top)
    yield Segment(grippers={arm: 0.0}, gripper_steps=style.gripper_steps, label="close")
    yield from transit(world, style, arm, Pose(top + 0.08 * UP, R), exclude=(obj,))
    if style.avoid_hazards:  # down until the hand feels the press force, then hold
        # the closed fingers reach past the TCP: stop short of the top by that much
        reach = world.hand_reach(arm)
        yield Segment({arm: Pose(top + (reach + 0.005) * UP, R)}, speed=style.approach_speed,
                      label="touch")
        force = press_force(world, arm, obj)
        guard = Guard(arm, 0.5 * force, obj)  # the arm's lead adds the rest as it stops
        # a millimetre at a time, each step coming to rest: a stiff arm moving on at
        # constant speed would hit the object with the lead its command has on it
        pose = Pose(top + (reach + 0.005) * UP, R)
        for _ in range(PRESS_STEPS):
            if world.hand_force(arm, obj) >= 0.25 * force:
                break
            pose = pose.moved(-PRESS_STEP * UP)
            yield Segment({arm: pose}, speed=0.1 * style.contact_speed, guards=(guard,),
                          label="press")
        yield from _hold_press(world, style, arm, obj, R, force)
    else:
        yield Segment({arm: Pose(top, R)}, speed=style.approach_speed, label="touch")
        yield Segment({arm: Pose(top - np.array([0.0, 0.0, 0.01]), R)},
                      speed=style.contact_speed, settle=20, label="press")
    yield from retreat_home(world, style, arm)


def _hold_press(world: World, style: Style, arm: str, obj: str, R: np.ndarray,
                force: float) -> Plan:
    """Hold the press for HOLD_STEPS steps, the hand's command a little below where the
    hand is: a soft arm (Baxter's, the Z1's) lags its command, and held where the guard
    stopped it, it closes the gap and presses on to two or three times the force. The
    command's lead under the hand grows by HOLD_STEP while the hand feels less than half
    the force and shrinks while it feels more than PRESS_EASE times it."""
    lead = HOLD_STEP
    for _ in range(HOLD_STEPS):
        felt = world.hand_force(arm, obj)
        if felt > PRESS_EASE * force:
            lead -= HOLD_STEP
        elif felt < 0.5 * force:
            lead += HOLD_STEP
        else:
            yield Segment(settle=1, label="hold")
            continue
        lead = min(max(lead, -PRESS_STEP), 3 * PRESS_STEP)
        here = world.current_pose(arm).p
        yield Segment({arm: Pose(here - lead * UP, R)}, speed=0.1 * style.contact_speed,
                      settle=1, label="hold")


def _press_frame(world: World, style: Style, arm: str, obj: str, top: np.ndarray) -> np.ndarray:
    """The hand pointing down over ``top``, its long (closing) axis along y; careful: turned
    about the vertical (by 45° steps) to where the hand's two ends stay farthest from the
    hazards and the other objects beside the button (a hand 21 cm long lying across a
    neighbour comes down on it), among the turns the arm reaches above the top. Where the
    arm holds no hand pointing down there at all, one leaning (:func:`_leaning_frame`)."""
    reach = world.hand_reach(arm)

    def held(R: np.ndarray) -> np.ndarray:
        # turned by a degree or two to what the arm holds on the pressed top (a five-joint
        # arm's TCP sits off its wrist's roll axis: leaning out, an SO-101 misses the
        # exact turn by 2-3 mm, and no branch follows it down)
        return attained(world, arm, Pose(top + reach * UP, R)).R

    default = held(world.grasp_frame(arm, DOWN, np.array([0.0, 1.0, 0.0])))

    def followed(R: np.ndarray) -> bool:
        # reached above the top and on the way down to it, on one branch (a five-joint arm
        # holds a turned hand high above the button, not down on it)
        return branch_for_path(world, arm, (Pose(top + 0.05 * UP, R),
                                            Pose(top + reach * UP, R))) is not None

    def out_of_reach(R: np.ndarray) -> bool:
        # not even roughly (as a straight move tracks it: 5 mm, 3 deg), on any branch
        pose = Pose(top + reach * UP, R)
        result = world.kinematics(arm).inverse(tuple(pose.p), pose.quat, restarts=8)
        return not result.ok(position_tol=5e-3, rotation_tol=5e-2)

    if style.avoid_hazards:
        boxes = [(o.lo, o.hi, o.margin) for o in world.obstacles(exclude=(obj,))]
        for body in world.scene.bodies:
            if body.name not in (obj, "table"):
                lo, hi = world.bounds(body.name)
                boxes.append((lo, hi, 0.0))
        level = top + HAND_ABOVE * UP  # the hand's body, just above the top
        best: tuple[float, np.ndarray] | None = None
        for yaw in np.deg2rad([90.0, 45.0, 0.0, 135.0]) if boxes else ():  # y first
            closing = np.array([np.cos(yaw), np.sin(yaw), 0.0])
            R = held(world.grasp_frame(arm, DOWN, closing))
            if not followed(R):
                continue
            ends = (level + HAND_HALF_LENGTH * closing, level - HAND_HALF_LENGTH * closing)
            clearance = min(box_distance(p, lo, hi) - margin for lo, hi, margin in boxes
                            for p in ends)
            if best is None or clearance > best[0] + 0.005:
                best = (clearance, R)
        if best is not None:
            return best[1]
    if out_of_reach(default):
        leaning = _leaning_frame(world, arm, top, followed, held)
        if leaning is not None:
            return leaning
    return default


def _leaning_frame(world: World, arm: str, top: np.ndarray,
                   followed: Callable[[np.ndarray], bool],
                   held: Callable[[np.ndarray], np.ndarray]) -> np.ndarray | None:
    """Where no hand pointing down is reached over ``top``, on any branch (a small arm
    pressing far out and low: an SO-101 36 cm from its base), the hand leaning out from
    the base, or back toward it, by the least of LEANS that is (``held``: as the arm holds
    it); its fingers close across the lean, so that they stay level. None if none is."""
    return next((R for R in (held(leaning_frame(world, arm, top, float(lean)))
                             for lean in np.deg2rad(LEANS)) if followed(R)), None)


#: How far above the pressed top (m) the hand's body is measured for clearance.
HAND_ABOVE = 0.03
#: Leans (deg) of the hand from pointing down that :func:`_leaning_frame` tries in turn:
#: positive out, away from the arm's base; negative back toward it.
LEANS = (20.0, 35.0, 50.0, 65.0, -20.0, -35.0, -50.0)


__all__ = ["LEAST_PRESS", "PRESS_FORCE", "plan_press", "press_force"]
