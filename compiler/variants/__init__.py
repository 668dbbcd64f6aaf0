"""Layout variants L0–L2: seeded, feasibility-checked layouts of a scenario (paper §3.4).

``generate_variant(scenario, "L1", seed=3)`` returns a :class:`Variant`: the scenario
with the level's rules applied and its :class:`~fsvla.compiler.scene.SceneSpec`. The same
(scenario, level, seed) gives the same layout on every machine. See ``docs/variants.md``.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from fsvla.dsl.models import Scenario
from pydantic import BaseModel, ConfigDict

from fsvla.embodiments import EmbodimentSpec

from ..scene import Level, SceneSpec, lower_scene
from .errors import Infeasibility, VariantError, describe_rule, lowering_diagnostics
from .feasibility import CLUTTER_CLEARANCE, CONTACT_TOLERANCE, REACH_MARGIN
from .generate import (
    NEAR_DISTANCE,
    NUISANCE_DISTANCE,
    NUISANCE_YAW,
    Generator,
    cached_build_asset,
    cached_build_zone_marker,
    load_spec,
    nuisance_rules,
    rng_for,
    rules_of,
)
from .layout import CLUTTER_PALETTE

LEVELS: tuple[Level, ...] = ("L0", "L1", "L2")


class Variant(BaseModel):
    """One generated layout: the varied scenario and the scene it lowers to."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    level: Level
    seed: int
    scenario: Scenario  # the level's rules applied: placements, clutter, limits, requirements
    scene: SceneSpec  # ``lower_scene`` of ``scenario``, with this level and seed
    samples: int  # layouts drawn until one was feasible (0: nothing to draw)


def generate_variant(
    scenario: Scenario,
    level: Level = "L0",
    seed: int = 0,
    *,
    allowed_roots: Sequence[Path] = (),
    embodiment: EmbodimentSpec | None = None,
    budget: int = 200,
) -> Variant:
    """The layout of ``scenario`` at ``level`` for ``seed``; raises :class:`VariantError`
    (a ``LoweringError``) when no feasible layout is found within ``budget`` samples, or a
    plain ``LoweringError`` when the scenario cannot be lowered at all."""
    if level not in LEVELS:
        raise ValueError(f"level must be one of {', '.join(LEVELS)}, got {level!r}")
    if budget < 1:
        raise ValueError(f"budget must be at least 1, got {budget}")
    spec = load_spec(scenario, embodiment)

    def lower(varied: Scenario) -> SceneSpec:
        return lower_scene(varied, level=level, seed=seed, allowed_roots=allowed_roots, embodiment=spec,
                           asset_builder=cached_build_asset, marker_builder=cached_build_zone_marker)

    canonical = lower(scenario)
    generator = Generator(scenario, level, canonical, spec, budget)
    varied, scene, samples = generator.search(rng_for(scenario, level, seed),
                                              lambda s: canonical if s is scenario else lower(s))
    return Variant(level=level, seed=seed, scenario=varied, scene=scene, samples=samples)


__all__ = [
    "CLUTTER_CLEARANCE", "CLUTTER_PALETTE", "CONTACT_TOLERANCE", "LEVELS", "NEAR_DISTANCE",
    "NUISANCE_DISTANCE", "NUISANCE_YAW", "REACH_MARGIN", "Infeasibility", "Variant", "VariantError",
    "describe_rule", "generate_variant", "lowering_diagnostics", "nuisance_rules", "rules_of",
]
