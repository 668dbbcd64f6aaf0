"""open and close: pull a sliding part (a drawer) by its handle or push it shut; swing a
hinged one (a lid, a door) by its knob or handle (:mod:`.hinge`)."""

from __future__ import annotations

import numpy as np

from fsvla.compiler.pose import axis_angle_matrix

from ..motion import ArmDriver, Guard, Pose, Segment
from ..skills import (
    DOWN,
    SQUEEZE_STEP,
    UP,
    Grasp,
    Plan,
    fixed_jaw_shifted,
    free_speed,
    nearest_arm,
    opening_for,
    reaches,
    transit,
)
from ..style import Style
from ..world import World
from .common import (
    HAND_HALF_WIDTH,
    HANDLE_DEPTH,
    push_force,
    required_fraction,
    success_fraction,
)
from .hinge import (
    has_shape,
    hinge,
    knob_pinch_fits,
    lower_lid,
    pinch_force,
    squeeze_on,
    swing_door,
    swing_lid,
)
from .lid import LID_PAST_VERTICAL, lift_lid
from .lid_tab import pull_over
from .push_shut import push_shut


def part_handle(world: World, body: str):
    """The handle of a body's first part: (world centre, opening direction, travel)."""
    part, joint = world.part(body)
    link = world.link_pose(body, part.link)
    handle = world.shape(body, "handle", link=part.link)
    centre = link.R @ np.asarray(handle.pose.position) + link.p
    body_pose = world.body_pose(body)
    direction = body_pose.R @ np.asarray(joint.axis, dtype=np.float64)
    return centre, direction / np.linalg.norm(direction), joint.upper - joint.lower, handle


def push_part_closed(world: World, style: Style, body: str) -> Plan:
    """Close a sliding part by pushing its front with the closed fingers, pointing down,
    below the handle (pulling the handle back from far out is beyond a Panda's reach)."""
    centre, opening, travel, handle = part_handle(world, body)
    part, _joint = world.part(body)
    link = world.link_pose(body, part.link)
    arm = nearest_arm(world, centre)
    R = world.grasp_frame(arm, DOWN, np.cross(UP, opening))
    height = 0.5 * (link.p[2] + centre[2] - float(handle.half_size[2]))
    # the hand is HAND_HALF_WIDTH thick about the TCP across its fingers: it comes down
    # well in front of the handle (HANDLE_DEPTH proud of the front; a hand that grazes it
    # on the way down knocks the drawer in and then hits it at full push speed), comes up
    # to the handle slowly, and pushes from rest
    standoff = HAND_HALF_WIDTH + HANDLE_DEPTH + 0.035
    start = np.array([link.p[0], link.p[1], height]) + opening * standoff
    tcp = Pose(start, R)
    yield Segment(grippers={arm: 0.0}, gripper_steps=style.gripper_steps, label="fist")
    yield from transit(world, style, arm, tcp, exclude=(body,))
    link = world.link_pose(body, part.link)  # where the front is now
    gap = float(opening @ (tcp.p - link.p)) - HAND_HALF_WIDTH - HANDLE_DEPTH
    near = tcp.moved(-(gap - 0.006) * opening)
    yield Segment({arm: near}, speed=max(2 * style.contact_speed, 0.5 * style.approach_speed),
                  label="to part")
    touch = near.moved(-0.008 * opening)
    yield Segment({arm: touch}, speed=style.contact_speed, settle=style.settle,
                  label="touch part")
    push = world.open_fraction(body) * travel - 0.002  # stop at the end of travel
    goal = touch.moved(-push * opening)
    # careful: a move-until-contact, so that a drawer meeting its stop (or a hand meeting
    # the carcass) does not spike the force: the push itself needs a few newtons
    guards = (Guard(arm, push_force(world, arm, body), body),) if style.avoid_hazards else ()
    # slowly: a rigid hand on a free-sliding drawer chatters, ~60 N spikes at 6 cm/s
    yield Segment({arm: goal}, speed=2 * style.contact_speed, settle=style.settle,
                  label="push part", guards=guards)
    for _ in range(3):  # the wrist, thicker than the hand, may meet the front first
        left = world.open_fraction(body) * travel
        if left < 0.02 * travel:
            break
        goal = world.current_pose(arm).moved(-(left - 0.002) * opening)
        yield Segment({arm: goal}, speed=2 * style.contact_speed, settle=style.settle,
                      label="push part", guards=guards)
    back = world.current_pose(arm)
    yield Segment({arm: back.moved(0.04 * opening)}, speed=free_speed(style), label="back")
    yield Segment({arm: back.moved(0.04 * opening + 0.1 * UP)}, speed=free_speed(style),
                  label="up")


def plan_move_part(world: World, style: Style, body: str, fraction: float) -> Plan:
    """Pull a sliding part's handle until it is open by ``fraction`` (closing: push)."""
    if fraction < world.open_fraction(body):
        yield from push_part_closed(world, style, body)
        return
    centre, opening, travel, handle = part_handle(world, body)
    part, _joint = world.part(body)
    half = np.asarray(handle.half_size, dtype=np.float64)
    arm = _handle_arm(world, centre, 2 * float(half[2]))
    if arm != nearest_arm(world, centre):
        # an arm reaching across to the other's side takes the handle's end on its own
        # side, away from the other arm
        link = world.link_pose(body, part.link)
        along = link.R[:, int(np.argmax(half[:2]))]
        if along @ (world.base_position(arm) - centre) < 0:
            along = -along
        centre = centre + max(0.0, float(half.max()) - HANDLE_END) * along
    delta = (fraction - world.open_fraction(body)) * travel
    tcp, width = _handle_grip(world, arm, -opening, centre, float(half[0]), float(half[2]),
                              delta * opening)
    approach = tcp.R @ world.approach_axis(arm)
    yield Segment(grippers={arm: 1.0}, gripper_steps=style.gripper_steps, label="open")
    # the IK branch that can still reach the handle where the pull ends
    yield from transit(world, style, arm, tcp.moved(-0.1 * approach), exclude=(body,),
                       then=tcp.moved(delta * opening))
    # careful: a move-until-contact (far out, a Panda's hand sagged below its command and
    # drove into the cabinet's front at 2 kN on its way in)
    guards = (Guard(arm, push_force(world, arm, body), body),) if style.avoid_hazards else ()
    yield Segment({arm: tcp}, speed=style.approach_speed, label="to handle", guards=guards)
    yield Segment(grippers={arm: opening_for(world, arm, width, style)},
                  gripper_steps=style.gripper_steps, settle=style.settle, label="grip handle")
    # careful: fingers that stop short of each other when closed (Baxter's) leave the handle
    # loose at the width model's opening: close on until the squeeze is felt
    yield from squeeze_on(world, style, arm, body, pinch_force(world, style, body),
                          step=SQUEEZE_STEP)
    yield Segment({arm: tcp.moved(delta * opening)}, speed=max(style.contact_speed * 4, 0.06),
                  settle=style.settle, label="slide part")
    yield Segment(grippers={arm: 1.0}, gripper_steps=style.gripper_steps, settle=style.settle,
                  label="let go")
    # slide off the end of the handle (backing away may be out of reach, and rising
    # would lift the handle), then back off and up
    part_link = world.link_pose(body, part.link)
    along = part_link.R[:, int(np.argmax(half[:2]))]
    if along @ (world.base_position(arm) - centre) < 0:
        along = -along
    off = world.current_pose(arm).moved((float(half.max()) + 0.035) * along)
    yield Segment({arm: off}, speed=free_speed(style), label="slide off")
    yield Segment({arm: off.moved(-0.03 * approach + 0.1 * UP)}, speed=free_speed(style),
                  label="up")


#: How far (m) from a handle's end an arm reaching across takes it.
HANDLE_END = 0.025


def _handle_arm(world: World, centre: np.ndarray, width: float) -> str:
    """The arm nearest a handle ``width`` (m) thick at ``centre`` among those whose fingers
    squeeze it (Baxter's left fingertips stop 1.6 cm apart when shut, its right ones 0.65
    cm: a 1.5 cm drawer handle is the right hand's), else the nearest."""
    by_distance = sorted(world.arm_names, key=lambda a: float(np.linalg.norm(
        (world.base_position(a) - centre)[:2])))
    return next((a for a in by_distance if world.min_width(a) <= width), by_distance[0])


#: How far (deg) a hand that cannot reach a drawer's handle level pitches down onto it,
#: in turn (a Z1 holds no level hand 11 cm above the table, 36 cm out).
HANDLE_PITCHES = (0.0, 30.0, 45.0, 60.0)


def _handle_grip(world: World, arm: str, inward: np.ndarray, centre: np.ndarray,
                 depth: float, thickness: float, pull: np.ndarray) -> tuple[Pose, float]:
    """The TCP pose that takes a drawer's handle (its centre, half ``depth`` along
    ``inward``, half ``thickness`` up), and the handle's width between the fingers there.
    The upright hand (fingers closing vertically) pointing ``inward``, of the two that
    differ by a half turn about the approach, from which one IK branch follows the pull by
    ``pull`` (m, world), the one nearer the hand's present turn first (low and close to a
    Panda's base, one of them has no comfortable answer at all); where neither is followed
    but the handle is reached, the nearer. Where the arm holds no such hand at the handle
    (a Z1 holds no level hand 11 cm above the table, 36 cm out), the hand pitched down
    about the handle's length by HANDLE_PITCHES in turn, its fingers closing across the
    handle, the first whose pull is followed. A gripper with one fixed jaw puts that jaw
    beside the handle (:meth:`World.grip_centre`)."""
    def driver() -> ArmDriver:
        return ArmDriver(arm, world.kinematics(arm), world.current_pose(arm),
                         world.arm_joints(arm), 1.0)

    level: tuple[Pose, float] | None = None
    for pitch in HANDLE_PITCHES:
        a = np.deg2rad(pitch)
        approach = np.cos(a) * inward + np.sin(a) * DOWN
        closing = np.cos(a) * UP + np.sin(a) * inward
        width = 2 * (thickness * np.cos(a) + depth * np.sin(a))
        start = centre - approach * (depth - 0.004)
        R0 = world.grasp_frame(arm, approach, closing)
        grips = [fixed_jaw_shifted(world, arm, Grasp(Pose(start, R), width, approach)).pose
                 for R in (R0, axis_angle_matrix(approach, np.pi) @ R0)]
        for tcp in grips:
            if driver().branch_that_tracks(tcp, tcp.moved(pull)) is not None:
                return tcp, width
        if level is None:  # the level hand: taken where reached, its pull followed or not
            level = (grips[0], width)
            if any(reaches(world, arm, tcp) for tcp in grips):
                return level
    assert level is not None
    return level


#: A careful pull that leaves a drawer open by less than this (a fraction of its travel)
#: past what is asked pulls again from where the handle is.
REPULL_MARGIN = 0.03
REPULLS = 2
#: An open fraction below this is shut: there is nothing to close.
SHUT = 0.02


#: A part is swung shut to this fraction of its range (then let go): a lid lowered onto
#: its seat would be pressed into it by the hand.
SWUNG_SHUT = 0.01


def plan_open(world: World, style: Style, roles: dict[str, str]) -> Plan:
    """A drawer: pull its handle; a lid: pinch its knob by its ends and lift it past upright
    (where it stays open) or as far as a requirement asks (where the careful pinch feels
    nothing, or the knob is wider than the gripper opens: lift it from below); a hinged
    door: pinch its handle and swing it open past the fraction asked."""
    body = roles["object"]
    part, joint = world.part(body)
    need = required_fraction(world, body)
    asked = max(need, success_fraction(world, body))  # what must hold at the end
    span = joint.upper - joint.lower
    if _sliding(world, body):
        target = max(0.8, need + 0.15)
        yield from plan_move_part(world, style, body, target)
        for _ in range(REPULLS):
            if not style.avoid_hazards or world.open_fraction(body) >= asked + REPULL_MARGIN:
                break
            # the handle slipped in the fingers, or the pull ended at the edge of the
            # reach: take it again where it is now and pull on
            yield from plan_move_part(world, style, body, target)
    elif _knob_lid(world, body):
        angle = min(max(LID_PAST_VERTICAL, (need + 0.07) * span), 0.95 * span)
        if knob_pinch_fits(world, body):
            least = min((asked + 0.07) * span, angle)
            # fingers too thick to hold the knob's ends lift it from below instead
            yield from swing_lid(world, style, body, angle, least,
                                 missed=lambda: lift_lid(world, style, body, angle))
        else:
            yield from lift_lid(world, style, body, angle)
    elif _handled_door(world, body):
        yield from swing_door(world, style, body, min(asked + 0.12, 0.95) * span)
    else:
        raise NotImplementedError(_unsupported(body, part.name, joint.type, "open"))


def plan_close(world: World, style: Style, roles: dict[str, str]) -> Plan:
    """A drawer: push its front shut. A part already shut: left alone. A lid standing open:
    pinch its knob, pull it over upright and lower it onto its seat. A hinged door:
    careful, push it shut with the closed hand on its face (:mod:`.push_shut`), or where
    no arm follows that, swing it by its handle; careless, swing it by its handle. Any
    other hinged panel, and a lid whose knob the hand cannot pinch (wider than it opens,
    out of reach, or felt nothing): push it shut."""
    body = roles["object"]
    part, joint = world.part(body)
    span = joint.upper - joint.lower
    if world.open_fraction(body) < SHUT:
        yield Segment(settle=20, label="already shut")
    elif _sliding(world, body):
        yield from push_part_closed(world, style, body)
    elif _knob_lid(world, body):
        yield from _close_lid(world, style, body, SWUNG_SHUT * span)
    elif _handled_door(world, body) and style.avoid_hazards:
        # pushed shut, holding nothing, where the arm follows the door's face; else by its
        # handle
        yield from push_shut(world, style, body, SWUNG_SHUT * span,
                             unreachable=lambda: swing_door(world, style, body, SWUNG_SHUT * span))
    elif _handled_door(world, body):
        yield from swing_door(world, style, body, SWUNG_SHUT * span)
    elif _hinged_panel(world, body):
        yield from push_shut(world, style, body, SWUNG_SHUT * span)
    else:
        raise NotImplementedError(_unsupported(body, part.name, joint.type, "close"))


def _close_lid(world: World, style: Style, body: str, angle: float) -> Plan:
    """A lid with a knob: lowered by its knob's ends where the fingers open across them
    (:func:`.hinge.lower_lid`), else pushed shut (:func:`.push_shut.push_shut`). Careful,
    a lid standing past upright that no grip by the knob's ends brings down is first
    pulled back over upright by its knob held flat (:func:`.lid_tab.pull_over`), and
    lowered as above from where it rests, if it does not fall shut."""
    fits = knob_pinch_fits(world, body)
    past = style.avoid_hazards and hinge(world, body).now > np.pi / 2

    if fits:
        tried = "nor could the hand hold its knob" + (" by its ends or flat" if past else "")
    else:
        tried = "its knob is wider than the gripper opens" + (", and no arm holds it flat"
                                                               if past else "")

    def push() -> Plan:
        return push_shut(world, style, body, angle, instead_of=tried)

    def lower() -> Plan:
        return lower_lid(world, style, body, angle, instead=push) if fits else push()

    if not past:
        yield from lower()
        return

    def pull() -> Plan:
        return pull_over(world, style, body, angle, then=lower, instead=push)

    yield from (lower_lid(world, style, body, angle, instead=pull) if fits else pull())


def _sliding(world: World, body: str) -> bool:
    """A prismatic part with a `handle` (a drawer)."""
    part, joint = world.part(body)
    return joint.type == "prismatic" and has_shape(world, body, part.link, "handle")


def _knob_lid(world: World, body: str) -> bool:
    """A revolute part with a `knob` and a `panel` (a lid hinged along one edge)."""
    part, joint = world.part(body)
    return (joint.type == "revolute" and has_shape(world, body, part.link, "knob")
            and has_shape(world, body, part.link, "panel"))


def _hinged_panel(world: World, body: str) -> bool:
    """A revolute part with a `panel` (a lid or a door, whatever it is held by)."""
    part, joint = world.part(body)
    return joint.type == "revolute" and has_shape(world, body, part.link, "panel")


def _handled_door(world: World, body: str) -> bool:
    """A revolute part with a `handle` and a `panel` (a door on a hinge)."""
    part, joint = world.part(body)
    return (joint.type == "revolute" and has_shape(world, body, part.link, "handle")
            and has_shape(world, body, part.link, "panel"))


def _unsupported(body: str, part: str, joint: str, verb: str) -> str:
    return (f"the experts cannot yet {verb} `{body}`'s {joint} `{part}`: they open and "
            f"close drawers and doors by a `handle` and lids by a `knob`, and push shut "
            f"any hinged part with a `panel`")


__all__ = ["SHUT", "part_handle", "plan_close", "plan_move_part", "plan_open", "push_part_closed"]
