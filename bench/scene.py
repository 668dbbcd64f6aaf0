"""Runtime speed per scenario: compile (lower) time of L0/L1/L2, SAPIEN build time,
physics steps per second with the robot holding home, render frames per second.

Targets (issue #3): a scene builds in at most 1 s; physics runs at least 5,000 steps/s
for a single-arm embodiment (physics only, the robots' gravity feed-forward on every
step, as ``BuiltScene.step`` does). L1/L2 are timed only where
``fsvla.compiler.variants`` exists; rendering only where a Vulkan device exists.

    python bench/scene.py [--steps 2000] [--frames 10] [--shader minimal] [--no-render]
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from fsvla.compiler.scene import lower_scene
from fsvla.dsl.loader import ScenarioLoader

from fsvla.resources import scenarios_dir
from fsvla.sim import build, render_available

TARGET_BUILD_S = 1.0
TARGET_STEPS_PER_S = 5000.0
WARMUP_STEPS = 100


def median_seconds(run: Callable[[], Any], repeat: int) -> float:
    samples = []
    for _ in range(repeat):
        start = time.perf_counter()
        run()
        samples.append(time.perf_counter() - start)
    return statistics.median(samples)


def variant_generator() -> Callable[..., Any] | None:
    try:
        from fsvla.compiler.variants import generate_variant
    except ImportError:
        return None
    return generate_variant


def compile_times(scenario: Any, repeat: int) -> dict[str, float | str]:
    """``lower_scene`` (L0) and ``generate_variant`` per level: the first call in the
    process, then the median over seeds 1..repeat (the generator memoises assets)."""
    times: dict[str, float | str] = {
        "lower_scene L0": median_seconds(lambda: lower_scene(scenario), repeat)}
    generate = variant_generator()
    if generate is None:
        times["L1, L2"] = "n/a (no fsvla.compiler.variants)"
        return times
    for level in ("L0", "L1", "L2"):
        try:
            first = median_seconds(lambda lv=level: generate(scenario, lv, 0), 1)
            seeds = iter(range(1, repeat + 1))
            warm = median_seconds(lambda lv=level, it=seeds: generate(scenario, lv, next(it)),
                                  repeat)
        except Exception as err:  # noqa: BLE001 - a bench reports, it does not stop
            times[level] = f"failed: {type(err).__name__}: {err}"
            continue
        times[level] = f"{first * 1000:.1f}/{warm * 1000:.1f} ms"
    return times


def steps_per_second(spec: Any, steps: int) -> tuple[float, float]:
    """(steps/s of BuiltScene.step, steps/s of bare scene.step with sleeping robots)."""
    built = build(spec, render=False)
    built.step(WARMUP_STEPS)
    start = time.perf_counter()
    built.step(steps)
    fed = steps / (time.perf_counter() - start)
    start = time.perf_counter()
    for _ in range(steps):
        built.scene.step()
    bare = steps / (time.perf_counter() - start)
    return fed, bare


def frames_per_second(spec: Any, frames: int, shader: str) -> tuple[float, float]:
    """(first render s, frames/s of all benchmark cameras together)."""
    built = build(spec, render=True, shader=shader)
    start = time.perf_counter()
    built.render_views()
    first = time.perf_counter() - start
    start = time.perf_counter()
    for _ in range(frames):
        built.render_views()
    return first, frames / (time.perf_counter() - start)


def fmt(value: float | str, unit: str = "ms") -> str:
    if isinstance(value, str):
        return value
    return f"{value * 1000:.1f} ms" if unit == "ms" else f"{value:.3f} s"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=2000)
    parser.add_argument("--frames", type=int, default=10)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--shader", default="minimal")
    parser.add_argument("--no-render", action="store_true")
    args = parser.parse_args()
    renders = not args.no_render and render_available()
    root = scenarios_dir()
    print(f"targets: build <= {TARGET_BUILD_S} s; physics >= {TARGET_STEPS_PER_S:.0f} steps/s "
          f"(single arm); render: {'shader ' + args.shader if renders else 'no device, skipped'}")
    for path in sorted(root.rglob("*.fsv")):
        result = ScenarioLoader(allowed_roots=[root]).load(path)
        if result.scenario is None:
            continue
        scenario = result.scenario
        spec = lower_scene(scenario)
        arms = sum(len(m.arms) for m in spec.mounts)
        compiled = compile_times(scenario, args.repeat)
        built_s = median_seconds(lambda s=spec: build(s, render=False), args.repeat)
        fed, bare = steps_per_second(spec, args.steps)
        print(f"{Path(path).relative_to(root)!s}  ({spec.embodiment.name}, {arms} arm(s), "
              f"{len(spec.bodies)} bodies, {len(spec.zones)} zones)")
        print("  compile   " + "  ".join(f"{k} {fmt(v)}" for k, v in compiled.items())
              + "  (variants: first call / median of later seeds)")
        print(f"  build     {fmt(built_s, 's')}  (physics only)  ratio to target "
              f"{built_s / TARGET_BUILD_S:.2f}")
        target = TARGET_STEPS_PER_S
        print(f"  physics   {fed:,.0f} steps/s holding home (ratio to the single-arm target "
              f"{fed / target:.2f}); {bare:,.0f} steps/s with the robots asleep "
              f"({fed * spec.physics.timestep:.1f}x real time)")
        if renders:
            render_s = median_seconds(lambda s=spec: build(s, render=True, shader=args.shader), 1)
            first, fps = frames_per_second(spec, args.frames, args.shader)
            print(f"  render    build {render_s:.3f} s; first frame {first:.2f} s; "
                  f"{fps:.1f} frames/s of {len(spec.cameras)} camera(s) "
                  f"({fps * len(spec.cameras):.1f} camera images/s)")


if __name__ == "__main__":
    main()
