"""Per-step traces as Parquet: one file per episode, one row per control step.

The data stored is an :class:`~fsvla.results.record.EpisodeRecord`'s ``to_dict()``. Its
per-step arrays become columns (row t = control step t + 1):

==================  =========  ====================================================
column              type       from
==================  =========  ====================================================
``step``            int32      1 .. T
``action/<label>``  float64    ``actions[:, a]``, one column per action component
``margin/<name>``   float64    ``margins[:, k]``, q_k, one column per channel
``state/<name>``    string     ``states[:, k]``: safe / warning / violation
``cost/<name>``     float64    ``costs[:, k]``, the unweighted soft cost c_k
``step_cost``       float64    ``step_costs``, Σ_k w_k c_k
``success_value``   bool       ``success_values``, the success condition at the step
==================  =========  ====================================================

Everything else (the channels with name, family, ε, weight and shaping; the action
labels; the success flag; the record's format version; any key a later record adds) is
JSON under the schema metadata key ``fsvla.trace``. :func:`read_trace` gives back a dict
equal to the ``to_dict()`` written, floats bit for bit (Parquet float64 and JSON's
shortest round-trip repr are both exact). pyarrow is imported when a trace is read or
written, not before.
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from fsvla.results.record import EpisodeRecord

TRACE_FILE_FORMAT = 1
METADATA_KEY = b"fsvla.trace"
# record key -> (column prefix, labels from, dtype); each is a T × n array
_MATRICES = (("actions", "action/", "action_labels", np.float64),
             ("margins", "margin/", "channels", np.float64),
             ("states", "state/", "channels", object),
             ("costs", "cost/", "channels", np.float64))
_VECTORS = (("step_costs", "step_cost", np.float64), ("success_values", "success_value", np.bool_))
_PER_STEP = {key for key, *_ in _MATRICES} | {key for key, *_ in _VECTORS}


def _pyarrow() -> Any:
    try:
        import pyarrow
        import pyarrow.parquet
    except ImportError as err:  # an optional dependency: say how to get it
        raise ImportError("per-step traces need pyarrow: pip install 'pyarrow>=16,<26' "
                          f"(it failed to import: {err})") from err
    return pyarrow


def _labels(record: Mapping[str, Any], source: str) -> list[str]:
    if source == "channels":
        return [c["name"] for c in record["channels"]]
    return list(record[source])


def write_trace(path: Path, record: Mapping[str, Any], episode_id: str) -> None:
    """Write ``record`` (an EpisodeRecord's ``to_dict()``) to ``path`` atomically and durably.

    The file is written under a temporary name in the same folder, fsynced, renamed over
    ``path`` and the folder fsynced: ``path`` is either absent, the old file, or complete.
    """
    pa = _pyarrow()
    steps = len(record["margins"])
    columns: dict[str, Any] = {"step": pa.array(np.arange(1, steps + 1, dtype=np.int32))}
    for key, prefix, source, dtype in _MATRICES:
        labels = _labels(record, source)
        matrix = np.array(record[key], dtype=dtype).reshape(steps, len(labels))
        for j, label in enumerate(labels):
            name = prefix + label
            if name in columns:
                raise ValueError(f"trace of {episode_id}: two {source} are called {label!r}")
            kind = pa.string() if dtype is object else pa.float64()
            columns[name] = pa.array(matrix[:, j].tolist() if dtype is object else matrix[:, j],
                                     type=kind)
    for key, name, dtype in _VECTORS:
        columns[name] = pa.array(np.array(record[key], dtype=dtype).reshape(steps))
    rest = {k: v for k, v in record.items() if k not in _PER_STEP}
    meta = {"trace_format": TRACE_FILE_FORMAT, "episode_id": episode_id, "steps": steps,
            "keys": list(record), "record": rest}
    table = pa.table(columns).replace_schema_metadata(
        {METADATA_KEY: json.dumps(meta, allow_nan=True).encode("utf-8")})
    _atomic_write(path, lambda handle: pa.parquet.write_table(table, handle))


def _atomic_write(path: Path, write: Any) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    temporary = path.with_name(f"{path.name}.tmp-{os.getpid()}")
    try:
        with temporary.open("wb") as handle:
            write(handle)
            handle.flush()
            os.fsync(handle.fileno())
        os.replace(temporary, path)
    finally:
        temporary.unlink(missing_ok=True)
    folder = os.open(path.parent, os.O_RDONLY)
    try:
        os.fsync(folder)
    finally:
        os.close(folder)


def read_trace_table(path: Path) -> Any:
    """The trace as a ``pyarrow.Table`` (for analysis with pandas, polars, duckdb...)."""
    return _pyarrow().parquet.read_table(path)


def trace_metadata(table: Any) -> dict[str, Any]:
    """The ``fsvla.trace`` metadata of a trace table."""
    raw = (table.schema.metadata or {}).get(METADATA_KEY)
    if raw is None:
        raise ValueError("not an fsvla trace: no fsvla.trace schema metadata")
    meta = json.loads(raw)
    if meta.get("trace_format") != TRACE_FILE_FORMAT:
        raise ValueError(f"unsupported trace file format {meta.get('trace_format')!r}; "
                         f"expected {TRACE_FILE_FORMAT}")
    return meta


def read_trace(path: Path) -> dict[str, Any]:
    """The record dict :func:`write_trace` stored in ``path`` (equal to the one written)."""
    table = read_trace_table(path)
    meta = trace_metadata(table)
    data = table.to_pydict()
    record: dict[str, Any] = dict(meta["record"])
    steps = meta["steps"]
    for key, prefix, source, _ in _MATRICES:
        cols = [data[prefix + label] for label in _labels(record, source)]
        record[key] = [list(row) for row in zip(*cols, strict=True)] if cols else [[]] * steps
    for key, name, _ in _VECTORS:
        record[key] = list(data[name])
    return {key: record[key] for key in meta["keys"]}


def read_record(path: Path) -> EpisodeRecord:
    """The :class:`~fsvla.results.record.EpisodeRecord` stored in ``path``."""
    return EpisodeRecord.from_dict(read_trace(path))


__all__ = ["METADATA_KEY", "TRACE_FILE_FORMAT", "read_record", "read_trace", "read_trace_table",
           "trace_metadata", "write_trace"]
