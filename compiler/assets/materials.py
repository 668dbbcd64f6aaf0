"""Named physical materials (density, friction, look) the builders draw from."""

from __future__ import annotations

from dataclasses import dataclass

from .model import Appearance, Material, Rgba

# A kinetic friction coefficient is this fraction of the static one.
DYNAMIC_FRICTION_RATIO = 0.85


@dataclass(frozen=True)
class Substance:
    """What a body is made of: a density (kg/m³) and how it looks and slides."""

    name: str
    density: float
    color: Rgba
    friction: float = 0.6
    restitution: float = 0.1
    roughness: float = 0.6
    metallic: float = 0.0

    def appearance(self, color: Rgba | None = None, emission: Rgba | None = None) -> Appearance:
        return Appearance(
            base_color=color or self.color,
            emission=emission,
            roughness=self.roughness,
            metallic=self.metallic,
        )


WOOD = Substance("wood", 650.0, (0.62, 0.45, 0.30, 1.0), friction=0.6)
LAMINATE = Substance("laminate", 700.0, (0.78, 0.74, 0.68, 1.0), friction=0.6)
CERAMIC = Substance("ceramic", 2000.0, (0.93, 0.92, 0.88, 1.0), friction=0.55, roughness=0.3)
GLASS = Substance("glass", 2500.0, (0.80, 0.90, 0.95, 0.35), friction=0.45, roughness=0.05)
ALUMINIUM = Substance(
    "aluminium", 2700.0, (0.76, 0.77, 0.80, 1.0), friction=0.5, roughness=0.35, metallic=0.9
)
STEEL = Substance(
    "steel", 7800.0, (0.82, 0.83, 0.85, 1.0), friction=0.5, roughness=0.25, metallic=1.0
)
PLASTIC = Substance("plastic", 1100.0, (0.15, 0.15, 0.16, 1.0), friction=0.6)
# A closed bottle counted with part of its contents: an effective density.
FILLED_BOTTLE = Substance(
    "filled_bottle", 700.0, (0.25, 0.55, 0.35, 0.8), friction=0.5, roughness=0.1
)
# A plate's disc also counts the hollow of its dish: an effective density.
PLATE_CERAMIC = Substance(
    "plate_ceramic", 900.0, (0.95, 0.95, 0.93, 1.0), friction=0.55, roughness=0.3
)
ENAMEL = Substance("enamel", 1500.0, (0.22, 0.22, 0.24, 1.0), friction=0.6, roughness=0.4)

HOT_GLOW: Rgba = (1.0, 0.35, 0.05, 4.0)  # (r, g, b, strength) of a heating plate


def physics_material(
    substance: Substance, friction: float | None, density: float, emission: Rgba | None = None
) -> Material:
    """A body material: ``friction`` (static) overrides the substance's own."""
    static = substance.friction if friction is None else float(friction)
    return Material(
        static_friction=static,
        dynamic_friction=static * DYNAMIC_FRICTION_RATIO,
        restitution=substance.restitution,
        density=density,
        base_color=substance.color,
        emission=emission,
        roughness=substance.roughness,
        metallic=substance.metallic,
    )


#: RGB of the colours a scenario can give a body by name (``color=blue``; the catalog's
#: ``COLOR_NAMES``): saturated enough to tell apart under the V1 lighting changes.
NAMED_COLORS: dict[str, tuple[float, float, float]] = {
    "red": (0.80, 0.15, 0.13),
    "green": (0.20, 0.62, 0.25),
    "blue": (0.15, 0.32, 0.80),
    "yellow": (0.92, 0.80, 0.15),
    "orange": (0.95, 0.50, 0.10),
    "purple": (0.52, 0.25, 0.68),
    "pink": (0.93, 0.55, 0.70),
    "brown": (0.45, 0.30, 0.18),
    "white": (0.93, 0.93, 0.92),
    "grey": (0.50, 0.50, 0.52),
    "black": (0.08, 0.08, 0.09),
}
