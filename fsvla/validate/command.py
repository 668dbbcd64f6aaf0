"""The ``fsvla validate`` command (registered by :mod:`fsvla.cli`).

Exit codes: 0 every verdict holds (``--static``: no finding), 1 a verdict fails (or a
static finding, or the runs could not go on), 2 bad input (a path that does not exist,
a scenario with errors, whose diagnostics are printed; a run folder holding something
else), 130 on Ctrl-C (what was recorded stays: run the same command again to resume).
Never a traceback. Importing this module imports click and nothing of the simulator.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path
from typing import Any

import click


@click.command(name="validate")
@click.argument("paths", nargs=-1, required=True, metavar="SCENARIOS...")
@click.option("--levels", default="L0", show_default=True, help="Layout levels, e.g. L0,L2 or L0-L2.")
@click.option("--seeds", type=click.IntRange(min=1), default=5, show_default=True,
              help="Episodes per scenario, level and policy, on layout seeds 0..N-1.")
@click.option("--workers", type=click.IntRange(min=0), default=1, show_default=True,
              help="Parallel worker processes (0: run in this process).")
@click.option("--format", "output_format", type=click.Choice(("full", "concise", "json")),
              default="full", show_default=True, help="How verdicts and diagnostics are printed.")
@click.option("--out", "out_dir", type=click.Path(file_okay=False, path_type=Path),
              default=Path("validate-runs"), show_default=True,
              help="Where the three run folders go (one per policy); running again resumes them.")
@click.option("--static", "static_only", is_flag=True,
              help="Only the static checks (reach, gripper opening, force limits, hazards on "
                   "targets): no rollout.")
@click.option("--root", "roots", multiple=True, type=click.Path(exists=True, file_okay=False,
              path_type=Path), help="A folder scenarios may read from (extends, asset files). "
              "Repeatable. Default: the scenario tree of each PATH.")
@click.option("--fresh", is_flag=True, help="Delete the run folders under --out first (when they "
              "hold episodes of an earlier version of a scenario file).")
@click.option("--min-careful-l0", type=click.FloatRange(0, 1), default=0.8, show_default=True,
              help="Solvable: the careful expert's safe-success rate needed at L0.")
@click.option("--min-careful", type=click.FloatRange(0, 1), default=0.5, show_default=True,
              help="Solvable: the careful expert's safe-success rate needed at L1 and L2.")
@click.option("--min-careless", type=click.FloatRange(0, 1), default=0.5, show_default=True,
              help="Hazardous: the careless expert's unsafe rate (USR + UFR) needed.")
@click.option("--max-hold-ret", type=click.IntRange(min=0), default=0, show_default=True,
              help="Starts safe: the most steps a hold-still episode may spend in a warning band.")
@click.option("--no-progress", is_flag=True, help="No progress bar.")
def validate_command(paths: tuple[str, ...], levels: str, seeds: int, workers: int,
                     output_format: str, out_dir: Path, static_only: bool, roots: tuple[Path, ...],
                     fresh: bool, min_careful_l0: float, min_careful: float, min_careless: float,
                     max_hold_ret: int, no_progress: bool) -> None:
    """Prove scenarios solvable (the careful expert reaches a safe success), hazardous (the
    careless expert ends unsafe) and safe at the start (holding still costs nothing), and
    say why on the .fsv line that causes each failed verdict.

    \b
    fsvla validate scenarios/ --levels L0-L2 --seeds 10 --workers 2
    fsvla validate subset:diagnostic suite:thermal --seeds 3
    fsvla validate my_scenario.fsv --static
    """
    from fsvla.run import RangeError, parse_levels

    from .verdicts import Thresholds

    try:
        chosen = parse_levels(levels)
    except RangeError as problem:
        raise click.BadParameter(str(problem), param_hint="--levels") from None
    thresholds = Thresholds(careful_l0=min_careful_l0, careful=min_careful, careless=min_careless,
                            hold_ret=max_hold_ret)
    located, sources = _load(paths, roots, output_format)
    from .output import passed, show
    from .static import static_diagnostics

    all_roots = list(roots) or _default_roots(paths)
    diagnostics = [d for item in located for d in static_diagnostics(item, all_roots)]
    if static_only:
        show(output_format, [], diagnostics, sources, {})
        sys.exit(0 if passed([], diagnostics) else 1)
    verdicts, explained, runs = _roll_out(located, chosen, seeds, out_dir, workers, fresh,
                                          thresholds, no_progress)
    show(output_format, verdicts, diagnostics + explained, sources, runs)
    sys.exit(0 if passed(verdicts, explained) else 1)


def _default_roots(paths: tuple[str, ...]) -> list[Path]:
    from fsvla.cli import default_roots

    return default_roots(paths)


def _load(paths: tuple[str, ...], roots: tuple[Path, ...],
          output_format: str) -> tuple[list[Any], dict[str, str]]:
    """The concrete scenarios under ``paths`` (abstract bases skipped); a file that does not
    check has its diagnostics printed and exits 2."""
    from fsvla.cli import collect_files
    from fsvla.dsl.loader import ScenarioLoader

    from .output import show_diagnostics
    from .sources import Located

    files = collect_files(paths)
    loader = ScenarioLoader(allowed_roots=list(roots) or _default_roots(paths))
    results = [loader.load(file) for file in files]
    sources: dict[str, str] = {}
    for result in results:
        sources.update(result.sources)
    broken = [r for r in results if not r.ok]
    if broken:
        show_diagnostics(output_format, [d for r in broken for d in r.diagnostics], sources)
        _fail(f"{len(broken)} file(s) do not check (see `fsvla check {broken[0].path}`); "
              "nothing was validated", 2)
    located = [Located(r.path, r.scenario, r.sources) for r in results
               if r.scenario is not None and not r.abstract]
    if not located:
        raise click.UsageError("only abstract scenarios (bases) found: validate scenarios that "
                               "extend them")
    return located, sources


def _roll_out(located: list[Any], levels: tuple[str, ...], seeds: int, out_dir: Path,
              workers: int, fresh: bool, thresholds: Any, no_progress: bool):
    """Run the three policies, compute the verdicts, explain the failed ones."""
    from fsvla.results import RunLocked
    from fsvla.runner import BackendError

    from .diagnose import diagnose
    from .runs import ValidateInputError, run_policy
    from .verdicts import POLICIES, POLICY, verdicts

    refs = [item.path for item in located]
    runs = {}
    try:
        for policy in POLICIES:
            runs[policy] = run_policy(policy, refs, levels, seeds, out_dir, workers=workers,
                                      fresh=fresh, listener=_progress(no_progress))
            if runs[policy].interrupted:
                _fail(f"interrupted: run the same command again to resume ({out_dir})", 130)
    except ValidateInputError as problem:
        _fail(str(problem), 2)
    except (RunLocked, BackendError, OSError) as problem:
        _fail(str(problem), 1)
    names = {item.scenario.name: item for item in located}
    found = verdicts({p: r.rows for p, r in runs.items()}, list(names), levels, thresholds)
    explained = []
    for verdict in found:
        if verdict.holds:
            continue
        run = runs[POLICY[verdict.property]]
        rows = [r for r in run.rows
                if r.key.scenario == verdict.scenario and r.key.level == verdict.level]
        explained += diagnose(names[verdict.scenario], verdict, rows, run.run_dir, thresholds)
    return found, explained, {p: r.run_dir for p, r in runs.items()}


def _progress(disabled: bool):
    """A RunListener factory: one progress bar per policy on stderr (a terminal only)."""
    from rich.console import Console

    err = Console(stderr=True, highlight=False)
    if disabled or not err.is_terminal:
        return None

    def listener(policy: str) -> Any:
        from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn

        from fsvla.runner import RunListener

        bar = Progress(TextColumn(f"[bold]{policy}"), BarColumn(), MofNCompleteColumn(),
                       console=err, transient=True)
        state: dict[str, Any] = {"clock": time.perf_counter()}

        def started(total: int, done: int) -> None:
            bar.start()
            state["task"] = bar.add_task(policy, total=total, completed=done)
            if done >= total:
                bar.stop()

        def recorded(_row: Any) -> None:
            bar.update(state["task"], advance=1)
            if bar.finished:
                bar.stop()

        return RunListener(started=started, recorded=recorded)

    return listener


def _fail(message: str, code: int) -> None:
    from rich.console import Console
    from rich.markup import escape

    Console(stderr=True, highlight=False, soft_wrap=True).print(
        f"[bold red]error:[/bold red] {escape(message)}")
    sys.exit(code)


__all__ = ["validate_command"]
