"""The runtime safety monitor (paper §4): signed margins q_k per control step, their
dual-threshold states and soft costs, temporal precondition FSMs and the success timer,
and the episode's ``fsvla.metrics`` trace. See ``docs/monitor.md``.

It names no simulator: it reads a scene through :class:`fsvla.world.MonitoredScene` and
the :class:`fsvla.world.StepProbe` that makes (``fsvla.sim`` implements both for SAPIEN).
"""

from .evaluator import Evaluator, channel_infos
from .monitor import SafetyMonitor
from .report import StepReport, classify, step_costs
from .state import WorldState

__all__ = ["Evaluator", "SafetyMonitor", "StepReport", "WorldState", "channel_infos", "classify", "step_costs"]
