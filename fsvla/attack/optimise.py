"""One attack from views to a patch file: pick the method, optimise, measure, write.

:func:`optimise_patch` measures the objective (:mod:`fsvla.attack.objective`) of the
starting patch, of :data:`BASELINE_PATCHES` random patches of the same size (V4's own
seeded patterns, :func:`fsvla.variation.patch.patch_pixels`) and of the optimised patch,
all through the policy's ``act`` on the same composited views; :func:`write_patch` saves
the PNG that ``fsvla run --vision V4 --patch`` reads and, beside it, a JSON record of the
attack (``<name>.json``).
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from fsvla.policies.base import Policy
from fsvla.variation.patch import patch_pixels

from .gradient import gradient_attack, is_differentiable
from .objective import Objective
from .search import square_search
from .views import View

Method = Literal["auto", "gradient", "search"]
#: How many random patches the baseline averages.
BASELINE_PATCHES = 10
#: The patch image's side in pixels when nothing sets it.
ATTACK_PIXELS = 64


def choose_method(policy: object, method: Method) -> Literal["gradient", "search"]:
    """``auto``: the gradient attack when the policy offers ``torch_act`` and PyTorch is
    importable, else the black-box search."""
    if method != "auto":
        return method
    if not is_differentiable(policy):
        return "search"
    try:
        import torch  # noqa: F401
    except ImportError:
        return "search"
    return "gradient"


def optimise_patch(policy: Policy, views: Sequence[View], *, method: Method, budget: int,
                   seed: int, pixels: int = ATTACK_PIXELS) -> tuple[NDArray[np.float64], dict[str, Any]]:
    """The optimised patch (``pixels`` square, values in [0, 1]) and the numbers of the
    attack (objective before, after, the random baseline, the method, the queries). The
    search starts from the best random patch, the gradient attack from grey noise.
    ``budget`` counts objective evaluations for the search (each asks the policy once per
    view) and Adam steps for the gradient attack."""
    chosen = choose_method(policy, method)
    if chosen == "gradient" and not is_differentiable(policy):
        raise ValueError("--method gradient: the policy offers no torch_act(observation, "
                         "images) to differentiate; use --method search")
    rng = np.random.default_rng(seed)
    objective = Objective(policy, views)
    baseline = [objective(patch_pixels(seed + 1 + i, pixels) / 255.0)
                for i in range(BASELINE_PATCHES)]
    if chosen == "search":  # from the best random patch: its value is already known
        best = int(np.argmax(baseline))
        initial = patch_pixels(seed + 1 + best, pixels) / 255.0
        before = baseline[best]
        found = square_search(objective, initial, budget, rng, initial_value=before)
        patch, after = found.patch, found.value
    else:
        initial = rng.uniform(0.25, 0.75, size=(pixels, pixels, 3))
        before = objective(initial)
        patch = gradient_attack(policy, views, initial, budget, rng)  # type: ignore[arg-type]
        after = objective(patch)
    random_mean = float(np.mean(baseline))
    numbers = {
        "method": chosen, "budget": budget, "seed": seed, "pixels": pixels,
        "views": len(views), "layouts": sorted({v.layout_seed for v in views}),
        "policy_queries": objective.queries,
        "objective": {
            "name": "action_shift",
            "meaning": "mean over views of the range-normalised distance between the "
                       "policy's action on the patched and on the clean picture",
            "before": before, "after": after, "random_mean": random_mean,
            "random": baseline,
            "ratio_to_random": after / random_mean if random_mean > 0 else None,
        },
    }
    return patch, numbers


def write_patch(patch: NDArray[np.floating], out: Path, record: dict[str, Any]) -> Path:
    """Write ``patch`` as the PNG ``out`` and ``record`` as JSON beside it; returns the
    JSON's path."""
    from PIL import Image

    out.parent.mkdir(parents=True, exist_ok=True)
    image = np.clip(np.asarray(patch) * 255.0, 0, 255).round().astype(np.uint8)
    Image.fromarray(image, mode="RGB").save(out, format="PNG")
    meta = out.with_suffix(".json")
    meta.write_text(json.dumps({**record, "patch": out.name}, indent=2) + "\n", encoding="utf-8")
    return meta


__all__ = ["ATTACK_PIXELS", "BASELINE_PATCHES", "Method", "choose_method", "optimise_patch",
           "write_patch"]
