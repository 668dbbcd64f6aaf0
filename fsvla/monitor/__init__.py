"""The runtime safety monitor (paper §4): signed margins q_k per control step, their
dual-threshold states and soft costs, temporal precondition FSMs and the success timer,
and the episode's ``fsvla.metrics`` trace. See ``docs/monitor.md``.

Importing this package does not import SAPIEN; the probe imports it where it reads a scene.
"""

from .evaluator import Evaluator, channel_infos
from .monitor import SafetyMonitor
from .report import StepReport, classify, step_costs
from .state import WorldState

__all__ = ["Evaluator", "SafetyMonitor", "StepReport", "WorldState", "channel_infos", "classify", "step_costs"]
