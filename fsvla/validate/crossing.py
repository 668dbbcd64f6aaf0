"""What pressed on a subject when a contact-force limit was crossed.

A recorded episode keeps each channel's margins, not the contacts behind them. To say
whether a ``contact_force(bottle) <= 17 N`` limit was crossed by the fingers' squeeze or by
the bottle landing on the table after it slipped out of them, :func:`replay_crossing`
replays the episode's recorded actions in a fresh environment (:class:`~.replay.Replay`:
the same layout and physics, bit for bit) and, at each step at which the channel is in
violation, reads the monitor's own world state: the strongest contact on one of the
channel's subjects (per pair, the largest over the step's physics substeps, as the channel
measures it; or a free body's net contact force, from its change of speed, which no single
pair carries: a knock, with what it touched at the step's end), and whether the subject,
if it is an object, was in the gripper (``grasped``). It keeps the first such step and the
hardest.
"""

from __future__ import annotations

from contextlib import closing
from dataclasses import dataclass
from pathlib import Path
from typing import Any


@dataclass(frozen=True)
class Crossing:
    """The contact behind a crossed force limit at one step."""

    step: int  # 0-based control step, as the episode's metrics count
    subject: str  # the entity the channel measures (`bottle`, `gripper`)
    force: float  # N, the largest over the step's substeps
    other: str | None  # what it pressed on (`table`, `link` of z1); None: a knock
    touching: tuple[str, ...]  # a knock: what it touched at the step's end
    held: bool | None  # whether a subject object was grasped then; None for a robot part

    def text(self) -> str:
        """```bottle` against `table`, 23.1 N, in the gripper, at step 211``."""
        held = "" if self.held is None else f", {'in' if self.held else 'not in'} the gripper"
        if self.other is not None:
            what = f"`{self.subject}` against {self.other}, {self.force:.2f} N"
        else:
            what = (f"`{self.subject}` knocked, {self.force:.2f} N of net contact force (from "
                    "its change of speed)")
            if self.touching:
                what += ", touching " + ", ".join(self.touching)
        return f"{what}{held}, at step {self.step}"


@dataclass(frozen=True)
class Crossings:
    """A force channel's crossings in one episode: the first and the strongest."""

    first: Crossing
    worst: Crossing

    def text(self) -> str:
        if self.worst == self.first:
            return f"what pressed: {self.first.text()}"
        return f"what pressed: first {self.first.text()}; hardest {self.worst.text()}"


def replay_crossing(run_dir: Path, episode_id: str, channel: str) -> Crossings | None:
    """Replay ``episode_id`` of the run in ``run_dir`` and return the contacts behind the
    steps at which ``channel`` (a ``contact_force`` channel's trace name) is in violation,
    the first and the strongest; None where the replay never crosses it."""
    from .replay import Replay

    replay = Replay(run_dir, episode_id)
    found: list[Crossing] = []
    spec = None
    with closing(replay.steps()) as steps:  # closed, and its environment, on a return
        for step in steps:
            if spec is None:  # the environment is built by the first step
                spec = next((c for c in replay.env.monitor_spec.channels if c.name == channel),
                            None)
                if spec is None or spec.metric != "contact_force":
                    return None
            if step.info["states"].get(channel) == "violation":
                crossing = _crossing(step.index, step.state, spec, replay.env.monitor.evaluator)
                if crossing is not None:
                    found.append(crossing)
    if not found:
        return None
    return Crossings(first=found[0], worst=max(found, key=lambda c: c.force))


def _crossing(index: int, state: Any, spec: Any, evaluator: Any) -> Crossing | None:
    """The strongest contact on one of the channel's subjects at this step: a pair, or a
    free body's net contact force (what the channel also measures: a knock, its speed
    changing in a substep, attributed to no pair)."""
    from fsvla.dsl.models import Predicate
    from fsvla.monitor.predicates import Scope, holds
    from fsvla.monitor.state import NET

    layout = evaluator.layout
    best: tuple[float, str, str] | None = None
    for subject in spec.subjects:
        frames = layout.frames(subject)
        for (a, b), force in state.contact_force.items():
            if (a in frames) == (b in frames):
                continue
            other = b if a in frames else a
            if best is None or force > best[0]:
                best = (float(force), subject, other)
    if best is None:
        return None
    force, subject, other = best
    touching: tuple[str, ...] = ()
    if other == NET:
        frames = layout.frames(subject)
        touching = tuple(dict.fromkeys(
            _frame_text(layout, b) for a, b in state.last_contacts
            if a in frames and b not in frames and b != NET))
    held = None
    if subject in layout.bodies:
        scope = Scope(state, layout, evaluator.geometry)
        held = bool(holds(Predicate(name="grasped", args=(subject,)), scope))
    return Crossing(step=index, subject=subject, force=force,
                    other=None if other == NET else _frame_text(layout, other),
                    touching=touching, held=held)


def _frame_text(layout: Any, frame: str) -> str:
    """A frame as an author knows it: `table`, `cabinet`'s `drawer`, `gripperStator` of z1."""
    if frame.startswith("@"):
        robot, _, link = frame[1:].partition(":")
        return f"`{link}` of {robot}"
    for name, body in layout.bodies.items():
        if frame in body.frames:
            _, _, link = frame.partition(":")
            return f"`{name}`" + (f"'s `{link}`" if link and body.articulated else "")
    return f"`{frame}`"


__all__ = ["Crossing", "Crossings", "replay_crossing"]
