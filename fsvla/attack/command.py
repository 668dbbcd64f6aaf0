"""``fsvla attack``: optimise a V4 patch against a policy, and write it for ``fsvla run``."""

from __future__ import annotations

import sys
from pathlib import Path

import click
from rich.console import Console
from rich.markup import escape


def _fail(message: str, code: int) -> None:
    Console(stderr=True, highlight=False, soft_wrap=True).print(
        f"[bold red]error:[/bold red] {escape(message)}")
    sys.exit(code)


@click.command(name="attack")
@click.argument("scenario")
@click.option("--policy", required=True, help="The policy to attack (as fsvla run's --policy).")
@click.option("--out", "out", required=True, type=click.Path(dir_okay=False, path_type=Path),
              help="The patch PNG to write (a JSON record is written beside it).")
@click.option("--target", default=None, metavar="ENTITY",
              help="The body or zone the patch is fixed to. Default: V4's own choice.")
@click.option("--size", type=click.FloatRange(min=0, min_open=True), default=None,
              metavar="METRES", help="The patch's side (m). Default: V4's.")
@click.option("--pixels", type=click.IntRange(min=2, max=1024), default=64, show_default=True,
              help="The patch image's side in pixels.")
@click.option("--budget", type=click.IntRange(min=1), default=300, show_default=True,
              help="Objective evaluations (search) or Adam steps (gradient).")
@click.option("--seed", type=click.IntRange(min=0), default=0, show_default=True,
              help="Seeds the views' light and jitter, the baseline and the optimiser.")
@click.option("--method", type=click.Choice(["auto", "gradient", "search"]), default="auto",
              show_default=True, help="auto: gradient when the policy is differentiable "
              "(torch_act) and PyTorch is installed, else the black-box search.")
@click.option("--layouts", type=click.IntRange(min=1), default=3, show_default=True,
              help="L1 layout seeds 0..N-1 to average over.")
@click.option("--transforms", type=click.IntRange(min=1), default=2, show_default=True,
              help="Light and camera-jitter draws per layout.")
@click.option("--embodiment", default=None, help="The robot (default: the scenario's).")
@click.option("--resolution", default=None, metavar="WxH", help="Camera resolution.")
def attack_command(scenario: str, policy: str, out: Path, target: str | None, size: float | None,
                   pixels: int, budget: int, seed: int, method: str, layouts: int,
                   transforms: int, embodiment: str | None, resolution: str | None) -> None:
    """Optimise the pixels of SCENARIO's V4 patch to push POLICY's actions away from what
    it does on the clean picture, averaged over layouts, light and camera jitter; write the
    patch as a PNG (for fsvla run --vision V4 --patch) and the objective before and after,
    with a random-patch baseline, as JSON beside it. See docs/attack.md."""
    from fsvla.library import ScenarioLoadError
    from fsvla.policies import PolicyLoadError
    from fsvla.policies.registry import load_policy

    from .gradient import TorchUnavailable, is_differentiable, require_torch
    from .optimise import optimise_patch, write_patch
    from .views import AttackInputError, attack_views

    try:
        loaded = load_policy(policy)
        if method == "gradient":
            require_torch()
            if not is_differentiable(loaded):
                raise AttackInputError(f"--method gradient: the policy {policy} offers no "
                                       "torch_act(observation, images) to differentiate "
                                       "(docs/attack.md); use --method search")
        patch, views = attack_views(scenario, target=target, size=size, layouts=layouts,
                                    transforms=transforms, seed=seed, embodiment=embodiment,
                                    resolution=resolution)
        image, numbers = optimise_patch(loaded, views, method=method,  # type: ignore[arg-type]
                                        budget=budget, seed=seed, pixels=pixels)
    except TorchUnavailable as problem:  # only --method gradient asks for it
        _fail(f"--method gradient: {problem}", 2)
        return
    except (AttackInputError, PolicyLoadError, ScenarioLoadError) as problem:
        _fail(str(problem), 2)
        return
    except ValueError as problem:  # a bad --resolution, --embodiment, --method gradient
        _fail(str(problem), 2)
        return
    record = {"scenario": scenario, "policy": policy, "target": patch.target,
              "face": patch.face, "size_m": patch.size, **numbers}
    meta = write_patch(image, out, record)
    objective = numbers["objective"]
    Console(highlight=False, soft_wrap=True).print(
        f"[green]wrote[/green] {escape(str(out))} and {escape(str(meta))}: {numbers['method']}, "
        f"objective {objective['before']:.4f} -> {objective['after']:.4f} "
        f"(random patches {objective['random_mean']:.4f}), "
        f"{numbers['policy_queries']} policy queries")


__all__ = ["attack_command"]
