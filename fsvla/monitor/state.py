"""A plain snapshot of the world at the end of one control step.

A :class:`fsvla.world.StepProbe` (``fsvla.sim.probe`` for SAPIEN) fills it from a running
scene; channels and predicates read only this, so they can be tested on hand-made
snapshots with no simulator.

Frames are named by string:

- a rigid body: its name (``"mug"``);
- a link of an articulated body: ``"<body>:<link>"`` (``"cabinet:drawer"``);
- a robot link: ``"@<robot>:<link>"`` (``"@panda:panda_hand"``).

Contact data are taken over the control step's physics substeps: ``contact_force`` holds,
per unordered frame pair, the largest magnitude of the pair's total contact force in any
substep (impulse / timestep), so a spike in a single substep is never missed;
``contact_torque`` holds, per ordered pair (frame, other), the largest magnitude of the
torque those contacts exert about the frame's centre of mass. ``last_contacts`` is the
force on the first frame by the second in the step's last substep (both orders present).
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

Matrix4 = NDArray[np.float64]
Pair = tuple[str, str]

#: The "other side" of a free body's net contact force (and torque) in ContactMaxima keys.
NET = "*"


def robot_frame(robot: str, link: str) -> str:
    return f"@{robot}:{link}"


def link_frame(body: str, link: str) -> str:
    return f"{body}:{link}"


def pair_key(a: str, b: str) -> Pair:
    """The unordered key of a frame pair."""
    return (a, b) if a <= b else (b, a)


class PoseMap(Mapping[str, Matrix4]):
    """Frame -> 4x4 pose, read in one pass: ``stack`` holds the matrices in ``names`` order
    and a pose is a view of it made when asked for (most of a step's poses go to the
    geometry as the stack, and only a few are read one by one)."""

    __slots__ = ("_index", "names", "stack")

    def __init__(self, names: tuple[str, ...], stack: NDArray[np.floating],
                 index: Mapping[str, int] | None = None):
        self.names, self.stack = names, stack
        self._index = {n: i for i, n in enumerate(names)} if index is None else index

    def __getitem__(self, frame: str) -> Matrix4:
        return self.stack[self._index[frame]]

    def get(self, frame: str, default: Matrix4 | None = None) -> Matrix4 | None:  # type: ignore[override]
        i = self._index.get(frame)
        return default if i is None else self.stack[i]

    def __contains__(self, frame: object) -> bool:
        return frame in self._index

    def __iter__(self) -> Iterator[str]:
        return iter(self.names)

    def __len__(self) -> int:
        return len(self.names)


@dataclass
class ContactMaxima:
    """Running maxima over the substeps of one control step."""

    force: dict[Pair, float] = field(default_factory=dict)  # unordered pair -> N
    torque: dict[Pair, float] = field(default_factory=dict)  # (frame, other) -> Nm

    def add_force(self, a: str, b: str, magnitude: float) -> None:
        key = pair_key(a, b)
        if magnitude > self.force.get(key, -1.0):
            self.force[key] = magnitude

    def add_torque(self, frame: str, other: str, magnitude: float) -> None:
        key = (frame, other)
        if magnitude > self.torque.get(key, -1.0):
            self.torque[key] = magnitude

    def clear(self) -> None:
        self.force.clear()
        self.torque.clear()


@dataclass(frozen=True)
class WorldState:
    """The world at the end of control step ``step`` (time ``time`` s since reset)."""

    step: int
    time: float
    poses: Mapping[str, Matrix4]  # frame -> 4x4 world pose
    joints: Mapping[str, float] = field(default_factory=dict)  # "<body>:<joint>" -> position
    contact_force: Mapping[Pair, float] = field(default_factory=dict)
    contact_torque: Mapping[Pair, float] = field(default_factory=dict)
    last_contacts: Mapping[Pair, NDArray[np.float64]] = field(default_factory=dict)
    contacts_read: bool = False  # whether any contact data were read this step

    def max_force(self, frames_a: frozenset[str], frames_b: frozenset[str] | None = None) -> float:
        """Largest substep contact force between a frame of ``a`` and one of ``b``
        (any frame outside ``a`` when ``b`` is None); 0 with no contact."""
        best = 0.0
        if frames_b is not None and len(frames_a) * len(frames_b) < len(self.contact_force):
            force = self.contact_force  # fewer frame pairs to look up than contacts to go through
            for a in frames_a:
                for b in frames_b:
                    best = max(best, force.get(pair_key(a, b), 0.0))
            return best
        for (x, y), value in self.contact_force.items():
            for s, o in ((x, y), (y, x)):
                if s in frames_a and (o not in frames_a if frames_b is None else o in frames_b):
                    best = max(best, value)
        return best

    def max_torque(self, frames: frozenset[str]) -> float:
        """Largest substep contact torque on a frame of ``frames`` by a frame outside it."""
        return max((v for (f, o), v in self.contact_torque.items() if f in frames and o not in frames),
                   default=0.0)

    def touching(self, frames_a: frozenset[str], frames_b: frozenset[str]) -> bool:
        """Any contact between the groups in the step (any substep, or the last one)."""
        if self.max_force(frames_a, frames_b) > 0.0:
            return True
        last = self.last_contacts
        if len(frames_a) * len(frames_b) < len(last):
            return any((a, b) in last for a in frames_a for b in frames_b)
        return any(a in frames_a and b in frames_b for a, b in last)

    def force_on(self, frames: frozenset[str], by: frozenset[str]) -> NDArray[np.float64]:
        """Total force on ``frames`` by ``by`` in the last substep."""
        total = np.zeros(3)
        for (a, b), force in self.last_contacts.items():
            if a in frames and b in by:
                total += force
        return total


__all__ = ["NET", "ContactMaxima", "Matrix4", "Pair", "PoseMap", "WorldState", "link_frame", "pair_key", "robot_frame"]
