"""Which episode: :class:`EpisodeKey`, and the names of the benchmark grid it lives in.

An episode of a run is identified by its scenario (with the scenario's suite and the
embodiment that runs it), its levels L × W × V, the run seed it is drawn from, and its
index within its cell (or among the scenario's warm-ups); its layout seed is a function
of the last two (:func:`fsvla.run.plan.layout_seed`). The plan makes the keys
(:mod:`fsvla.run.plan`); the results store keeps them, one column per field
(:mod:`fsvla.results.rows` maps them); a policy is told its episode's key
(:class:`fsvla.policies.base.EpisodeInfo`); the metrics group episodes by them
(:class:`fsvla.metrics.trace.EpisodeMeta`); the report shows them.

Every one of those layers imports this module, so it imports pydantic and nothing of
fsvla (importing ``fsvla.run`` imports only pydantic, too).
"""

from __future__ import annotations

from typing import Literal, get_args

from pydantic import BaseModel, ConfigDict, Field, model_validator

Suite = Literal["force", "thermal", "boundary", "collaborative", "temporal"]
SUITES: tuple[str, ...] = get_args(Suite)

Level = Literal["L0", "L1", "L2"]
Language = Literal["W0", "W1", "W2", "W3", "W4"]
Vision = Literal["V0", "V1", "V2", "V3", "V4"]

#: A scenario name as the language spells it (no ``-``: the episode id uses it as separator).
SCENARIO_NAME = r"^[A-Za-z0-9_.]+$"


class EpisodeKey(BaseModel):
    """Where one episode sits: scenario × embodiment × L × W × V × run seed × index.

    ``episode_id`` is ``<scenario>-<L>-<W>-<V>-s<seed>-e<index:03d>``, and
    ``<scenario>-warmup-s<seed>-e<index:03d>`` for a warm-up (always at L0/W0/V0):
    readable, sortable, a pure function of the key (the same in every process and under
    ``--extend``: the index is padded to three digits, not to the size of the run), and
    unique in a run because scenario names are. The embodiment is not part of the id: a
    run has one per scenario.
    """

    model_config = ConfigDict(extra="forbid", frozen=True)

    scenario: str = Field(pattern=SCENARIO_NAME)
    suite: Suite
    embodiment: str = Field(min_length=1)
    level: Level = "L0"
    language: Language = "W0"
    vision: Vision = "V0"
    seed: int = Field(ge=0)  # the run seed (one of --seeds) the episode is drawn from
    index: int = Field(default=0, ge=0)  # within its cell, or among the scenario's warm-ups
    warmup: bool = False  # an unscored warm-up episode

    @model_validator(mode="after")
    def _warmups_are_canonical(self) -> EpisodeKey:
        levels = (self.level, self.language, self.vision)
        if self.warmup and levels != ("L0", "W0", "V0"):
            raise ValueError(f"a warm-up episode runs at L0/W0/V0, actually: {'/'.join(levels)}")
        return self

    @property
    def episode_id(self) -> str:
        """The episode's id (see the class doc); also its trace's file name."""
        if self.warmup:
            return f"{self.scenario}-warmup-s{self.seed}-e{self.index:03d}"
        return (f"{self.scenario}-{self.level}-{self.language}-{self.vision}"
                f"-s{self.seed}-e{self.index:03d}")


__all__ = ["SCENARIO_NAME", "SUITES", "EpisodeKey", "Language", "Level", "Suite", "Vision"]
