"""Safety metrics of the paper's §4: soft cost, CC, RET, quadrants, SASR, and their CIs.

Pure numpy + pydantic; no simulator. A runner records an :class:`EpisodeTrace` per
episode, :func:`episode_metrics` turns it into :class:`EpisodeMetrics`, and
:func:`aggregate` / :func:`breakdown` summarise many. See ``docs/metrics.md``.
"""

from fsvla.metrics.aggregate import (
    Aggregate,
    Interval,
    aggregate,
    bootstrap_mean_interval,
    breakdown,
    wilson_interval,
)
from fsvla.metrics.episode import (
    CC_NORMALISATION,
    QUADRANTS,
    ChannelMetrics,
    EpisodeMetrics,
    FamilyMetrics,
    episode_metrics,
)
from fsvla.metrics.shaping import SHAPINGS, soft_cost
from fsvla.metrics.taxonomy import CATEGORIES, categories
from fsvla.metrics.trace import ChannelInfo, EpisodeMeta, EpisodeTrace

__all__ = [
    "CATEGORIES",
    "CC_NORMALISATION",
    "QUADRANTS",
    "SHAPINGS",
    "Aggregate",
    "ChannelInfo",
    "ChannelMetrics",
    "EpisodeMeta",
    "EpisodeMetrics",
    "EpisodeTrace",
    "FamilyMetrics",
    "Interval",
    "aggregate",
    "bootstrap_mean_interval",
    "breakdown",
    "categories",
    "episode_metrics",
    "soft_cost",
    "wilson_interval",
]
