"""Process-level dissection of one episode (paper Fig. 5 and Table 4).

By default the episode is the unsafe success with the largest RET over all runs (ties:
the larger RET / T, then the first recorded); ``--episode ID`` (or ``LABEL:ID`` when
several runs hold the same id) picks another. The per-channel table (RET_k / T, hard
crossing, first violation step, minimum margin, channel CC) and the per-family rows come
from the stored row, i.e. the numbers the metrics were computed with; the margins q_k(t)
drawn come from the episode's Parquet trace, with each channel's ε_k (warning band) and
hard threshold 0. Keyframes come from a recorded video when the run folder has one
(:mod:`fsvla.report.keyframes`).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from pydantic import BaseModel, ConfigDict, computed_field

from fsvla.metrics.taxonomy import CATEGORY_BY_ID, SUITE_CATEGORY
from fsvla.report.data import Episode, ReportInputError, RunData
from fsvla.report.keyframes import Keyframes, load_keyframes
from fsvla.run.key import EpisodeKey


class ChannelRow(BaseModel):
    """One channel's row of Table 4."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    name: str
    family: str
    soft_threshold: float | None  # ε_k (from the trace; None without it)
    ret: int  # RET_k
    ret_fraction: float  # RET_k / T
    hard_crossed: bool
    first_violation_step: int | None  # 0-based, as the metrics count
    min_margin: float
    cc: float  # Σ_t w_k c_k


class FamilyRow(BaseModel):
    """All channels of one family pooled (a row of the paper's Table 4)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    family: str
    label: str
    ret: int
    ret_fraction: float
    hard_crossed: bool


class Dissection(BaseModel):
    """Everything Fig. 5 and Table 4 show about one episode."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    label: str  # the policy
    run_dir: str
    key: EpisodeKey
    selection: str  # how it was chosen
    instruction: str | None
    status: str
    failure_reason: str | None
    quadrant: str
    horizon: int  # T
    ret: int
    ret_fraction: float
    cc: float
    cc_per_step: float  # CC / T, the tables' scale
    cc_normalised: float  # CC / (T · Σ_k w_k)
    channels: tuple[ChannelRow, ...]
    families: tuple[FamilyRow, ...]
    margin_channels: tuple[str, ...]  # the trace's channels, in the columns of margins
    margins: tuple[tuple[float, ...], ...] | None  # steps × channels, from the trace
    trace_note: str | None  # why the margins are missing
    keyframes: Keyframes

    @computed_field  # type: ignore[prop-decorator]
    @property
    def episode_id(self) -> str:
        return self.key.episode_id


def _family_label(family: str) -> str:
    category = SUITE_CATEGORY.get(family)
    return CATEGORY_BY_ID[category].label if category else family.replace("_", " ").title()


def _pick_default(runs: Sequence[RunData]) -> tuple[RunData, Episode, str] | None:
    candidates = [(run, ep) for run in runs for ep in run.episodes if ep.metrics.channels]
    unsafe = [(r, e) for r, e in candidates if e.metrics.quadrant == "unsafe_success"]
    pool = unsafe or candidates
    if not pool:
        return None
    # max() keeps the first of equals: the first run given, the first recorded episode.
    run, ep = max(pool, key=lambda re: (re[1].metrics.ret, re[1].metrics.ret_fraction))
    if unsafe:
        why = (f"the unsafe success with the largest RET ({ep.metrics.ret} of "
               f"{ep.metrics.horizon} steps) among {len(unsafe)} unsafe successes")
    else:
        why = (f"no unsafe success in these runs: the episode with the largest RET "
               f"({ep.metrics.ret} of {ep.metrics.horizon} steps) instead")
    return run, ep, why


def _find(runs: Sequence[RunData], choice: str) -> tuple[RunData, Episode, str]:
    prefix, _, episode_id = choice.rpartition(":")
    pool = [r for r in runs
            if not prefix or prefix in (r.label, r.run_dir.name, str(r.run_dir))]
    if prefix and not pool:
        names = ", ".join(r.label for r in runs)
        raise ReportInputError(f"--episode {choice}: no run is called {prefix!r} (runs: {names})")
    hits = [(r, e) for r in pool for e in r.episodes if e.id == episode_id]
    if not hits:
        raise ReportInputError(f"--episode {choice}: no scored episode {episode_id!r} in "
                               f"{', '.join(str(r.run_dir) for r in pool)}")
    if len(hits) > 1:
        raise ReportInputError(f"--episode {choice}: {len(hits)} runs hold {episode_id!r} "
                               f"({', '.join(r.label for r, _ in hits)}); write "
                               f"LABEL:{episode_id} to pick one")
    run, ep = hits[0]
    return run, ep, "chosen with --episode"


def _margins(run: RunData, ep: Episode) -> tuple[dict | None, str | None]:
    if ep.row.trace_path is None:
        return None, "this episode has no trace (it faulted before its first step)"
    path = run.run_dir / ep.row.trace_path
    try:
        from fsvla.results import read_trace

        return read_trace(path), None
    except (ImportError, OSError, ValueError) as err:
        return None, f"its trace could not be read: {err}"


def dissect(runs: Sequence[RunData], episode: str | None = None) -> Dissection | None:
    """The dissection of ``episode`` (see the module doc); None when no episode has channels."""
    picked = _find(runs, episode) if episode else _pick_default(runs)
    if picked is None:
        return None
    run, ep, why = picked
    record, note = _margins(run, ep)
    eps = {c["name"]: float(c["soft_threshold"]) for c in record["channels"]} if record else {}
    m = ep.metrics
    channels = tuple(
        ChannelRow(name=c.name, family=c.family, soft_threshold=eps.get(c.name), ret=c.ret,
                   ret_fraction=c.ret_fraction, hard_crossed=c.hard_crossed,
                   first_violation_step=c.first_violation_step, min_margin=c.min_margin,
                   cc=c.cc) for c in m.channels)
    families = tuple(FamilyRow(family=f.family, label=_family_label(f.family), ret=f.ret,
                               ret_fraction=f.ret_fraction, hard_crossed=f.hard_crossed)
                     for f in m.families)
    margins = tuple(tuple(float(v) for v in row) for row in record["margins"]) if record else None
    return Dissection(
        label=run.label, run_dir=str(run.run_dir), key=m.meta.key, selection=why,
        instruction=ep.row.instruction, status=ep.row.status,
        failure_reason=ep.row.failure_reason, quadrant=m.quadrant, horizon=m.horizon,
        ret=m.ret, ret_fraction=m.ret_fraction, cc=m.cc, cc_per_step=m.cc_per_step,
        cc_normalised=m.cc_normalised,
        channels=channels, families=families, margins=margins, trace_note=note,
        margin_channels=tuple(c["name"] for c in record["channels"]) if record else (),
        keyframes=load_keyframes(Path(run.run_dir), ep.id, steps=ep.row.steps))


__all__ = ["ChannelRow", "Dissection", "FamilyRow", "dissect"]
