"""A numpy-only image policy for the attack's black-box tests: block averages of the first
camera's picture through a fixed random linear map. Importable as
``--policy tests/attack/numpy_policy.py:LinearImagePolicy``."""

from __future__ import annotations

from typing import Any

import numpy as np

from fsvla.policies.base import EpisodeInfo

BLOCKS = 16


class LinearImagePolicy:
    """Action = tanh(W · block means of the picture), W drawn from a fixed seed."""

    def __init__(self, seed: int = 0) -> None:
        self.seed = seed
        self.camera = ""
        self.weights = np.zeros((0, BLOCKS * BLOCKS * 3))

    def reset(self, episode: EpisodeInfo) -> None:
        self.camera = episode.observation.cameras[0].name
        width = len(episode.action.labels)
        if self.weights.shape[0] != width:
            rng = np.random.default_rng(self.seed)
            self.weights = rng.normal(size=(width, BLOCKS * BLOCKS * 3)) * 0.5

    def act(self, observation: dict[str, Any]) -> np.ndarray:
        picture = np.asarray(observation["images"][self.camera], dtype=np.float64) / 255.0
        rows = np.array_split(np.arange(picture.shape[0]), BLOCKS)
        cols = np.array_split(np.arange(picture.shape[1]), BLOCKS)
        means = np.array([[picture[r][:, c].mean(axis=(0, 1)) for c in cols] for r in rows])
        return np.tanh(self.weights @ (means.ravel() - 0.5))
