"""The report's header: the protocol each run followed, read from its run folder.

Scenarios, L/W/V levels, seeds, episodes per cell, warm-up, λ, how faults count, the CC
scale and the software versions (every writer session's, so a run resumed after an
upgrade says so). The CC scale is ``fsvla.metrics.CC_NORMALISATION``: the report computes
every CC from the stored episodes, so the statement is the report's, whatever text a run
folder recorded when it was created. Fields that differ between the runs compared are listed, since
their numbers are then not directly comparable.
"""

from __future__ import annotations

from collections.abc import Sequence

from pydantic import BaseModel, ConfigDict

from fsvla.metrics import CC_NORMALISATION
from fsvla.metrics.aggregate import cluster_labels
from fsvla.report.data import RunData
from fsvla.report.tables import Settings

FAULT_POLICY = ("Faulted episodes count as task failures, scored on the steps that ran "
                "(with none, as a safe failure without exposure); warm-up episodes are "
                "excluded from every number.")
#: The CC scale in one line, for the protocol table (CC_NORMALISATION says it in full).
CC_SCALE = "CC / T per episode (SASR's scale), averaged; CC/Σw = CC / (T · Σ_k w_k)"
#: How the intervals are made, in a line (docs/metrics.md, *What is independent*).
INTERVALS = ("they count distinct layouts, not episodes: Wilson for rates with n = layouts, "
             "a percentile bootstrap over layouts for means")
#: How a run drew its layouts, by results schema version (docs/results.md).
LAYOUT_PROTOCOLS = {1: "one per run seed (results schema 1)",
                    2: "one per episode: SHA-256 of (run seed, episode index); L0 jittered"}
#: Protocol fields compared across runs (their values should agree for a fair comparison).
COMPARED = ("scenario_names", "levels", "languages", "visions", "sweep", "episodes_per_cell",
            "seeds",
            "layout_protocol", "warmup", "sasr_lambda", "control_mode", "obs_mode", "terminate_on_violation")


class RunProtocol(BaseModel):
    """One run's protocol."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    label: str
    run_dir: str
    policy: str
    scenarios: tuple[str, ...]  # as given to fsvla run (files, folders, names)
    scenario_names: tuple[str, ...]  # the scenarios its scored episodes come from
    suites: tuple[str, ...]
    embodiments: tuple[str, ...]
    levels: tuple[str, ...]
    languages: tuple[str, ...]
    visions: tuple[str, ...]
    sweep: bool  # one-axis sweeps (fsvla run --sweep), not the grid
    cells_per_scenario: int
    episodes_per_cell: int
    seeds: tuple[int, ...]  # run seeds
    layout_protocol: str  # how the layouts were drawn (LAYOUT_PROTOCOLS)
    layouts_scored: int  # distinct layouts among the scored episodes
    warmup: int  # warm-up episodes per scenario (configured)
    warmups_recorded: int  # excluded from every number
    episodes_scored: int
    faults: dict[str, int]
    sasr_lambda: float
    control_mode: str
    obs_mode: str
    terminate_on_violation: bool
    created_at: str
    updated_at: str
    versions: dict[str, str]  # package -> version(s), "a → b" when sessions differ


class Protocol(BaseModel):
    """The header of a report."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    runs: tuple[RunProtocol, ...]
    differences: tuple[str, ...]  # COMPARED fields whose values differ between runs
    cc_normalisation: str = CC_NORMALISATION
    cc_scale: str = CC_SCALE
    fault_policy: str = FAULT_POLICY
    confidence: float
    n_resamples: int
    bootstrap_seed: int


def _versions(run: RunData) -> dict[str, str]:
    seen: dict[str, list[str]] = {}
    history = [s.get("versions") or {} for s in run.sessions] or [run.info.versions]
    for versions in (run.info.versions, *history):
        for name, version in versions.items():
            values = seen.setdefault(name, [])
            if version not in values:
                values.append(str(version))
    return {name: " → ".join(values) for name, values in seen.items()}


def _layouts(run: RunData) -> int:
    """Distinct layouts among the run's scored episodes (one without a digest counts alone)."""
    return int(cluster_labels([m.meta.layout_digest for m in run.metrics]).max()) + 1


def run_protocol(run: RunData) -> RunProtocol:
    config = run.info.config
    keys = [e.metrics.meta.key for e in run.episodes]
    return RunProtocol(
        label=run.label, run_dir=str(run.run_dir), policy=config.policy,
        scenarios=config.scenarios,
        scenario_names=tuple(sorted({k.scenario for k in keys})),
        suites=tuple(sorted({k.suite for k in keys})),
        embodiments=tuple(sorted({k.embodiment for k in keys})),
        levels=config.levels, languages=config.languages, visions=config.visions,
        sweep=config.sweep, cells_per_scenario=len(config.cells()),
        episodes_per_cell=config.episodes, seeds=config.seeds,
        layout_protocol=LAYOUT_PROTOCOLS.get(run.info.schema_version, "unknown"),
        layouts_scored=_layouts(run), warmup=config.warmup,
        warmups_recorded=run.warmups, episodes_scored=len(run.episodes),
        faults=run.fault_counts(), sasr_lambda=config.sasr_lambda,
        control_mode=config.control_mode, obs_mode=config.obs_mode,
        terminate_on_violation=config.terminate_on_violation,
        created_at=run.info.created_at.isoformat(timespec="seconds"),
        updated_at=run.info.updated_at.isoformat(timespec="seconds"),
        versions=_versions(run))


def protocol(runs: Sequence[RunData], settings: Settings) -> Protocol:
    protocols = tuple(run_protocol(r) for r in runs)
    differences = tuple(f for f in COMPARED
                        if len({repr(getattr(p, f)) for p in protocols}) > 1)
    return Protocol(runs=protocols, differences=differences, confidence=settings.confidence,
                    n_resamples=settings.n_resamples, bootstrap_seed=settings.seed)


__all__ = [
    "CC_SCALE",
    "COMPARED",
    "FAULT_POLICY",
    "INTERVALS",
    "LAYOUT_PROTOCOLS",
    "Protocol",
    "RunProtocol",
    "protocol",
    "run_protocol",
]
