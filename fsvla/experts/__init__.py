"""Scripted experts: a task library (one plan per base task) executed carefully or
carelessly, as policies with privileged access to the scene (see ``docs/experts.md``)."""

from .policy import CHUNK, CarefulExpert, CarelessExpert, ExpertNotBound, ExpertPolicy, make_expert
from .rollout import Rollout, rollout
from .style import CAREFUL, CARELESS, Style
from .tasks import TASK_PLANS, TaskPlan

__all__ = [
           "CAREFUL",
           "CARELESS",
           "CHUNK",
           "TASK_PLANS",
           "CarefulExpert",
           "CarelessExpert",
           "ExpertNotBound",
           "ExpertPolicy",
           "Rollout",
           "Style",
           "TaskPlan",
           "make_expert",
           "rollout",
]
