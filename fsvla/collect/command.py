"""The ``fsvla collect`` command (registered by :mod:`fsvla.cli`)."""

from __future__ import annotations

import sys
from pathlib import Path

import click
from rich.console import Console


@click.command(name="collect")
@click.argument("scenario")
@click.option("--episodes", type=click.IntRange(min=1), required=True,
              help="How many safe, successful episodes the dataset should hold.")
@click.option("--level", type=click.Choice(["L0", "L1", "L2"]), default="L0", show_default=True,
              help="Layout level; each attempt uses the next layout seed.")
@click.option("-o", "--out", "out_dir", required=True, type=click.Path(file_okay=False, path_type=Path),
              help="The LeRobot dataset folder; collecting into it again resumes.")
@click.option("--max-attempts", type=click.IntRange(min=1), default=None,
              help="Give up after this many attempts in all (default: 3 per episode).")
@click.option("--state-only", is_flag=True,
              help="No camera videos (no render device needed).")
@click.option("--cameras", metavar="NAMES", default=None,
              help="The cameras recorded, comma-separated, e.g. front,wrist. Default: all of "
                   "the embodiment's.")
@click.option("--resolution", metavar="WIDTHxHEIGHT", default=None,
              help="Every recorded camera's resolution, e.g. 128x96. Default: each camera's own.")
def collect_command(scenario: str, episodes: int, level: str, out_dir: Path,
                    max_attempts: int | None, state_only: bool, cameras: str | None,
                    resolution: str | None) -> None:
    """Record the careful expert's safe, successful episodes of SCENARIO (a built-in name
    or a .fsv file) as a LeRobot dataset: multi-view video, state, action and instruction
    per frame."""
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeRemainingColumn,
    )

    from fsvla.collect import DatasetMismatch, collect
    from fsvla.library import ScenarioLoadError
    from fsvla.sim.render import RenderUnavailable

    console = Console(stderr=True, highlight=False)
    columns = (TextColumn("collecting"), BarColumn(), MofNCompleteColumn(),
               TextColumn("{task.fields[attempts]} attempts"), TimeRemainingColumn())
    try:
        with Progress(*columns, console=console, transient=True) as bar:
            task = bar.add_task("collect", total=episodes, attempts=0)
            progress = collect(scenario, out_dir, episodes, level=level, images=not state_only,
                               max_attempts=max_attempts,
                               cameras=cameras.split(",") if cameras else None,
                               resolution=resolution,
                               on_attempt=lambda p: bar.update(task, completed=p.kept,
                                                               attempts=p.attempts))
    except (ScenarioLoadError, DatasetMismatch, ValueError) as err:
        console.print(f"[bold red]error:[/bold red] {err}")
        sys.exit(2)
    except RenderUnavailable as err:
        console.print(f"[bold red]error:[/bold red] {err} (or pass --state-only)")
        sys.exit(1)
    rejected = ", ".join(f"{n} {why}" for why, n in progress.rejected.items()) or "none"
    out = Console(highlight=False)
    out.print(f"{out_dir}: {progress.kept} episode(s) of {progress.scenario} at {progress.level} "
              f"after {progress.attempts} attempt(s); rejected: {rejected}")
    if progress.kept < episodes:
        console.print(f"[bold yellow]warning:[/bold yellow] only {progress.kept} of {episodes} "
                      "episodes were safe successes; run again with --max-attempts to go on")
        sys.exit(1)
