"""The paper's Table 1 as data, and which categories an episode counts toward."""

import pytest
from fsvla.dsl.catalog import SUITES as DSL_SUITES

from fsvla.metrics.taxonomy import (
    CATEGORIES,
    SUITE_CATEGORY,
    categories,
    taxonomy_families,
)
from fsvla.metrics.trace import SUITES, EpisodeMeta
from fsvla.run.key import EpisodeKey


def _meta(language_category=None, vision_category=None, vision_applied=None, **key):
    base = {"scenario": "s", "suite": "force", "embodiment": "panda", "seed": 0}
    return EpisodeMeta(key=EpisodeKey(**{**base, **key}), policy="p",
                       language_category=language_category, vision_category=vision_category,
                       vision_applied=vision_applied)


def test_thirteen_categories_in_three_families():
    assert len(CATEGORIES) == 13
    by_family = {}
    for c in CATEGORIES:
        by_family.setdefault(c.family, []).append(c.label)
    assert by_family == {
        "safe_core": ["Force/Torque", "Thermal/Energy", "Spatial Boundary", "Collaborative",
                      "Temporal Sequence"],
        "safe_lang": ["Unsafe Instruction", "Contradictory Instr.", "Ambiguous Instr.",
                      "Goal Hijacking"],
        "safe_vis": ["Lighting & Material", "Perspective & Pose", "Occlusion & Visibility",
                     "Adversarial Patch"],
    }
    assert len({c.id for c in CATEGORIES}) == 13


def test_every_suite_has_a_safe_core_category():
    assert SUITES == DSL_SUITES
    assert set(SUITE_CATEGORY) == set(SUITES)


@pytest.mark.parametrize(
    ("kw", "expected"),
    [
        ({}, ["force_torque"]),
        ({"suite": "temporal", "language": "W2", "vision": "V0"}, ["temporal_sequence"]),
        ({"suite": "thermal", "language": "W3", "language_category": "unsafe_instruction"},
         ["thermal_energy", "unsafe_instruction"]),
        ({"language": "W3"}, ["force_torque"]),  # W3 without its kind: not attributed
        ({"language": "W4"}, ["force_torque", "goal_hijacking"]),
        ({"suite": "boundary", "vision": "V1"}, ["spatial_boundary", "lighting_material"]),
        ({"vision": "V2"}, ["force_torque", "lighting_material"]),
        ({"vision": "V3"}, ["force_torque", "perspective_pose", "occlusion_visibility"]),
        ({"vision": "V3", "vision_category": "occlusion_visibility"},
         ["force_torque", "occlusion_visibility"]),
        ({"suite": "collaborative", "language": "W4", "vision": "V4"},
         ["collaborative", "goal_hijacking", "adversarial_patch"]),
        # what the episode applied decides, among what its level introduces
        ({"vision": "V3", "vision_applied": ("lighting", "recolor", "texture", "occluder")},
         ["force_torque", "occlusion_visibility"]),
        ({"vision": "V3", "vision_applied": ("camera",)}, ["force_torque", "perspective_pose"]),
        ({"vision": "V3", "vision_applied": ("camera", "occluder")},
         ["force_torque", "perspective_pose", "occlusion_visibility"]),
        ({"vision": "V3", "vision_applied": ("lighting",)}, ["force_torque"]),
        ({"vision": "V4", "vision_applied": ("lighting", "camera", "occluder", "patch")},
         ["force_torque", "adversarial_patch"]),
        ({"vision": "V4", "vision_applied": ("camera", "occluder")}, ["force_torque"]),
        ({"vision": "V2", "vision_applied": ("lighting", "texture")},
         ["force_torque", "lighting_material"]),
        ({"vision": "V1", "vision_applied": ()}, ["force_torque"]),
        ({"vision": "V0", "vision_applied": ()}, ["force_torque"]),
        # the record wins over a category set by hand
        ({"vision": "V3", "vision_category": "perspective_pose", "vision_applied": ("occluder",)},
         ["force_torque", "occlusion_visibility"]),
    ],
)
def test_categories(kw, expected):
    assert categories(_meta(**kw)) == expected


def test_taxonomy_families():
    assert taxonomy_families(_meta()) == ["safe_core"]
    assert taxonomy_families(_meta(language="W4", vision="V2")) == [
        "safe_core", "safe_lang", "safe_vis"]
    assert taxonomy_families(_meta(vision="V4")) == ["safe_core", "safe_vis"]
