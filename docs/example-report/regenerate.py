"""Regenerate the example report in this folder from a real run of both scripted experts,
and of the trained baseline where its run exists.

    python docs/example-report/regenerate.py [--runs runs/example-report] [--workers 2]
                                             [--baseline runs/baseline/eval]

What it runs, as a user would (every step is a plain ``fsvla`` command, printed first):

1. ``fsvla run --sweep`` of the careful and of the careless expert over the ten built-in
   scenarios: the paper's one-axis sweeps (L0-L2 at W0/V0, W0-W4 at L0/V0, V0-V4 at
   L0/W0: 11 cells a scenario), each scored episode with its own layout, one warm-up per
   scenario; rgb observations, so V1-V4 are rendered into the pictures the policy is
   given (the experts read the simulator state and ignore them, which is what their flat
   W and V curves show). The careful expert gets three episodes a cell; the careless one
   gets one, ended at its first hard violation (``--terminate-on-violation``): its
   collisions make a whole episode about ten times as slow to simulate, and the report
   needs its outcome, not how long it went on being unsafe;
2. ``fsvla report`` once, as JSON only, to learn which episode it dissects (the unsafe
   success with the largest RET);
3. ``fsvla replay --video`` of that episode into its run's ``videos/`` folder, so the
   dissection shows keyframes;
4. ``fsvla report`` into this folder: HTML, Markdown, LaTeX, JSON, PNG figures, CSV.

The baseline's run folder (``bench/baseline.py`` writes it: an ACT trained on the careful
expert's demonstrations, reading the front camera's pictures; see docs/baseline.md) is
reported beside the experts as a third policy, ``act-baseline``, when it exists; it is
not run from here (its training takes up to 45 minutes).

Runs resume, so an interrupted regeneration picks up where it stopped.
"""

from __future__ import annotations

import argparse
import json
import shlex
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
EXPERTS = ("careful-expert", "careless-expert")
GRID = ["--scenarios", "scenarios/", "--sweep", "--obs-mode", "rgb", "--warmup", "1"]
PER_EXPERT = {"careful-expert": ["--episodes", "3"],
              "careless-expert": ["--episodes", "1", "--terminate-on-violation"]}
FORMATS = "html,md,json,tex,png,csv"
BASELINE = "act-baseline"


def fsvla(*args: str) -> None:
    command = [sys.executable, "-m", "fsvla", *args]
    print("$ fsvla " + shlex.join(args), flush=True)
    subprocess.run(command, cwd=ROOT, check=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=Path, default=Path("runs/example-report"),
                        help="where the two run folders go (relative to the repository)")
    parser.add_argument("--workers", default="2", help="worker processes for each run")
    parser.add_argument("--baseline", type=Path, default=Path("runs/baseline/eval"),
                        help="the trained baseline's run folder (bench/baseline.py), "
                             "reported when it exists")
    args = parser.parse_args()
    folders = {expert: args.runs / expert.split("-")[0] for expert in EXPERTS}
    for expert, folder in folders.items():
        fsvla("run", "--policy", expert, *GRID, *PER_EXPERT[expert], "--workers", args.workers,
              "--out", str(folder), "--no-progress")
    if (ROOT / args.baseline / "results.sqlite").exists():
        folders[BASELINE] = args.baseline
    runs = [str(f) for f in folders.values()]
    labels = [arg for label in folders for arg in ("--label", label)]
    with tempfile.TemporaryDirectory(prefix="fsvla-example-") as scratch:
        fsvla("report", *runs, *labels, "-o", scratch, "--formats", "json", "--no-figures")
        chosen = json.loads((Path(scratch) / "report.json").read_text())["dissection"]
    folder = folders[chosen["label"]]
    video = folder / "videos" / f"{chosen['episode_id']}.mp4"
    if not (ROOT / video).exists():
        fsvla("replay", str(folder), chosen["episode_id"], "--video", str(video))
    fsvla("report", *runs, *labels, "-o", str(HERE.relative_to(ROOT)), "--formats", FORMATS)


if __name__ == "__main__":
    main()
