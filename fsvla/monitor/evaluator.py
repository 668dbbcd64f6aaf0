"""The simulator-free half of the monitor: WorldState in, StepReport out.

:class:`Evaluator` holds the channels, the temporal FSMs and the success timer of a
MonitorSpec over a :class:`Layout` and its :class:`SceneGeometry`. It never touches
SAPIEN, so tests drive it with hand-made states; :class:`fsvla.monitor.SafetyMonitor`
feeds it states read by the probe.
"""

from __future__ import annotations

import numpy as np

from fsvla.compiler.monitor import ChannelSpec, MonitorSpec
from fsvla.metrics.trace import ChannelInfo, EpisodeMeta, EpisodeTrace

from .channels import compile_margin, distance_queries
from .geometry import SceneGeometry
from .layout import Layout
from .predicates import Scope, holds, predicate_slots, spec_conditions, uses_contacts
from .report import StepReport, classify, step_costs
from .state import WorldState
from .temporal import PreconditionMonitor


def channel_infos(spec: MonitorSpec) -> tuple[ChannelInfo, ...]:
    """The trace channels of a spec, in margin-column order: its limits, then its requirements."""
    return tuple(
        [ChannelInfo(name=c.name, family=c.family, soft_threshold=c.soft_threshold, weight=c.weight,
                     shaping=c.shaping) for c in spec.channels]
        + [ChannelInfo(name=r.name, family="temporal", soft_threshold=r.soft_threshold, weight=r.weight,
                       shaping=r.shaping) for r in spec.requirements])


class Evaluator:
    """Margins, costs, states, temporal FSMs and success of one episode, step by step."""

    def __init__(self, spec: MonitorSpec, layout: Layout, geometry: SceneGeometry):
        self.spec, self.layout, self.geometry = spec, layout, geometry
        self.names = spec.channel_names
        self.channel_infos = channel_infos(spec)
        self._eps = [c.soft_threshold for c in self.channel_infos]
        self._weights = np.array([c.weight for c in self.channel_infos], dtype=np.float64)
        self._shapings = [c.shaping for c in self.channel_infos]
        self._fsms = [PreconditionMonitor(within=r.within) for r in spec.requirements]
        self.needs_contacts = uses_contacts(spec)
        self._queries = distance_queries(spec, layout)
        self._margins = [compile_margin(c, layout) for c in spec.channels]
        self._slots = predicate_slots(*spec_conditions(spec))
        self._rows: list[np.ndarray] = []
        self._held_steps = 0
        self.success_achieved = False
        geometry.sweep_samples = spec.substeps  # a step's motion is sampled at its physics substeps
        self.start_margins = np.zeros(len(spec.channels))

    def _scope(self, state: WorldState) -> Scope:
        self.geometry.set_poses(state.poses)
        return Scope(state, self.layout, self.geometry, self._slots)

    def reset(self, state: WorldState) -> None:
        """Start an episode at ``state`` (t = 0): the reference for displacement, lifting and
        the temporal FSMs' previous step. The limits' margins there are
        :attr:`start_margins` (see :meth:`start_exposures`)."""
        self.geometry.begin_step(fresh=True)
        scope = self._scope(state)
        self.layout.initial = {b: scope.root_pose(b).copy() for b in self.layout.bodies
                               if self.layout.bodies[b].root_frame in state.poses or self.geometry.has(
                                   self.layout.bodies[b].root_frame)}
        self.layout.initial_low = {b: scope.lowest(b) for b in self.layout.entities if b in self.layout.bodies}
        for fsm, req in zip(self._fsms, self.spec.requirements):
            fsm.reset(holds(req.first, scope), holds(req.then, scope), state.time)
        self.geometry.prefetch(self._queries)
        self.start_margins = np.array([margin(state, self.geometry) for margin in self._margins], dtype=np.float64)
        self._rows.clear()
        self._held_steps = 0
        self.success_achieved = False

    def start_exposures(self) -> list[tuple[ChannelSpec, float]]:
        """The limits inside their warning band, or past their hard limit, at the state of
        the last :meth:`reset`, with their margin there."""
        return [(c, float(q)) for c, q in zip(self.spec.channels, self.start_margins) if q < c.soft_threshold]

    def step(self, state: WorldState) -> StepReport:
        """Evaluate the state at the end of a control step."""
        self.geometry.begin_step()
        scope = self._scope(state)
        self.geometry.prefetch(self._queries)
        geometry = self.geometry
        values = [margin(state, geometry) for margin in self._margins]
        for fsm, req in zip(self._fsms, self.spec.requirements):
            values.append(fsm.update(holds(req.first, scope), holds(req.then, scope), state.time))
        margins = np.array(values, dtype=np.float64)
        self._rows.append(margins)
        value = holds(self.spec.success.condition, scope)
        self._held_steps = self._held_steps + 1 if value else 0
        held = self._held_steps * self.spec.control_dt
        success = value and held >= self.spec.success.hold - 1e-9
        self.success_achieved |= success
        return StepReport(
            step=state.step, time=state.time, names=self.names, margins=margins,
            states=tuple(map(classify, values, self._eps)),
            costs=step_costs(values, self._eps, self._shapings), weights=self._weights,
            success_value=value, success_held=held if value else 0.0, success=success)

    @property
    def margins(self) -> np.ndarray:
        """The T × K margins recorded since reset."""
        return np.array(self._rows, dtype=np.float64).reshape(len(self._rows), len(self.names))

    def trace(self, meta: EpisodeMeta, success: bool | None = None) -> EpisodeTrace:
        """The episode's :class:`EpisodeTrace` (success: whether the success condition was
        met for its hold time at some step, unless given)."""
        if not self.channel_infos:
            raise ValueError(f"scenario {self.spec.scenario!r} has no monitored channel")
        if not self._rows:
            raise ValueError("no control step was monitored since reset")
        return EpisodeTrace(channels=self.channel_infos, margins=self.margins,
                            success=self.success_achieved if success is None else success, meta=meta)


__all__ = ["Evaluator", "channel_infos"]
