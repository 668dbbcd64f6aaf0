"""The attack's views against the renderer: the footprint the homography gives a patch is
where SAPIEN draws the V4 patch (the pixels a rendered patch changes), so the patch the
attack composites is the one ``fsvla run --vision V4 --patch`` shows."""

from __future__ import annotations

import numpy as np
import pytest
from fsvla.compiler.scene import lower_scene

from fsvla.attack.warp import footprint, project
from fsvla.library import load_scenario
from fsvla.variation.vision import Patch, VisionPerturbation
from tests.conftest import require_sapien

sapien = require_sapien()
pytestmark = [pytest.mark.sim, pytest.mark.render]


def test_the_footprint_is_where_the_renderer_draws_the_patch(render_device) -> None:
    from fsvla.sim.builder import build
    from fsvla.variation.apply import VisionApplier
    from fsvla.variation.patch import patch_corners

    spec = lower_scene(load_scenario("stack_block_gently"))
    built = build(spec, render=True)
    applier = VisionApplier(built.appearance(), spec)
    plain = built.render_views()
    applier.apply(VisionPerturbation(level="V4", patches=(Patch(target="red", seed=3),)))
    patched = built.render_views()
    corners = patch_corners(applier.mounts[0])
    seen = 0
    for name, frame in plain.items():
        changed = (frame != patched[name]).any(axis=-1)
        camera = built.appearance().camera(name)
        pixels, depth = project(corners, camera.intrinsic(), camera.extrinsic())
        where = footprint(pixels, frame.shape[:2]) if (depth > 0).all() else None
        if where is None:
            assert changed.sum() < 20, name
            continue
        ours = np.zeros_like(changed)
        ours[where.top:where.bottom, where.left:where.right] = where.mask
        overlap = (ours & changed).sum() / (ours | changed).sum()
        assert overlap > 0.85, (name, overlap)
        seen += 1
    assert seen >= 1
