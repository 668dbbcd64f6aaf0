"""What a perturbation applies (``VisionPerturbation.applied``) and the Safe-Vis categories
an episode is attributed to from it."""

from __future__ import annotations

import pytest

from fsvla.library import load_scenario
from fsvla.metrics.taxonomy import vision_categories_applied
from fsvla.variation.vision import VisionPerturbation, perturbation_for


def test_each_level_adds_its_kinds() -> None:
    stove = load_scenario("lift_pot_beside_stove")
    applied = {level: perturbation_for(stove, level, 3).applied()
               for level in ("V0", "V1", "V2", "V3", "V4")}
    assert applied == {
        "V0": (),
        "V1": ("lighting",),
        "V2": ("lighting", "recolor", "texture"),
        "V3": ("lighting", "recolor", "texture", "camera", "occluder"),
        "V4": ("lighting", "recolor", "texture", "camera", "occluder", "patch"),
    }
    assert vision_categories_applied("V3", applied["V3"]) == ["perspective_pose",
                                                              "occlusion_visibility"]
    assert vision_categories_applied("V4", applied["V4"]) == ["adversarial_patch"]


def test_a_v3_block_with_only_an_occluder_applies_no_viewpoint_shift() -> None:
    stove = load_scenario("lift_pot_beside_stove")  # V3: camera(...), occlude(stove, ...)
    occlude = [s for s in stove.vision["V3"] if s.name == "occlude"]
    only = stove.model_copy(update={"vision": {**stove.vision, "V3": tuple(occlude)}})
    p = perturbation_for(only, "V3", 0)
    assert p.camera is None and "camera" not in p.applied() and "occluder" in p.applied()
    assert vision_categories_applied("V3", p.applied()) == ["occlusion_visibility"]


@pytest.mark.parametrize("level", ["V1", "V2", "V3", "V4"])
def test_nothing_applied_attributes_nothing(level: str) -> None:
    assert VisionPerturbation(level=level).applied() == ()
    assert vision_categories_applied(level, ()) == []
