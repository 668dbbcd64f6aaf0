"""The scripted experts as policies: ``reset(EpisodeInfo)``, ``act(observation)`` → an
action chunk, exactly like a learned policy, plus one hook for their privileged state.

The hook: an expert must be bound to the environment it acts in before ``reset``::

    expert = CarefulExpert()          # or load_policy("careful-expert")
    expert.bind_env(env)              # env: the fsvla.env.FsvlaEnv of this episode
    obs, info = env.reset()
    expert.reset(episode_info)
    chunk = expert.act(obs)           # (H, A) joint_pos or ee_pose actions

A runner should call ``bind_env`` on every policy that has it (``needs_env = True``),
once per episode, right after it builds the env; ``make_expert(env, "careful")`` does
both steps for scripts. ``reset`` reads the scene's state, so it must come after
``env.reset()``.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Iterator
from dataclasses import replace
from itertools import chain
from typing import Any

import numpy as np

from fsvla.compiler.pose import quat_to_matrix
from fsvla.dsl.catalog import BIMANUAL_TASKS

from .clearance import ArmClearance, LeastClearance
from .motion import ArmDriver, Guard, Pose, Segment, Step, expand
from .skills import carrying_arm, nearest_arm, park_others
from .style import CAREFUL, CARELESS, STYLES, Style
from .tasks import TASK_PLANS
from .tasks.arm_gap import OtherArmClearance
from .world import World

#: Actions per chunk the experts return (the plan is re-read between segments anyway).
CHUNK = 10


#: The control modes the experts' absolute targets are written in.
EXPERT_MODES = ("joint_pos", "ee_pose")


class ExpertNotBound(RuntimeError):
    """An expert was reset or asked to act without ``bind_env(env)``."""


class ExpertPolicy:
    """A scripted expert for the env it is bound to (see the module doc)."""

    needs_env = True

    def __init__(self, style: Style | str = CAREFUL, chunk: int = CHUNK) -> None:
        self.style = STYLES[style] if isinstance(style, str) else style
        self.name = f"{self.style.name}-expert"
        self.chunk = chunk
        self._env: Any = None
        self._world: World | None = None
        self._plan: Iterator[Segment] | None = None
        self._queue: deque[Step] = deque()
        self._drivers: dict[str, ArmDriver] = {}
        self._last: Step | None = None
        self.log: list[str] = []  # the segments executed, for tests and debugging
        self.labels: list[str] = []  # the segment of every action returned

    # ------------------------------------------------------------------ the hook
    def bind_env(self, env: Any) -> None:
        """Give the expert the environment whose privileged state it may read.

        The expert writes absolute targets, so the env must take them: ``joint_pos`` or
        ``ee_pose`` (a delta or velocity mode would read them as nonsense of the right size)."""
        mode = env.codec.mode.value
        if mode not in EXPERT_MODES:
            raise ValueError(f"the scripted experts act in the control modes "
                             f"{' and '.join(EXPERT_MODES)}, not {mode!r}: run them with "
                             f"--control-mode joint_pos (the default)")
        self._env = env

    # ------------------------------------------------------------------ policy API
    def reset(self, episode: Any = None) -> None:
        if self._env is None:
            raise ExpertNotBound(f"{self.name} needs the environment: call "
                                 "bind_env(env) before reset (see fsvla.experts)")
        # the scene as it is now: an env's reset may have built a new one since bind_env
        world = self._world = World.of_env(self._env)
        task = world.scenario.task
        if task.name not in TASK_PLANS:
            raise ValueError(f"no expert plan for task {task.name!r}")
        self._drivers = {}
        for name in world.arm_names:
            self._drivers[name] = ArmDriver(name, world.kinematics(name),
                                            world.current_pose(name), world.arm_joints(name),
                                            world.gripper_opening(name))
        task_plan, roles = TASK_PLANS[task.name], dict(task.roles)
        active = None  # the arm that works alone while the others park
        if task.name in BIMANUAL_TASKS or len(world.arm_names) == 1:
            plan = task_plan.plan(world, self.style, roles)
        else:
            # one arm works: the other first moves out of its way (where arms are kept apart)
            obj, target = task.roles["object"], task.roles.get("target")
            bodies = {body.name for body in world.scene.bodies}
            if task_plan.arm is not None:  # the task chooses its arm: chosen once, here
                active = task_plan.arm(world, self.style, roles)
                plan = task_plan.plan(world, self.style, roles, arm=active)
            else:
                active = carrying_arm(world, obj, target) if target in bodies \
                    else nearest_arm(world, world.body_pose(obj).p)
                plan = task_plan.plan(world, self.style, roles)
            work = tuple(world.body_pose(body).p for body in task.roles.values())
            plan = chain(park_others(world, self.style, active, work), plan)
        for name in world.arm_names:  # (the plans are generators: nothing has run yet)
            # the working arm keeps clear of the others where they stand (parked)
            others = tuple(a for a in world.arm_names if a != name) if name == active else ()
            self._keep_clear(world, name, others)
        self._plan = plan
        self._queue.clear()
        self._last = None
        self.log = []
        self.labels = []

    def _keep_clear(self, world: World, arm: str, others: tuple[str, ...] = ()) -> None:
        """Careful: the arm's IK chooses answers whose links, not only the hand, keep clear
        of the hazards that watch them and of the ``others`` arms where they stand."""
        if not self.style.avoid_hazards:
            return
        clearance = LeastClearance([ArmClearance(world, arm)] + [
            OtherArmClearance(world, arm, other) for other in others])
        self._drivers[arm].clearance = clearance if clearance.active else None

    def act(self, observation: dict[str, Any]) -> np.ndarray:
        if not self._drivers:
            raise ExpertNotBound(f"{self.name}: reset(episode) first")
        steps: list[Step] = []
        # a chunk ends with its segment: the plan reads the world when it is resumed, so
        # the next segment is made only once the last one has run
        while len(steps) < self.chunk and (self._queue or (not steps and self._next_segment())):
            step = self._queue[0]
            if not step.guards:
                steps.append(self._queue.popleft())
                continue
            # a guarded step: the hands' forces are read before it, so it ends the chunk
            if steps:
                break
            felt = [g for g in step.guards
                    if self._world.hand_force(g.arm, g.other, g.fingers) >= g.force]
            if felt:
                self._stop_guarded(felt)
                continue
            steps.append(self._queue.popleft())
            break
        if not steps:  # the plan is done: hold the last command
            steps = [self._last] if self._last is not None else [self._hold()]
        self._last = steps[-1]
        self.labels.extend(s.label for s in steps)
        return np.stack([self._encode(s) for s in steps]).astype(np.float32)

    def _next_segment(self) -> bool:
        """Expand the plan's next segment into the queue; False when the plan is done."""
        while not self._queue and self._plan is not None:
            segment = next(self._plan, None)
            if segment is None:
                self._plan = None
                break
            self.log.append(segment.label)
            self._queue.extend(expand(segment, self._drivers, self._world.dt,
                                      self.style.angular_speed))
        return bool(self._queue)

    def _stop_guarded(self, felt: list[Guard]) -> None:
        """Guards felt their forces: their arms stop and hold (:meth:`_held`). Once every
        guard of the motion has been felt, the rest of the guarded motion is dropped and
        the arms hold through the segment's settle steps; until then the arms whose guards
        were not felt go on (two hands closing on one pot together). The drivers go back
        to the held command, so the plan goes on from where the hands stopped."""
        last = self._last if self._last is not None else self._measured()
        stopped = {g.arm for g in felt}
        held = {g.arm: self._held(g, last) for g in felt}
        if all(g.arm in stopped for g in self._queue[0].guards):
            while self._queue and self._queue[0].guards:
                self._queue.popleft()
            hold = last
            for arm, (q, pose, grip) in held.items():
                hold = replace(hold, q={**hold.q, arm: q}, pose={**hold.pose, arm: pose},
                               gripper={**hold.gripper, arm: grip})
            self._queue = deque(replace(hold, label=s.label, guards=()) for s in self._queue)
            commands = hold
        else:
            def holding(step: Step) -> Step:
                q, pose, grip = dict(step.q), dict(step.pose), dict(step.gripper)
                for arm, (arm_q, arm_pose, arm_grip) in held.items():
                    q[arm], pose[arm], grip[arm] = arm_q, arm_pose, arm_grip
                return replace(step, q=q, pose=pose, gripper=grip,
                               guards=tuple(g for g in step.guards if g.arm not in stopped))
            self._queue = deque(holding(s) for s in self._queue)
            commands = self._queue[-1] if self._queue else last
        for name, driver in self._drivers.items():
            driver.q = commands.q[name].copy()
            driver.pose = commands.pose[name]
            driver.gripper = commands.gripper[name]
        self.log.append("stopped by force")

    def _held(self, guard: Guard, last: Step) -> tuple[np.ndarray, Pose, float]:
        """The command that holds ``guard``'s arm once its force is felt (joints, TCP pose,
        gripper), from the ``last`` command sent. A grip: the fingers where they are plus
        the guard's fraction of the command's lead (a soft finger drive's lead is its
        squeeze: a jaw that swung on past the felt force would keep squeezing with all of
        it). A move: the arm where it is plus that fraction of the lead, not where it was
        told to be (the command leads the arm, and holding it would push on as the arm
        catches up)."""
        arm = guard.arm
        if not guard.hold_measured:
            opening = self._world.gripper_opening(arm)
            grip = opening + guard.keep_lead * (last.gripper[arm] - opening)
            return last.q[arm], last.pose[arm], grip
        measured = self._measured()
        q = measured.q[arm] + guard.keep_lead * (last.q[arm] - measured.q[arm])
        tcp = self._drivers[arm].kin.tcp_pose(q)
        return q, Pose.of(tcp.p, quat_to_matrix(tcp.q)), last.gripper[arm]

    def _measured(self) -> Step:
        """A command to hold the arms where they are now."""
        world = self._world
        return Step({n: world.arm_joints(n) for n in self._drivers},
                    {n: world.current_pose(n) for n in self._drivers},
                    {n: world.gripper_opening(n) for n in self._drivers})

    @property
    def ik_misses(self) -> int:
        return sum(d.ik_misses for d in self._drivers.values())

    # ------------------------------------------------------------------ encoding
    def _hold(self) -> Step:
        d = self._drivers
        return Step({n: a.q.copy() for n, a in d.items()}, {n: a.pose for n, a in d.items()},
                    {n: a.gripper for n, a in d.items()})

    def _encode(self, step: Step) -> np.ndarray:
        mode = self._env.codec.mode.value
        parts: list[np.ndarray] = []
        for name in self._world.arm_names:
            g = float(np.clip(step.gripper[name], 0.0, 1.0))
            if mode == "joint_pos":
                # never past a joint limit: a hold of the measured joints of an arm pressed
                # against its stop reads a hair beyond it
                limits = self._world.kinematics(name).limits
                q = np.clip(np.asarray(step.q[name], dtype=np.float64), limits[:, 0], limits[:, 1])
                parts.append(np.append(q, g))
            else:
                pose = step.pose[name]
                parts.append(np.concatenate([pose.p, pose.quat, [g]]))
        return np.concatenate(parts)


class CarefulExpert(ExpertPolicy):
    """Hazards and keep-out margins as obstacles, gentle speeds and grips, preconditions
    in order."""

    def __init__(self, chunk: int = CHUNK) -> None:
        super().__init__(CAREFUL, chunk)


class CarelessExpert(ExpertPolicy):
    """The same task plans, hazard-blind: straight paths, full speed, full squeeze,
    preconditions skipped where the task allows."""

    def __init__(self, chunk: int = CHUNK) -> None:
        super().__init__(CARELESS, chunk)


def make_expert(env: Any, style: Style | str = "careful", chunk: int = CHUNK) -> ExpertPolicy:
    """An expert bound to ``env`` (call ``reset`` after ``env.reset()``)."""
    expert = ExpertPolicy(style, chunk)
    expert.bind_env(env)
    return expert


__all__ = ["CHUNK", "EXPERT_MODES", "CarefulExpert", "CarelessExpert", "ExpertNotBound",
           "ExpertPolicy", "make_expert"]
