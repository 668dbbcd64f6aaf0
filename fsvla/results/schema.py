"""The SQLite schema of a run folder's ``results.sqlite`` (see ``docs/results.md``).

``SCHEMA_VERSION`` (``PRAGMA user_version``) is the version this fsvla writes. Version 1
lacks the ``episodes`` columns that ``ADDED_COLUMNS`` names; such a folder is read (its
rows get those values as :func:`fsvla.results.rows.row_from_sql` derives them) but never
written: its episodes were drawn under another protocol, so resuming it would mix two.
"""

from __future__ import annotations

from fsvla.results.models import FAILURE_REASONS

SCHEMA_VERSION = 2
#: Schema versions a reader opens (older ones read-only).
READABLE_VERSIONS: tuple[int, ...] = (1, 2)
#: Columns of ``episodes`` each version added, by version.
ADDED_COLUMNS: dict[int, tuple[str, ...]] = {2: ("layout_seed", "vision_applied_json")}
DATABASE = "results.sqlite"
TRACES = "traces"
LOCK = "lock"

_REASONS = ", ".join(f"'{r}'" for r in FAILURE_REASONS)

TABLES: tuple[str, ...] = (
    """CREATE TABLE run (
        id INTEGER PRIMARY KEY CHECK (id = 1),
        schema_version INTEGER NOT NULL,
        config_json TEXT NOT NULL,          -- the RunConfig, updated by --extend
        versions_json TEXT NOT NULL,        -- versions at creation
        created_at TEXT NOT NULL,
        updated_at TEXT NOT NULL,
        cc_normalisation TEXT NOT NULL
    )""",
    """CREATE TABLE sessions (
        id INTEGER PRIMARY KEY AUTOINCREMENT,
        kind TEXT NOT NULL CHECK (kind IN ('create', 'resume', 'extend')),
        started_at TEXT NOT NULL,
        config_json TEXT NOT NULL,
        versions_json TEXT NOT NULL
    )""",
    f"""CREATE TABLE episodes (
        episode_id TEXT PRIMARY KEY,
        session_id INTEGER NOT NULL REFERENCES sessions (id),
        policy TEXT NOT NULL,
        scenario TEXT NOT NULL,
        scenario_ref TEXT NOT NULL,
        scenario_digest TEXT NOT NULL,
        suite TEXT NOT NULL,
        embodiment TEXT NOT NULL,
        level TEXT NOT NULL,
        language TEXT NOT NULL,
        vision TEXT NOT NULL,
        seed INTEGER NOT NULL,
        episode_index INTEGER NOT NULL,
        layout_seed INTEGER NOT NULL,       -- with level, the layout (fsvla.run.plan)
        language_seed INTEGER NOT NULL,
        vision_seed INTEGER NOT NULL,
        policy_seed INTEGER NOT NULL,
        warmup INTEGER NOT NULL CHECK (warmup IN (0, 1)),
        instruction TEXT,
        instruction_origin TEXT,
        instruction_category TEXT,
        language_category TEXT,
        vision_category TEXT,
        vision_json TEXT,
        vision_applied_json TEXT,           -- the kinds of perturbation applied (JSON list)
        layout_digest TEXT,
        status TEXT NOT NULL CHECK (status IN ('completed', 'faulted')),
        failure_reason TEXT CHECK (failure_reason IS NULL OR failure_reason IN ({_REASONS})),
        failure_detail TEXT,
        steps INTEGER NOT NULL,
        success INTEGER CHECK (success IN (0, 1)),
        violation INTEGER CHECK (violation IN (0, 1)),
        quadrant TEXT,
        horizon INTEGER,
        cc REAL,
        cc_normalised REAL,
        ret INTEGER,
        ret_fraction REAL,
        sasr REAL,
        sasr_lambda REAL NOT NULL,
        channels_json TEXT,
        families_json TEXT,
        wall_time_s REAL NOT NULL,
        started_at TEXT NOT NULL,
        finished_at TEXT NOT NULL,
        recorded_at TEXT NOT NULL,
        trace_path TEXT,
        CHECK ((status = 'faulted') = (failure_reason IS NOT NULL)),
        CHECK (status = 'faulted' OR horizon IS NOT NULL)
    )""",
    "CREATE INDEX episodes_cell ON episodes (scenario, level, language, vision)",
    "CREATE INDEX episodes_status ON episodes (status, failure_reason)",
)

EPISODE_COLUMNS: tuple[str, ...] = (
    "episode_id", "session_id", "policy", "scenario", "scenario_ref", "scenario_digest", "suite",
    "embodiment", "level", "language", "vision", "seed", "episode_index", "layout_seed",
    "language_seed",
    "vision_seed", "policy_seed", "warmup", "instruction", "instruction_origin",
    "instruction_category", "language_category", "vision_category", "vision_json",
    "vision_applied_json", "layout_digest", "status", "failure_reason", "failure_detail", "steps", "success",
    "violation", "quadrant", "horizon", "cc", "cc_normalised", "ret", "ret_fraction", "sasr",
    "sasr_lambda", "channels_json", "families_json", "wall_time_s", "started_at", "finished_at",
    "recorded_at", "trace_path",
)

INSERT_EPISODE = (f"INSERT INTO episodes ({', '.join(EPISODE_COLUMNS)}) "
                  f"VALUES ({', '.join(':' + c for c in EPISODE_COLUMNS)})")

__all__ = ["ADDED_COLUMNS", "DATABASE", "EPISODE_COLUMNS", "INSERT_EPISODE", "LOCK",
           "READABLE_VERSIONS", "SCHEMA_VERSION", "TABLES", "TRACES"]
