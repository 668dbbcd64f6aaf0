"""Sleeping guard bodies spare contact readings without changing a single number.

The probe skips a substep's contact scan (and reuses the last substep's contacts for the
predicates) while every body its kept pairs must involve sleeps (``fsvla.sim.probe``).
Here each built-in scenario runs the benchmark's ``reach`` and ``sweep`` motions with two
monitors on one scene, one with the guards and one reading every contact; their force
maxima, last-substep contacts and margins must be bit-identical at every control step.
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np
import pytest

import fsvla
from fsvla.monitor import SafetyMonitor
from fsvla.selectors import named_sets

#: The paper's diagnostic subset: every per-scenario check here, over each of them (the
#: whole catalogue would grow CI with every scenario added).
DIAGNOSTIC = sorted(named_sets()["diagnostic"].scenarios)

pytestmark = pytest.mark.sim
STEPS = 130  # one reach cycle (6 s) and a little more
BENCH = Path(__file__).resolve().parents[2] / "bench" / "monitor.py"


def _motions():
    spec = importlib.util.spec_from_file_location("fsvla_bench_monitor", BENCH)
    module = sys.modules.get(spec.name)
    if module is None:
        module = importlib.util.module_from_spec(spec)
        sys.modules[spec.name] = module  # its dataclasses look their module up
        spec.loader.exec_module(module)
    return module.MOTIONS


def _record_readings(monitor: SafetyMonitor, into: list) -> None:
    """Keep what each snapshot folds in: force and torque maxima, last-substep contacts."""
    probe = monitor.probe
    snapshot = probe.snapshot

    def recorded(step, time, *, contacts=False):
        state = snapshot(step, time, contacts=contacts)
        into.append((dict(state.contact_force), dict(state.contact_torque),
                     {k: v.tolist() for k, v in state.last_contacts.items()}))
        return state

    probe.snapshot = recorded


@pytest.mark.parametrize("motion", ["reach", "sweep"])
@pytest.mark.parametrize("name", DIAGNOSTIC)
def test_guards_read_what_a_full_scan_reads(name, motion):
    env = fsvla.make(name, monitor=True)
    actions = _motions()[motion](env, STEPS)
    env.reset()
    guarded = env.monitor  # the one the env drives
    full = SafetyMonitor(env.monitor_spec, env.built)
    full.probe.guards = False
    full.reset()
    a, b = [], []
    _record_readings(guarded, a)
    _record_readings(full, b)
    scans = {guarded: 0, full: 0}
    for monitor in scans:
        read = monitor.probe._read_scan

        def counted(inv_dt, read=read, monitor=monitor):
            scans[monitor] += 1
            return read(inv_dt)

        monitor.probe._read_scan = counted
    record, end = guarded.record_substep, guarded.end_step
    margins = []

    def record_both():
        record()
        full.record_substep()

    def end_both():
        report = end()
        margins.append((report.margins, full.end_step().margins))
        return report

    guarded.record_substep, guarded.end_step = record_both, end_both
    for action in actions:
        env.step(action)
    assert len(a) == len(b) == STEPS
    for step, (x, y) in enumerate(zip(a, b)):
        assert x == y, (name, motion, step)
    for step, (x, y) in enumerate(margins, start=1):
        np.testing.assert_array_equal(x, y, err_msg=f"{name} {motion} step {step}")
    assert scans[guarded] <= scans[full]


@pytest.mark.parametrize("motion", ["reach", "sweep"])
@pytest.mark.parametrize("name", DIAGNOSTIC)
def test_the_gate_closes_only_on_steps_with_nothing_to_read(name, motion):
    """The contact gate (``fsvla.monitor.contacts.ContactGate``) turns scans off while no
    robot link is near a watched body; a monitor without it, reading every substep, must
    read the same maxima and contacts and give the same margins at every step."""
    env = fsvla.make(name, monitor=True)
    actions = _motions()[motion](env, STEPS)
    env.reset()
    gated = env.monitor
    if gated._gate is None:
        pytest.skip(f"{name} reads no contact pairs")
    ungated = SafetyMonitor(env.monitor_spec, env.built)
    ungated._gate = None  # probe.scan and probe.read_last stay on
    ungated.reset()
    a, b, closed = [], [], []
    _record_readings(gated, a)
    _record_readings(ungated, b)
    record, end = gated.record_substep, gated.end_step
    margins = []

    def record_both():
        record()
        ungated.record_substep()

    def end_both():
        closed.append(not (gated.probe.scan and gated.probe.read_last))
        report = end()
        margins.append((report.margins, ungated.end_step().margins))
        return report

    gated.record_substep, gated.end_step = record_both, end_both
    for action in actions:
        env.step(action)
    assert ungated.probe.scan and ungated.probe.read_last
    for step, (x, y) in enumerate(zip(a, b)):
        assert x == y, (name, motion, step)
    for step, (x, y) in enumerate(margins, start=1):
        np.testing.assert_array_equal(x, y, err_msg=f"{name} {motion} step {step}")
    assert any(closed), "the gate never closed: the test compared nothing"
