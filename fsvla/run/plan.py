"""Expand a :class:`RunConfig` into the episodes of a run, each with its own seeds and key.

Order: every scenario's warm-up episodes come first (at L0/W0/V0, ``warmup`` flag set,
never scored), then the scored episodes in rounds: round ``e`` holds episode ``e`` of
every cell (scenario × ``RunConfig.cells()``: the L × W × V grid, or its one-axis sweeps),
so a run stopped early still covers every cell evenly.

How "episodes spread over seeds" is realised, for episode index ``e`` of a cell:

* ``seed`` = ``seeds[e mod len(seeds)]``: the run seed the episode is drawn from
  (:class:`~fsvla.run.key.EpisodeKey` ``seed``, in its id), round-robin over the seeds;
* ``layout_seed`` = :func:`layout_seed` (``seed``, ``e``): a SHA-256 of both, so every
  scored episode of a cell has its own layout (with the level, it fixes the layout: at
  L0 the canonical one with its nuisance jitter), the same on every machine;
* ``language_seed`` = ``vision_seed`` = ``policy_seed`` = ``e``: they pick the W and V draws
  (``instruction_for`` / ``perturbation_for`` already mix the scenario, dimension and level
  into their generator) and seed the policy.

None of the four depends on W or V (nor the three last on L), so episode ``e`` of two
cells of a level differs only in the cell's levels (common random numbers): they share
a layout, which is why intervals count layouts, not episodes (:mod:`fsvla.metrics.aggregate`).

Each episode's :class:`~fsvla.run.key.EpisodeKey` (scenario, suite, embodiment, levels,
layout seed, index, warm-up flag) gives its id, e.g. ``lift_pot-L1-W3-V0-s2-e007``.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from pydantic import BaseModel, ConfigDict, Field

from fsvla.run.config import RunConfig
from fsvla.run.key import SCENARIO_NAME, EpisodeKey, Language, Level, Suite, Vision

if TYPE_CHECKING:
    from fsvla.dsl.models import Scenario


class PlannedScenario(BaseModel):
    """What the plan needs of a loaded scenario."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    name: str = Field(pattern=SCENARIO_NAME)
    ref: str  # a path or built-in name that loads it again (workers, replay)
    suite: Suite
    embodiment: str  # the scenario's own; RunConfig.embodiment overrides it
    digest: str  # the scenario's source_digest

    @classmethod
    def of(cls, scenario: Scenario, ref: str | Path) -> PlannedScenario:
        """From a checked scenario loaded from ``ref``."""
        return cls(name=scenario.name, ref=str(ref), suite=scenario.suite,
                   embodiment=scenario.embodiment, digest=scenario.source_digest)


class EpisodeSpec(BaseModel):
    """Everything that fixes one episode; enough to replay it exactly."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    key: EpisodeKey
    scenario_ref: str
    scenario_digest: str
    layout_seed: int = Field(ge=0)  # with key.level, the layout (layout_seed())
    language_seed: int = Field(ge=0)
    vision_seed: int = Field(ge=0)
    policy_seed: int = Field(ge=0)

    @property
    def episode_id(self) -> str:
        """The key's id; also the trace's file name."""
        return self.key.episode_id


def plan_episodes(config: RunConfig, scenarios: list[PlannedScenario]) -> list[EpisodeSpec]:
    """All episodes of the run, warm-ups first (see the module doc for order and seeds)."""
    names = [s.name for s in scenarios]
    repeated = sorted({n for n in names if names.count(n) > 1})
    if repeated:
        refs = ", ".join(s.ref for s in scenarios if s.name in repeated)
        raise ValueError(f"scenario names must be unique in a run, repeated: "
                         f"{', '.join(repeated)} ({refs})")
    specs = [_spec(config, s, "L0", "W0", "V0", e, warmup=True)
             for s in scenarios for e in range(config.warmup)]
    specs += [_spec(config, s, level, language, vision, e)
              for e in range(config.episodes)
              for s in scenarios
              for level, language, vision in config.cells()]
    return specs


#: Layout seeds lie in [0, LAYOUT_SEEDS): 31 bits, an INTEGER in every store and language.
LAYOUT_SEEDS = 2**31


def layout_seed(seed: int, index: int, *, warmup: bool = False) -> int:
    """The layout seed of episode ``index`` drawn from run seed ``seed`` (a warm-up's is
    drawn apart): SHA-256 of them (``fsvla.compiler.seeding.stable_seed``), 31 bits."""
    from fsvla.compiler.seeding import stable_seed

    parts = ("layout", seed, index, "warmup") if warmup else ("layout", seed, index)
    return stable_seed(*parts) % LAYOUT_SEEDS


def _spec(config: RunConfig, scenario: PlannedScenario, level: Level, language: Language,
          vision: Vision, index: int, warmup: bool = False) -> EpisodeSpec:
    seed = config.seeds[index % len(config.seeds)]
    key = EpisodeKey(scenario=scenario.name, suite=scenario.suite,
                     embodiment=config.embodiment or scenario.embodiment, level=level,
                     language=language, vision=vision, seed=seed, index=index, warmup=warmup)
    return EpisodeSpec(key=key, scenario_ref=scenario.ref, scenario_digest=scenario.digest,
                       layout_seed=layout_seed(seed, index, warmup=warmup),
                       language_seed=index, vision_seed=index, policy_seed=index)


__all__ = ["LAYOUT_SEEDS", "EpisodeSpec", "PlannedScenario", "layout_seed", "plan_episodes"]
