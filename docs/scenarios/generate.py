"""Write the scenario catalogue, docs/scenarios.md, and what it shows.

    python docs/scenarios/generate.py                  # the page, from the scenarios and
                                                       # the recorded rates (what CI checks)
    python docs/scenarios/generate.py --thumbs         # + missing thumbnails (--thumbs-all: every one)
    python docs/scenarios/generate.py --validate --seeds 2 [--levels L0-L2] [--workers 1]
                                      [SCENARIOS ...]  # + run fsvla validate and record its rates
    python docs/scenarios/generate.py --record OUT.json --seeds 2 --levels L0-L2 \\
                                      --wall-s 2400 --command "fsvla validate ..."
                                                       # + record a validate output made earlier

The page is a function of the scenario files, ``scenarios/sets.toml`` and
``docs/scenarios/validate.json`` (``fsvla.catalogue``); ``tests/test_catalogue.py``
regenerates it and fails when the checked-in page differs, or a thumbnail is missing.
Thumbnails (``docs/scenarios/thumbs/NAME.png``, 160x120) are the front camera at L0,
seed 0, with the safety overlays, as ``fsvla preview NAME --view front`` renders it
(SAPIEN and a Vulkan device: lavapipe on a machine with no GPU). Rates come from
``fsvla validate SCENARIOS --levels L --seeds N --format json`` (SCENARIOS default: every
built-in scenario): each scenario's verdicts replace those recorded before, with the
seeds, the command, the date, the wall time and the commit of the run.
"""

from __future__ import annotations

import argparse
import json
import shlex
import subprocess
import sys
import time
from datetime import date
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
PAGE = ROOT / "docs" / "scenarios.md"
RECORD = HERE / "validate.json"
THUMBS = HERE / "thumbs"
THUMB_SIZE = (160, 120)


def write_page() -> None:
    from fsvla.catalogue import catalogue_page, load_record

    PAGE.write_text(catalogue_page(load_record(RECORD)), encoding="utf-8")
    print(f"wrote {PAGE.relative_to(ROOT)}")


def render_thumbs(every: bool) -> None:
    from PIL import ImageOps

    from fsvla.catalogue import builtin_scenarios_checked
    from fsvla.sim.preview import layout, render_preview

    THUMBS.mkdir(parents=True, exist_ok=True)
    for scenario, _path in builtin_scenarios_checked():
        target = THUMBS / f"{scenario.name}.png"
        if target.exists() and not every:
            continue
        clock = time.perf_counter()
        laid, scene = layout(scenario, "L0", 0)
        image = render_preview(laid, scene, overlays=True, shader="minimal", view="front")
        ImageOps.fit(image, THUMB_SIZE).save(target, optimize=True)
        print(f"wrote {target.relative_to(ROOT)} in {time.perf_counter() - clock:.0f} s",
              flush=True)


def run_validate(items: list[str], levels: str, seeds: int, workers: int, out: Path) -> None:
    args = ["validate", *items, "--levels", levels, "--seeds", str(seeds), "--workers",
            str(workers), "--format", "json", "--no-progress", "--out", str(out)]
    print("$ fsvla " + shlex.join(args), flush=True)
    clock = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "fsvla", *args], cwd=ROOT, stdout=subprocess.PIPE,
                          text=True, check=False)
    if done.returncode not in (0, 1):  # 1: a verdict fails, which the page shows
        sys.exit(f"fsvla validate exited {done.returncode}; nothing recorded")
    shown = [a for a in args if a not in ("--no-progress", "--out", str(out))]
    record(json.loads(done.stdout), "fsvla " + shlex.join(shown), levels, seeds,
           time.perf_counter() - clock)


def record(output: dict, command: str, levels: str, seeds: int, wall_s: float,
           commit: str | None = None) -> None:
    from fsvla.catalogue import ValidateRun, findings, load_record, write_record
    from fsvla.catalogue import builtin_scenarios_checked as checked
    from fsvla.run import parse_levels

    commit = commit or subprocess.run(["git", "rev-parse", "HEAD"], cwd=ROOT, capture_output=True,
                                      text=True, check=False).stdout.strip() or None
    run = ValidateRun(command=command, levels=parse_levels(levels), seeds=tuple(range(seeds)),
                      recorded=date.today().isoformat(), wall_s=round(wall_s), commit=commit,
                      findings=findings(output))
    digests = {scenario.name: scenario.source_digest for scenario, _path in checked()}
    write_record(load_record(RECORD).merged(run, output, digests), RECORD)
    print(f"recorded {len(output.get('verdicts', []))} verdicts in {RECORD.relative_to(ROOT)}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scenarios", nargs="*", default=["scenarios/"],
                        help="what --validate validates (files, folders, names, selectors)")
    parser.add_argument("--thumbs", action="store_true", help="render missing thumbnails")
    parser.add_argument("--thumbs-all", action="store_true", help="render every thumbnail")
    parser.add_argument("--validate", action="store_true", help="run fsvla validate, record")
    parser.add_argument("--record", type=Path, metavar="OUT.json",
                        help="record the output of an earlier fsvla validate --format json")
    parser.add_argument("--command", help="with --record: the command that wrote it")
    parser.add_argument("--wall-s", type=float, default=0.0, help="with --record: its wall time")
    parser.add_argument("--commit", help="with --record: the commit it ran on (default: HEAD)")
    parser.add_argument("--levels", default="L0-L2")
    parser.add_argument("--seeds", type=int, default=2, help="layout seeds 0..N-1")
    parser.add_argument("--workers", type=int, default=1)
    parser.add_argument("--out", type=Path, default=ROOT / "runs" / "catalogue-validate",
                        help="fsvla validate's run folders (resumed when run again)")
    args = parser.parse_args()
    if args.validate:
        run_validate(args.scenarios, args.levels, args.seeds, args.workers, args.out)
    elif args.record:
        if not args.command:
            parser.error("--record needs --command (the command that wrote the file)")
        record(json.loads(args.record.read_text()), args.command, args.levels, args.seeds,
               args.wall_s, args.commit)
    if args.thumbs or args.thumbs_all:
        render_thumbs(args.thumbs_all)
    write_page()


if __name__ == "__main__":
    main()
