"""How ``fsvla validate`` prints: the verdict table and the diagnostics, in the three formats
of ``fsvla check`` (full, concise, json)."""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from pathlib import Path

import click
from rich.console import Console
from rich.table import Table

from fsvla.dsl.diagnostics import Diagnostic
from fsvla.dsl.render import render_concise, render_full, render_json

from .verdicts import PROPERTIES, Verdict

HEADINGS = {"solvable": "solvable", "hazardous": "hazardous", "starts_safe": "starts safe"}


def console() -> Console:
    return Console(highlight=False, soft_wrap=True)


def show(output_format: str, verdicts: Sequence[Verdict], diagnostics: Sequence[Diagnostic],
         sources: Mapping[str, str], runs: Mapping[str, Path]) -> None:
    """Print the verdicts (none for ``--static``) and the diagnostics."""
    diagnostics = sorted(diagnostics, key=Diagnostic.sort_key)
    if output_format == "json":
        click.echo(json.dumps({
            "verdicts": [verdict_json(v) for v in verdicts],
            "diagnostics": [d.model_dump(mode="json") for d in diagnostics],
            "runs": {policy: str(path) for policy, path in runs.items()}}, indent=2))
        return
    if output_format == "concise":
        for verdict in verdicts:
            click.echo(f"{verdict.scenario} {verdict.level} {HEADINGS[verdict.property]}: "
                       f"{'holds' if verdict.holds else 'FAILS'} ({verdict.describe()})")
        for diagnostic in diagnostics:
            click.echo(render_concise(diagnostic))
        return
    out = console()
    if verdicts:
        out.print(verdict_table(verdicts))
    for diagnostic in diagnostics:
        out.print(render_full(diagnostic, sources))
    out.print(summary(verdicts, diagnostics), style="bold green" if passed(verdicts, diagnostics)
              else "bold red")


def show_diagnostics(output_format: str, diagnostics: Sequence[Diagnostic],
                     sources: Mapping[str, str]) -> None:
    """Print diagnostics alone (a scenario that does not check), as ``fsvla check`` does."""
    if output_format == "json":
        click.echo(render_json(diagnostics))
        return
    out = console()
    for diagnostic in diagnostics:
        if output_format == "concise":
            click.echo(render_concise(diagnostic))
        else:
            out.print(render_full(diagnostic, sources))


def verdict_json(verdict: Verdict) -> dict[str, object]:
    return {"scenario": verdict.scenario, "level": verdict.level, "verdict": verdict.property,
            "policy": verdict.policy, "count": verdict.count, "episodes": verdict.episodes,
            "rate": verdict.rate, "needed": verdict.needed, "holds": verdict.holds}


def verdict_table(verdicts: Sequence[Verdict]) -> Table:
    table = Table(title="Verdicts (episodes that count / episodes)", title_justify="left")
    table.add_column("scenario", no_wrap=True)
    table.add_column("level")
    for prop in PROPERTIES:
        table.add_column(HEADINGS[prop], no_wrap=True)
    cells: dict[tuple[str, str], dict[str, Verdict]] = {}
    for verdict in verdicts:
        cells.setdefault((verdict.scenario, verdict.level), {})[verdict.property] = verdict
    for (scenario, level), found in cells.items():
        table.add_row(scenario, level, *(_cell(found.get(prop)) for prop in PROPERTIES))
    return table


def _cell(verdict: Verdict | None) -> str:
    if verdict is None:
        return ""
    mark = "[green]holds[/green]" if verdict.holds else "[bold red]FAILS[/bold red]"
    return f"{mark} {verdict.count}/{verdict.episodes}"


def passed(verdicts: Sequence[Verdict], diagnostics: Sequence[Diagnostic]) -> bool:
    """Exit 0: every verdict holds (``--static``: no finding at all)."""
    if verdicts:
        return all(v.holds for v in verdicts)
    return not diagnostics


def summary(verdicts: Sequence[Verdict], diagnostics: Sequence[Diagnostic]) -> str:
    if not verdicts:
        found = len(diagnostics)
        return "static checks: no problems" if not found else f"static checks: {found} finding(s)"
    failed = sum(not v.holds for v in verdicts)
    scenarios = len({v.scenario for v in verdicts})
    head = f"{scenarios} scenario(s), {len(verdicts)} verdict(s): "
    return head + ("all hold" if not failed else f"{failed} fail(s)")


__all__ = ["console", "passed", "show", "show_diagnostics", "summary", "verdict_json",
           "verdict_table"]
