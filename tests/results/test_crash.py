"""Crashes and kills: a run folder keeps every finished episode and nothing half-written.

Each test runs a writer in a child process that dies (``os._exit``, no cleanup, as a
SIGKILL would leave it) at a chosen point, then reopens the folder here.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from fsvla.results import ResultStore, read_trace
from fsvla.run import RunConfig

VERSIONS = {"python": "3.11.7", "fsvla": "0.1.0"}

# argv: run folder, config JSON, plan JSON, outcomes JSON, how many to record, where to die
_WRITER = """
import json, os, sys
from pathlib import Path
import fsvla.results.store as store_module
from fsvla.results import EpisodeOutcome, ResultStore
from fsvla.run import EpisodeSpec, RunConfig

run_dir, config, plan, outcomes, count, die = sys.argv[1:]
config = RunConfig.model_validate_json(config)
plan = [EpisodeSpec.model_validate(s) for s in json.loads(plan)]
outcomes = [EpisodeOutcome.model_validate(o) for o in json.loads(outcomes)]
real_write = store_module.write_trace

def write_then_die(path, record, episode_id):
    real_write(path, record, episode_id)
    os._exit(9)                        # killed between the trace and the row

def die_mid_write(path, record, episode_id):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.with_name(path.name + ".tmp-" + str(os.getpid())).write_bytes(b"PAR1 half")
    os._exit(9)                        # killed while writing the trace

store = ResultStore.open_or_create(Path(run_dir), config, {"python": "x"})
for i, (spec, outcome) in enumerate(zip(plan[:int(count)], outcomes)):
    if i == int(count) - 1 and die == "after_trace":
        store_module.write_trace = write_then_die
    if i == int(count) - 1 and die == "mid_trace":
        store_module.write_trace = die_mid_write
    store.record(spec, outcome)
if die == "no_close":
    os._exit(9)                        # killed after its commits, before close()
store.close()
"""


def _run_writer(run_dir: Path, config: RunConfig, plan: list, outcome_factory, record,
                count: int, die: str) -> int:
    """Record ``record`` as each of the first ``count`` episodes of ``plan``, dying at ``die``."""
    outcomes = [outcome_factory(record, spec=spec).model_dump(mode="json") for spec in plan[:count]]
    args = [sys.executable, "-c", _WRITER, str(run_dir), config.model_dump_json(),
            json.dumps([s.model_dump(mode="json") for s in plan]), json.dumps(outcomes),
            str(count), die]
    done = subprocess.run(args, capture_output=True, text=True, timeout=120, check=False)
    assert done.returncode in (0, 9), done.stderr
    return done.returncode


def _scored(plan: list) -> list:
    return [s for s in plan if not s.key.warmup]


def test_kill_between_trace_and_row(tmp_path: Path, config: RunConfig, plan: list,
                                    record_factory, outcome_factory) -> None:
    run_dir, specs = tmp_path / "run", _scored(plan)
    assert _run_writer(run_dir, config, specs, outcome_factory, record_factory(seed=1), 3, "after_trace") == 9
    with ResultStore.open(run_dir, config, VERSIONS) as store:
        assert store.recorded_ids() == {specs[0].episode_id, specs[1].episode_id}
        assert store.pending(specs)[0] == specs[2]  # the killed episode runs again
        orphan = run_dir / "traces" / f"{specs[2].episode_id}.parquet"
        assert store.orphan_traces() == [orphan]
        again = record_factory(seed=2)
        store.record(specs[2], outcome_factory(again, spec=specs[2]))  # overwrites the orphan
        assert store.orphan_traces() == []
        assert [r.episode_id for r in store.episodes()] == [s.episode_id for s in specs[:3]]
        assert read_trace(orphan) == again.to_dict()


def test_kill_while_writing_a_trace(tmp_path: Path, config: RunConfig, plan: list,
                                    record_factory, outcome_factory) -> None:
    run_dir, specs = tmp_path / "run", _scored(plan)
    assert _run_writer(run_dir, config, specs, outcome_factory, record_factory(seed=1), 2, "mid_trace") == 9
    assert any(".tmp-" in p.name for p in (run_dir / "traces").iterdir())
    with ResultStore.open(run_dir, config, VERSIONS) as store:  # removes the temporary
        assert store.recorded_ids() == {specs[0].episode_id}
        assert store.orphan_traces() == []
        assert [p.name for p in (run_dir / "traces").iterdir()] == [
            f"{specs[0].episode_id}.parquet"]


def test_kill_without_close_keeps_the_commits_in_the_wal(tmp_path: Path, config: RunConfig,
                                                         plan: list, record_factory,
                                                         outcome_factory) -> None:
    run_dir, specs = tmp_path / "run", _scored(plan)
    assert _run_writer(run_dir, config, specs, outcome_factory, record_factory(seed=1), 4, "no_close") == 9
    wal = run_dir / "results.sqlite-wal"
    assert wal.exists() and wal.stat().st_size > 0  # the rows are still only in the WAL
    with ResultStore.open(run_dir, readonly=True) as reader:  # readers see them
        assert len(reader.episodes()) == 4
    with ResultStore.open(run_dir, config, VERSIONS) as store:  # the lock died with the writer
        assert len(store.episodes()) == 4
    assert not wal.exists() or wal.stat().st_size == 0  # close() checkpointed it


def test_close_leaves_a_single_database_file(tmp_path: Path, config: RunConfig, plan: list,
                                             record_factory, outcome_factory) -> None:
    run_dir, specs = tmp_path / "run", _scored(plan)
    assert _run_writer(run_dir, config, specs, outcome_factory, record_factory(), 2, "none") == 0
    assert sorted(p.name for p in run_dir.iterdir()) == ["lock", "results.sqlite", "traces"]
    with ResultStore.open(run_dir, readonly=True) as reader:
        assert len(reader.episodes()) == 2


def test_resume_runs_each_episode_once(tmp_path: Path, config: RunConfig, plan: list,
                                       record_factory, outcome_factory) -> None:
    run_dir = tmp_path / "run"
    _run_writer(run_dir, config, plan, outcome_factory, record_factory(seed=1), 5, "after_trace")
    with ResultStore.open(run_dir, config, VERSIONS) as store:
        for spec in store.pending(plan):
            store.record(spec, outcome_factory(record_factory(), spec=spec))
        ids = [r.episode_id for r in store.episodes()]
    assert sorted(ids) == sorted(s.episode_id for s in plan) and len(set(ids)) == len(ids)
