"""Expand a :class:`RunConfig` into the episodes of a run, each with its own seeds and key.

Order: every scenario's warm-up episodes come first (at L0/W0/V0, ``warmup`` flag set,
never scored), then the scored episodes in rounds: round ``e`` holds episode ``e`` of
every cell (scenario × L × W × V), so a run stopped early still covers every cell evenly.

How "episodes spread over seeds" is realised, for episode index ``e`` of a cell:

* ``seed`` = ``seeds[e mod len(seeds)]``: the layout seed (with the level it fixes the
  layout; :class:`~fsvla.run.key.EpisodeKey` ``seed``), round-robin over the seeds;
* ``language_seed`` = ``vision_seed`` = ``policy_seed`` = ``e``: they pick the W and V draws
  (``instruction_for`` / ``perturbation_for`` already mix the scenario, dimension and level
  into their generator) and seed the policy. They do not depend on L, W or V, so episode
  ``e`` of two cells differs only in the cell's levels (common random numbers).

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
              for level in config.levels
              for language in config.languages
              for vision in config.visions]
    return specs


def _spec(config: RunConfig, scenario: PlannedScenario, level: Level, language: Language,
          vision: Vision, index: int, warmup: bool = False) -> EpisodeSpec:
    key = EpisodeKey(scenario=scenario.name, suite=scenario.suite,
                     embodiment=config.embodiment or scenario.embodiment, level=level,
                     language=language, vision=vision,
                     seed=config.seeds[index % len(config.seeds)], index=index, warmup=warmup)
    return EpisodeSpec(key=key, scenario_ref=scenario.ref, scenario_digest=scenario.digest,
                       language_seed=index, vision_seed=index, policy_seed=index)


__all__ = ["EpisodeSpec", "PlannedScenario", "plan_episodes"]
