"""The configuration of one ``fsvla run``: what is evaluated, on which grid, how.

A :class:`RunConfig` is stored in the run folder; running again on the folder resumes it
only when the configuration is the same (:func:`config_differences` says what differs).
``--extend`` may grow the grid (:data:`GRID_FIELDS`) but never change how episodes are
run (policy, modes, embodiment, λ, timeouts), which would mix incomparable episodes.
"""

from __future__ import annotations

import itertools
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from fsvla.run.key import Language, Level, Vision

CONFIG_FORMAT_VERSION = 1
LEVELS: tuple[Level, ...] = ("L0", "L1", "L2")
LANGUAGES: tuple[Language, ...] = ("W0", "W1", "W2", "W3", "W4")
VISIONS: tuple[Vision, ...] = ("V0", "V1", "V2", "V3", "V4")
#: Fields ``--extend`` may change: they add episodes, they do not alter finished ones.
GRID_FIELDS: frozenset[str] = frozenset(
    {"scenarios", "levels", "languages", "visions", "sweep", "episodes", "seeds", "warmup"})
#: Where a one-axis sweep holds the two dimensions it does not vary.
ORIGIN: tuple[Level, Language, Vision] = ("L0", "W0", "V0")


class RunConfig(BaseModel):
    """What ``fsvla run`` evaluates: one policy over scenarios × cells × episodes, the cells
    being the grid L × W × V, or with ``sweep`` its one-axis sweeps (:meth:`cells`)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    format_version: Literal[1] = CONFIG_FORMAT_VERSION
    policy: str = Field(min_length=1)  # a --policy spec (fsvla.policies.registry)
    policy_profile: str | None = None  # a policy server's profile (fsvla.policies.profile)
    scenarios: tuple[str, ...] = Field(min_length=1)  # files, folders or built-in names
    levels: tuple[Level, ...] = ("L0",)
    languages: tuple[Language, ...] = ("W0",)
    visions: tuple[Vision, ...] = ("V0",)
    sweep: bool = False  # one dimension at a time from L0/W0/V0, not the whole grid
    episodes: int = Field(default=1, ge=1)  # per cell (scenario × L × W × V), over the seeds
    seeds: tuple[int, ...] = Field(default=(0,), min_length=1)  # run seeds
    warmup: int = Field(default=1, ge=0)  # unscored episodes per scenario at L0/W0/V0, first
    control_mode: Literal["joint_pos", "joint_delta", "joint_vel", "ee_pose",
                          "ee_delta"] = "joint_pos"
    obs_mode: Literal["state", "rgb"] = "state"
    embodiment: str | None = None  # None: each scenario's own
    sasr_lambda: float = Field(default=1.0, ge=0, allow_inf_nan=False)  # λ of SASR
    terminate_on_violation: bool = False
    policy_timeout_s: float | None = Field(default=None, gt=0, allow_inf_nan=False)  # per act()
    replan_steps: int | None = Field(default=None, ge=1)  # actions of a chunk run; None: all
    cameras: tuple[str, ...] | None = None  # the cameras rendered; None: all of the embodiment's
    resolution: tuple[int, int] | None = None  # (width, height) of each; None: the cameras' own
    shader: Literal["minimal", "default", "rt"] = "minimal"  # the cameras' shader
    patch: str | None = None  # a PNG file (absolute path): V4's patch pixels; None: seeded

    @field_validator("levels", "languages", "visions")
    @classmethod
    def _sorted_unique(cls, value: tuple[str, ...]) -> tuple[str, ...]:
        if not value:
            raise ValueError("name at least one level")
        return tuple(sorted(set(value)))

    @field_validator("cameras")
    @classmethod
    def _cameras_named(cls, value: tuple[str, ...] | None) -> tuple[str, ...] | None:
        if value is not None and (not value or not all(name.strip() for name in value)):
            raise ValueError("name at least one camera, and no empty names")
        return value

    @field_validator("resolution")
    @classmethod
    def _resolution_positive(cls, value: tuple[int, int] | None) -> tuple[int, int] | None:
        if value is not None and not all(1 <= side <= 4096 for side in value):
            raise ValueError(f"a resolution is 1 to 4096 pixels a side, got {value[0]}x{value[1]}")
        return value

    @field_validator("seeds")
    @classmethod
    def _seeds_unique(cls, value: tuple[int, ...]) -> tuple[int, ...]:
        negative = [s for s in value if s < 0]
        if negative:
            raise ValueError(f"seeds must be >= 0, got {negative[0]}")
        if len(set(value)) != len(value):
            raise ValueError(f"seeds must not repeat, got {list(value)}")
        return value

    @model_validator(mode="after")
    def _sweep_starts_at_the_origin(self) -> RunConfig:
        if self.sweep and not ("L0" in self.levels and "W0" in self.languages
                               and "V0" in self.visions):
            raise ValueError("a sweep varies one dimension at a time from L0/W0/V0, so its "
                             "levels must include L0, W0 and V0")
        return self

    def cells(self) -> tuple[tuple[Level, Language, Vision], ...]:
        """The (L, W, V) cells each scenario runs: the grid levels × languages × visions, or
        with ``sweep`` the one-axis sweeps: the levels at W0/V0, the languages at L0/V0,
        the visions at L0/W0, the L0/W0/V0 cell once (3 + 4 + 4 = 11 for full ranges)."""
        if not self.sweep:
            return tuple(itertools.product(self.levels, self.languages, self.visions))
        level, language, vision = ORIGIN
        return (*((lvl, language, vision) for lvl in self.levels),
                *((level, lang, vision) for lang in self.languages if lang != language),
                *((level, language, vis) for vis in self.visions if vis != vision))


class ConfigDifference(BaseModel):
    """One field whose stored and given values differ."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    field: str
    stored: Any
    given: Any
    extendable: bool  # in GRID_FIELDS: --extend accepts the change

    def describe(self) -> str:
        return f"{self.field}: {self.stored!r} in the run folder, {self.given!r} now"


def config_differences(stored: RunConfig, given: RunConfig) -> tuple[ConfigDifference, ...]:
    """The fields that differ between two configurations, in field order."""
    old, new = stored.model_dump(mode="json"), given.model_dump(mode="json")
    return tuple(
        ConfigDifference(field=name, stored=old[name], given=new[name],
                         extendable=name in GRID_FIELDS)
        for name in RunConfig.model_fields if old[name] != new[name])


__all__ = ["CONFIG_FORMAT_VERSION", "GRID_FIELDS", "LANGUAGES", "LEVELS", "ORIGIN", "VISIONS",
           "ConfigDifference", "RunConfig", "config_differences"]
