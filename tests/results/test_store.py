"""The SQLite result store: rows, metrics read back, faults, configuration checks."""

from __future__ import annotations

import sqlite3
from pathlib import Path

import pytest

from fsvla.metrics import CC_NORMALISATION, aggregate, episode_metrics
from fsvla.metrics.trace import EpisodeTrace
from fsvla.results import ResultStore, RunConfigMismatch, RunLocked, read_trace
from fsvla.results.rows import episode_meta
from fsvla.run import RunConfig

VERSIONS = {"python": "3.11.7", "fsvla": "0.1.0", "sapien": "3.0.3", "numpy": "1.26.4"}


def _scored(plan: list) -> list:
    return [s for s in plan if not s.key.warmup]


def test_create_records_the_run(tmp_path: Path, config: RunConfig) -> None:
    with ResultStore.create(tmp_path / "run", config, VERSIONS) as store:
        info = store.info()
    assert info.config == config and info.versions == VERSIONS
    assert info.cc_normalisation == CC_NORMALISATION
    assert {p.name for p in (tmp_path / "run").iterdir()} == {"results.sqlite", "traces", "lock"}
    db = sqlite3.connect(tmp_path / "run" / "results.sqlite")
    assert db.execute("PRAGMA journal_mode").fetchone()[0] == "wal"
    assert {r[0] for r in db.execute("SELECT name FROM sqlite_master WHERE type = 'table'")} >= {
        "run", "sessions", "episodes"}


def test_create_refuses_an_existing_run(tmp_path: Path, config: RunConfig) -> None:
    ResultStore.create(tmp_path / "run", config, VERSIONS).close()
    with pytest.raises(FileExistsError, match="already holds a run"):
        ResultStore.create(tmp_path / "run", config, VERSIONS)


def test_row_round_trip(tmp_path: Path, config: RunConfig, plan: list, record_factory,
                        outcome_factory) -> None:
    spec = _scored(plan)[3]
    record = record_factory(steps=8, seed=5)
    outcome = outcome_factory(record, spec=spec)
    with ResultStore.create(tmp_path / "run", config, VERSIONS) as store:
        written = store.record(spec, outcome)
    with ResultStore.open(tmp_path / "run", readonly=True) as store:
        (row,) = store.episodes()
        assert row == written
        assert row == store.episode(spec.episode_id)
        assert store.trace(spec.episode_id) == record.to_dict()
    assert row.status == "completed" and row.failure_reason is None
    assert row.key == spec.key and row.episode_id == spec.episode_id
    assert row.instruction == outcome.instruction.text
    assert row.perturbation == outcome.perturbation
    assert row.steps == row.horizon == 8
    assert row.trace_path == f"traces/{spec.episode_id}.parquet"
    assert (spec.key.language, spec.key.vision, row.language_category) == (
        "W3", "V1", "unsafe_instruction")
    assert row.spec() == spec  # enough to replay it


def test_the_key_is_stored_one_column_a_field(tmp_path: Path, config: RunConfig, plan: list,
                                              record_factory, outcome_factory) -> None:
    """The key round-trips through the store, in the columns every run folder has."""
    warm, scored = plan[0], _scored(plan)[3]
    with ResultStore.create(tmp_path / "run", config, VERSIONS) as store:
        for spec in (warm, scored):
            store.record(spec, outcome_factory(record_factory(), spec=spec))
    with ResultStore.open(tmp_path / "run", readonly=True) as store:
        assert [row.key for row in store.episodes()] == [warm.key, scored.key]
        assert store.episode(scored.episode_id).key == scored.key
    db = sqlite3.connect(tmp_path / "run" / "results.sqlite")
    columns = ("episode_id, scenario, suite, embodiment, level, language, vision, seed, "
               "episode_index, warmup")
    stored = db.execute(f"SELECT {columns} FROM episodes ORDER BY rowid").fetchall()
    assert stored == [(k.episode_id, k.scenario, k.suite, k.embodiment, k.level, k.language,
                       k.vision, k.seed, k.index, int(k.warmup)) for k in (warm.key, scored.key)]


def test_a_row_whose_id_is_not_its_key_is_refused(tmp_path: Path, config: RunConfig,
                                                  plan: list, record_factory,
                                                  outcome_factory) -> None:
    spec = _scored(plan)[0]
    with ResultStore.create(tmp_path / "run", config, VERSIONS) as store:
        store.record(spec, outcome_factory(record_factory(), spec=spec))
    with sqlite3.connect(tmp_path / "run" / "results.sqlite") as db:
        db.execute("UPDATE episodes SET seed = 5")
    with (ResultStore.open(tmp_path / "run", readonly=True) as store,
          pytest.raises(ValueError, match=f"stored as '{spec.episode_id}' has the key of "
                        "'lift_pot_beside_stove-L0-W0-V0-s5-e000'")):
        store.episodes()


def test_levels_of_instruction_and_perturbation_must_match(tmp_path: Path, config: RunConfig,
                                                           plan: list, record_factory,
                                                           outcome_factory) -> None:
    w3v1, w0v0 = _scored(plan)[3], _scored(plan)[0]
    with ResultStore.create(tmp_path / "run", config, VERSIONS) as store:
        with pytest.raises(ValueError, match=r"-W3-V1-s0-e000 is at W3 but its instruction is "
                           "at W0"):
            store.record(w3v1, outcome_factory(record_factory(), spec=w0v0))
        assert store.episodes() == []


def test_metrics_read_back_equal_the_ones_computed(tmp_path: Path, config: RunConfig,
                                                   plan: list, record_factory,
                                                   outcome_factory) -> None:
    specs = _scored(plan)[:6]
    expected = []
    with ResultStore.create(tmp_path / "run", config, VERSIONS) as store:
        for i, spec in enumerate(specs):
            record = record_factory(steps=5 + i, seed=i, success=i % 2 == 0)
            outcome = outcome_factory(record, spec=spec)
            store.record(spec, outcome)
            expected.append(episode_metrics(record.trace(episode_meta(spec, outcome,
                                                                      config.policy))))
    with ResultStore.open(tmp_path / "run", readonly=True) as store:
        got = store.metrics()
        rows = store.episodes()
    assert got == expected
    assert [r.sasr for r in rows] == [m.sasr(config.sasr_lambda) for m in expected]
    w3 = [m for m in got if m.meta.key.language == "W3"]
    assert w3 and {m.meta.language_category for m in w3} == {"unsafe_instruction"}
    assert aggregate(got) == aggregate(expected)


def test_warmups_are_recorded_but_not_scored(tmp_path: Path, config: RunConfig, plan: list,
                                             record_factory, outcome_factory) -> None:
    warm, scored = plan[0], _scored(plan)[0]
    with ResultStore.create(tmp_path / "run", config, VERSIONS) as store:
        store.record(warm, outcome_factory(record_factory()))
        store.record(scored, outcome_factory(record_factory()))
        assert [m.meta.key for m in store.metrics()] == [scored.key]
        assert len(store.metrics(include_warmup=True)) == 2
        assert store.pending(plan[:3]) == [plan[1]]  # the other scenario's warm-up


def test_faulted_episode_with_steps(tmp_path: Path, config: RunConfig, plan: list,
                                    record_factory, outcome_factory) -> None:
    spec = _scored(plan)[0]
    record = record_factory(steps=6, success=True)
    data = record.to_dict()
    data["margins"][4] = [float("nan"), 0.1]  # the simulator blew up at step 5
    outcome = outcome_factory(failure="sim_error", record=None).model_copy(update={"record": data})
    with ResultStore.create(tmp_path / "run", config, VERSIONS) as store:
        row = store.record(spec, outcome)
        (metrics,) = store.metrics()
        assert store.metrics(faults="exclude") == []
        assert store.trace(spec.episode_id)["margins"][4][1] == 0.1  # the whole trace is kept
    assert row.status == "faulted" and row.failure_reason == "sim_error"
    assert row.failure_detail == "sim_error: boom"
    assert row.steps == 6 and row.horizon == 4  # scored on the finite prefix
    assert row.success is False and metrics.success is False  # a fault is a failure
    trace = record.trace(episode_meta(spec, outcome, config.policy))
    prefix = EpisodeTrace(channels=trace.channels, margins=trace.margins[:4], success=False,
                          meta=trace.meta)
    assert metrics == episode_metrics(prefix)


@pytest.mark.parametrize("reason", ["policy_error", "invalid_action", "policy_timeout",
                                    "connection_lost", "sim_error"])
def test_faulted_episode_without_steps(tmp_path: Path, config: RunConfig, plan: list,
                                       outcome_factory, reason: str) -> None:
    spec = _scored(plan)[1]
    outcome = outcome_factory(None, failure=reason, instruction=None, perturbation=None,
                              layout_digest=None)
    with ResultStore.create(tmp_path / "run", config, VERSIONS) as store:
        row = store.record(spec, outcome)
        (metrics,) = store.metrics()
    assert (row.status, row.failure_reason, row.steps, row.horizon, row.trace_path) == (
        "faulted", reason, 0, None, None)
    assert row.cc is None and row.quadrant is None and row.channels is None
    assert (metrics.quadrant, metrics.cc, metrics.horizon) == ("safe_failure", 0.0, 1)


def test_bad_input_writes_nothing(tmp_path: Path, config: RunConfig, plan: list,
                                  record_factory, outcome_factory) -> None:
    spec = _scored(plan)[0]
    data = record_factory(steps=3).to_dict()
    data["margins"][1][0] = float("nan")  # a completed episode must have finite margins
    outcome = outcome_factory(record_factory(steps=3)).model_copy(update={"record": data})
    with ResultStore.create(tmp_path / "run", config, VERSIONS) as store:
        with pytest.raises(ValueError, match="margins must be finite"):
            store.record(spec, outcome)
        assert store.episodes() == []
        assert list((tmp_path / "run" / "traces").iterdir()) == []


def test_completed_outcome_must_be_whole(outcome_factory, record_factory) -> None:
    with pytest.raises(ValueError, match="a completed episode needs record"):
        outcome_factory(None)
    with pytest.raises(ValueError, match="ran no steps"):
        outcome_factory(record_factory(steps=0))


def test_an_episode_is_recorded_once(tmp_path: Path, config: RunConfig, plan: list,
                                     record_factory, outcome_factory) -> None:
    spec = _scored(plan)[0]
    first = record_factory(seed=1)
    with ResultStore.create(tmp_path / "run", config, VERSIONS) as store:
        store.record(spec, outcome_factory(first))
        with pytest.raises(ValueError, match="already recorded"):
            store.record(spec, outcome_factory(record_factory(seed=2)))
        assert store.trace(spec.episode_id) == first.to_dict()  # untouched
        assert len(store.episodes()) == 1


def test_pending_is_the_plan_minus_the_recorded(tmp_path: Path, config: RunConfig, plan: list,
                                               record_factory, outcome_factory) -> None:
    with ResultStore.create(tmp_path / "run", config, VERSIONS) as store:
        for spec in plan[::3]:
            store.record(spec, outcome_factory(record_factory(), spec=spec))
    with ResultStore.open(tmp_path / "run", config, VERSIONS) as store:
        assert store.pending(plan) == [s for i, s in enumerate(plan) if i % 3]
        assert [s["kind"] for s in store.sessions()] == ["create", "resume"]


def test_different_config_is_refused_with_the_fields(tmp_path: Path, config: RunConfig) -> None:
    ResultStore.create(tmp_path / "run", config, VERSIONS).close()
    other = config.model_copy(update={"episodes": 5, "obs_mode": "rgb"})
    with pytest.raises(RunConfigMismatch) as caught:
        ResultStore.open(tmp_path / "run", other, VERSIONS)
    assert str(caught.value) == (
        f"{tmp_path / 'run'} holds a run with a different configuration:\n"
        "  episodes: 2 in the run folder, 5 now\n"
        "  obs_mode: 'state' in the run folder, 'rgb' now\n"
        "Pass --extend to grow the run with the new grid, or choose another run folder.")
    assert [d.field for d in caught.value.differences] == ["episodes", "obs_mode"]
    with pytest.raises(RunConfigMismatch, match=r"(?s)cannot change in a run:\n"
                       r"  obs_mode: 'state' in the run folder, 'rgb' now\nStart a new"):
        ResultStore.open(tmp_path / "run", other, VERSIONS, extend=True)
    # a refused open leaves the run as it was, and unlocked
    with ResultStore.open(tmp_path / "run", config, VERSIONS) as store:
        assert store.config == config


def test_extend_grows_the_grid(tmp_path: Path, config: RunConfig) -> None:
    ResultStore.create(tmp_path / "run", config, VERSIONS).close()
    bigger = config.model_copy(update={"episodes": 5, "visions": ("V0", "V1")})
    with pytest.raises(RunConfigMismatch):
        ResultStore.open(tmp_path / "run", bigger, VERSIONS)
    with ResultStore.open(tmp_path / "run", bigger, VERSIONS, extend=True) as store:
        assert store.config == bigger
    with ResultStore.open(tmp_path / "run", readonly=True) as store:
        assert [s["kind"] for s in store.sessions()] == ["create", "extend"]
        assert store.sessions()[1]["config"]["episodes"] == 5


def test_one_writer_at_a_time(tmp_path: Path, config: RunConfig) -> None:
    with ResultStore.create(tmp_path / "run", config, VERSIONS):
        with pytest.raises(RunLocked, match="being written by another process"):
            ResultStore.open(tmp_path / "run", config, VERSIONS)
        with ResultStore.open(tmp_path / "run", readonly=True) as reader:
            assert reader.config == config
    ResultStore.open(tmp_path / "run", config, VERSIONS).close()


def test_readonly_store_refuses_to_record(tmp_path: Path, config: RunConfig, plan: list,
                                          record_factory, outcome_factory) -> None:
    ResultStore.create(tmp_path / "run", config, VERSIONS).close()
    with ResultStore.open(tmp_path / "run", readonly=True) as store, \
            pytest.raises(PermissionError):
        store.record(plan[0], outcome_factory(record_factory()))


def test_open_of_a_folder_without_a_run(tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError, match="holds no run"):
        ResultStore.open(tmp_path)


def test_open_or_create(tmp_path: Path, config: RunConfig) -> None:
    ResultStore.open_or_create(tmp_path / "run", config, VERSIONS).close()
    with ResultStore.open_or_create(tmp_path / "run", config, VERSIONS) as store:
        assert [s["kind"] for s in store.sessions()] == ["create", "resume"]


def test_metrics_rejects_unknown_fault_policy(tmp_path: Path, config: RunConfig) -> None:
    with ResultStore.create(tmp_path / "run", config, VERSIONS) as store, \
            pytest.raises(ValueError, match="'failure' or 'exclude'"):
        store.metrics(faults="ignore")  # type: ignore[arg-type]


def test_trace_of_a_row_is_its_file(tmp_path: Path, config: RunConfig, plan: list,
                                    record_factory, outcome_factory) -> None:
    spec = _scored(plan)[2]
    record = record_factory()
    with ResultStore.create(tmp_path / "run", config, VERSIONS) as store:
        row = store.record(spec, outcome_factory(record, spec=spec))
    assert read_trace(tmp_path / "run" / row.trace_path) == record.to_dict()


def test_a_foreign_database_file_is_refused_untouched(tmp_path: Path, config: RunConfig) -> None:
    run_dir = tmp_path / "run"
    run_dir.mkdir()
    (run_dir / "results.sqlite").write_bytes(b"not a database at all" * 100)
    for attempt in (lambda: ResultStore.open_or_create(run_dir, config, VERSIONS),
                    lambda: ResultStore.open(run_dir, readonly=True)):
        with pytest.raises(ValueError, match="is not an fsvla results database"):
            attempt()
    assert (run_dir / "results.sqlite").read_bytes() == b"not a database at all" * 100


def test_faults_lower_the_rates(tmp_path: Path, config: RunConfig, plan: list,
                                record_factory, outcome_factory) -> None:
    first, second = _scored(plan)[:2]
    record = record_factory(steps=3)
    record = type(record)(**{**record.__dict__, "margins": record.margins * 0 + 1.0,
                             "success": True})  # safe throughout: a safe success
    with ResultStore.create(tmp_path / "run", config, VERSIONS) as store:
        store.record(first, outcome_factory(record, spec=first))
        store.record(second, outcome_factory(None, failure="policy_timeout", instruction=None,
                                             perturbation=None))
        counted = aggregate(store.metrics())
        excluded = aggregate(store.metrics(faults="exclude"))
    assert (counted.n, counted.ssr.estimate, counted.sfr.estimate) == (2, 0.5, 0.5)
    assert (excluded.n, excluded.ssr.estimate) == (1, 1.0)
