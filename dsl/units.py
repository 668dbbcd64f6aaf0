"""Physical units of the .fsv language.

Every physical quantity in a scenario carries a unit. The checker converts each
quantity to SI (metres, newtons, newton-metres, radians, seconds, kilograms,
hertz) so the scenario IR holds plain floats in one system of units.
"""

from __future__ import annotations

import math
from enum import Enum


class Dimension(str, Enum):
    """What a quantity measures; each dimension has one SI unit in the IR."""

    LENGTH = "length"
    FORCE = "force"
    TORQUE = "torque"
    ANGLE = "angle"
    TIME = "time"
    MASS = "mass"
    FREQUENCY = "frequency"
    NUMBER = "number"  # dimensionless: factors, counts, coefficients

    @property
    def si_unit(self) -> str:
        return _SI_UNIT[self]

    @property
    def example_unit(self) -> str:
        """The unit an example in a message uses."""
        return _EXAMPLE_UNIT.get(self, self.si_unit)

    @property
    def units(self) -> list[str]:
        """The unit spellings accepted for this dimension, most common first."""
        return [unit for unit, (dim, _) in UNITS.items() if dim is self]


# unit spelling -> (dimension, factor to SI)
UNITS: dict[str, tuple[Dimension, float]] = {
    "m": (Dimension.LENGTH, 1.0),
    "cm": (Dimension.LENGTH, 0.01),
    "mm": (Dimension.LENGTH, 0.001),
    "N": (Dimension.FORCE, 1.0),
    "Nm": (Dimension.TORQUE, 1.0),
    "deg": (Dimension.ANGLE, math.pi / 180.0),
    "rad": (Dimension.ANGLE, 1.0),
    "s": (Dimension.TIME, 1.0),
    "ms": (Dimension.TIME, 0.001),
    "kg": (Dimension.MASS, 1.0),
    "g": (Dimension.MASS, 0.001),
    "Hz": (Dimension.FREQUENCY, 1.0),
}

_SI_UNIT = {
    Dimension.LENGTH: "m",
    Dimension.FORCE: "N",
    Dimension.TORQUE: "Nm",
    Dimension.ANGLE: "rad",
    Dimension.TIME: "s",
    Dimension.MASS: "kg",
    Dimension.FREQUENCY: "Hz",
    Dimension.NUMBER: "",
}


_EXAMPLE_UNIT = {Dimension.LENGTH: "cm", Dimension.ANGLE: "deg"}


def to_si(value: float, unit: str) -> tuple[Dimension, float]:
    """Convert ``value`` given in ``unit`` to SI; raises KeyError for an unknown unit."""
    dimension, factor = UNITS[unit]
    return dimension, value * factor


def describe_units(dimension: Dimension) -> str:
    """A short list of accepted units for messages, e.g. "m, cm or mm"."""
    units = dimension.units
    if len(units) == 1:
        return units[0]
    return ", ".join(units[:-1]) + " or " + units[-1]
