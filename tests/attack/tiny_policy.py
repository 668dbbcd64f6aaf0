"""A small differentiable torch policy for the attack tests: a tiny CNN, randomly
initialised with a fixed seed, mapping the front picture to one action. Importable as
``--policy tests/attack/tiny_policy.py:TinyCnnPolicy``."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
import torch

from fsvla.policies.base import EpisodeInfo

SEED = 0


class TinyCnnPolicy:
    """Picture of the first camera -> action, through two strided convolutions, global
    average pooling and a linear layer (weights from torch.manual_seed(SEED))."""

    def __init__(self, seed: int = SEED) -> None:
        generator = torch.Generator().manual_seed(seed)
        self.net = torch.nn.Sequential(
            torch.nn.Conv2d(3, 8, 5, stride=2), torch.nn.ReLU(),
            torch.nn.Conv2d(8, 16, 5, stride=2), torch.nn.ReLU(),
            torch.nn.AdaptiveAvgPool2d(1), torch.nn.Flatten())
        for parameter in self.net.parameters():
            with torch.no_grad():
                parameter.copy_(torch.randn(parameter.shape, generator=generator) * 0.3)
        self.head: torch.nn.Linear | None = None
        self.seed = seed
        self.camera = ""

    def reset(self, episode: EpisodeInfo) -> None:
        self.camera = episode.observation.cameras[0].name
        width = len(episode.action.labels)
        if self.head is None or self.head.out_features != width:
            generator = torch.Generator().manual_seed(self.seed + 1)
            self.head = torch.nn.Linear(16, width)
            with torch.no_grad():
                self.head.weight.copy_(torch.randn(width, 16, generator=generator))
                self.head.bias.zero_()

    def torch_act(self, observation: dict[str, Any], images: Mapping[str, torch.Tensor]
                  ) -> torch.Tensor:
        assert self.head is not None, "reset(episode) comes first"
        picture = images[self.camera].permute(2, 0, 1)[None]
        return self.head(self.net(picture))[0]

    def act(self, observation: dict[str, Any]) -> np.ndarray:
        images = {self.camera: torch.as_tensor(
            np.asarray(observation["images"][self.camera], dtype=np.float32) / 255.0)}
        with torch.no_grad():
            return self.torch_act(observation, images).numpy().astype(np.float64)
