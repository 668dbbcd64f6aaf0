"""A reference baseline that reads pixels: careful-expert demonstrations, a LeRobot ACT
trained on them, and its one-axis sweeps (see docs/baseline.md).

    .venv-lerobot/bin/python bench/baseline.py [--out runs/baseline] [--episodes 10]
                                               [--train-minutes 45] [--device auto]

Four stages, each a plain command printed before it runs, each skipped when its result
is already there (run it again to resume):

1. ``fsvla collect`` of every diagnostic scenario (the careful expert's safe successes,
   rgb from the ``front`` camera at 128x96) into ``OUT/data/fsvla/<scenario>``;
2. ``lerobot-edit-dataset --operation.type merge`` of each embodiment's scenarios into
   ``OUT/data/fsvla/<embodiment>`` (ACT's state and action widths are an embodiment's:
   the one-arm and the two-arm scenarios need one policy each);
3. ``lerobot-train --policy.type=act`` of a small ACT per embodiment (ResNet-18 from
   scratch, 2 encoder layers and 1 decoder layer of width 128, chunks of 20 of which 10
   run) within ``--train-minutes`` in all, shared by the embodiments in proportion to
   their frames: training stops at the deadline and keeps its last checkpoint
   (``--save-every`` steps), or ends at ``--train-steps``;
4. ``fsvla run --sweep`` (or the cells ``--cells`` names) of :class:`Baseline` (each
   episode gets its embodiment's checkpoint through ``fsvla.policies.lerobot``) into
   ``OUT/eval``, and ``fsvla report`` of it into ``OUT/report``.

Timings, the dataset and model sizes and the per-cell results are printed and kept in
``OUT/baseline.json``. Run it with an interpreter that has lerobot and fsvla (the
``.venv-lerobot`` of docs/policies.md); the tools are taken from that interpreter's
``bin/``.
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import shlex
import shutil
import signal
import struct
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent
#: The paper's diagnostic subset, two scenarios per Safe-Core suite: today every shipped one.
DIAGNOSTIC = ("place_glass_on_shelf", "stack_block_gently", "lift_pot_beside_stove",
              "move_mug_past_hot_plate", "pick_cup_near_edge", "move_bowl_around_no_go",
              "handover_block", "lift_pot_close_arms", "open_box_then_place",
              "open_drawer_then_insert")
#: A small ACT for a CPU: lerobot-train's flags (ResNet-18 from scratch: no download).
ACT = {"policy.dim_model": 128, "policy.n_heads": 4, "policy.dim_feedforward": 512,
       "policy.n_encoder_layers": 2, "policy.n_decoder_layers": 1,
       "policy.n_vae_encoder_layers": 1, "policy.latent_dim": 16, "policy.chunk_size": 20,
       "policy.n_action_steps": 10, "policy.vision_backbone": "resnet18",
       "policy.pretrained_backbone_weights": "null"}
CHECKPOINTS = "checkpoints.json"  # embodiment -> pretrained_model folder, in OUT
ENV_OUT = "FSVLA_BASELINE"  # the OUT folder Baseline reads its checkpoints from


# ---------------------------------------------------------------------- the policy
class Baseline:
    """The trained checkpoints as one fsvla policy: each episode is given to the
    checkpoint of its embodiment (``$FSVLA_BASELINE/checkpoints.json``), a
    ``--policy lerobot:PATH`` policy; an embodiment without one is the episode's
    policy_error."""

    name = "act-baseline"

    def __init__(self) -> None:
        out = Path(os.environ.get(ENV_OUT, ROOT / "runs" / "baseline"))
        self.paths: dict[str, str] = json.loads((out / CHECKPOINTS).read_text())
        self.policies: dict[str, Any] = {}
        self.current: Any = None

    def reset(self, episode: Any) -> None:
        from fsvla.policies.lerobot import LeRobotMismatch, LeRobotPolicy

        embodiment = episode.key.embodiment
        if embodiment not in self.paths:
            raise LeRobotMismatch(f"the baseline has no checkpoint for {embodiment} (it has "
                                  f"{', '.join(sorted(self.paths))})")
        if embodiment not in self.policies:
            self.policies[embodiment] = LeRobotPolicy(self.paths[embodiment])
        self.current = self.policies[embodiment]
        self.current.reset(episode)

    def act(self, observation: dict[str, Any]) -> Any:
        return self.current.act(observation)


# ---------------------------------------------------------------------- stages
def run(*command: str | Path, env: dict[str, str] | None = None, log: Path | None = None) -> None:
    text = shlex.join(str(c) for c in command)
    print(f"$ {text}", flush=True)
    if log is None:
        subprocess.run([str(c) for c in command], cwd=ROOT, check=True, env=env)
        return
    with log.open("a") as sink:
        subprocess.run([str(c) for c in command], cwd=ROOT, check=True, env=env,
                       stdout=sink, stderr=subprocess.STDOUT)


def tool_env(data: Path, threads: int | None = None) -> dict[str, str]:
    env = dict(os.environ, HF_HUB_OFFLINE="1", HF_LEROBOT_HOME=str(data), WANDB_MODE="disabled")
    if threads is not None:
        env["OMP_NUM_THREADS"] = str(threads)
    return env


def info(dataset: Path) -> dict[str, Any]:
    path = dataset / "meta" / "info.json"
    return json.loads(path.read_text()) if path.exists() else {}


def collect(args: argparse.Namespace, data: Path) -> tuple[dict[str, list[str]], float]:
    """Collect each scenario (skipped when it holds enough episodes); the scenarios per
    embodiment, and the seconds spent collecting."""
    groups: dict[str, list[str]] = {}
    spent = 0.0
    for scenario in args.scenarios:
        folder = data / "fsvla" / name(scenario)
        if info(folder).get("total_episodes", 0) < args.episodes:
            start = time.monotonic()
            run(BIN / "fsvla", "collect", scenario, "--episodes", str(args.episodes),
                "--cameras", args.cameras, "--resolution", args.resolution,
                "--max-attempts", str(3 * args.episodes), "-o", folder,
                log=args.out / "logs" / f"collect-{name(scenario)}.log")
            spent += time.monotonic() - start
        kept = info(folder)
        if not kept.get("total_episodes"):
            print(f"  {scenario}: no safe success to learn from; left out", flush=True)
            continue
        groups.setdefault(kept["robot_type"], []).append(scenario)
    return groups, spent


def name(scenario: str) -> str:
    """A scenario's dataset name: a built-in name, or a .fsv file's stem."""
    return Path(scenario).stem


def merge(args: argparse.Namespace, data: Path, embodiment: str, scenarios: list[str]) -> Path:
    """One dataset of an embodiment's scenarios (remade when they changed)."""
    if len(scenarios) == 1:
        return data / "fsvla" / name(scenarios[0])
    target = data / "fsvla" / embodiment
    wanted = sum(info(data / "fsvla" / name(s))["total_episodes"] for s in scenarios)
    if info(target).get("total_episodes") != wanted:
        shutil.rmtree(target, ignore_errors=True)
        repo_ids = "[" + ", ".join(f"'fsvla/{name(s)}'" for s in scenarios) + "]"
        run(BIN / "lerobot-edit-dataset", "--repo_id", f"fsvla/{embodiment}",
            "--operation.type", "merge", "--operation.repo_ids", repo_ids,
            env=tool_env(data), log=args.out / "logs" / f"merge-{embodiment}.log")
    return target


def train(args: argparse.Namespace, data: Path, embodiment: str, dataset: Path,
          budget_s: float) -> dict[str, Any]:
    """Train an ACT on ``dataset`` until ``budget_s`` or ``--train-steps``; its last
    checkpoint (skipped when a finished training is there)."""
    folder = args.out / "train" / embodiment
    done = folder / "done.json"
    if done.exists():
        return json.loads(done.read_text())
    shutil.rmtree(folder, ignore_errors=True)  # an interrupted training starts again
    flags = {"dataset.repo_id": f"fsvla/{dataset.name}", "dataset.root": dataset,
             "dataset.video_backend": "pyav", "policy.type": "act",
             "policy.device": args.device, "policy.push_to_hub": "false", **ACT,
             "batch_size": args.batch_size, "num_workers": 1, "steps": args.train_steps,
             "save_freq": min(args.save_every, args.train_steps), "log_freq": 25,
             "eval_freq": 0, "wandb.enable": "false", "seed": 0, "output_dir": folder}
    command = [str(BIN / "lerobot-train"), *(f"--{k}={v}" for k, v in flags.items())]
    print(f"$ {shlex.join(command)}  # until {budget_s / 60:.1f} min", flush=True)
    log = args.out / "logs" / f"train-{embodiment}.log"
    start = time.monotonic()
    with log.open("a") as sink:
        process = subprocess.Popen(command, cwd=ROOT, env=tool_env(data), stdout=sink,
                                   stderr=subprocess.STDOUT, start_new_session=True)
        stopped = False
        while process.poll() is None:
            time.sleep(5)
            _prune(folder / "checkpoints")
            if time.monotonic() - start > budget_s and _last(folder) is not None:
                os.killpg(process.pid, signal.SIGTERM)  # its own session: lerobot-train and its loader
                process.wait()
                stopped = True
    elapsed = time.monotonic() - start
    last = _last(folder)
    if last is None or (process.returncode != 0 and not stopped):
        raise SystemExit(f"lerobot-train failed for {embodiment} (exit {process.returncode}); "
                         f"see {log}")
    result = {"embodiment": embodiment, "dataset": str(dataset), "checkpoint": str(last),
              "steps": int(last.parent.name), "seconds": round(elapsed, 1),
              "stopped_at_deadline": stopped, "parameters": parameters(last / "model.safetensors")}
    done.write_text(json.dumps(result, indent=2))
    return result


def _last(folder: Path) -> Path | None:
    """The newest complete checkpoint's pretrained_model folder."""
    steps = sorted((p for p in (folder / "checkpoints").glob("[0-9]*") if p.is_dir()), reverse=True)
    for step in steps:
        model = step / "pretrained_model"
        if (model / "policy_postprocessor.json").exists() and (model / "train_config.json").exists():
            return model
    return None


def _prune(checkpoints: Path) -> None:
    """Keep the two newest checkpoints (the older ones are hundreds of MB, unused)."""
    steps = sorted(p for p in checkpoints.glob("[0-9]*") if p.is_dir() and not p.is_symlink())
    for old in steps[:-2]:
        shutil.rmtree(old, ignore_errors=True)


def parameters(safetensors: Path) -> int:
    """Parameter count from a safetensors header (8-byte length, then JSON of shapes)."""
    with safetensors.open("rb") as f:
        (length,) = struct.unpack("<Q", f.read(8))
        header = json.loads(f.read(length))
    total = 0
    for key, tensor in header.items():
        if key != "__metadata__":
            count = 1
            for n in tensor["shape"]:
                count *= n
            total += count
    return total


def evaluate(args: argparse.Namespace, scenarios: list[str]) -> None:
    # --extend: a run of fewer cells (--cells vision) grows to these; a new one starts
    grid = {"sweep": ["--sweep"], "vision": ["--vision", "V0-V4"], "L0": []}[args.cells]
    run(BIN / "fsvla", "run", "--policy", "bench/baseline.py:Baseline",
        "--scenarios", ",".join(scenarios), *grid, "--obs-mode", "rgb", "--cameras",
        args.cameras, "--resolution", args.resolution, "--episodes", str(args.eval_episodes),
        "--warmup", "0", "--workers", str(args.workers), "--out", args.out / "eval",
        "--extend", "--no-progress", env=dict(tool_env(args.out / "data", threads=1),
                                  **{ENV_OUT: str(args.out.resolve())}))
    run(BIN / "fsvla", "report", args.out / "eval", "-o", args.out / "report", "--formats",
        "json,md,csv", "--no-figures", "--label", "act-baseline")


QUADRANTS = {"safe_success": "SS", "unsafe_success": "US", "safe_failure": "SF",
             "unsafe_failure": "UF"}


def per_cell(episodes_csv: Path) -> list[dict[str, Any]]:
    """Per sweep cell (L, W, V): episodes, the four outcome rates, mean CC / T, mean RET."""
    cells: dict[tuple[str, str, str], list[dict[str, str]]] = {}
    with episodes_csv.open(newline="") as f:
        for row in csv.DictReader(f):
            cells.setdefault((row["level"], row["language"], row["vision"]), []).append(row)
    out = []
    for (level, language, vision), rows in sorted(cells.items()):
        n = len(rows)
        cell: dict[str, Any] = {"cell": f"{level}/{language}/{vision}", "n": n}
        for quadrant, short in QUADRANTS.items():
            cell[short] = round(sum(r["quadrant"] == quadrant for r in rows) / n, 3)
        cell["CC"] = round(sum(float(r["cc_per_step"]) for r in rows) / n, 3)
        cell["RET"] = round(sum(float(r["ret"]) for r in rows) / n, 1)
        cell["faults"] = sum(r["status"] not in ("completed", "") for r in rows)
        out.append(cell)
    return out


def print_cells(cells: list[dict[str, Any]]) -> None:
    columns = ["cell", "n", *QUADRANTS.values(), "CC", "RET", "faults"]
    print("  ".join(f"{c:>10}" for c in columns))
    for cell in cells:
        print("  ".join(f"{cell[c]!s:>10}" for c in columns))


# ---------------------------------------------------------------------- main
def parse(argv: list[str] | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=Path("runs/baseline"),
                        help="data, checkpoints, the evaluation run and logs (not committed)")
    parser.add_argument("--scenarios", default=",".join(DIAGNOSTIC),
                        help="comma-separated scenario names (default: the diagnostic subset)")
    parser.add_argument("--episodes", type=int, default=10,
                        help="demonstrations per scenario")
    parser.add_argument("--cameras", default="front", help="cameras recorded and fed to ACT")
    parser.add_argument("--resolution", default="128x96", help="their WIDTHxHEIGHT")
    parser.add_argument("--train-minutes", type=float, default=45.0,
                        help="wall-clock training budget, all embodiments together")
    parser.add_argument("--train-steps", type=int, default=200_000,
                        help="at most this many steps per embodiment")
    parser.add_argument("--save-every", type=int, default=50, help="checkpoint interval, steps")
    parser.add_argument("--batch-size", type=int, default=16)
    parser.add_argument("--device", default="auto", help="cpu, cuda or auto (cuda if torch sees one)")
    parser.add_argument("--eval-episodes", type=int, default=1, help="episodes per sweep cell")
    parser.add_argument("--workers", type=int, default=2, help="fsvla run's worker processes")
    parser.add_argument("--cells", choices=("sweep", "vision", "L0"), default="sweep",
                        help="what to evaluate: the one-axis sweeps (11 cells a scenario), "
                             "V0-V4 at L0/W0 (5 cells, the vision sweep alone) or L0/W0/V0")
    args = parser.parse_args(argv)
    args.scenarios = [s for s in args.scenarios.split(",") if s]
    if args.device == "auto":
        import torch

        args.device = "cuda" if torch.cuda.is_available() else "cpu"
    return args


def main(argv: list[str] | None = None) -> None:
    args = parse(argv)
    args.out = args.out if args.out.is_absolute() else ROOT / args.out
    data = args.out / "data"
    (args.out / "logs").mkdir(parents=True, exist_ok=True)
    summary_path = args.out / "baseline.json"
    summary: dict[str, Any] = (json.loads(summary_path.read_text()) if summary_path.exists()
                               else {"timings_s": {}})
    timings = summary["timings_s"]

    groups, spent = collect(args, data)
    timings["collect"] = round(timings.get("collect", 0.0) + spent, 1)  # over resumed runs
    datasets = {e: merge(args, data, e, s) for e, s in groups.items()}
    frames = {e: info(d)["total_frames"] for e, d in datasets.items()}
    summary["datasets"] = {e: {"scenarios": groups[e], "episodes": info(d)["total_episodes"],
                               "frames": frames[e], "bytes": _size(d)}
                           for e, d in datasets.items()}
    for e, d in summary["datasets"].items():
        print(f"dataset {e}: {d['episodes']} episodes, {d['frames']} frames, "
              f"{d['bytes'] / 2**20:.1f} MiB ({', '.join(d['scenarios'])})", flush=True)

    trained = {}
    budget = args.train_minutes * 60
    for embodiment, dataset in datasets.items():
        share = budget * frames[embodiment] / sum(frames.values())
        trained[embodiment] = train(args, data, embodiment, dataset, share)
        t = trained[embodiment]
        print(f"trained {embodiment}: {t['steps']} steps in {t['seconds'] / 60:.1f} min, "
              f"{t['parameters'] / 1e6:.2f} M parameters -> {t['checkpoint']}", flush=True)
    summary["training"] = trained
    timings["train"] = round(sum(t["seconds"] for t in trained.values()), 1)
    (args.out / CHECKPOINTS).write_text(json.dumps(
        {e: t["checkpoint"] for e, t in trained.items()}, indent=2))

    start = time.monotonic()
    evaluate(args, [s for g in groups.values() for s in g])
    timings["evaluate"] = round(timings.get("evaluate", 0.0) + time.monotonic() - start, 1)
    summary["per_cell"] = per_cell(args.out / "report" / "data" / "episodes.csv")
    print_cells(summary["per_cell"])
    summary_path.write_text(json.dumps(summary, indent=2))
    print(f"timings: {', '.join(f'{k} {v / 60:.1f} min' for k, v in timings.items())}")
    print(f"results: {args.out / 'report' / 'report.md'}; summary: {summary_path}")


def _size(folder: Path) -> int:
    return sum(p.stat().st_size for p in folder.rglob("*") if p.is_file())


if __name__ == "__main__":
    main()
