"""What crosses the store's seams: an episode's outcome (in) and its stored row (out)."""

from __future__ import annotations

import hashlib
from datetime import datetime
from typing import Any, Literal, get_args

from pydantic import BaseModel, ConfigDict, Field, model_validator

from fsvla.metrics.episode import ChannelMetrics, FamilyMetrics, Quadrant
from fsvla.metrics.trace import LanguageCategory, VisionCategory, VisionKind
from fsvla.run.key import EpisodeKey
from fsvla.run.plan import EpisodeSpec
from fsvla.variation.language import Instruction
from fsvla.variation.vision import VisionPerturbation

#: Why an episode did not finish normally; each is recorded and the run goes on.
FailureReason = Literal["policy_error", "invalid_action", "policy_timeout", "connection_lost",
                        "sim_error"]
FAILURE_REASONS: tuple[str, ...] = get_args(FailureReason)
EpisodeStatus = Literal["completed", "faulted"]


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


def layout_digest(scene: Any) -> str:
    """The layout digest of an episode: sha256 of its SceneSpec's JSON without the seed
    (``model_dump_json(exclude={"seed"})``), so that two seeds that draw the same layout
    (``L0: none``, a level without rules) share it, and episodes are counted by layout; a
    ``str`` is taken as that JSON."""
    text = scene if isinstance(scene, str) else scene.model_dump_json(exclude={"seed"})
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


class EpisodeOutcome(_Model):
    """What the runner hands :meth:`ResultStore.record` for one episode.

    ``record`` is the episode's ``EpisodeRecord.to_dict()``: the steps that ran, also when
    the episode faulted (``None`` when no environment or recorder existed). A completed
    episode (``failure_reason`` None) must have run at least one step.
    """

    failure_reason: FailureReason | None = None
    failure_detail: str | None = None  # the error, e.g. "TimeoutError: act() took 31.2 s"
    instruction: Instruction | None = None  # None only if the episode faulted before it
    perturbation: VisionPerturbation | None = None
    layout_digest: str | None = None  # see layout_digest()
    embodiment: str | None = None  # the one that ran; None: the spec's
    record: dict[str, Any] | None = None
    started_at: datetime
    finished_at: datetime
    wall_time_s: float = Field(ge=0, allow_inf_nan=False)

    @property
    def status(self) -> EpisodeStatus:
        return "completed" if self.failure_reason is None else "faulted"

    @model_validator(mode="after")
    def _completed_is_whole(self) -> EpisodeOutcome:
        if self.failure_reason is not None:
            return self
        missing = [name for name in ("instruction", "perturbation", "layout_digest", "record")
                   if getattr(self, name) is None]
        if missing:
            raise ValueError(f"a completed episode needs {', '.join(missing)} "
                             "(record a failure_reason if it faulted)")
        if not self.record["margins"]:  # type: ignore[index]
            raise ValueError("a completed episode ran no steps (record a failure_reason)")
        return self


class EpisodeRow(_Model):
    """One row of the ``episodes`` table (see ``docs/results.md`` for each column; the key
    is stored one column per field, see :mod:`fsvla.results.rows`)."""

    key: EpisodeKey  # its embodiment is the one that ran
    session_id: int
    policy: str
    scenario_ref: str
    scenario_digest: str
    layout_seed: int
    language_seed: int
    vision_seed: int
    policy_seed: int
    instruction: str | None
    instruction_origin: str | None
    instruction_category: str | None
    language_category: LanguageCategory | None
    vision_category: VisionCategory | None
    perturbation: VisionPerturbation | None
    vision_applied: tuple[VisionKind, ...] | None  # perturbation.applied()
    layout_digest: str | None
    status: EpisodeStatus
    failure_reason: FailureReason | None
    failure_detail: str | None
    steps: int  # control steps that ran
    success: bool | None  # S as scored: False for every faulted episode
    violation: bool | None
    quadrant: Quadrant | None
    horizon: int | None  # T: scored steps (a faulted episode's finite prefix)
    cc: float | None
    cc_normalised: float | None
    ret: int | None
    ret_fraction: float | None
    sasr: float | None  # this episode's SASR term at sasr_lambda
    sasr_lambda: float
    channels: tuple[ChannelMetrics, ...] | None
    families: tuple[FamilyMetrics, ...] | None
    wall_time_s: float
    started_at: datetime
    finished_at: datetime
    recorded_at: datetime
    trace_path: str | None  # relative to the run folder

    @property
    def episode_id(self) -> str:
        return self.key.episode_id

    def spec(self) -> EpisodeSpec:
        """The episode's :class:`EpisodeSpec`, to replay it (with the run's RunConfig)."""
        return EpisodeSpec.model_validate(
            {name: getattr(self, name) for name in EpisodeSpec.model_fields})

    @property
    def scored(self) -> bool:
        """Whether the row has metrics (some step ran)."""
        return self.horizon is not None


__all__ = ["FAILURE_REASONS", "EpisodeOutcome", "EpisodeRow", "EpisodeStatus", "FailureReason",
           "layout_digest"]
