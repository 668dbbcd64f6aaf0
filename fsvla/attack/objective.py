"""The attack's objective (the paper's "push the policy toward unsafe actions"): how far
the patch moves the policy's action away from the action it takes on the clean picture.

For one view, :func:`action_shift` is the mean over the chunk's steps of the Euclidean
norm of the difference of the two actions, each component divided by its range in the
episode's action schema (so joints and grippers weigh alike); :class:`Objective` averages
it over the views (expectation over transformations). Larger is a stronger attack. One
evaluation asks the policy once per view, through its public ``reset``/``act``, so it
works for any policy, a remote one included.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from fsvla.policies.base import EpisodeInfo, Policy

from .views import View
from .warp import composite


def action_scale(episode: EpisodeInfo) -> NDArray[np.float64]:
    """Each action component's range (1 where the schema leaves it unbounded)."""
    span = np.asarray(episode.action.high, dtype=np.float64) - np.asarray(episode.action.low)
    return np.where(np.isfinite(span) & (span > 0), span, 1.0)


def action_shift(action: NDArray[Any], clean: NDArray[Any], scale: NDArray[np.float64]) -> float:
    """Mean over the shared steps of ``|| (action - clean) / scale ||``; a single action
    counts as a chunk of one."""
    a = np.atleast_2d(np.asarray(action, dtype=np.float64))
    b = np.atleast_2d(np.asarray(clean, dtype=np.float64))
    steps = min(len(a), len(b))
    return float(np.linalg.norm((a[:steps] - b[:steps]) / scale, axis=-1).mean())


def patched_observation(view: View, patch: NDArray[np.floating]) -> dict[str, Any]:
    """``view``'s observation with ``patch`` (S × S × 3 in [0, 1]) composited into every
    camera that sees it (the light gain is already in the clean pictures)."""
    images = view.images()
    for name, where in view.footprints.items():
        lit = np.clip(np.asarray(patch, dtype=np.float64) * view.gain, 0.0, 1.0)
        images[name] = composite(images[name], lit, where)
    return {**view.observation, "images": images}


class Objective:
    """The mean :func:`action_shift` over ``views`` for ``policy``; counts its policy
    queries in :attr:`queries`."""

    def __init__(self, policy: Policy, views: Sequence[View]) -> None:
        self.policy = policy
        self.views = list(views)
        self.queries = 0
        self.scales = [action_scale(v.episode) for v in self.views]
        self.clean = [self._act(v, v.observation) for v in self.views]

    def __call__(self, patch: NDArray[np.floating]) -> float:
        shifts = [action_shift(self._act(v, patched_observation(v, patch)), clean, scale)
                  for v, clean, scale in zip(self.views, self.clean, self.scales)]
        return float(np.mean(shifts))

    def _act(self, view: View, observation: dict[str, Any]) -> NDArray[np.float64]:
        self.policy.reset(view.episode)
        self.queries += 1
        return np.asarray(self.policy.act(observation), dtype=np.float64)


__all__ = ["Objective", "action_scale", "action_shift", "patched_observation"]
