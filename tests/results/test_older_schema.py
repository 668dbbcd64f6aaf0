"""A run folder of results schema 1 still loads (read-only), with the columns it lacks
derived, and refuses to be written to."""

from __future__ import annotations

import sqlite3
from pathlib import Path

import pytest

from fsvla.results import ResultStore, schema
from fsvla.runner.prepare import RunInputError, check_run_folder

from .conftest import make_outcome, make_record


def downgrade_to_schema_1(run_dir: Path) -> None:
    """Make ``run_dir`` what an fsvla of schema 1 wrote: without the newer columns."""
    db = sqlite3.connect(run_dir / schema.DATABASE)
    try:
        for version in sorted(schema.ADDED_COLUMNS):
            for column in schema.ADDED_COLUMNS[version]:
                db.execute(f"ALTER TABLE episodes DROP COLUMN {column}")
        db.execute("UPDATE run SET schema_version = 1")
        db.execute("PRAGMA user_version = 1")
        db.commit()
    finally:
        db.close()


@pytest.fixture
def old_run(tmp_path: Path, config, plan) -> tuple[Path, dict]:
    run_dir = tmp_path / "old"
    with ResultStore.create(run_dir, config) as store:
        for i, spec in enumerate(plan[:6]):
            store.record(spec, make_outcome(make_record(seed=i), spec=spec))
        expected = {row.episode_id: row for row in store.episodes()}
    downgrade_to_schema_1(run_dir)
    return run_dir, expected


def test_an_old_run_folder_is_read_with_its_missing_columns_derived(old_run) -> None:
    run_dir, expected = old_run
    with ResultStore.open(run_dir, readonly=True) as store:
        assert store.schema_version == 1 and store.info().schema_version == 1
        rows = store.episodes()
        assert [r.episode_id for r in rows] == list(expected)
        for row in rows:
            # schema 1 drew one layout per run seed: its layout seed was the run seed
            assert row.layout_seed == row.key.seed
            recorded = expected[row.episode_id].model_copy(update={"layout_seed": row.key.seed})
            assert row == recorded  # the rest derived exactly as recorded now
        assert {r.key.vision: r.vision_applied for r in rows} == {"V0": (), "V1": ("lighting",)}
        assert len(store.metrics(include_warmup=True)) == 6


def test_an_old_run_folder_is_reported(old_run) -> None:
    from fsvla.report import Settings, build_report, load_runs

    run_dir, _ = old_run
    report = build_report(load_runs([run_dir]), settings=Settings(n_resamples=20))
    assert report.aggregate.rows[0].n == 4  # the six rows less the two warm-ups


def test_an_old_run_folder_is_not_written(old_run, config) -> None:
    run_dir, _ = old_run
    with pytest.raises(ValueError, match="older fsvla .*schema version 1.* start a new run folder"):
        ResultStore.open(run_dir, config)
    with pytest.raises(RunInputError, match="--out: .*older fsvla"):
        check_run_folder(run_dir, config)
