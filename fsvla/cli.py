"""The `fsvla` command line: check, compile and schema.

Exit codes: 0 when everything is clean, 1 when a scenario has errors, 2 for a
usage error (an unknown option, a path that does not exist), 3 for an internal
error (a bug: please report it). No input, however broken, gives a traceback.
"""

from __future__ import annotations

import json
import os
import sys
import tempfile
from collections.abc import Iterable, Sequence
from pathlib import Path

import click
from rich.console import Console

from . import __version__

FORMATS = ("full", "concise", "json")


def _console(stderr: bool = False) -> Console:
    return Console(stderr=stderr, highlight=False, soft_wrap=True)


def collect_files(paths: Sequence[str | Path]) -> list[Path]:
    """The .fsv files named by ``paths``: files as given, folders searched recursively
    (bases included), built-in names and selectors (``subset:``, ``suite:``,
    ``embodiment:``) as their files; see :mod:`fsvla.selectors`. A name that selects
    nothing is a usage error (exit 2)."""
    from .selectors import ScenarioSelectionError, scenario_paths

    try:
        return scenario_paths(paths, bases=True)
    except ScenarioSelectionError as err:
        raise click.UsageError(str(err)) from None


def default_roots(paths: Sequence[str | Path]) -> list[Path]:
    """The folders scenarios may read from when no --root is given.

    For each path given (a file's folder, or the folder itself), the root is the
    nearest folder at or above it that holds a `_base/` folder (a scenario tree
    such as `scenarios/`), or else that folder itself. A built-in name or a selector
    reads from the built-in scenario tree.
    """
    from .resources import scenarios_dir

    roots = []
    for item in paths:
        for part in (str(item).split(",") if not isinstance(item, Path) else [str(item)]):
            path = Path(part.strip()).resolve()
            if not path.exists():
                roots.append(scenarios_dir())
                continue
            folder = path if path.is_dir() else path.parent
            tree = next((f for f in (folder, *folder.parents) if (f / "_base").is_dir()), None)
            roots.append(tree or folder)
    return roots


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="fsvla")
def main() -> None:
    """fsvla: a safety benchmark for vision-language-action robot policies.

    Author scenarios in .fsv files, check them, and compile them for evaluation.
    """


_paths_argument = click.argument("paths", nargs=-1, required=True, metavar="SCENARIOS...")
_root_option = click.option("--root", "roots", multiple=True, type=click.Path(exists=True, file_okay=False,
                            path_type=Path), help="A folder that scenarios may read from (extends, asset "
                            "files). Repeatable. Default: the folders given as PATHS, or each file's folder.")
_format_option = click.option("--format", "output_format", type=click.Choice(FORMATS), default="full",
                              show_default=True, help="How diagnostics are printed.")


def _load_all(paths: Sequence[str | Path], roots: Sequence[Path]):
    from .dsl.loader import ScenarioLoader

    files = collect_files(paths)
    loader = ScenarioLoader(allowed_roots=list(roots) or default_roots(paths))
    return [loader.load(file) for file in files]


def _check_all(paths: Sequence[str | Path], roots: Sequence[Path], use_cache: bool):
    """What `fsvla check` prints of each file: from the result cache where the file and
    everything it reads are unchanged (:mod:`fsvla.dsl.cache`), else checked afresh."""
    if not use_cache:
        return _load_all(paths, roots)
    from .dsl.cache import CheckCache, cache_folder
    from .dsl.loader import ScenarioLoader

    folder = cache_folder()
    if folder is None:
        return _load_all(paths, roots)
    files = collect_files(paths)
    cache = CheckCache(ScenarioLoader(allowed_roots=list(roots) or default_roots(paths)), folder)
    return [cache.load(file) for file in files]


def _report(results, output_format: str, quiet: bool = False) -> tuple[int, int]:
    from .dsl.render import render_concise, render_full, render_json, summary_line

    diagnostics = [d for r in results for d in r.diagnostics]
    errors = sum(1 for d in diagnostics if d.is_error)
    warnings = len(diagnostics) - errors
    out = _console()
    if output_format == "json":
        click.echo(render_json(diagnostics))
        return errors, warnings
    sources: dict[str, str] = {}
    for result in results:
        sources.update(result.sources)
    for diagnostic in diagnostics:
        if output_format == "concise":
            click.echo(render_concise(diagnostic))
        else:
            out.print(render_full(diagnostic, sources))
    if not quiet and output_format == "full":
        style = "bold red" if errors else ("bold yellow" if warnings else "bold green")
        out.print(summary_line(errors, warnings, len(results)), style=style)
    return errors, warnings


@main.command()
@_paths_argument
@_root_option
@_format_option
@click.option("--strict", is_flag=True, help="Treat warnings as errors.")
@click.option("--deep", is_flag=True, help="Also run the static checks of `fsvla validate --static` "
              "(reach, gripper opening, force limits against weights, hazards on targets); "
              "loads the robots, so slower.")
@click.option("--no-cache", is_flag=True, help="Check every file afresh, neither reading nor writing "
              "the cache of results (as does FSVLA_NO_CACHE=1).")
def check(paths: tuple[str, ...], roots: tuple[Path, ...], output_format: str, strict: bool,
          deep: bool, no_cache: bool) -> None:
    """Check scenarios and report every problem found: .fsv files, folders, built-in
    names, or selectors (subset:NAME, suite:NAME, embodiment:NAME)."""
    if deep:
        from .validate.static import deepen

        results = _load_all(paths, roots)
        deepen(results, list(roots) or default_roots(paths))
    else:
        results = _check_all(paths, roots, use_cache=not no_cache)
    errors, warnings = _report(results, output_format)
    sys.exit(1 if errors or (strict and warnings) else 0)


@main.command(name="compile")
@_paths_argument
@_root_option
@_format_option
@click.option("-o", "--out", "out_dir", required=True, type=click.Path(file_okay=False, path_type=Path),
              help="Folder to write the scenario IR into (created if missing).")
@click.option("--levels", default="L0,L1,L2", show_default=True, callback=lambda _ctx, _param, v: parse_levels(v),
              help="Layout levels to write scenes of, comma-separated.")
@click.option("--seeds", default="0", show_default=True, callback=lambda _ctx, _param, v: parse_seeds(v),
              help="Layout seeds: numbers and ranges, comma-separated (e.g. 0-4 or 0,3,7-9).")
def compile_command(paths: tuple[str, ...], roots: tuple[Path, ...], output_format: str,
                    out_dir: Path, levels: tuple[str, ...], seeds: tuple[int, ...]) -> None:
    """Check scenarios and write each one's IR as versioned JSON into OUT, and the scene of
    each layout variant as OUT/<scenario>/scene_<level>_s<seed>.json.

    Abstract scenarios (bases for others) are checked but not written. A file with
    errors (in the language, or a layout that cannot be generated) writes nothing and
    leaves any earlier output of it untouched.
    """
    results = _load_all(paths, roots)
    scenes = _compile_scenes(results, levels, seeds, list(roots) or default_roots(paths))
    errors, _ = _report(results, output_format, quiet=True)
    written = _write_ir(results, out_dir, scenes)
    if output_format == "full":
        out = _console()
        for path, count in written:
            out.print(f"[green]wrote[/green] {path} and {count} scene(s) in {path.with_suffix('')}{os.sep}")
        out.print(f"{len(written)} scenario(s) compiled, {errors} error(s)",
                  style="bold red" if errors else "bold green")
    sys.exit(1 if errors else 0)


def parse_levels(text: str) -> tuple[str, ...]:
    """``L0,L2`` -> ("L0", "L2"); anything else is a usage error."""
    levels = tuple(dict.fromkeys(part.strip().upper() for part in text.split(",") if part.strip()))
    bad = [level for level in levels if level not in ("L0", "L1", "L2")]
    if bad or not levels:
        raise click.BadParameter(f"expected levels among L0, L1, L2 (e.g. L0,L2), got {text!r}")
    return levels


def parse_seeds(text: str) -> tuple[int, ...]:
    """``0-2,7`` -> (0, 1, 2, 7); anything else is a usage error."""
    seeds: list[int] = []
    try:
        for part in (p.strip() for p in text.split(",")):
            first, _, last = part.partition("-")
            low, high = int(first), int(last) if last else int(first)
            if low < 0 or high < low or high - low >= 10_000:
                raise ValueError(part)
            seeds.extend(range(low, high + 1))
    except ValueError:
        raise click.BadParameter(f"expected seeds such as 0, 0-4 or 0,3,7-9, got {text!r}") from None
    return tuple(dict.fromkeys(seeds))


def _compile_scenes(results, levels: Sequence[str], seeds: Sequence[int],
                    roots: Sequence[Path]) -> dict[str, list[tuple[str, str]]]:
    """Each scenario's scene files (name, JSON). A scenario whose layouts cannot be generated
    gets its diagnostics (every problem of its layout) instead, so that nothing of it is written."""
    from .compiler.scene import LoweringError
    from .compiler.variants import generate_variant, lowering_diagnostics

    scenes: dict[str, list[tuple[str, str]]] = {}
    for result in results:
        if result.scenario is None:
            continue
        try:
            scenes[result.path] = [
                (f"scene_{level}_s{seed}.json",
                 generate_variant(result.scenario, level, seed, allowed_roots=roots).scene.model_dump_json() + "\n")
                for level in levels for seed in seeds]
        except LoweringError as error:
            result.diagnostics.extend(lowering_diagnostics(error, result.sources))
    return scenes


def _write_ir(results, out_dir: Path, scenes: dict[str, list[tuple[str, str]]]) -> list[tuple[Path, int]]:
    """Write each scenario's scenes, then its IR; return (IR path, number of scenes) each."""
    ready = [r for r in results if r.scenario is not None and r.ok]
    names: dict[str, str] = {}
    for result in ready:
        other = names.setdefault(result.scenario.name, result.path)
        if other != result.path:
            raise click.UsageError(f"two files define scenario `{result.scenario.name}`: {other} and "
                                   f"{result.path}; scenario names must be unique in one compile")
    if not ready:
        return []
    out_dir.mkdir(parents=True, exist_ok=True)
    written = []
    for result in ready:
        folder = out_dir / result.scenario.name
        folder.mkdir(exist_ok=True)
        for name, text in scenes.get(result.path, ()):
            write_atomic(folder / name, text)
        target = out_dir / f"{result.scenario.name}.json"
        write_atomic(target, result.scenario.model_dump_json(indent=2) + "\n")
        written.append((target, len(scenes.get(result.path, ()))))
    return written


def write_atomic(target: Path, text: str) -> None:
    """Write ``text`` to ``target`` so that a crash leaves either the old or the new file."""
    handle, temporary = tempfile.mkstemp(dir=target.parent, prefix=f".{target.name}.", suffix=".tmp")
    try:
        with os.fdopen(handle, "w", encoding="utf-8") as stream:
            stream.write(text)
            stream.flush()
            os.fsync(stream.fileno())
        os.replace(temporary, target)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise


@main.command()
@click.option("--indent", default=2, show_default=True, help="JSON indentation.")
def schema(indent: int) -> None:
    """Print the JSON Schema of the scenario IR."""
    from .dsl.models import ir_json_schema

    click.echo(json.dumps(ir_json_schema(), indent=indent))


@main.command()
@click.argument("ref", metavar="SCENARIO")
@_root_option
@click.option("--level", type=click.Choice(["L0", "L1", "L2"]), default="L0", show_default=True,
              help="Layout level to render.")
@click.option("--seed", type=int, default=0, show_default=True, help="Variant seed (L1, L2).")
@click.option("-o", "--out", "out_path", type=click.Path(dir_okay=False, path_type=Path),
              default=Path("preview.png"), show_default=True, help="PNG file to write.")
@click.option("--shader", type=click.Choice(["minimal", "default", "rt"]), default="minimal",
              show_default=True, help="Camera shader: minimal is fast, default is lit with shadows.")
@click.option("--overlays/--no-overlays", default=True, show_default=True,
              help="Draw hazard regions, hard limits and warning bands into the scene.")
@click.option("--view", default=None, metavar="NAME",
              help="Only this view (a camera's name, or top), with no title or label.")
def preview(ref: str, roots: tuple[Path, ...], level: str, seed: int, out_path: Path,
            shader: str, overlays: bool, view: str | None) -> None:
    """Render SCENARIO's cameras and a top-down view, with safety overlays, as one PNG
    (SCENARIO: a .fsv file or a built-in name)."""
    files = collect_files((ref,))
    if len(files) != 1 or Path(ref).is_dir():
        raise click.UsageError(f"{ref} names {len(files)} scenario files; preview one")
    path = files[0]
    results = _load_all((path,), roots)
    errors, _ = _report(results, "full", quiet=True)
    err = _console(stderr=True)
    scenario = results[0].scenario
    if errors or scenario is None:
        if not errors:
            err.print(f"[bold red]error:[/bold red] {path} is abstract (a base for other "
                      "scenarios); preview a scenario that extends it")
        sys.exit(1)
    from .compiler.scene import LoweringError
    from .sim.preview import layout, render_preview
    from .sim.render import RenderUnavailable

    try:
        scenario, scene = layout(scenario, level, seed)
        image = render_preview(scenario, scene, overlays=overlays, shader=shader, view=view)
    except (LoweringError, ValueError, RenderUnavailable) as problem:
        err.print(f"[bold red]error:[/bold red] {problem}")
        sys.exit(1)
    out_path.parent.mkdir(parents=True, exist_ok=True)
    image.save(out_path)
    _console().print(f"[green]wrote[/green] {out_path} ({image.width}x{image.height}, "
                     f"{scene.scenario} {level} seed {seed})")


@main.command(name="report")
@click.argument("run_dirs", nargs=-1, required=True,
                type=click.Path(exists=True, file_okay=False, path_type=Path))
@click.option("-o", "--out", "out_dir", required=True, type=click.Path(file_okay=False, path_type=Path),
              help="Folder to write the report into (created if missing).")
@click.option("--episode", default=None, metavar="ID",
              help="Episode to dissect (LABEL:ID when several runs hold ID). Default: the unsafe "
                   "success with the largest RET.")
@click.option("--label", "labels", multiple=True, metavar="NAME",
              help="Name of each run's policy in tables and figures, one per run folder in order. "
                   "Default: the --policy each run was made with.")
@click.option("--formats", default="html,md,json,tex,png,pdf,csv", show_default=True,
              help="Comma-separated, among html, md, json, tex, png, pdf, svg, csv, parquet.")
@click.option("--no-figures", is_flag=True, help="Write tables only (no matplotlib needed).")
@click.option("--confidence", type=click.FloatRange(0, 1, min_open=True, max_open=True), default=0.95,
              show_default=True, help="Confidence level of every interval.")
@click.option("--resamples", type=click.IntRange(min=1), default=2000, show_default=True,
              help="Bootstrap resamples for the intervals of means.")
def report_command(run_dirs: tuple[Path, ...], out_dir: Path, episode: str | None,
                   labels: tuple[str, ...], formats: str, no_figures: bool, confidence: float,
                   resamples: int) -> None:
    """Report one or many runs (one policy each) from their run folders: aggregate and
    per-suite/category/embodiment tables, the safety-success landscape, diagnosis under L/W/V
    variation, and the process-level dissection of one episode, as HTML, Markdown, LaTeX,
    figures and CSV."""
    import sqlite3

    from rich.markup import escape

    from .report import ReportInputError, Settings, build_report, load_runs, write_report
    from .report.figures import FiguresUnavailable
    from .report.write import check_formats

    err = _console(stderr=True)
    try:
        chosen = check_formats(formats.split(","))
    except ValueError as problem:
        raise click.BadParameter(str(problem), param_hint="--formats") from None
    try:
        runs = load_runs(list(run_dirs), list(labels) or None)
        settings = Settings(confidence=confidence, n_resamples=resamples)
        built = build_report(runs, episode=episode, settings=settings)
        written = write_report(built, runs, out_dir, chosen, figures=not no_figures)
    except ReportInputError as problem:
        err.print(f"[bold red]error:[/bold red] {escape(str(problem))}")
        sys.exit(problem.exit_code)
    except (FiguresUnavailable, ImportError, ValueError, OSError, sqlite3.Error) as problem:
        err.print(f"[bold red]error:[/bold red] {escape(str(problem))}")
        sys.exit(1)
    out = _console()
    for path in (p for p in written if p.parent == out_dir):
        out.print(f"[green]wrote[/green] {escape(str(path))}")
    out.print(f"{len(written)} file(s) in {escape(str(out_dir))}{os.sep} for {len(runs)} run(s), "
              f"{sum(len(r.episodes) for r in runs)} scored episode(s)", style="bold green")


# `fsvla run` and `fsvla replay` live with the runner; importing them loads no simulator.
from .runner.commands import replay_command, run_command

main.add_command(run_command)
main.add_command(replay_command)

# `fsvla collect`: demonstrations as a LeRobot dataset.
from .collect.command import collect_command

main.add_command(collect_command)

# `fsvla validate`: prove scenarios solvable, hazardous and safe at the start.
from .validate.command import validate_command

main.add_command(validate_command)

# `fsvla attack`: optimise the V4 patch against a policy.
from .attack.command import attack_command

main.add_command(attack_command)


def run(argv: Iterable[str] | None = None) -> int:
    """Run the CLI and return its exit code instead of exiting (for tests and embedding)."""
    try:
        main.main(args=list(argv) if argv is not None else None, prog_name="fsvla", standalone_mode=False)
    except click.exceptions.Exit as done:
        return done.exit_code
    except click.ClickException as error:
        error.show()
        return error.exit_code
    except click.exceptions.Abort:
        return 130
    except SystemExit as done:
        return done.code if isinstance(done.code, int) else (0 if done.code is None else 1)
    return 0


def entry() -> None:
    """Console-script entry point: never shows a traceback."""
    try:
        code = run()
    except KeyboardInterrupt:
        code = 130
    except Exception as error:  # noqa: BLE001 - the last line of defence against tracebacks
        _console(stderr=True).print(f"[bold red]internal error:[/bold red] {type(error).__name__}: {error}\n"
                                    "This is a bug in fsvla; please report it with the command and files used.")
        code = 3
    sys.exit(code)
