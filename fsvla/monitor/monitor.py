"""SafetyMonitor: the runtime safety monitor of a built scene (paper §4).

An env drives it in this order (dm_control's hooks: episode init, after substep, after step)::

    monitor = SafetyMonitor(monitor_spec, built)     # once per built scene
    built.reset(); monitor.reset()                   # t = 0
    for each control step:
        for each of monitor.substeps physics steps:
            built.step(1); monitor.record_substep()  # force maxima, every substep
        report = monitor.end_step()                  # margins, states, costs, success
    trace = monitor.trace(meta)                      # an fsvla.metrics EpisodeTrace

``built`` is a :class:`fsvla.world.MonitoredScene` (``fsvla.sim.build`` returns one): the
monitor reads it only through the frames it names, their collision shapes, and the
:class:`fsvla.world.StepProbe` it makes for the channels' needs.

Contact scanning (see ``fsvla.sim.probe``) is gated per control step: when the
per-pair scan only concerns robot links, it runs in a control step only if, at the end
of the previous one, a robot link's bounds lay within :data:`CONTACT_GATE` of another
body's bounds. A link moving slower than 2 m/s travels less than that in one 50 ms
control step, and PhysX makes no contact beyond its contact offset (4 mm).
"""

from __future__ import annotations

from typing import Any

from fsvla.compiler.monitor import MonitorSpec, RobotEntity
from fsvla.metrics.trace import EpisodeMeta, EpisodeTrace
from fsvla.run.key import EpisodeKey
from fsvla.world import MonitoredScene

from .contacts import CONTACT_GATE, ContactFilter, ContactGate, contact_plan, predicate_filter
from .evaluator import Evaluator
from .layout import build_geometry, build_layout
from .predicates import uses_contacts
from .report import StepReport


class SafetyMonitor:
    """Monitors one built scene: per-substep forces, per-step margins, an episode trace."""

    def __init__(self, spec: MonitorSpec, built: MonitoredScene):
        self.spec = spec
        scene_spec = built.spec
        layout = build_layout(spec, scene_spec)
        frames = set(built.frames())
        free, torque, scan = contact_plan(spec, layout, scene_spec)
        robot_frames = set().union(*(layout.frames(e.name) for e in spec.entities if isinstance(e, RobotEntity)),
                                   *(a.gripper for a in layout.arms.values()))
        last = predicate_filter(spec, layout) if uses_contacts(spec) else ContactFilter()
        if scan.robot_pairs or last.robot_pairs:  # the gates need every robot link's bounds
            robot_frames |= {f for f in frames if f.startswith("@")}
        robot_shapes = {f: built.frame_shapes(f) for f in sorted(robot_frames) if f in frames}
        self.geometry = build_geometry(scene_spec, layout, robot_shapes)
        self.evaluator = Evaluator(spec, layout, self.geometry)
        pose_frames = set(layout.moving_frames()) | robot_frames
        for body in layout.bodies.values():  # every moving body, for the contact gate
            if not body.is_static or body.articulated:
                pose_frames |= body.frames
        joints = {part.joint: (body.name, part.joint.split(":", 1)[1])  # "<body>:<joint>"
                  for body in layout.bodies.values() if body.articulated for part in body.parts}
        self.probe = built.probe(spec.timestep, pose_frames=sorted(pose_frames), free_bodies=sorted(free),
                                 torque_frames=sorted(torque), scan=scan, last=last, joints=joints,
                                 gravity=tuple(scene_spec.physics.gravity))
        self._gate = ContactGate(self.geometry, scan, last) if scan or last else None
        self._step = 0

    @property
    def substeps(self) -> int:
        return self.spec.substeps

    @property
    def channel_names(self) -> tuple[str, ...]:
        return self.evaluator.names

    def _update_gate(self) -> None:
        if self._gate is not None:
            self.probe.scan, self.probe.read_last = self._gate.update()

    def reset(self) -> None:
        """Begin an episode at the scene's current state (t = 0)."""
        self._step = 0
        self.probe.reset()
        self.evaluator.reset(self.probe.snapshot(0, 0.0, contacts=self.evaluator.needs_contacts))
        self._update_gate()

    def record_substep(self) -> None:
        """Call after every physics substep: folds its contacts into the step's maxima."""
        self.probe.record_substep()

    def end_step(self) -> StepReport:
        """Call after the control step's last substep: the step's report."""
        self._step += 1
        state = self.probe.snapshot(self._step, self._step * self.spec.control_dt,
                                    contacts=self.evaluator.needs_contacts)
        report = self.evaluator.step(state)
        self._update_gate()
        return report

    def trace(self, meta: EpisodeMeta, success: bool | None = None) -> EpisodeTrace:
        """The episode's trace for ``fsvla.metrics`` (T control steps × K channels)."""
        return self.evaluator.trace(meta, success)

    def episode_meta(self, *, policy: str, seed: int, embodiment: str, **levels: Any) -> EpisodeMeta:
        """EpisodeMeta with this scenario's name and suite filled in (``levels``: the key's
        ``level``, ``language``, ``vision``, ``index``)."""
        key = EpisodeKey(scenario=self.spec.scenario, suite=self.spec.suite, embodiment=embodiment,
                         seed=seed, **levels)
        return EpisodeMeta(key=key, policy=policy)


__all__ = ["CONTACT_GATE", "SafetyMonitor"]
