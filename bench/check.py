"""`fsvla check` as a process over 66+ scenario files: cold and warm result cache.

Target: `fsvla check` of the scenario tree in under 0.5 s as a whole process, with 66
files. The built-in tree is copied into a temporary folder and topped up with copies of
its concrete scenarios (beside their originals, so that `extends` resolves as before) to
reach ``--files``; nothing is written under scenarios/. Each figure is the median of
``--repeat`` runs of ``python -m fsvla check``:

- cold: an empty result cache for every run (every file parsed and checked, and stored);
- warm: the cache filled by an earlier run (every file's inputs hashed and compared);
- no cache: ``--no-cache``, for reference.

Beside each wall time, the CPU time (user + system) the process used: on a busy machine
wall times grow with the load, CPU times much less.

Lark's parser cache is warm throughout (a first run fills it). Bytecode caching is as
the environment sets it; where PYTHONDONTWRITEBYTECODE is set, the three are timed again
with .pyc files in a temporary PYTHONPYCACHEPREFIX. Each run's output must equal the
no-cache run's, byte for byte.

    python bench/check.py [--files 66] [--repeat 5]
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from fsvla.resources import scenarios_dir

TARGET_PROCESS_S = 0.5
BASE_FOLDER = "_base"


def scenario_tree(folder: Path, files: int) -> Path:
    """A copy of the built-in tree under ``folder`` with at least ``files`` .fsv files."""
    tree = folder / "scenarios"
    shutil.copytree(scenarios_dir(), tree, ignore=shutil.ignore_patterns("__pycache__", "*.py"))
    concrete = sorted(p for p in tree.rglob("*.fsv") if BASE_FOLDER not in p.relative_to(tree).parts)
    count, copy = len(list(tree.rglob("*.fsv"))), 0
    while count < files:
        original = concrete[copy % len(concrete)]
        shutil.copyfile(original, original.with_name(f"copy{copy // len(concrete)}_{original.name}"))
        count, copy = count + 1, copy + 1
    return tree


def check_once(tree: Path, env: dict[str, str], *extra: str) -> tuple[float, float, str]:
    """Wall and CPU seconds one `fsvla check` of ``tree`` takes as a process, and what it prints."""
    args = [sys.executable, "-m", "fsvla", "check", "--format", "concise", *extra, str(tree)]
    cpu = _children_cpu()
    start = time.perf_counter()
    done = subprocess.run(args, check=False, capture_output=True, text=True, env=env, cwd=tree.parent)
    seconds = time.perf_counter() - start
    if done.returncode != 0:
        raise SystemExit(f"{' '.join(args)} failed ({done.returncode}):\n{done.stdout}{done.stderr}")
    return seconds, _children_cpu() - cpu, done.stdout


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def time_checks(tree: Path, env: dict[str, str], repeat: int,
                folder: Path) -> dict[str, tuple[float, float]]:
    """Median wall and CPU seconds of `fsvla check` with a cold cache, a warm cache and none."""
    *_, expected = check_once(tree, env, "--no-cache")  # fills lark's cache (and any .pyc)
    samples: dict[str, list[tuple[float, float]]] = {"cold": [], "warm": [], "no cache": []}
    warm_env = {**env, "FSVLA_CACHE_DIR": str(folder / "warm")}
    check_once(tree, warm_env)
    for run in range(repeat):
        cold_env = {**env, "FSVLA_CACHE_DIR": str(folder / f"cold{run}")}
        for name, (run_env, extra) in {"cold": (cold_env, ()), "warm": (warm_env, ()),
                                       "no cache": (env, ("--no-cache",))}.items():
            seconds, cpu, out = check_once(tree, run_env, *extra)
            if out != expected:
                raise SystemExit(f"`fsvla check` printed something else with the {name} cache")
            samples[name].append((seconds, cpu))
    return {name: (statistics.median(s for s, _ in values), statistics.median(c for _, c in values))
            for name, values in samples.items()}


def report(label: str, figures: dict[str, tuple[float, float]], repeat: int) -> None:
    print(f"{label} (median of {repeat}; load average {os.getloadavg()[0]:.2f}):")
    for name, (seconds, cpu) in figures.items():
        print(f"  {name:9} {seconds:6.3f} s (CPU {cpu:5.3f} s)   target < {TARGET_PROCESS_S} s  "
              f"ratio {seconds / TARGET_PROCESS_S:.2f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--files", type=int, default=66, help="scenario files to check (at least)")
    parser.add_argument("--repeat", type=int, default=5, help="runs per figure")
    args = parser.parse_args()

    with tempfile.TemporaryDirectory(prefix="fsvla-bench-check-") as name:
        folder = Path(name)
        tree = scenario_tree(folder, args.files)
        files = len(list(tree.rglob("*.fsv")))
        env = {k: v for k, v in os.environ.items() if k != "FSVLA_NO_CACHE"}
        bytecode = "off (PYTHONDONTWRITEBYTECODE)" if env.get("PYTHONDONTWRITEBYTECODE") else "on"
        print(f"`fsvla check` of {files} files as a process; bytecode cache as inherited: {bytecode}")
        report("as inherited", time_checks(tree, env, args.repeat, folder / "inherited"), args.repeat)
        if bytecode != "on":
            env = {k: v for k, v in env.items() if k != "PYTHONDONTWRITEBYTECODE"}
            env["PYTHONPYCACHEPREFIX"] = str(folder / "pycache")  # .pyc files there, not in the tree
            report("with a bytecode cache", time_checks(tree, env, args.repeat, folder / "bytecode"),
                   args.repeat)


if __name__ == "__main__":
    main()
