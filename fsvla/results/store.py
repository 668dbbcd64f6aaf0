"""A run folder's results: one SQLite database and one Parquet trace per episode.

::

    runs/exp1/
      results.sqlite    run, sessions and episodes tables (WAL mode)
      traces/<episode_id>.parquet
      lock              held (flock) by the one process writing the run

One writer: the runner's main process opens the store, workers send it outcomes, and it
alone calls :meth:`ResultStore.record`. The lock refuses a second writer; readers
(reports, replay) open with ``readonly=True`` at any time, also while a run writes.

Crash safety: :meth:`ResultStore.record` validates and scores first, then writes the
trace (temporary name, fsync, rename), then inserts the row in one transaction
(``synchronous=FULL``). An episode is recorded iff its row exists; a trace without a row
(a crash between the two writes) is overwritten when the episode runs again.
"""

from __future__ import annotations

import contextlib
import fcntl
import json
import os
import sqlite3
from collections.abc import Iterator, Sequence
from datetime import datetime, timezone
from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict

from fsvla.metrics.episode import CC_NORMALISATION, EpisodeMetrics
from fsvla.results import schema
from fsvla.results.models import EpisodeOutcome, EpisodeRow
from fsvla.results.rows import build_row, row_from_sql, row_metrics, row_to_sql, unscored_failure
from fsvla.results.traces import read_trace, write_trace
from fsvla.results.versions import collect_versions
from fsvla.run.config import ConfigDifference, RunConfig, config_differences
from fsvla.run.plan import EpisodeSpec

SessionKind = Literal["create", "resume", "extend"]
FaultPolicy = Literal["failure", "exclude"]


class RunInfo(BaseModel):
    """The ``run`` table."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    schema_version: int
    config: RunConfig
    versions: dict[str, str]
    created_at: datetime
    updated_at: datetime
    cc_normalisation: str


class RunConfigMismatch(ValueError):
    """The run folder holds a run with another configuration."""

    def __init__(self, run_dir: Path, differences: Sequence[ConfigDifference], extend: bool) -> None:
        self.run_dir = run_dir
        self.differences = tuple(differences)
        lines = [f"  {d.describe()}" for d in self.differences]
        if extend:
            head = (f"{run_dir}: --extend may only grow the grid (scenarios, levels, languages, "
                    "visions, episodes, seeds, warmup); these fields cannot change in a run:")
            tail = "Start a new run folder to change them."
        else:
            head = f"{run_dir} holds a run with a different configuration:"
            tail = ("Pass --extend to grow the run with the new grid, or choose another "
                    "run folder.")
        super().__init__("\n".join([head, *lines, tail]))


class RunLocked(RuntimeError):
    """Another process is writing the run folder."""


def _now() -> str:
    return datetime.now(timezone.utc).isoformat()


class ResultStore:
    """The results of one run folder; see the module doc. Use as a context manager."""

    def __init__(self, run_dir: Path, connection: sqlite3.Connection, *, readonly: bool,
                 session_id: int | None, lock: int | None) -> None:
        self.run_dir = run_dir
        self._db = connection
        self.readonly = readonly
        self.session_id = session_id
        self._lock = lock

    # ---------------------------------------------------------------- opening
    @classmethod
    def exists(cls, run_dir: Path) -> bool:
        """Whether ``run_dir`` holds a run (a database with its run record)."""
        path = Path(run_dir) / schema.DATABASE
        if not path.exists():
            return False
        db = sqlite3.connect(f"file:{path}?mode=ro", uri=True)
        try:
            tables = db.execute("SELECT count(*) FROM sqlite_master WHERE name = 'run'")
            return tables.fetchone()[0] == 1 and db.execute(
                "SELECT count(*) FROM run").fetchone()[0] == 1
        except sqlite3.DatabaseError as err:
            raise ValueError(f"{path} is not an fsvla results database ({err}); "
                             "leave it alone and choose another run folder") from None
        finally:
            db.close()

    @classmethod
    def create(cls, run_dir: Path, config: RunConfig,
               versions: dict[str, str] | None = None) -> ResultStore:
        """A new run in ``run_dir`` (created if missing); refuses a folder that holds one."""
        run_dir = Path(run_dir)
        run_dir.mkdir(parents=True, exist_ok=True)
        lock = _acquire(run_dir)
        with contextlib.ExitStack() as stack:
            stack.callback(_release, lock)
            if cls.exists(run_dir):
                raise FileExistsError(f"{run_dir} already holds a run: open it to resume")
            versions = versions if versions is not None else collect_versions()
            db = _connect(run_dir / schema.DATABASE)
            stack.callback(db.close)
            with _transaction(db):
                for statement in schema.TABLES:
                    db.execute(statement)
                db.execute("INSERT INTO run VALUES (1, ?, ?, ?, ?, ?, ?)",
                           (schema.SCHEMA_VERSION, config.model_dump_json(),
                            json.dumps(versions), _now(), _now(), CC_NORMALISATION))
                db.execute(f"PRAGMA user_version = {schema.SCHEMA_VERSION}")
                session = _new_session(db, "create", config, versions)
            (run_dir / schema.TRACES).mkdir(exist_ok=True)
            stack.pop_all()  # success: the store keeps the connection and the lock
        return cls(run_dir, db, readonly=False, session_id=session, lock=lock)

    @classmethod
    def open(cls, run_dir: Path, config: RunConfig | None = None,
             versions: dict[str, str] | None = None, *, extend: bool = False,
             readonly: bool = False) -> ResultStore:
        """The run in ``run_dir``. For writing (``readonly=False``) it takes the lock and
        starts a session; given ``config``, it must equal the stored one, or differ only in
        the grid when ``extend`` (the stored configuration is then replaced by ``config``)."""
        run_dir = Path(run_dir)
        if not cls.exists(run_dir):
            raise FileNotFoundError(f"{run_dir} holds no run (no {schema.DATABASE} with a run "
                                    "record)")
        if readonly:
            db = sqlite3.connect(f"file:{run_dir / schema.DATABASE}?mode=ro", uri=True,
                                 isolation_level=None)
            db.row_factory = sqlite3.Row
            store = cls(run_dir, db, readonly=True, session_id=None, lock=None)
            store._check_schema()
            return store
        lock = _acquire(run_dir)
        with contextlib.ExitStack() as stack:
            stack.callback(_release, lock)
            db = _connect(run_dir / schema.DATABASE)
            stack.callback(db.close)
            store = cls(run_dir, db, readonly=False, session_id=None, lock=lock)
            store._check_schema()
            store.session_id = store._start_session(config, versions, extend)
            store._remove_temporaries()
            stack.pop_all()
        return store

    @classmethod
    def open_or_create(cls, run_dir: Path, config: RunConfig,
                       versions: dict[str, str] | None = None, *,
                       extend: bool = False) -> ResultStore:
        """What ``fsvla run --out run_dir`` does: resume the run there, or start it."""
        if cls.exists(run_dir):
            return cls.open(run_dir, config, versions, extend=extend)
        return cls.create(run_dir, config, versions)

    def close(self) -> None:
        """Checkpoint the WAL into the database (so the folder is one file plus traces) and
        release the lock. Safe to call twice."""
        if self._db is None:
            return
        try:
            if not self.readonly:
                self._db.execute("PRAGMA wal_checkpoint(TRUNCATE)")
            self._db.close()
        finally:
            self._db = None  # type: ignore[assignment]
            _release(self._lock)
            self._lock = None

    def __enter__(self) -> ResultStore:  # noqa: PYI034 (typing.Self needs 3.11; we support 3.10)
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # ---------------------------------------------------------------- the run
    def info(self) -> RunInfo:
        row = self._db.execute("SELECT * FROM run").fetchone()
        return RunInfo(schema_version=row["schema_version"],
                       config=RunConfig.model_validate_json(row["config_json"]),
                       versions=json.loads(row["versions_json"]), created_at=row["created_at"],
                       updated_at=row["updated_at"], cc_normalisation=row["cc_normalisation"])

    @property
    def config(self) -> RunConfig:
        return self.info().config

    def sessions(self) -> list[dict[str, Any]]:
        """Every time a writer opened the run: id, kind, started_at, config and versions."""
        rows = self._db.execute("SELECT * FROM sessions ORDER BY id").fetchall()
        return [{"id": r["id"], "kind": r["kind"], "started_at": r["started_at"],
                 "config": json.loads(r["config_json"]),
                 "versions": json.loads(r["versions_json"])} for r in rows]

    # ---------------------------------------------------------------- episodes
    def recorded_ids(self) -> set[str]:
        return {r[0] for r in self._db.execute("SELECT episode_id FROM episodes")}

    def pending(self, plan: Sequence[EpisodeSpec]) -> list[EpisodeSpec]:
        """The episodes of ``plan`` not yet recorded, in plan order."""
        done = self.recorded_ids()
        return [spec for spec in plan if spec.episode_id not in done]

    def record(self, spec: EpisodeSpec, outcome: EpisodeOutcome) -> EpisodeRow:
        """Store one finished (or faulted) episode: its trace, then its row (module doc).

        Raises ValueError, before writing anything, on an outcome that cannot be stored
        (non-finite margins in a completed episode, a mismatched record) or an episode
        that is already recorded."""
        if self.readonly:
            raise PermissionError(f"{self.run_dir} is open read-only")
        if self._db.execute("SELECT 1 FROM episodes WHERE episode_id = ?",
                            (spec.episode_id,)).fetchone():
            raise ValueError(f"episode {spec.episode_id} is already recorded in {self.run_dir}")
        config = self.config
        trace_path = (f"{schema.TRACES}/{spec.episode_id}.parquet"
                      if outcome.record is not None else None)
        row = build_row(spec, outcome, policy=config.policy, lam=config.sasr_lambda,
                        session_id=self.session_id or 0, trace_path=trace_path)
        if outcome.record is not None and trace_path is not None:
            write_trace(self.run_dir / trace_path, outcome.record, spec.episode_id)
        with _transaction(self._db):
            self._db.execute(schema.INSERT_EPISODE, row_to_sql(row))
            self._db.execute("UPDATE run SET updated_at = ?", (_now(),))
        return row

    def episodes(self, *, include_warmup: bool = True) -> list[EpisodeRow]:
        """Every recorded episode's row, in the order they were recorded."""
        where = "" if include_warmup else " WHERE warmup = 0"
        rows = self._db.execute(f"SELECT * FROM episodes{where} ORDER BY rowid").fetchall()
        return [row_from_sql(r) for r in rows]

    def episode(self, episode_id: str) -> EpisodeRow:
        row = self._db.execute("SELECT * FROM episodes WHERE episode_id = ?",
                               (episode_id,)).fetchone()
        if row is None:
            raise KeyError(f"no episode {episode_id!r} recorded in {self.run_dir}")
        return row_from_sql(row)

    def trace(self, episode_id: str) -> dict[str, Any] | None:
        """The episode's per-step record (``EpisodeRecord.to_dict()``), None if it has none."""
        path = self.episode(episode_id).trace_path
        return None if path is None else read_trace(self.run_dir / path)

    def metrics(self, *, include_warmup: bool = False,
                faults: FaultPolicy = "failure") -> list[EpisodeMetrics]:
        """The episodes' :class:`EpisodeMetrics`, for :func:`fsvla.metrics.aggregate`.

        ``faults="failure"`` (the default, the paper's choice) counts every faulted episode
        as a task failure: scored on the steps it ran, or, if none, as a safe failure with
        no exposure. ``faults="exclude"`` leaves faulted episodes out. Warm-ups are left
        out unless ``include_warmup``."""
        if faults not in ("failure", "exclude"):
            raise ValueError(f"Expect `faults` to be 'failure' or 'exclude', actually: {faults!r}")
        out = []
        for row in self.episodes(include_warmup=include_warmup):
            if row.status == "faulted" and faults == "exclude":
                continue
            out.append(row_metrics(row) or unscored_failure(row))
        return out

    def orphan_traces(self) -> list[Path]:
        """Trace files without a row (left by a crash between the two writes)."""
        recorded = {r[0] for r in self._db.execute(
            "SELECT trace_path FROM episodes WHERE trace_path IS NOT NULL")}
        folder = self.run_dir / schema.TRACES
        return sorted(p for p in folder.glob("*.parquet")
                      if f"{schema.TRACES}/{p.name}" not in recorded)

    # ---------------------------------------------------------------- internals
    def _check_schema(self) -> None:
        version = self._db.execute("PRAGMA user_version").fetchone()[0]
        if version not in schema.READABLE_VERSIONS:
            raise ValueError(f"{self.run_dir}: results schema version {version}, this fsvla "
                             f"reads versions {', '.join(map(str, schema.READABLE_VERSIONS))}")
        if version != schema.SCHEMA_VERSION and not self.readonly:
            raise ValueError(older_schema(self.run_dir, version))

    @property
    def schema_version(self) -> int:
        """The results schema version of this run folder (``PRAGMA user_version``)."""
        return int(self._db.execute("PRAGMA user_version").fetchone()[0])

    def _start_session(self, config: RunConfig | None, versions: dict[str, str] | None,
                       extend: bool) -> int:
        stored = self.config
        given = config if config is not None else stored
        differences = config_differences(stored, given)
        fixed = [d for d in differences if not d.extendable]
        if fixed or (differences and not extend):
            raise RunConfigMismatch(self.run_dir, fixed if extend else differences, extend)
        kind: SessionKind = "extend" if differences else "resume"
        versions = versions if versions is not None else collect_versions()
        with _transaction(self._db):
            if differences:
                self._db.execute("UPDATE run SET config_json = ?, updated_at = ?",
                                 (given.model_dump_json(), _now()))
            return _new_session(self._db, kind, given, versions)

    def _remove_temporaries(self) -> None:
        for path in (self.run_dir / schema.TRACES).glob("*.parquet.tmp-*"):
            path.unlink(missing_ok=True)


def older_schema(run_dir: Path, version: int) -> str:
    """Why a run folder of an older schema version cannot be written to."""
    return (f"{run_dir} was recorded by an older fsvla (results schema version {version}; "
            f"this fsvla writes version {schema.SCHEMA_VERSION}): its episodes follow the "
            "older protocol (docs/results.md, *Schema versions*), so it can be reported and "
            "replayed but not resumed or extended; start a new run folder")


def _connect(path: Path) -> sqlite3.Connection:
    db = sqlite3.connect(path, isolation_level=None)  # transactions are explicit
    db.row_factory = sqlite3.Row
    mode = db.execute("PRAGMA journal_mode = WAL").fetchone()[0]
    if mode.lower() != "wal":
        raise OSError(f"{path}: SQLite could not use WAL mode here (got {mode!r})")
    db.execute("PRAGMA synchronous = FULL")
    db.execute("PRAGMA foreign_keys = ON")
    db.execute("PRAGMA busy_timeout = 10000")
    return db


@contextlib.contextmanager
def _transaction(db: sqlite3.Connection) -> Iterator[None]:
    db.execute("BEGIN IMMEDIATE")
    try:
        yield
    except BaseException:
        db.execute("ROLLBACK")
        raise
    db.execute("COMMIT")


def _new_session(db: sqlite3.Connection, kind: SessionKind, config: RunConfig,
                 versions: dict[str, str]) -> int:
    cursor = db.execute(
        "INSERT INTO sessions (kind, started_at, config_json, versions_json) VALUES (?, ?, ?, ?)",
        (kind, _now(), config.model_dump_json(), json.dumps(versions)))
    return int(cursor.lastrowid or 0)


def _acquire(run_dir: Path) -> int:
    fd = os.open(run_dir / schema.LOCK, os.O_RDWR | os.O_CREAT, 0o644)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        holder = os.pread(fd, 32, 0).decode(errors="replace").strip() or "unknown"
        os.close(fd)
        raise RunLocked(f"{run_dir} is being written by another process (pid {holder}); "
                        "one fsvla run per run folder") from None
    os.ftruncate(fd, 0)
    os.pwrite(fd, str(os.getpid()).encode(), 0)
    return fd


def _release(fd: int | None) -> None:
    if fd is not None:
        fcntl.flock(fd, fcntl.LOCK_UN)
        os.close(fd)


__all__ = ["FaultPolicy", "ResultStore", "RunConfigMismatch", "RunInfo", "RunLocked"]
