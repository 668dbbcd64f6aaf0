"""Front-end speed: parse + check time per scenario file, and `fsvla check` as a process.

Targets (issue #2): a 200-line file parses and checks in under 20 ms; `fsvla check
scenarios/` as a whole process in under 0.5 s, without importing SAPIEN.

Cache state: per-file times are medians with the parser warm (built once per process,
as in a long-running one). The process time is a median after a first run that fills
lark's parser cache (``Lark(..., cache=True)`` keeps the analysed grammar in the
temporary folder, once per grammar and lark version); the first run with an empty cache is timed
separately, in an empty temporary folder. Bytecode caching is as the environment sets
it (PYTHONDONTWRITEBYTECODE compiles every module from source at each start); where it
is off, a run with .pyc files in a temporary PYTHONPYCACHEPREFIX is timed as well.

    python bench/compile.py [--repeat 20]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from fsvla.dsl.loader import ScenarioLoader

from fsvla.resources import scenarios_dir

TARGET_FILE_MS = 20.0
TARGET_PROCESS_S = 0.5


def synthetic_scenario(lines: int) -> str:
    """A valid scenario of about ``lines`` lines: many objects, hazards and limits."""
    out = ["# synthetic benchmark scenario", "scenario bench_big", "  suite boundary",
           "  task pick_place(object=cup, target=tray)", "  embodiment dual_panda",
           '  instruction "Move the cup onto the tray."', "  horizon 30 s",
           "  object cup: mug(radius=4 cm, height=10 cm) at (0, 0)",
           "  object tray: tray(size=(30 cm, 20 cm)) at (30 cm, 20 cm)"]
    index = 0
    while len(out) < lines - 8:
        x, y = (index % 9) * 4 - 16, (index // 9) % 9 * 4 - 16
        out.append(f"  object block_{index}: block(size=(3 cm, 3 cm, 3 cm)) at ({x} cm, {y} cm) yaw {index} deg")
        out.append(f"  hazard zone_{index}: no_go_zone(radius=2 cm) right_of block_{index} by 5 cm")
        out.append("    keep gripper, cup outside 1 cm warn 2 cm cost quadratic")
        out.append(f"  constrain gap_{index}: clearance(robot, block_{index}) >= 1 cm warn 1 cm weight 0.5")
        out.append(f"  watch displacement(block_{index}) <= 2 cm warn 1 cm")
        index += 1
    out += ["  require grasped(cup) before on(cup, tray)",
            "  success on(cup, tray) and released(cup) for 1 s",
            "  variants", "    L1: jitter cup 2 cm", "    L2: clutter 3, tighten gap_0 to 2 cm",
            "  language", '    W1: "Put the cup on the tray."']
    return "\n".join(out) + "\n"


def time_file(path: Path, repeat: int, root: Path) -> tuple[float, int]:
    """Median milliseconds to parse and check ``path`` with a fresh loader (parser warm)."""
    ScenarioLoader(allowed_roots=[root]).load(path)  # build the parser once, as a long-running process would
    samples = []
    for _ in range(repeat):
        loader = ScenarioLoader(allowed_roots=[root])
        start = time.perf_counter()
        result = loader.load(path)
        samples.append((time.perf_counter() - start) * 1000)
    assert result.ok, [d.message for d in result.errors]
    return statistics.median(samples), len(path.read_text().splitlines())


def time_process(args: list[str], repeat: int, env: dict[str, str] | None = None) -> float:
    samples = []
    for _ in range(repeat):
        start = time.perf_counter()
        done = subprocess.run(args, check=False, capture_output=True, text=True, env=env)
        samples.append(time.perf_counter() - start)
        if done.returncode != 0:
            raise SystemExit(f"{' '.join(args)} failed:\n{done.stdout}{done.stderr}")
    return statistics.median(samples)


def imports_sapien() -> bool:
    probe = ("import sys; from fsvla.cli import run; "
             "run(['check', '--format', 'concise', sys.argv[1]]); "
             "print('sapien' in sys.modules or 'fcl' in sys.modules)")
    done = subprocess.run([sys.executable, "-c", probe, str(scenarios_dir())], check=False,
                          capture_output=True, text=True)
    return done.stdout.strip().splitlines()[-1] == "True"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=20)
    args = parser.parse_args()

    print("parse + check per file (median, parser warm):")
    total = 0.0
    for path in sorted(scenarios_dir().rglob("*.fsv")):
        ms, lines = time_file(path, args.repeat, scenarios_dir())
        total += ms
        print(f"  {path.relative_to(scenarios_dir())!s:45} {lines:4d} lines {ms:7.2f} ms")
    print(f"  {'all built-in scenarios':45}            {total:7.2f} ms")

    with tempfile.TemporaryDirectory() as folder:
        big = Path(folder) / "bench_big.fsv"
        big.write_text(synthetic_scenario(200))
        ms, lines = time_file(big, args.repeat, Path(folder))
    print(f"  {'synthetic scenario':45} {lines:4d} lines {ms:7.2f} ms"
          f"   target < {TARGET_FILE_MS:.0f} ms  ratio {ms / TARGET_FILE_MS:.2f}")

    # `--no-cache`: every run parses and checks every file (bench/check.py times the
    # result cache)
    fsvla = [sys.executable, "-m", "fsvla", "check", "--no-cache", str(scenarios_dir())]
    time_process(fsvla, 1)  # fills lark's parser cache if it is empty
    runs = max(5, args.repeat // 2)
    seconds = time_process(fsvla, runs)
    print(f"`fsvla check --no-cache scenarios/` as a process (median of {runs}, lark's cache warm): {seconds:.3f} s"
          f"   target < {TARGET_PROCESS_S} s  ratio {seconds / TARGET_PROCESS_S:.2f}")
    bytecode = "off (PYTHONDONTWRITEBYTECODE)" if os.environ.get("PYTHONDONTWRITEBYTECODE") else "on"
    print(f"  bytecode cache as inherited: {bytecode}")
    with tempfile.TemporaryDirectory() as folder:
        cold = time_process(fsvla, 1, env={**os.environ, "TMPDIR": folder})
    print(f"  the first run, with an empty lark cache: {cold:.3f} s")
    if bytecode != "on":
        with tempfile.TemporaryDirectory() as folder:
            env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
            env["PYTHONPYCACHEPREFIX"] = folder  # .pyc files there, not in the tree
            time_process(fsvla, 1, env=env)
            cached = time_process(fsvla, runs, env=env)
        print(f"  with a bytecode cache (median of {runs}): {cached:.3f} s")
    print(f"SAPIEN or FCL imported by `fsvla check`: {imports_sapien()}")


if __name__ == "__main__":
    main()
