"""A run's results: the SQLite store of episode rows and the Parquet per-step traces.

See ``docs/results.md``. Importing this package imports neither SAPIEN nor pyarrow
(traces import pyarrow when read or written).
"""

from fsvla.results.models import (
    FAILURE_REASONS,
    EpisodeOutcome,
    EpisodeRow,
    FailureReason,
    layout_digest,
)
from fsvla.results.record import EpisodeRecord
from fsvla.results.store import ResultStore, RunConfigMismatch, RunInfo, RunLocked
from fsvla.results.traces import read_record, read_trace, read_trace_table, write_trace
from fsvla.results.versions import collect_versions

__all__ = [
    "FAILURE_REASONS",
    "EpisodeOutcome",
    "EpisodeRecord",
    "EpisodeRow",
    "FailureReason",
    "ResultStore",
    "RunConfigMismatch",
    "RunInfo",
    "RunLocked",
    "collect_versions",
    "layout_digest",
    "read_record",
    "read_trace",
    "read_trace_table",
    "write_trace",
]
