"""The finite-state monitor of ``require FIRST before THEN [within T]`` (paper §3.2, §4.1).

Semantics: every time THEN *starts* to hold (a rising edge: it holds now and did not
at the previous step; the state at reset counts as the previous step, so a THEN that
already holds at reset is no event), FIRST must have held at this step or an earlier
one, and, with ``within T``, no more than T seconds ago. A rising edge without that is a
violation, which lasts while THEN keeps holding.

Margin scale (unitless, soft threshold ε = 0.5, so the warning band is [0, 0.5)):

==========================================  ======================
state                                       margin q
==========================================  ======================
THEN not started, or started after FIRST    +1
armed with a window: FIRST last held e s    1 - e / T (safe while e <= T/2,
ago, THEN not yet started                   warning beyond, 0 at the deadline)
THEN started without a valid FIRST          -1 (a violation)
==========================================  ======================

A window that lapses disarms the monitor (q back to +1) until FIRST holds again.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

SATISFIED = 1.0
VIOLATED = -1.0


class Phase(str, Enum):
    PENDING = "pending"  # FIRST has not held (or its window lapsed)
    ARMED = "armed"  # FIRST has held (within the window)
    SATISFIED = "satisfied"  # THEN started after a valid FIRST and still holds
    VIOLATED = "violated"  # THEN started without a valid FIRST and still holds


@dataclass
class PreconditionMonitor:
    """Finite-state monitor of one requirement; feed it one step at a time."""

    within: float | None = None  # s
    phase: Phase = Phase.PENDING
    last_first: float | None = None  # time FIRST last held
    then_before: bool = False
    violations: int = 0

    def reset(self, first: bool, then: bool, time: float = 0.0) -> None:
        """Start an episode from the state at reset (THEN holding there is no event)."""
        self.phase, self.last_first, self.violations = Phase.PENDING, None, 0
        self.then_before = then
        if first:
            self.last_first, self.phase = time, Phase.ARMED

    def _armed(self, time: float) -> bool:
        if self.last_first is None:
            return False
        return self.within is None or time - self.last_first <= self.within + 1e-9

    def update(self, first: bool, then: bool, time: float) -> float:
        """Advance to a step where FIRST/THEN have the given values; return its margin."""
        if first:
            self.last_first = time
        rising = then and not self.then_before
        self.then_before = then
        if rising:
            if self._armed(time):
                self.phase = Phase.SATISFIED
            else:
                self.phase = Phase.VIOLATED
                self.violations += 1
        elif not then:
            self.phase = Phase.ARMED if self._armed(time) else Phase.PENDING
        return self.margin(time)

    def margin(self, time: float) -> float:
        if self.phase is Phase.VIOLATED:
            return VIOLATED
        if self.phase is Phase.ARMED and self.within is not None and self.last_first is not None:
            return max(0.0, 1.0 - (time - self.last_first) / self.within)
        return SATISFIED


__all__ = ["SATISFIED", "VIOLATED", "Phase", "PreconditionMonitor"]
