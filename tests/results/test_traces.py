"""Per-step Parquet traces: exact round trips, schema, metadata, atomic writes."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from fsvla.results import read_record, read_trace, read_trace_table, write_trace
from fsvla.results.traces import METADATA_KEY, trace_metadata


def _bits(values: object) -> np.ndarray:
    return np.asarray(values, dtype=np.float64).view(np.uint64)


def test_round_trip_is_exact(tmp_path: Path, record_factory) -> None:
    record = record_factory(steps=40, seed=3)
    path = tmp_path / "traces" / "ep.parquet"
    write_trace(path, record.to_dict(), "ep")
    back = read_trace(path)
    assert back == record.to_dict()
    for key in ("actions", "margins", "costs", "step_costs"):
        assert np.array_equal(_bits(back[key]), _bits(getattr(record, key))), key
    assert np.signbit(back["actions"][0][0])  # -0.0 survives
    assert back["margins"][-1][1] == 5e-324


def test_read_record_rebuilds_the_episode_record(tmp_path: Path, record_factory) -> None:
    record = record_factory(steps=5)
    write_trace(tmp_path / "ep.parquet", record.to_dict(), "ep")
    back = read_record(tmp_path / "ep.parquet")
    assert back.channels == record.channels and back.action_labels == record.action_labels
    assert back.states == record.states and back.success == record.success
    for key in ("actions", "margins", "costs", "step_costs", "success_values"):
        assert np.array_equal(getattr(back, key), getattr(record, key)), key
        assert getattr(back, key).dtype == getattr(record, key).dtype


def test_one_row_per_step_with_named_columns(tmp_path: Path, record_factory) -> None:
    write_trace(tmp_path / "ep.parquet", record_factory(steps=4).to_dict(), "ep")
    table = read_trace_table(tmp_path / "ep.parquet")
    assert table.num_rows == 4
    assert table.column_names == [
        "step", "action/arm.joint1", "action/arm.joint2", "action/arm.gripper",
        "margin/pot_stove_clearance", "margin/table_edge", "state/pot_stove_clearance",
        "state/table_edge", "cost/pot_stove_clearance", "cost/table_edge", "step_cost",
        "success_value"]
    assert table.column("step").to_pylist() == [1, 2, 3, 4]
    assert str(table.schema.field("state/table_edge").type) == "string"
    meta = trace_metadata(table)
    assert meta["episode_id"] == "ep"
    assert meta["record"]["channels"][1] == {"name": "table_edge", "family": "boundary",
                                             "soft_threshold": 0.03, "weight": 2.0,
                                             "shaping": "quadratic"}


def test_episode_without_steps(tmp_path: Path, record_factory) -> None:
    record = record_factory(steps=0, success=False)
    write_trace(tmp_path / "ep.parquet", record.to_dict(), "ep")
    assert read_trace(tmp_path / "ep.parquet") == record.to_dict()
    assert read_record(tmp_path / "ep.parquet").margins.shape == (0, 2)


def test_non_finite_values_survive(tmp_path: Path, record_factory) -> None:
    data = record_factory(steps=3).to_dict()
    data["margins"][2] = [float("nan"), float("-inf")]
    data["actions"][1][0] = float("inf")
    write_trace(tmp_path / "ep.parquet", data, "ep")
    back = read_trace(tmp_path / "ep.parquet")
    assert np.array_equal(np.array(back["margins"]), np.array(data["margins"]), equal_nan=True)
    assert back["actions"][1][0] == float("inf")


def test_keys_a_later_record_adds_are_kept(tmp_path: Path, record_factory) -> None:
    data = {**record_factory(steps=2).to_dict(), "terminated_by": "success", "notes": [1.5, None]}
    write_trace(tmp_path / "ep.parquet", data, "ep")
    assert read_trace(tmp_path / "ep.parquet") == data


def test_write_replaces_atomically_and_leaves_no_temporary(tmp_path: Path, record_factory) -> None:
    path = tmp_path / "ep.parquet"
    write_trace(path, record_factory(steps=2, seed=1).to_dict(), "ep")
    new = record_factory(steps=3, seed=2).to_dict()
    write_trace(path, new, "ep")
    assert read_trace(path) == new
    assert [p.name for p in tmp_path.iterdir()] == ["ep.parquet"]


def test_failed_write_keeps_the_old_file(tmp_path: Path, record_factory) -> None:
    path = tmp_path / "ep.parquet"
    old = record_factory(steps=2).to_dict()
    write_trace(path, old, "ep")
    bad = {**old, "margins": [[0.1, 0.2, 0.3]]}  # three margins for two channels
    with pytest.raises(ValueError):
        write_trace(path, bad, "ep")
    assert read_trace(path) == old
    assert [p.name for p in tmp_path.iterdir()] == ["ep.parquet"]


def test_write_interrupted_midway_keeps_the_old_file(tmp_path: Path, record_factory,
                                                    monkeypatch: pytest.MonkeyPatch) -> None:
    import pyarrow.parquet as pq

    path = tmp_path / "ep.parquet"
    old = record_factory(steps=2).to_dict()
    write_trace(path, old, "ep")

    def half_written(table: object, handle) -> None:
        handle.write(b"PAR1 and then the disk filled up")
        raise OSError("No space left on device")

    monkeypatch.setattr(pq, "write_table", half_written)
    with pytest.raises(OSError, match="No space"):
        write_trace(path, record_factory(steps=3, seed=9).to_dict(), "ep")
    monkeypatch.undo()
    assert read_trace(path) == old
    assert [p.name for p in tmp_path.iterdir()] == ["ep.parquet"]


def test_foreign_parquet_is_refused(tmp_path: Path) -> None:
    import pyarrow as pa
    import pyarrow.parquet as pq

    pq.write_table(pa.table({"x": [1]}), tmp_path / "x.parquet")
    with pytest.raises(ValueError, match="not an fsvla trace"):
        read_trace(tmp_path / "x.parquet")
    table = pa.table({"x": [1]}).replace_schema_metadata(
        {METADATA_KEY: json.dumps({"trace_format": 99}).encode()})
    pq.write_table(table, tmp_path / "y.parquet")
    with pytest.raises(ValueError, match="unsupported trace file format 99"):
        read_trace(tmp_path / "y.parquet")
