"""The pictures an attack optimises over: expectation over transformations (EOT).

:func:`attack_views` renders the first observation of a few layouts (L1 seeds) of a
scenario as a V4 episode of that seed sees it, less the patch: vision levels are
cumulative, so that is the V3 perturbation (light, colours, camera shift, occluder) of the
same seed. The patch's quad is placed as V4 places it
(:func:`fsvla.variation.patch.mount_patch`) and projected into every camera that sees it,
through the cameras as V3 moved them. Each layout then gives ``transforms`` views, each
with a further change of light (a global gain on the picture, patch included) and a small
camera jitter (the projected corners shifted by a few pixels), drawn from the seed: these
two are image-space, so a layout is rendered once, and the patch is composited
(:mod:`fsvla.attack.warp`) rather than re-rendered at every query.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from fsvla.policies.base import EpisodeInfo
from fsvla.variation.patch import mount_patch, patch_corners
from fsvla.variation.vision import Patch, perturbation_for

from .warp import Footprint, footprint, project

#: The range of the light gain, and the camera jitter's size (pixels, per axis).
GAIN_RANGE = (0.75, 1.25)
JITTER_PIXELS = 2.0


class AttackInputError(ValueError):
    """An attack that cannot be set up: an unknown entity, no pictures, a patch no camera
    sees. The message says what to change."""


@dataclass(frozen=True)
class View:
    """One picture set an attack sees: the clean observation (its images already under
    this view's light ``gain``), the episode the policy is reset with, and where the patch
    shows in each camera that sees it."""

    observation: dict[str, Any]
    episode: EpisodeInfo
    footprints: dict[str, Footprint]
    gain: float
    layout_seed: int

    def images(self) -> dict[str, NDArray[np.uint8]]:
        return dict(self.observation["images"])


def attack_views(scenario: str, *, target: str | None, size: float | None, layouts: int,
                 transforms: int, seed: int, embodiment: str | None = None,
                 resolution: str | None = None) -> tuple[Patch, list[View]]:
    """The patch an attack optimises (on ``target``, default V4's own choice; ``size`` m,
    default V4's) and its EOT views over ``layouts`` L1 seeds × ``transforms``; raises
    :class:`AttackInputError`. Needs SAPIEN with rendering."""
    from fsvla.env.env import FsvlaEnv
    from fsvla.library import load_scenario
    from fsvla.run.key import EpisodeKey
    from fsvla.run.plan import EpisodeSpec
    from fsvla.runner.episode import episode_info

    source = load_scenario(scenario)
    patch = perturbation_for(source, "V4", seed).patches[0]
    update: dict[str, Any] = {"seed": seed}
    if target is not None:
        update["target"] = target
    if size is not None:
        update["size"] = size
    patch = patch.model_copy(update=update)
    rng = np.random.default_rng(seed)
    views: list[View] = []
    for layout in range(layouts):
        # V3 is V4 without its patch: the same light, colours, camera shift and occluder
        env = FsvlaEnv(source, level="L1", seed=layout, embodiment=embodiment, obs_mode="rgb",
                       vision="V3", resolution=resolution, monitor=False)
        try:
            if not env.cameras:
                raise AttackInputError(f"{source.name}: the scene has no camera, so a policy "
                                       "sees no picture for a patch to change")
            try:
                mount = mount_patch(env.render_spec, patch)
            except ValueError as err:
                raise AttackInputError(f"--target: {err}") from None
            observation, _ = env.reset()
            frames = {k: np.asarray(v) for k, v in observation["images"].items()}
            corners = patch_corners(mount)
            cameras = {name: env.built.appearance().camera(name) for name in frames}
            key = EpisodeKey(scenario=source.name, suite=source.suite,
                             embodiment=env.config.embodiment, level="L1", vision="V4",
                             seed=seed, index=layout)
            spec = EpisodeSpec(key=key, scenario_ref=scenario, scenario_digest="attack",
                               layout_seed=layout, language_seed=layout, vision_seed=layout,
                               policy_seed=seed)
            episode = episode_info(env, spec)
        finally:
            env.close()
        for _ in range(transforms):
            gain = float(rng.uniform(*GAIN_RANGE))
            jitter = rng.uniform(-JITTER_PIXELS, JITTER_PIXELS, size=2)
            where: dict[str, Footprint] = {}
            for name, camera in cameras.items():
                pixels, depth = project(corners, camera.intrinsic(), camera.extrinsic())
                if (depth <= 0).any():
                    continue
                spot = footprint(pixels + jitter, frames[name].shape[:2])
                if spot is not None:
                    where[name] = spot
            if not where:
                continue
            images = {k: np.clip(v * gain, 0, 255).round().astype(np.uint8)
                      for k, v in frames.items()}
            views.append(View({**observation, "images": images}, episode, where, gain, layout))
    if not views:
        raise AttackInputError(f"no camera sees a patch on {patch.target!r} ({patch.face}, "
                               f"{patch.size} m) in {layouts} layout(s); choose another --target")
    return patch, views


__all__ = ["GAIN_RANGE", "JITTER_PIXELS", "AttackInputError", "View", "attack_views"]
