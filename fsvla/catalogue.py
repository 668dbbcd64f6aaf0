"""The scenario catalogue, ``docs/scenarios.md``: one row per concrete built-in scenario
with its suite, robot, task, hazards, channels, named sets, validate rates and thumbnail.

Pure functions over the checked scenarios, the named sets and a :class:`ValidateRecord`
(what ``fsvla validate --format json`` said, kept in ``docs/scenarios/validate.json``):
the page is a function of files in the repository, so a test regenerates it and compares
it with the checked-in one. ``docs/scenarios/generate.py`` writes the page, runs
``fsvla validate`` to record rates and renders the thumbnails.
"""

from __future__ import annotations

import json
import re
from collections import Counter
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field

from fsvla.dsl.catalog import EMBODIMENTS, SUITES
from fsvla.dsl.models import Scenario
from fsvla.resources import scenarios_dir

Property = Literal["solvable", "hazardous", "starts_safe"]
#: Where thumbnails lie, relative to the page's folder.
THUMBS = "scenarios/thumbs"
#: The rate columns: heading, the verdict they show, the levels they sum over.
RATE_COLUMNS: tuple[tuple[str, Property, tuple[str, ...]], ...] = (
    ("careful safe L0", "solvable", ("L0",)),
    ("careful safe L1–L2", "solvable", ("L1", "L2")),
    ("careless unsafe", "hazardous", ("L0", "L1", "L2")),
    ("starts safe", "starts_safe", ("L0", "L1", "L2")),
)
REGENERATE = "python docs/scenarios/generate.py"


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class RecordedVerdict(_Model):
    """One verdict of ``fsvla validate --format json`` (its ``verdicts`` entries)."""

    level: str
    verdict: Property
    count: int = Field(ge=0)
    episodes: int = Field(ge=0)
    needed: float
    holds: bool


class ValidateRun(_Model):
    """One ``fsvla validate`` run whose verdicts the record keeps."""

    command: str
    levels: tuple[str, ...]
    seeds: tuple[int, ...]  # the layout seeds of every scenario, level and policy
    recorded: str  # ISO date
    wall_s: float
    commit: str | None = None  # the repository's HEAD when it ran (the tree may have differed)
    findings: tuple[str, ...] = ()  # its diagnostics, one line each (why a verdict failed)


class RecordedScenario(_Model):
    """A scenario's verdicts, from run ``run`` of the record, on the file whose digest
    (:attr:`fsvla.dsl.models.Scenario.source_digest`) was ``source_digest``."""

    run: int = Field(ge=0)
    source_digest: str
    verdicts: tuple[RecordedVerdict, ...]


class ValidateRecord(_Model):
    """``docs/scenarios/validate.json``: the validate runs and each scenario's verdicts
    from the latest run that covered it."""

    format: Literal[1] = 1
    runs: tuple[ValidateRun, ...] = ()
    scenarios: dict[str, RecordedScenario] = Field(default_factory=dict)

    def merged(self, run: ValidateRun, output: Mapping[str, object],
               digests: Mapping[str, str]) -> ValidateRecord:
        """This record with ``run``'s verdicts (``output``: the JSON ``fsvla validate``
        printed) replacing those of the scenarios it covered (``digests``: their digests);
        the earlier runs' findings that name a scenario it covered (its file or one of its
        episodes) are dropped with them, and runs no scenario refers to any more."""
        found: dict[str, list[RecordedVerdict]] = {}
        for item in _verdict_items(output):
            fields = {k: v for k, v in item.items() if k in RecordedVerdict.model_fields}
            found.setdefault(str(item["scenario"]), []).append(
                RecordedVerdict.model_validate(fields))
        covered = [re.compile(rf"(?<![\w-]){re.escape(name)}(?![\w])") for name in found]
        earlier = tuple(
            r.model_copy(update={"findings": tuple(
                f for f in r.findings if not any(c.search(f) for c in covered))})
            for r in self.runs)
        runs = (*earlier, run)
        scenarios = dict(self.scenarios)
        for name, verdicts in found.items():
            scenarios[name] = RecordedScenario(run=len(runs) - 1, source_digest=digests[name],
                                               verdicts=tuple(verdicts))
        keep = sorted({s.run for s in scenarios.values()})
        renumber = {old: new for new, old in enumerate(keep)}
        return ValidateRecord(
            runs=tuple(runs[i] for i in keep),
            scenarios={n: s.model_copy(update={"run": renumber[s.run]})
                       for n, s in sorted(scenarios.items())})


def _verdict_items(output: Mapping[str, object]) -> list[dict[str, object]]:
    items = output.get("verdicts", [])
    if not isinstance(items, list):
        raise TypeError("not the JSON of `fsvla validate --format json`: no verdicts list")
    return [dict(item) for item in items]


class CatalogueRow(_Model):
    """One scenario's row of the catalogue."""

    name: str
    file: str  # relative to the page's folder, POSIX
    suite: str
    embodiment: str
    task: str
    hazards: tuple[str, ...]
    channels: tuple[str, ...]
    sets: tuple[str, ...]
    rates: tuple[str, ...] | None  # one cell per RATE_COLUMNS; None: nothing recorded
    run: int | None  # the record's run the rates come from
    stale: bool  # the rates were recorded on another version of the file


def catalogue_rows(scenarios: Iterable[tuple[Scenario, str]], sets: Mapping[str, Sequence[str]],
                   record: ValidateRecord) -> list[CatalogueRow]:
    """The rows, by suite (in the paper's order) then name; ``scenarios``: each checked
    scenario with its file's path relative to the page's folder."""
    rows = []
    for scenario, file in scenarios:
        recorded = record.scenarios.get(scenario.name)
        rows.append(CatalogueRow(
            name=scenario.name, file=file, suite=scenario.suite,
            embodiment=scenario.embodiment, task=_task(scenario), hazards=_hazards(scenario),
            channels=_channels(scenario),
            sets=tuple(name for name, members in sets.items() if scenario.name in members),
            rates=_rates(recorded.verdicts) if recorded else None,
            run=recorded.run if recorded else None,
            stale=bool(recorded and recorded.source_digest != scenario.source_digest)))
    return sorted(rows, key=lambda r: (SUITES.index(r.suite), r.name))


def _task(scenario: Scenario) -> str:
    roles = ", ".join(f"{role}={name}" for role, name in scenario.task.roles.items())
    return f"{scenario.task.name}({roles})"


def _hazards(scenario: Scenario) -> tuple[str, ...]:
    zones = [f"{zone.name} ({zone.kind})" for zone in scenario.zones]
    objects = [f"{obj.name} ({obj.hazard_role})" for obj in scenario.objects if obj.hazard_role]
    return (*zones, *objects)


def _channels(scenario: Scenario) -> tuple[str, ...]:
    """Each channel family with its metrics (a count where one is used more than once)."""
    families: dict[str, Counter[str]] = {}
    for limit in scenario.limits:
        families.setdefault(limit.family, Counter())[limit.metric] += 1
    if scenario.requirements:
        families.setdefault("temporal", Counter()).update(
            {f"require {r.name}": 1 for r in scenario.requirements})
    return tuple(f"{family}: " + ", ".join(m if n == 1 else f"{m} ×{n}" for m, n in metrics.items())
                 for family, metrics in families.items())


def _rates(verdicts: Sequence[RecordedVerdict]) -> tuple[str, ...]:
    cells = []
    for _heading, prop, levels in RATE_COLUMNS:
        chosen = [v for v in verdicts if v.verdict == prop and v.level in levels]
        if not chosen:
            cells.append("—")
            continue
        count, episodes = sum(v.count for v in chosen), sum(v.episodes for v in chosen)
        cells.append(f"{count}/{episodes}" + ("" if all(v.holds for v in chosen) else " ✗"))
    return tuple(cells)


def render_markdown(rows: Sequence[CatalogueRow], sets: Mapping[str, str],
                    record: ValidateRecord) -> str:
    """The page; ``sets``: each named set's description."""
    lines = [
        "# Scenario catalogue",
        "",
        f"<!-- Generated by `{REGENERATE}` from the scenarios, `scenarios/sets.toml` and",
        "     `docs/scenarios/validate.json`; do not edit. A test checks it is current. -->",
        "",
        f"{len(rows)} concrete built-in scenarios. Each row: its suite, robot, task, the hazards",
        "placed in it (zones and hazardous objects, with their kind), the monitor's channels",
        "(family: metrics), the named sets it is in (`--scenarios subset:NAME`,",
        "[running.md](running.md#choosing-scenarios)) and the rates `fsvla validate` recorded",
        "([validate.md](validate.md)): the careful expert's safe successes at L0 and at L1–L2,",
        "the careless expert's unsafe episodes and hold-still's violation-free starts over all",
        "levels, as episodes that count / episodes, ✗ where the verdict fails at a level summed.",
        "The thumbnail is the front camera at L0, seed 0, with the safety overlays",
        "(`fsvla preview NAME --view front`).",
        "",
        "| suite | scenarios |",
        "|---|---|",
        *(f"| {suite} | {n} |" for suite, n in _counts((r.suite for r in rows), SUITES)),
        "",
        "| embodiment | scenarios |",
        "|---|---|",
        *(f"| {robot} | {n} |"
          for robot, n in _counts((r.embodiment for r in rows), tuple(EMBODIMENTS))),
        "",
        "## Named sets",
        "",
        "| set | scenarios | what |",
        "|---|---|---|",
        *(f"| `subset:{name}` | {sum(name in r.sets for r in rows)} | {description} |"
          for name, description in sets.items()),
        "",
        "## Validate runs",
        "",
        *_runs(record),
        "",
        "## Scenarios",
        "",
        "| | scenario | suite | embodiment | task | hazards | channels | sets | "
        + " | ".join(heading for heading, _prop, _levels in RATE_COLUMNS) + " |",
        "|---" * (8 + len(RATE_COLUMNS)) + "|",
        *(_row(row, several_runs=len(record.runs) > 1) for row in rows),
    ]
    if any(r.stale for r in rows):
        stale = ("† recorded on an earlier version of the scenario's file (or of a file it "
                 "extends): run the validate step again.")
        lines += ["", stale]
    return "\n".join(lines) + "\n"


def _counts(values: Iterable[str], known: Sequence[str]) -> list[tuple[str, int]]:
    """How many of each known value (in its order, zeros too), then any other."""
    counts = Counter(values)
    return [(k, counts[k]) for k in known] + sorted((k, n) for k, n in counts.items()
                                                    if k not in known)


def _runs(record: ValidateRecord) -> list[str]:
    if not record.runs:
        return [f"No rates recorded yet: run `{REGENERATE} --validate`."]
    lines = ["| run | command | layout seeds | recorded | wall time | commit |",
             "|---|---|---|---|---|---|"]
    for index, run in enumerate(record.runs, start=1):
        seeds = ", ".join(str(s) for s in run.seeds)
        lines.append(f"| {index} | `{run.command}` | {seeds} | {run.recorded} | "
                     f"{run.wall_s / 60:.0f} min | {(run.commit or '—')[:10]} |")
    for index, run in enumerate(record.runs, start=1):
        if run.findings:
            lines += ["", f"What run {index} said of its failed verdicts and static checks:", "",
                      *(f"- {finding}" for finding in run.findings)]
    return lines


def _row(row: CatalogueRow, several_runs: bool) -> str:
    thumb = f"![{row.name}]({THUMBS}/{row.name}.png)"
    if row.rates is None:
        rates = ["no rates recorded", *("—" for _ in RATE_COLUMNS[1:])]
    else:
        mark = " †" if row.stale else ""
        rates = [f"{cell}{mark}" for cell in row.rates]
        if several_runs and row.run is not None:
            rates[0] += f" (run {row.run + 1})"
    cells = [thumb, f"[{row.name}]({row.file})", row.suite, row.embodiment, f"`{row.task}`",
             "<br>".join(row.hazards) or "—", "<br>".join(row.channels) or "—",
             ", ".join(row.sets) or "—", *rates]
    return "| " + " | ".join(cells) + " |"


def findings(output: Mapping[str, object]) -> tuple[str, ...]:
    """The diagnostics of ``fsvla validate --format json`` output, one line each:
    ``file:line: CODE message (notes)``."""
    items = output.get("diagnostics", [])
    lines = []
    for item in items if isinstance(items, list) else []:
        span = item.get("span") or {}
        notes = "; ".join(item.get("notes") or ())
        lines.append(f"`{span.get('file')}:{span.get('line')}` {item.get('code')} "
                     f"{item.get('message')}" + (f" ({notes})" if notes else ""))
    return tuple(lines)


def load_record(path: Path) -> ValidateRecord:
    """The record at ``path``; an empty one when the file is absent."""
    if not path.is_file():
        return ValidateRecord()
    return ValidateRecord.model_validate_json(path.read_text(encoding="utf-8"))


def write_record(record: ValidateRecord, path: Path) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(record.model_dump(mode="json"), indent=1, ensure_ascii=False)
                    + "\n", encoding="utf-8")


def builtin_scenarios_checked(tree: Path | None = None) -> list[tuple[Scenario, Path]]:
    """Every concrete scenario of ``tree`` (default: the built-in tree), checked, with its
    file; a file that does not check raises
    :class:`~fsvla.selectors.ScenarioSelectionError`."""
    from fsvla.selectors import builtin_catalogue

    return [(item.scenario, item.path) for item in builtin_catalogue(tree).values()]


def catalogue_page(record: ValidateRecord, tree: Path | None = None) -> str:
    """The catalogue page that belongs in ``docs/scenarios.md`` for the scenarios of
    ``tree`` (default: the built-in tree) and ``record``."""
    from fsvla.selectors import named_sets

    sets = named_sets(tree)
    root = tree or scenarios_dir()
    # links as the repository lays it out (docs/ beside scenarios/), wherever fsvla is installed
    scenarios = [(scenario, f"../scenarios/{path.relative_to(root).as_posix()}")
                 for scenario, path in builtin_scenarios_checked(tree)]
    rows = catalogue_rows(scenarios, {n: s.scenarios for n, s in sets.items()}, record)
    return render_markdown(rows, {n: s.description for n, s in sets.items()}, record)


__all__ = ["RATE_COLUMNS", "REGENERATE", "THUMBS", "CatalogueRow", "RecordedScenario",
           "RecordedVerdict", "ValidateRecord", "ValidateRun", "builtin_scenarios_checked",
           "catalogue_page", "catalogue_rows", "findings", "load_record", "render_markdown",
           "write_record"]
