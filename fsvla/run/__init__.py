"""``fsvla run``: the run configuration, the episode plan and option parsing.

See ``docs/results.md``. Importing this package imports neither SAPIEN nor pyarrow.
"""

from fsvla.run.config import GRID_FIELDS, ConfigDifference, RunConfig, config_differences
from fsvla.run.plan import EpisodeSpec, PlannedScenario, episode_id, plan_episodes
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
    "EpisodeSpec",
    "PlannedScenario",
    "RangeError",
    "RunConfig",
    "config_differences",
    "episode_id",
    "parse_languages",
    "parse_levels",
    "parse_seeds",
    "parse_visions",
    "plan_episodes",
]
