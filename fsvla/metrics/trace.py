"""What one monitored episode leaves behind: its channels, its margins q_k(s_t), its outcome.

An :class:`EpisodeTrace` holds a T × K array of signed margins (row t = control step,
column k = channel, larger is safer; see paper Eq. threshold), the task-success flag and
the episode's coordinates in the benchmark (scenario, suite, L/W/V levels, seed, policy).
Everything the metrics need is in it; it serialises to plain JSON with
:meth:`EpisodeTrace.to_dict` / :meth:`EpisodeTrace.from_dict`.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal, get_args

import numpy as np
import numpy.typing as npt
from pydantic import BaseModel, ConfigDict, Field, PlainSerializer, PlainValidator, model_validator

from fsvla.metrics.shaping import ShapingName
from fsvla.run.key import SUITES, EpisodeKey, Language, Level, Suite, Vision

Family = Literal["force", "thermal", "boundary", "collaborative", "temporal", "side_effect"]
FAMILIES: tuple[str, ...] = get_args(Family)

# Which Safe-Lang category a W3 instruction realises (paper Table 1).
LanguageCategory = Literal[
    "unsafe_instruction", "contradictory_instruction", "ambiguous_instruction"
]
# Which Safe-Vis category a V3 observation realises; absent, V3 counts toward both.
VisionCategory = Literal["perspective_pose", "occlusion_visibility"]
# The kinds of perturbation a vision level applies (fsvla.variation.vision), in level order:
# V1 lighting; V2 recolor, texture; V3 camera (viewpoint shift), occluder; V4 patch.
VisionKind = Literal["lighting", "recolor", "texture", "camera", "occluder", "patch"]
VISION_KINDS: tuple[str, ...] = get_args(VisionKind)

TRACE_FORMAT_VERSION = 2  # 2: the metadata holds the episode's key (EpisodeMeta.key)


class ChannelInfo(BaseModel):
    """One monitored safety channel k: its soft threshold ε_k, weight w_k and shaping g_k."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    name: str = Field(min_length=1)
    family: Family
    soft_threshold: float = Field(gt=0, allow_inf_nan=False)  # ε_k, in the margin's unit
    weight: float = Field(default=1.0, ge=0, allow_inf_nan=False)  # w_k
    shaping: ShapingName = "linear"  # g_k


class EpisodeMeta(BaseModel):
    """Where an episode sits in the benchmark grid (its :class:`~fsvla.run.key.EpisodeKey`:
    scenario × L × W × V × seed), which policy ran it, the Safe-Lang / Safe-Vis category
    its W3 / V3 level realises, the kinds of visual perturbation it applied (None: not
    recorded) and the digest of its layout (None: not recorded; episodes that share one
    are not independent, see :func:`fsvla.metrics.aggregate`)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    key: EpisodeKey
    policy: str = Field(min_length=1)
    language_category: LanguageCategory | None = None  # only at W3
    vision_category: VisionCategory | None = None  # only at V3
    vision_applied: tuple[VisionKind, ...] | None = None  # in VISION_KINDS order
    layout_digest: str | None = None  # episodes that share one are one independent unit

    @model_validator(mode="after")
    def _categories_match_levels(self) -> EpisodeMeta:
        if self.language_category is not None and self.key.language != "W3":
            raise ValueError(
                f"`language_category` is only set for W3 instructions, actually: "
                f"{self.language_category!r} at {self.key.language}"
            )
        if self.vision_category is not None and self.key.vision != "V3":
            raise ValueError(
                f"`vision_category` is only set for V3 observations, actually: "
                f"{self.vision_category!r} at {self.key.vision}"
            )
        return self


def _as_margins(value: Any) -> np.ndarray:
    try:
        arr = np.array(value, dtype=np.float64)  # a copy: the trace owns its array
    except (TypeError, ValueError) as exc:
        raise ValueError(f"margins must be a T x K array of numbers: {exc}") from None
    if arr.ndim != 2:
        raise ValueError(f"margins must be a 2D (T x K) array, actually: shape {arr.shape}")
    if arr.shape[0] < 1:
        raise ValueError("margins must hold at least one step (T >= 1)")
    if not np.all(np.isfinite(arr)):
        t, k = np.argwhere(~np.isfinite(arr))[0]
        raise ValueError(f"margins must be finite, actually: {arr[t, k]} at step {t}, channel {k}")
    arr.flags.writeable = False
    return arr


def _margins_to_list(arr: np.ndarray) -> list[list[float]]:
    return arr.tolist()


Margins = Annotated[
    npt.NDArray[np.float64],
    PlainValidator(_as_margins),
    PlainSerializer(_margins_to_list, when_used="json"),
]


class EpisodeTrace(BaseModel):
    """Per-step margins of one episode (T × K), its channels, its success flag and metadata."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    channels: tuple[ChannelInfo, ...] = Field(min_length=1)
    margins: Margins  # q_k(s_t): row t, column k; read-only
    success: bool  # S: the task's success predicate held
    meta: EpisodeMeta

    @model_validator(mode="after")
    def _shape_matches_channels(self) -> EpisodeTrace:
        names = [c.name for c in self.channels]
        dupes = sorted({n for n in names if names.count(n) > 1})
        if dupes:
            raise ValueError(f"channel names must be unique, repeated: {', '.join(dupes)}")
        if self.margins.shape[1] != len(self.channels):
            raise ValueError(
                f"margins have {self.margins.shape[1]} columns but there are "
                f"{len(self.channels)} channels"
            )
        return self

    @property
    def horizon(self) -> int:
        """T, the number of monitored control steps."""
        return int(self.margins.shape[0])

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict (lists and scalars only), tagged with the trace format version."""
        return {"version": TRACE_FORMAT_VERSION, **self.model_dump(mode="json")}

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> EpisodeTrace:
        """Inverse of :meth:`to_dict`; rejects other format versions and unknown keys."""
        body = dict(data)
        version = body.pop("version", None)
        if version != TRACE_FORMAT_VERSION:
            raise ValueError(
                f"unsupported trace format version {version!r}; expected {TRACE_FORMAT_VERSION}"
            )
        return cls.model_validate(body)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, EpisodeTrace):
            return NotImplemented
        return (
            self.channels == other.channels
            and self.success == other.success
            and self.meta == other.meta
            and np.array_equal(self.margins, other.margins)
        )

    __hash__ = None  # type: ignore[assignment]  # holds an array: not hashable


__all__ = [
    "FAMILIES",
    "SUITES",
    "TRACE_FORMAT_VERSION",
    "VISION_KINDS",
    "ChannelInfo",
    "EpisodeMeta",
    "EpisodeTrace",
    "Family",
    "Language",
    "LanguageCategory",
    "Level",
    "Suite",
    "Vision",
    "VisionCategory",
    "VisionKind",
]
