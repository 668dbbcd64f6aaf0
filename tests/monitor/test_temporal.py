"""The precondition FSM alone, then through the Evaluator with grasped/lifted predicates."""

from __future__ import annotations

import pytest

from fsvla.monitor.temporal import Phase, PreconditionMonitor

from .conftest import LEFT, RIGHT, state, translation

DT = 0.05


def _run(fsm: PreconditionMonitor, steps: list[tuple[bool, bool]]) -> list[float]:
    fsm.reset(False, False)
    return [fsm.update(a, b, (i + 1) * DT) for i, (a, b) in enumerate(steps)]


def test_first_then_is_fine():
    margins = _run(PreconditionMonitor(), [(False, False), (True, False), (False, False), (False, True)])
    assert margins == [1.0, 1.0, 1.0, 1.0]


def test_then_before_first_is_a_violation_while_it_lasts():
    fsm = PreconditionMonitor()
    margins = _run(fsm, [(False, False), (False, True), (False, True), (True, False), (False, True)])
    assert margins == [1.0, -1.0, -1.0, 1.0, 1.0]
    assert fsm.violations == 1


def test_first_and_then_in_the_same_step_is_fine():
    assert _run(PreconditionMonitor(), [(True, True)]) == [1.0]


def test_within_exceeded_is_a_violation():
    fsm = PreconditionMonitor(within=0.2)  # 4 steps
    margins = _run(fsm, [(True, False)] + [(False, False)] * 5 + [(False, True)])
    assert margins[-1] == -1.0
    assert fsm.phase is Phase.VIOLATED


def test_the_window_runs_down_through_the_warning_band():
    fsm = PreconditionMonitor(within=1.0)
    margins = _run(fsm, [(True, False)] + [(False, False)] * 16 + [(False, True)])
    assert margins[0] == pytest.approx(1.0)
    assert margins[10] == pytest.approx(1.0 - 10 * DT)  # 0.5 s after FIRST: at the soft threshold
    assert 0.0 <= margins[16] < 0.5  # warning
    assert margins[-1] == 1.0  # THEN within 0.85 s: satisfied


def test_then_holding_at_reset_is_no_event():
    fsm = PreconditionMonitor()
    fsm.reset(False, True)
    assert [fsm.update(False, True, DT), fsm.update(False, False, 2 * DT), fsm.update(False, True, 3 * DT)] \
        == [1.0, 1.0, -1.0]


def _grasp(poses: dict, **kw):
    contacts = {(LEFT, "pot"): [0, 5.0, 0], ("pot", LEFT): [0, -5.0, 0],
                (RIGHT, "pot"): [0, -5.0, 0], ("pot", RIGHT): [0, 5.0, 0]}
    return {"last_contacts": contacts, **kw}


def _lift(base: dict, dz: float) -> dict:
    poses = dict(base)
    poses["pot"] = base["pot"] @ translation(0.0, 0.0, dz)
    return poses


def test_requirement_through_predicates(world):
    evaluator, base = world
    k = evaluator.names.index("grasp_first")
    evaluator.reset(state(base))
    good = [evaluator.step(state(base, 1, **_grasp(base))),  # grasped: the 1 s window opens
            evaluator.step(state(base, 2)),  # let go: the window runs
            evaluator.step(state(_lift(base, 0.03), 3))]  # lifted 0.1 s after the grasp
    assert [r.margins[k] for r in good] == [1.0, pytest.approx(1.0 - DT / 1.0), 1.0]
    assert good[-1].states[k] == "safe"

    evaluator.reset(state(base))
    bad = evaluator.step(state(_lift(base, 0.03), 1))  # lifted, never grasped
    assert bad.margins[k] == -1.0 and bad.states[k] == "violation"
    trace_margins = evaluator.margins
    assert trace_margins.shape == (1, len(evaluator.names))


def test_success_needs_its_hold_time(world):
    evaluator, base = world
    evaluator.reset(state(base))
    lifted = _lift(base, 0.06)
    first = evaluator.step(state(lifted, 1))
    second = evaluator.step(state(lifted, 2))
    assert first.success_value and not first.success and first.success_held == pytest.approx(DT)
    assert second.success and second.success_held == pytest.approx(2 * DT)
    dropped = evaluator.step(state(base, 3))
    assert not dropped.success_value and dropped.success_held == 0.0
    assert evaluator.success_achieved
