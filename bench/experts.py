"""The scripted experts over the built-in scenarios: the careful one's safe success, the
careless one's harm, per scenario and layout level, over many seeds.

Bars (issue: experts and the first ten scenarios): over 10 seeds at L0 the careful expert
reaches safe success in at least 8 and the careless expert ends unsafe (unsafe success or
unsafe failure) in at least 5; at L1 and L2 the careful expert's safe success stays at
least 5 in 10. The table prints, for each expert, the four quadrants (SS/US/SF/UF episode
counts), the mean CC and the mean RET/T; the last column says whether the bar holds.

The episodes run through ``fsvla run`` (state-only, no warm-up) into one run folder per
expert under ``--out``, so the numbers can be read again with ``fsvla report`` and an
interrupted bench resumes where it stopped.

    python bench/experts.py [--out runs/bench-experts] [--seeds 10] [--levels L0,L1,L2]
                            [--scenarios scenarios/] [--workers 2]
"""

from __future__ import annotations

import argparse
import os
import time
from collections import defaultdict
from collections.abc import Iterable
from pathlib import Path
from statistics import fmean

from fsvla.results import EpisodeRow, ResultStore
from fsvla.runner import RunListener, execute_run, make_backend, make_config, prepare_run

EXPERTS = ("careful", "careless")
QUADRANTS = ("safe_success", "unsafe_success", "safe_failure", "unsafe_failure")
SHORT = {"safe_success": "SS", "unsafe_success": "US", "safe_failure": "SF", "unsafe_failure": "UF"}


def run_expert(expert: str, args: argparse.Namespace) -> list[EpisodeRow]:
    """Every scored episode of one expert's run (resumed if its folder has one)."""
    config = make_config(policy=f"{expert}-expert", scenarios=tuple(args.scenarios),
                         levels=tuple(args.levels), episodes=args.seeds,
                         seeds=tuple(range(args.seeds)), warmup=0, obs_mode="state")
    folder = args.out / expert
    clock = time.perf_counter()
    count = [0]

    def recorded(row: EpisodeRow) -> None:
        count[0] += 1
        print(f"  {expert:8} {count[0]:4}: {row.key.scenario} {row.key.level} seed {row.key.seed}: "
              f"{row.quadrant or row.failure_reason} ({row.wall_time_s:.0f} s)", flush=True)

    listener = RunListener(started=lambda total, done: print(
        f"{expert} expert: {total} episodes, {done} already in {folder}", flush=True),
        recorded=recorded)
    result = execute_run(prepare_run(config), folder,
                         make_backend("process", config, args.workers), listener=listener)
    if result.recorded:
        print(f"{expert} expert: {result.recorded} episodes in {time.perf_counter() - clock:.0f} s "
              f"({result.per_minute:.1f} per minute)", flush=True)
    with ResultStore.open(folder, readonly=True) as store:
        return store.episodes(include_warmup=False)


def bar(expert: str, level: str, rows: list[EpisodeRow]) -> tuple[str, bool]:
    """The bar for this expert and level and whether ``rows`` meet it."""
    n = len(rows)
    quadrants = [row.quadrant for row in rows]
    if expert == "careful":
        need = 0.8 if level == "L0" else 0.5
        return f"SS >= {need:.0%}", quadrants.count("safe_success") >= need * n
    if level != "L0":
        return "-", True
    unsafe = quadrants.count("unsafe_success") + quadrants.count("unsafe_failure")
    return "unsafe >= 50%", unsafe >= 0.5 * n


def table(rows_by_expert: dict[str, list[EpisodeRow]]) -> bool:
    """Print the table; whether every bar holds."""
    cells: dict[tuple[str, str, str], list[EpisodeRow]] = defaultdict(list)
    for expert, rows in rows_by_expert.items():
        for row in rows:
            cells[(row.key.scenario, row.key.level, expert)].append(row)
    print(f"\n{'scenario':26} {'level':5} {'expert':8} {'n':>3} "
          + " ".join(f"{SHORT[q]:>3}" for q in QUADRANTS)
          + f" {'fault':>5} {'CC':>8} {'RET/T':>6}  bar")
    every = True
    for scenario, level, expert in sorted(cells, key=lambda k: (k[0], k[1], EXPERTS.index(k[2]))):
        rows = cells[(scenario, level, expert)]
        counts = [sum(row.quadrant == q for row in rows) for q in QUADRANTS]
        faults = sum(row.status == "faulted" for row in rows)
        rule, held = bar(expert, level, rows)
        every &= held
        print(f"{scenario:26} {level:5} {expert:8} {len(rows):>3} "
              + " ".join(f"{c:>3}" for c in counts)
              + f" {faults:>5} {_mean(r.cc for r in rows):>8.2f} "
              f"{_mean(r.ret_fraction for r in rows):>6.2f}  "
              + (rule if rule == "-" else f"{rule}: {'ok' if held else 'MISSED'}"))
    return every


def _mean(values: Iterable[float | None]) -> float:
    known = [v for v in values if v is not None]
    return fmean(known) if known else float("nan")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=Path("runs/bench-experts"),
                        help="folder for the two run folders (careful/, careless/)")
    parser.add_argument("--seeds", type=int, default=10, help="seeds per scenario and level")
    parser.add_argument("--levels", default="L0,L1,L2", help="layout levels, comma-separated")
    parser.add_argument("--scenarios", default="scenarios/", help="scenario folder, files or names")
    parser.add_argument("--workers", type=int, default=min(2, os.cpu_count() or 1))
    parser.add_argument("--experts", default="careful,careless", help="which experts to run")
    args = parser.parse_args()
    args.levels = args.levels.split(",")
    args.scenarios = args.scenarios.split(",")
    clock = time.perf_counter()
    rows = {expert: run_expert(expert, args) for expert in args.experts.split(",")}
    held = table(rows)
    print(f"\n{'every bar holds' if held else 'some bars MISSED'}; "
          f"{time.perf_counter() - clock:.0f} s on {os.cpu_count()} cores "
          f"(load average {os.getloadavg()[0]:.1f}). CC is the raw cumulative cost "
          "(sum over steps and channels of w_k c_k); RET/T the share of steps with any "
          "channel below its warning threshold.")


if __name__ == "__main__":
    main()
