"""``fsvla run``: the run configuration, the episode plan, episode keys and option parsing.

See ``docs/results.md``. Importing this package imports pydantic and nothing else of note
(no SAPIEN, no pyarrow, no other fsvla package): the metrics, the results, the policies
and the report all import :class:`EpisodeKey` from here.
"""

from fsvla.run.config import GRID_FIELDS, ConfigDifference, RunConfig, config_differences
from fsvla.run.key import EpisodeKey
from fsvla.run.plan import EpisodeSpec, PlannedScenario, layout_seed, plan_episodes
from fsvla.run.ranges import (
    RangeError,
    parse_languages,
    parse_levels,
    parse_seeds,
    parse_visions,
)

__all__ = [
    "GRID_FIELDS",
    "ConfigDifference",
    "EpisodeKey",
    "EpisodeSpec",
    "PlannedScenario",
    "RangeError",
    "RunConfig",
    "config_differences",
    "layout_seed",
    "parse_languages",
    "parse_levels",
    "parse_seeds",
    "parse_visions",
    "plan_episodes",
]
