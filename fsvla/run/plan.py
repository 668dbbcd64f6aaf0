"""Expand a :class:`RunConfig` into the episodes of a run, each with its own seeds and id.

Order: every scenario's warm-up episodes come first (at L0/W0/V0, ``warmup`` flag set,
never scored), then the scored episodes in rounds: round ``e`` holds episode ``e`` of
every cell (scenario × L × W × V), so a run stopped early still covers every cell evenly.

How "episodes spread over seeds" is realised, for episode index ``e`` of a cell:

* ``seed`` = ``seeds[e mod len(seeds)]``: the layout seed (with the level it fixes the
  layout; :class:`~fsvla.metrics.trace.EpisodeMeta` ``seed``), round-robin over the seeds;
* ``language_seed`` = ``vision_seed`` = ``policy_seed`` = ``e``: they pick the W and V draws
  (``instruction_for`` / ``perturbation_for`` already mix the scenario, dimension and level
  into their generator) and seed the policy. They do not depend on L, W or V, so episode
  ``e`` of two cells differs only in the cell's levels (common random numbers).

The id is ``<scenario>-<L>-<W>-<V>-s<seed>-e<index:03d>`` (``<scenario>-warmup-s<seed>-e<index:03d>``
for warm-ups): readable, sortable, a pure function of the episode's coordinates (so the
same in every process and under ``--extend``: the index is padded to three digits, not to
the size of the run), and unique because scenario names are.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import TYPE_CHECKING

from pydantic import BaseModel, ConfigDict, Field

from fsvla.metrics.trace import Language, Level, Suite, Vision
from fsvla.run.config import RunConfig

if TYPE_CHECKING:
    from fsvla.dsl.models import Scenario

_NAME = re.compile(r"^[A-Za-z0-9_.]+$")


class PlannedScenario(BaseModel):
    """What the plan needs of a loaded scenario."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    name: str = Field(pattern=_NAME.pattern)
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

    episode_id: str = Field(pattern=r"^[A-Za-z0-9_.-]+$")  # also its trace's file name
    scenario: str
    scenario_ref: str
    scenario_digest: str
    suite: Suite
    embodiment: str
    level: Level
    language: Language
    vision: Vision
    seed: int = Field(ge=0)  # layout seed
    episode_index: int = Field(ge=0)  # within its cell (or among the scenario's warm-ups)
    language_seed: int = Field(ge=0)
    vision_seed: int = Field(ge=0)
    policy_seed: int = Field(ge=0)
    warmup: bool = False


def episode_id(scenario: str, level: str, language: str, vision: str, seed: int, index: int,
               warmup: bool = False) -> str:
    """The id of an episode (see the module doc)."""
    if warmup:
        return f"{scenario}-warmup-s{seed}-e{index:03d}"
    return f"{scenario}-{level}-{language}-{vision}-s{seed}-e{index:03d}"


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
    seed = config.seeds[index % len(config.seeds)]
    return EpisodeSpec(
        episode_id=episode_id(scenario.name, level, language, vision, seed, index, warmup),
        scenario=scenario.name, scenario_ref=scenario.ref, scenario_digest=scenario.digest,
        suite=scenario.suite, embodiment=config.embodiment or scenario.embodiment,
        level=level, language=language, vision=vision, seed=seed, episode_index=index,
        language_seed=index, vision_seed=index, policy_seed=index, warmup=warmup)


__all__ = ["EpisodeSpec", "PlannedScenario", "episode_id", "plan_episodes"]
