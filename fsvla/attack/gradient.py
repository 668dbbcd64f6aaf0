"""Gradient patch attack: Adam through a differentiable composite, with EOT.

For a policy that is a differentiable PyTorch model, the patch is composited into each
view's pictures with ``torch.nn.functional.grid_sample`` over the same grid the black-box
compositor samples (:mod:`fsvla.attack.warp`), the policy's action is computed with
gradients, and Adam raises the mean :func:`~fsvla.attack.objective.action_shift` over all
views (expectation over transformations). The patch is ``sigmoid(z)`` of free logits
``z``, so it stays in [0, 1].

A policy takes part by offering :class:`DifferentiablePolicy`'s method
``torch_act(observation, images)``: ``images`` maps each camera to an ``H × W × 3`` float
tensor in [0, 1] (what ``act`` would get as uint8), and it returns the action (or chunk)
as a tensor that carries gradients to them. PyTorch is imported only here.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any, Protocol, runtime_checkable

import numpy as np
from numpy.typing import NDArray

from .objective import action_scale
from .views import View

INSTALL = "the gradient attack needs PyTorch (pip install torch, or a LeRobot environment)"


class TorchUnavailable(RuntimeError):
    """PyTorch is not installed where fsvla runs."""


@runtime_checkable
class DifferentiablePolicy(Protocol):
    def torch_act(self, observation: dict[str, Any], images: Mapping[str, Any]) -> Any: ...


def is_differentiable(policy: object) -> bool:
    """Whether ``policy`` offers ``torch_act`` (see the module doc)."""
    return isinstance(policy, DifferentiablePolicy)


def require_torch() -> Any:
    """The ``torch`` module; :class:`TorchUnavailable` saying how to install it."""
    try:
        import torch
    except ImportError as err:
        raise TorchUnavailable(f"{INSTALL} ({err})") from None
    return torch


def gradient_attack(policy: DifferentiablePolicy, views: Sequence[View],
                    initial: NDArray[np.floating], steps: int, rng: np.random.Generator,
                    lr: float = 0.1) -> NDArray[np.float64]:
    """The best patch (S × S × 3 in [0, 1]) of ``steps`` Adam steps from ``initial`` (as
    the differentiable objective rated it)."""
    torch = require_torch()
    torch.manual_seed(int(rng.integers(2**31)))
    start = np.clip(np.asarray(initial, dtype=np.float64), 1e-3, 1 - 1e-3)
    logits = torch.tensor(np.log(start / (1 - start)), dtype=torch.float32, requires_grad=True)
    optimiser = torch.optim.Adam([logits], lr=lr)
    prepared = [_prepare(torch, view) for view in views]
    with torch.no_grad():
        clean = [_clean(torch, policy, v, frames) for v, (frames, _) in zip(views, prepared)]
    scales = [action_scale(v.episode) for v in views]
    best, best_value = start, -np.inf
    for _ in range(max(steps, 1)):
        optimiser.zero_grad()
        patch = torch.sigmoid(logits)
        shifts = []
        for view, (frames, places), reference, scale in zip(views, prepared, clean, scales):
            images = _composite(torch, frames, places, patch * view.gain)
            action = torch.atleast_2d(policy.torch_act(view.observation, images))
            steps_shared = min(len(action), len(reference))
            diff = (action[:steps_shared] - reference[:steps_shared]) / torch.as_tensor(
                scale, dtype=action.dtype)
            shifts.append(torch.sqrt((diff ** 2).sum(dim=-1) + 1e-12).mean())
        value = torch.stack(shifts).mean()
        if float(value.detach()) > best_value:
            best_value, best = float(value.detach()), patch.detach().cpu().numpy().astype(np.float64)
        (-value).backward()
        optimiser.step()
    return best


def _prepare(torch: Any, view: View) -> tuple[dict[str, Any], dict[str, tuple[Any, Any, Any]]]:
    frames = {k: torch.as_tensor(np.asarray(v, dtype=np.float32) / 255.0)
              for k, v in view.images().items()}
    places = {k: (w, torch.as_tensor(w.grid)[None], torch.as_tensor(w.mask)[..., None])
              for k, w in view.footprints.items()}
    return frames, places


def _clean(torch: Any, policy: DifferentiablePolicy, view: View, frames: dict[str, Any]) -> Any:
    return torch.atleast_2d(policy.torch_act(view.observation, frames)).detach()


def _composite(torch: Any, frames: dict[str, Any], places: dict[str, tuple[Any, Any, Any]],
               patch: Any) -> dict[str, Any]:
    """``frames`` with ``patch`` (S × S × 3) sampled into each footprint."""
    source = patch.clamp(0.0, 1.0).permute(2, 0, 1)[None]
    out = dict(frames)
    for name, (where, grid, mask) in places.items():
        sampled = torch.nn.functional.grid_sample(source, grid, mode="bilinear",
                                                  padding_mode="border", align_corners=False)
        sampled = sampled[0].permute(1, 2, 0)
        frame = frames[name].clone()
        box = frame[where.top:where.bottom, where.left:where.right]
        frame[where.top:where.bottom, where.left:where.right] = torch.where(mask, sampled, box)
        out[name] = frame
    return out


__all__ = ["INSTALL", "DifferentiablePolicy", "TorchUnavailable", "gradient_attack",
           "is_differentiable", "require_torch"]
