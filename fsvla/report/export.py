"""The report's numbers as flat records, for CSV (always) and Parquet (with pyarrow).

* ``aggregate``: one row per policy, every metric with its interval and the quadrant counts;
* ``per_<by>``: one row per group × policy (suite, category, embodiment, level, language,
  vision);
* ``derived``: the §5.2 shares per policy;
* ``episodes``: every episode behind the numbers, with the columns the groups are made
  from, so that any number can be recounted by filtering this file;
* ``dissection_channels``: Table 4 of the dissected episode.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Sequence
from typing import Any

from fsvla.metrics import Interval, categories
from fsvla.report.build import Report
from fsvla.report.data import RunData
from fsvla.report.tables import GroupTable

Record = dict[str, Any]


def _interval(prefix: str, interval: Interval | None) -> Record:
    if interval is None:
        return {prefix: None, f"{prefix}_low": None, f"{prefix}_high": None}
    return {prefix: interval.estimate, f"{prefix}_low": interval.low,
            f"{prefix}_high": interval.high}


def aggregate_records(report: Report) -> list[Record]:
    out = []
    for r in report.aggregate.rows:
        record: Record = {"policy": r.label, "run_dir": r.run_dir, "n": r.n,
                          "n_layouts": r.n_layouts, **r.counts, "faults": r.faults}
        for name in ("ssr", "usr", "sfr", "ufr", "cc", "sasr", "cc_weighted", "cc_raw",
                     "ret_fraction"):
            record.update(_interval(name, getattr(r, name)))
        record.update(sasr_lambda=r.sasr_lambda, confidence=report.protocol.confidence,
                      best=";".join(m for m, labels in report.aggregate.best.items()
                                    if r.label in labels))
        out.append(record)
    return out


def group_records(table: GroupTable) -> list[Record]:
    out = []
    for row in table.rows:
        for policy in table.policies:
            cell = row.cells.get(policy)
            record: Record = {table.by: row.key, "label": row.label, "section": row.section,
                              "policy": policy, "n": 0 if cell is None else cell.n,
                              "n_layouts": 0 if cell is None else cell.n_layouts}
            if table.by in ("level", "language", "vision"):
                record["protocol"] = None if cell is None else cell.protocol
            for name in ("ssr", "cc", "sasr"):
                record.update(_interval(name, None if cell is None else getattr(cell, name)))
            out.append(record)
    return out


def derived_records(report: Report) -> list[Record]:
    return [{"policy": d.label, "n": d.n, "success_rate": d.success_rate,
             "successes": d.successes, "unsafe_successes": d.unsafe_successes,
             **_interval("unsafe_share_of_successes", d.unsafe_share_of_successes),
             "failures": d.failures, "unsafe_failures": d.unsafe_failures,
             **_interval("unsafe_share_of_failures", d.unsafe_share_of_failures)}
            for d in report.derived]


def episode_records(runs: Sequence[RunData]) -> list[Record]:
    """Every scored episode of every run, as the tables count it."""
    out = []
    for run in runs:
        for ep in run.episodes:
            m, row = ep.metrics, ep.row
            out.append({
                "policy": run.label, "run_dir": str(run.run_dir), "episode_id": ep.id,
                **m.meta.key.model_dump(exclude={"index", "warmup"}),
                "layout_seed": row.layout_seed, "layout_digest": row.layout_digest,
                "categories": ";".join(categories(m.meta)), "status": row.status,
                "failure_reason": row.failure_reason, "quadrant": m.quadrant,
                "success": m.success, "violation": m.violation, "horizon": m.horizon,
                "cc": m.cc, "cc_per_step": m.cc_per_step, "cc_normalised": m.cc_normalised,
                "ret": m.ret,
                "ret_fraction": m.ret_fraction, "sasr": m.sasr(run.sasr_lambda),
                "trace_path": row.trace_path})
    return out


def dissection_records(report: Report) -> list[Record]:
    d = report.dissection
    if d is None:
        return []
    return [{"episode_id": d.episode_id, "policy": d.label, **c.model_dump()}
            for c in d.channels]


def all_records(report: Report, runs: Sequence[RunData]) -> dict[str, list[Record]]:
    """Every exported table by file stem."""
    tables = {"aggregate": aggregate_records(report), "derived": derived_records(report)}
    for table in (*report.groups.values(), *report.severity.values()):
        tables[f"per_{table.by}"] = group_records(table)
    tables["episodes"] = episode_records(runs)
    tables["dissection_channels"] = dissection_records(report)
    return tables


def to_csv(records: list[Record]) -> str:
    """Records as CSV text (header from the first record; floats with full precision)."""
    if not records:
        return ""
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=list(records[0]), lineterminator="\n")
    writer.writeheader()
    writer.writerows({k: ("" if v is None else repr(v) if isinstance(v, float) else v)
                      for k, v in r.items()} for r in records)
    return buffer.getvalue()


def to_parquet(records: list[Record]) -> bytes:
    """Records as Parquet file bytes (needs pyarrow, the results extra)."""
    try:
        import pyarrow
        import pyarrow.parquet
    except ImportError as err:
        raise ImportError("Parquet export needs pyarrow: pip install 'fsvla[results]' "
                          f"(it failed to import: {err})") from err
    buffer = io.BytesIO()
    pyarrow.parquet.write_table(pyarrow.Table.from_pylist(records), buffer)
    return buffer.getvalue()


__all__ = ["aggregate_records", "all_records", "derived_records", "dissection_records",
           "episode_records", "group_records", "to_csv", "to_parquet"]
