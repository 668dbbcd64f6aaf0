"""The registry of task plans: each base task of ``fsvla.dsl.catalog.TASKS``, the roles it
binds, what the scene must offer, and the plan (its module) that performs it."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from ..skills import Plan
from ..style import Style
from ..world import World
from .bimanual_lift import plan_bimanual_lift
from .handover import plan_handover
from .insert import plan_insert
from .lift import plan_lift
from .open_close import plan_close, plan_open
from .pick_place import plan_pick_place
from .pour import plan_pour, pour_arm
from .press import plan_press
from .push import plan_push


@dataclass(frozen=True)
class TaskPlan:
    """A base task: the roles it needs, what the scene must offer, and its plan."""

    name: str
    roles: tuple[str, ...]
    needs: str  # the scene requirements, in words
    plan: Callable[..., Plan]  # (world, style, roles); with ``arm``, also ``arm=``
    #: which arm a one-arm task works with, where it chooses (else the one nearest the
    #: object, or the :func:`~fsvla.experts.skills.carrying_arm` to a target): the other
    #: arms move out of its way first, and ``plan`` is given that arm as ``arm=``
    arm: Callable[[World, Style, dict[str, str]], str] | None = None


TASK_PLANS: dict[str, TaskPlan] = {t.name: t for t in (
    TaskPlan("pick_place", ("object", "target"), "a graspable object; a target with a top",
             plan_pick_place),
    TaskPlan("stack", ("object", "target"), "a graspable object; a target with a flat top",
             plan_pick_place),
    TaskPlan("lift", ("object",), "a graspable object", plan_lift),
    TaskPlan("push", ("object", "target"), "an object that slides; a target location",
             plan_push),
    TaskPlan("open", ("object",), "an articulated body whose part has a `handle` (a drawer, "
             "a door) or a `knob` (a lid)", plan_open),
    TaskPlan("close", ("object",), "an articulated body whose part has a `handle` (a drawer, "
             "a door) or a `knob` (a lid)", plan_close),
    TaskPlan("insert", ("object", "target"),
             "a graspable object; a container (a drawer_cabinet: opened first)", plan_insert),
    TaskPlan("pour", ("object", "target"), "a graspable container; a target below it",
             plan_pour, pour_arm),
    TaskPlan("press", ("object",), "an object to press from above", plan_press),
    TaskPlan("bimanual_lift", ("object",), "two arms; an object with `handle_*` shapes",
             plan_bimanual_lift),
    TaskPlan("handover", ("object",), "two arms; a graspable object; optionally a support",
             plan_handover),
)}

__all__ = ["TASK_PLANS", "TaskPlan"]
