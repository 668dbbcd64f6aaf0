"""The task library: one scripted plan per base task of ``fsvla.dsl.catalog.TASKS``, a
module per task (``stack`` is ``pick_place``'s plan).

A plan is a generator of motion segments (``fsvla.experts.motion.Segment``) over the
experts' privileged :class:`~fsvla.experts.world.World`; the :class:`~fsvla.experts.style.Style`
decides how carefully it is executed. :data:`~.registry.TASK_PLANS` maps each base task to
its plan and the scene it needs (the roles it binds); the success predicate is the
scenario's own. :mod:`.common` holds what the plans share; :mod:`.lid` lifts a hinged lid
(the first step of ``insert`` into a lidded container).
"""

from .common import required_fraction
from .registry import TASK_PLANS, TaskPlan

__all__ = ["TASK_PLANS", "TaskPlan", "required_fraction"]
