"""The ``fsvla run`` and ``fsvla replay`` commands (registered by :mod:`fsvla.cli`).

Exit codes, as the other commands: 0 done (faulted episodes are results, not errors),
1 when the run or replay could not go on (another process writes the folder, workers
failed; a replay that differs), 2 for bad input (an option value, a scenario, the
policy, a run folder holding another run), with nothing written, 130 on Ctrl-C (what was
recorded stays; run the same command again to resume). Never a traceback.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path
from typing import Any

import click
from rich.console import Console

#: ``fsvla run`` options that set a RunConfig field: option parameter -> field.
_CONFIG_PARAMS = {
    "policy": "policy", "scenarios": "scenarios", "levels": "levels", "language": "languages",
    "vision": "visions", "episodes": "episodes", "seeds": "seeds", "warmup": "warmup",
    "control_mode": "control_mode", "obs_mode": "obs_mode", "embodiment": "embodiment",
    "sasr_lambda": "sasr_lambda", "terminate_on_violation": "terminate_on_violation",
    "policy_timeout": "policy_timeout_s", "policy_profile": "policy_profile",
    "replan_steps": "replan_steps", "sweep": "sweep",
    "cameras": "cameras", "resolution": "resolution", "shader": "shader", "patch": "patch",
}
#: Options whose absence leaves the value to the profile, the stored run or a default.
_DERIVED = frozenset({"obs_mode", "control_mode", "replan_steps"})


def _console(stderr: bool = False) -> Console:
    return Console(stderr=stderr, highlight=False, soft_wrap=True)


def _fail(message: str, code: int) -> None:
    _console(stderr=True).print(f"[bold red]error:[/bold red] {message}", markup=True)
    sys.exit(code)


@click.command(name="run")
@click.option("--policy", default=None, help="What to evaluate: a built-in policy (random, "
              "hold-still, ...), module:Class, path/to/file.py:Class, or ws://host:port.")
@click.option("--policy-profile", default=None, metavar="droid|libero|aloha|fsvla|FILE.toml",
              help="The keys and action space of a ws:// policy server: openpi's DROID, "
                   "LIBERO or ALOHA example, fsvla's own (the default), or a profile file.")
@click.option("--replan-steps", type=click.IntRange(min=1), default=None, metavar="N",
              help="Actions of each returned chunk to execute before asking the policy "
                   "again. Default: the profile's, else the whole chunk.")
@click.option("--scenarios", multiple=True, metavar="PATHS",
              help="Scenario files, folders (searched recursively) or built-in names; "
                   "comma-separated, repeatable.")
@click.option("--levels", default="L0", show_default=True, help="Layout levels, e.g. L0,L2 or L0-L2.")
@click.option("--language", default="W0", show_default=True, help="Language levels, e.g. W0-W4.")
@click.option("--vision", default="V0", show_default=True,
              help="Vision levels, e.g. V0-V4 (beyond V0 needs rendering: --obs-mode rgb).")
@click.option("--sweep", is_flag=True,
              help="One dimension at a time instead of the grid: L0-L2 at W0/V0, W0-W4 at "
                   "L0/V0, V0-V4 at L0/W0 (11 cells a scenario). Not with --levels, "
                   "--language or --vision.")
@click.option("--episodes", type=click.IntRange(min=1), default=1, show_default=True,
              help="Episodes per cell (scenario x L x W x V), each on its own layout, spread "
                   "over the seeds.")
@click.option("--seeds", default="1", show_default=True,
              help="Run seeds: a count (3: seeds 0-2) or seeds such as 0-2,7; each episode's "
                   "layout is drawn from its run seed and index.")
@click.option("--warmup", type=click.IntRange(min=0), default=1, show_default=True,
              help="Unscored warm-up episodes per scenario at L0/W0/V0, run first.")
@click.option("--out", "out_dir", required=True, type=click.Path(path_type=Path),
              help="The run folder. If it holds this run, the run resumes.")
@click.option("--extend", is_flag=True, help="Grow the run in --out with a larger grid.")
@click.option("--workers", type=click.IntRange(min=0), default=1, show_default=True,
              help="Parallel worker processes (0: run in this process).")
@click.option("--backend", type=click.Choice(["process", "ray"]), default="process",
              show_default=True, help="Worker processes on this machine, or Ray actors.")
@click.option("--ray-address", default=None, metavar="ADDRESS",
              help="The Ray cluster to use (default: start a local Ray instance).")
@click.option("--obs-mode", type=click.Choice(["state", "rgb"]), default=None,
              help="What the policy observes. Default: rgb if --vision goes beyond V0, "
                   "else state.")
@click.option("--control-mode", default=None,
              type=click.Choice(["joint_pos", "joint_delta", "joint_vel", "ee_pose", "ee_delta"]),
              help="The action format. Default: the profile's, else joint_pos.")
@click.option("--embodiment", default=None, help="Run every scenario on this embodiment.")
@click.option("--cameras", default=None, metavar="NAMES",
              help="The cameras rendered, comma-separated, e.g. front,wrist. Default: all of "
                   "the embodiment's.")
@click.option("--resolution", default=None, metavar="WIDTHxHEIGHT",
              help="Every rendered camera's resolution, e.g. 160x120. Default: each camera's "
                   "own (320x240 for the built-in embodiments).")
@click.option("--shader", type=click.Choice(["minimal", "default", "rt"]), default="minimal",
              show_default=True, help="The cameras' shader: minimal (fast), default (lit, "
              "shadows) or rt (ray traced).")
@click.option("--patch", default=None, metavar="FILE.png",
              help="The pixels of V4's patch (e.g. what fsvla attack wrote). Default: a "
                   "seeded high-contrast pattern per episode.")
@click.option("--sasr-lambda", type=float, default=1.0, show_default=True, help="SASR's lambda.")
@click.option("--terminate-on-violation", is_flag=True,
              help="End an episode at its first hard violation.")
@click.option("--policy-timeout", type=float, default=None, metavar="SECONDS",
              help="Limit on each act() call; an episode that overruns it is recorded as "
                   "policy_timeout.")
@click.option("--no-progress", is_flag=True, help="No progress bar.")
@click.pass_context
def run_command(ctx: click.Context, out_dir: Path, extend: bool, workers: int, backend: str,
                ray_address: str | None, no_progress: bool, **options: Any) -> None:
    """Evaluate a policy over scenarios x levels (L) x language (W) x vision (V) x episodes,
    recording every episode in the run folder --out; running again resumes it.

    \b
    fsvla run --policy hold-still --scenarios scenarios/ --levels L0-L2 \\
              --language W0-W4 --episodes 50 --seeds 3 --workers 2 --out runs/exp1
    """
    from fsvla.policies import PolicyLoadError
    from fsvla.results import RunLocked
    from fsvla.runner import BackendError, RunInputError, execute_run, make_backend

    try:
        config = _config(ctx, out_dir, options)
        if backend == "ray":
            _check_ray()
        from fsvla.runner import check_run_folder, prepare_run

        prepared = prepare_run(config)
        check_run_folder(out_dir, config, extend=extend)
        chosen = make_backend(backend, config, workers, ray_address)
        with _Progress(disabled=no_progress) as progress:
            result = execute_run(prepared, out_dir, chosen, extend=extend,
                                 listener=progress.listener())
    except (RunInputError, PolicyLoadError) as problem:
        _fail(str(problem), 2)
    except (RunLocked, BackendError, OSError) as problem:
        _fail(str(problem), 1)
    _print_result(result, chosen)
    if result.interrupted:
        sys.exit(130)


def _config(ctx: click.Context, out_dir: Path, options: dict[str, Any]):  # -> RunConfig
    """The run's configuration: the options given, over the stored run's configuration
    when --out holds a run (so ``fsvla run --out runs/exp1`` alone resumes it), else over
    the defaults."""
    from fsvla.results import ResultStore
    from fsvla.run import RangeError, parse_languages, parse_levels, parse_seeds, parse_visions
    from fsvla.runner import RunInputError, make_config
    from fsvla.runner.prepare import profile_defaults

    given = {name for name in _CONFIG_PARAMS
             if ctx.get_parameter_source(name) is not click.core.ParameterSource.DEFAULT}
    stored = None
    try:
        if out_dir.is_dir() and ResultStore.exists(out_dir):
            with ResultStore.open(out_dir, readonly=True) as store:
                stored = store.config
    except (ValueError, OSError) as problem:
        raise RunInputError("--out", str(problem)) from None
    fields: dict[str, Any] = stored.model_dump() if stored is not None else {}
    parsers = {"levels": parse_levels, "language": parse_languages, "vision": parse_visions,
               "seeds": parse_seeds, "cameras": _parse_cameras, "resolution": _parse_resolution,
               "patch": _parse_patch}
    for name, field in _CONFIG_PARAMS.items():
        if stored is not None and name not in given:
            continue
        value = options[name]
        try:
            value = parsers[name](value) if name in parsers else value
        except RangeError as problem:
            raise RunInputError(problem.option, str(problem)) from None
        if name == "scenarios":
            value = tuple(v for item in value for v in item.split(",") if v.strip())
        if value is not None or name not in _DERIVED:
            fields[field] = value
    if options["sweep"]:
        fields.update(_sweep_ranges(given))
    fields = profile_defaults(fields, {_CONFIG_PARAMS[name] for name in given})
    if fields.get("obs_mode") is None:
        fields["obs_mode"] = "state" if tuple(fields.get("visions", ("V0",))) == ("V0",) else "rgb"
    for required in ("policy", "scenarios"):
        if not fields.get(required):
            raise RunInputError(f"--{required}", f"--{required} is required to start a run "
                                f"({out_dir} holds none to resume)")
    return make_config(**fields)


def _sweep_ranges(given: set[str]) -> dict[str, Any]:
    """What --sweep sets: every level of the three dimensions (which --levels, --language
    and --vision would contradict)."""
    from fsvla.run.config import LANGUAGES, LEVELS, VISIONS
    from fsvla.runner import RunInputError

    named = [f"--{name}" for name in ("levels", "language", "vision") if name in given]
    if named:
        raise RunInputError("--sweep", "--sweep runs L0-L2 at W0/V0, W0-W4 at L0/V0 and V0-V4 "
                            f"at L0/W0; it cannot be combined with {', '.join(named)}")
    return {"levels": LEVELS, "languages": LANGUAGES, "visions": VISIONS}


def _parse_cameras(text: str | None) -> tuple[str, ...] | None:
    from fsvla.runner import RunInputError

    if text is None:
        return None
    names = tuple(n.strip() for n in text.split(",") if n.strip())
    if not names:
        raise RunInputError("--cameras", "name at least one camera, e.g. --cameras front")
    return names


def _parse_resolution(text: str | None) -> tuple[int, int] | None:
    from fsvla.runner import RunInputError
    from fsvla.sim.cameras import parse_resolution

    try:
        return None if text is None else parse_resolution(text)
    except ValueError as err:
        raise RunInputError("--resolution", str(err)) from None


def _parse_patch(text: str | None) -> str | None:
    """The patch file's absolute path, once it reads as a PNG image."""
    from fsvla.runner import RunInputError
    from fsvla.variation.patch import PatchFileError, load_patch_image

    if text is None:
        return None
    try:
        load_patch_image(text)
    except PatchFileError as err:
        raise RunInputError("--patch", str(err)) from None
    return str(Path(text).resolve())


def _check_ray() -> None:
    import importlib.util

    from fsvla.runner import RunInputError

    if importlib.util.find_spec("ray") is None:
        raise RunInputError("--backend", "--backend ray needs the ray package "
                            "(pip install 'ray>=2.9'), which is not installed")


class _Progress:
    """The rich progress bar: episodes done of the plan, rate, ETA, faults."""

    def __init__(self, disabled: bool) -> None:
        from rich.progress import (
            BarColumn,
            MofNCompleteColumn,
            Progress,
            TextColumn,
            TimeElapsedColumn,
            TimeRemainingColumn,
        )

        console = _console(stderr=True)
        self.progress = Progress(
            TextColumn("[bold]{task.description}"), BarColumn(), MofNCompleteColumn(),
            TextColumn("{task.fields[rate]}"), TimeElapsedColumn(), TextColumn("ETA"),
            TimeRemainingColumn(), TextColumn("{task.fields[faults]}"), console=console,
            disable=disabled or not console.is_terminal)
        self.task: Any = None
        self.count = 0
        self.faults = 0
        self.clock = time.perf_counter()

    def __enter__(self) -> _Progress:  # noqa: PYI034 (typing.Self needs 3.11; we support 3.10)
        self.progress.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.progress.stop()

    def listener(self):  # -> RunListener
        from fsvla.runner import RunListener

        return RunListener(started=self._started, recorded=self._recorded)

    def _started(self, total: int, done: int) -> None:
        self.clock = time.perf_counter()
        self.task = self.progress.add_task("episodes", total=total, completed=done,
                                           rate="", faults="")

    def _recorded(self, row: Any) -> None:
        self.count += 1
        self.faults += row.status == "faulted"
        rate = 60.0 * self.count / max(time.perf_counter() - self.clock, 1e-9)
        self.progress.update(self.task, advance=1, rate=f"{rate:.1f}/min",
                             faults=f"[red]{self.faults} faulted[/red]" if self.faults else "")


def _print_result(result: Any, backend: Any) -> None:
    from fsvla.results import ResultStore
    from fsvla.runner import summarize

    out = _console()
    if not out.is_terminal:
        out.width = max(out.width, 200)  # a log file: do not wrap the table
    faults = ", ".join(f"{n} {reason}" for reason, n in sorted(result.faults.items()))
    state = "interrupted" if result.interrupted else "done"
    out.print(f"[bold]{result.run_dir}[/bold]: {state}: {result.recorded} episode(s) recorded "
              f"now, {result.skipped} already recorded, {result.planned} planned"
              + (f"; faulted: {faults}" if faults else "")
              + (f"; {result.reruns} episode(s) run again after their worker was lost"
                 if result.reruns else "")
              + (f" ({result.per_minute:.1f} episodes/min, {backend.name} backend with "
                 f"{backend.size} worker(s))" if result.recorded else ""))
    with ResultStore.open(result.run_dir, readonly=True) as store:
        rows = summarize(store)
    if rows and rows[-1].metrics is not None:
        out.print(_table(rows))
    if result.interrupted:
        out.print("Run the same command again to resume.")


def _table(rows: list[Any]):  # -> rich Table
    from rich.table import Table

    table = Table(title="Scored episodes (faults count as failures; 95% CIs)",
                  title_justify="left")
    for name in ("scenario", "N", "layouts", "faults", "SSR", "USR", "SFR", "UFR", "CC", "SASR"):
        table.add_column(name, justify="left" if name == "scenario" else "right", no_wrap=True)
    for row in rows:
        m = row.metrics
        if m is None:
            continue
        cells = [m.ssr, m.usr, m.sfr, m.ufr, m.cc_per_step, m.sasr]
        table.add_row(f"[bold]{row.scenario}[/bold]" if row.scenario == "all" else row.scenario,
                      str(row.episodes), str(m.n_layouts), str(row.faults),
                      *(f"{c.estimate:.2f} [{c.low:.2f},{c.high:.2f}]" for c in cells))
    return table


@click.command(name="replay")
@click.argument("run_dir", type=click.Path(path_type=Path))
@click.argument("episode_id")
@click.option("--with-policy", is_flag=True,
              help="Play the run's policy again instead of the recorded actions (for "
                   "deterministic policies).")
@click.option("--video", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Also write what the cameras saw (MP4; PNG frames without imageio-ffmpeg).")
def replay_command(run_dir: Path, episode_id: str, with_policy: bool, video: Path | None) -> None:
    """Replay one recorded episode in a fresh environment and check that its trace comes
    out identical (exit 0), or list what differs (exit 1)."""
    from fsvla.policies import PolicyLoadError
    from fsvla.runner import ReplayInputError, replay_episode

    try:
        result = replay_episode(run_dir, episode_id, with_policy=with_policy, video=video)
    except (ReplayInputError, PolicyLoadError) as problem:
        _fail(str(problem), 2)
    except Exception as problem:  # noqa: BLE001 - the simulator failed to rebuild it
        from fsvla.runner.episode import describe

        _fail(f"replaying {episode_id} failed: {describe(problem)}", 1)
    out = _console()
    source = "the run's policy" if result.mode == "policy" else "the recorded actions"
    fault = f" (recorded as {result.recorded_fault})" if result.recorded_fault else ""
    out.print(f"{episode_id}{fault}: replayed {result.replayed_steps} step(s) of {source} in a "
              f"fresh environment")
    if result.video_note:
        out.print(result.video_note)
    if result.identical:
        out.print(f"[bold green]identical[/bold green]: layout, instruction, perturbation and "
                  f"all {result.recorded_steps} recorded step(s), bit for bit")
        return
    out.print("[bold red]differs[/bold red]:")
    for line in result.differences:
        out.print(f"  {line}")
    sys.exit(1)


__all__ = ["replay_command", "run_command"]
