"""The V4 patch in a rendered SAPIEN scene: it covers >= 1 % of the front picture at the
default settings, rides on the body it is fixed to (and shows in a wrist camera), sits
where :func:`fsvla.variation.patch.patch_corners` says with its image unmirrored, changes
no physics, and goes away on restore. A patch's pixels are found by rendering with and
without it and counting the pixels that changed."""

from __future__ import annotations

import numpy as np
import pytest
from fsvla.compiler.scene import lower_scene

from fsvla.library import load_scenario
from fsvla.sim.builder import build
from fsvla.variation.apply import VisionApplier
from fsvla.variation.patch import patch_corners
from fsvla.variation.vision import Patch, VisionPerturbation, perturbation_for
from tests.conftest import require_sapien

sapien = require_sapien()
pytestmark = [pytest.mark.sim, pytest.mark.render]

#: The issue's bar: the share of the front picture a default patch covers.
COVERAGE_BAR = 0.01


def _scene(name: str):
    scenario = load_scenario(name)
    spec = lower_scene(scenario)
    built = build(spec, render=True)
    return scenario, built, VisionApplier(built.appearance(), spec)


def _changed(applier: VisionApplier, built, patches: tuple[Patch, ...]) -> dict[str, np.ndarray]:
    """Per camera, the pixels that the patches change (H × W bool), rendered now."""
    applier.restore()
    plain = built.render_views()
    applier.apply(VisionPerturbation(level="V4", patches=patches))
    patched = built.render_views()
    return {name: (plain[name] != patched[name]).any(axis=-1) for name in plain}


def _project(applier: VisionApplier, camera: str, points: np.ndarray) -> np.ndarray:
    """Pixel (u, v) of world ``points`` in ``camera``."""
    view = applier.appearance.camera(camera)
    cam = np.c_[points, np.ones(len(points))] @ view.extrinsic().T
    uv = cam @ view.intrinsic().T
    return uv[:, :2] / uv[:, 2:]


def _inside(polygon: np.ndarray, mask: np.ndarray, margin: float = 1.5) -> float:
    """The share of ``mask``'s true pixels (their centres) inside the convex ``polygon``
    (pixel coordinates) grown by ``margin`` pixels."""
    v, u = np.nonzero(mask)
    points = np.c_[u + 0.5, v + 0.5]
    centre = polygon.mean(axis=0)
    inside = np.ones(len(points), dtype=bool)
    for a, b in zip(polygon, np.roll(polygon, -1, axis=0)):
        edge = b - a
        normal = np.array([edge[1], -edge[0]]) / np.linalg.norm(edge)
        if normal @ (centre - a) > 0:
            normal = -normal  # outward
        inside &= (points - a) @ normal <= margin
    return float(inside.mean())


@pytest.mark.parametrize("name", ["move_mug_past_hot_plate", "stack_block_gently",
                                  "lift_pot_beside_stove"])
def test_a_default_patch_covers_one_percent_of_the_front_picture(render_device, name: str) -> None:
    scenario, built, applier = _scene(name)
    patches = perturbation_for(scenario, "V4", 0).patches
    assert patches and patches[0].size == pytest.approx(0.14) and patches[0].face == "front"
    changed = _changed(applier, built, patches)
    assert changed["front"].mean() >= COVERAGE_BAR, changed["front"].mean()
    (mount,) = applier.mounts
    quad = _project(applier, "front", patch_corners(mount))
    assert _inside(quad, changed["front"]) > 0.98


def test_the_patch_rides_on_its_body_into_the_wrist_view(render_device) -> None:
    _, built, applier = _scene("move_mug_past_hot_plate")
    patch = Patch(target="mug", seed=4, face="top")
    mug = built.bodies["mug"]
    changed = _changed(applier, built, (patch,))
    rows = np.nonzero(changed["front"])[0]
    assert changed["front"].mean() > 0.002 and not changed["wrist"].any()

    # carried: 10 cm up, the patch with it, where patch_corners says it is
    lifted = sapien.Pose(mug.pose.p + np.array([0.0, 0.0, 0.10]), mug.pose.q)
    mug.pose = lifted
    moved = _changed(applier, built, (patch,))
    (mount,) = applier.mounts
    quad = _project(applier, "front", patch_corners(mount, lifted))
    assert _inside(quad, moved["front"]) > 0.98
    assert np.nonzero(moved["front"])[0].mean() < rows.mean() - 10  # higher in the picture

    # held under the wrist camera: seen there too
    wrist = applier.appearance.camera("wrist").pose
    forward = sapien.Pose(wrist.p, wrist.q).to_transformation_matrix()[:3, 0]
    top = np.asarray(mount.corners).mean(axis=0)  # the patch's centre, in the mug's frame
    under = sapien.Pose(wrist.p + 0.3 * forward - top, mug.pose.q)
    mug.pose = under
    seen = _changed(applier, built, (patch,))
    assert seen["wrist"].mean() > COVERAGE_BAR, seen["wrist"].mean()
    quad = _project(applier, "wrist", patch_corners(mount, under))
    assert _inside(quad, seen["wrist"]) > 0.98


def test_the_image_is_unmirrored_with_its_top_left_at_the_first_corner(render_device) -> None:
    _, built, applier = _scene("move_mug_past_hot_plate")
    image = np.zeros((64, 64, 3), dtype=np.uint8)
    image[:32, :32] = (255, 0, 0)  # top-left red, top-right green, bottom-right blue,
    image[:32, 32:] = (0, 255, 0)  # bottom-left white
    image[32:, 32:] = (0, 0, 255)
    image[32:, :32] = (255, 255, 255)
    applier.apply(VisionPerturbation(level="V4", patches=(Patch(target="mug", seed=0),)))
    (mount,) = applier.mounts
    applier.restore()
    appearance = built.appearance()
    undo = appearance.add_patch(mount.body, np.asarray(mount.corners), image)
    picture = built.render_views()["front"].astype(int)
    undo()
    corners = patch_corners(mount)
    centre = corners.mean(axis=0)
    for corner, colour in zip(corners, ("red", "green", "blue", "white")):
        u, v = _project(applier, "front", (0.7 * corner + 0.3 * centre)[None])[0]
        r, g, b = picture[int(v), int(u)]
        assert {"red": r > 2 * max(g, b), "green": g > 2 * max(r, b), "blue": b > 2 * max(r, g),
                "white": min(r, g, b) > 100 and max(r, g, b) - min(r, g, b) < 30}[colour], \
            (colour, (r, g, b))


def test_a_patch_changes_no_physics_and_restore_takes_it_away(render_device) -> None:
    scenario, built, applier = _scene("move_mug_past_hot_plate")
    mug = built.bodies["mug"]

    def physics() -> tuple:
        body = mug.find_component_by_type(sapien.physx.PhysxRigidDynamicComponent)
        shapes = [(type(s).__name__, tuple(s.local_pose.p), tuple(s.local_pose.q))
                  for s in body.collision_shapes]
        return body.mass, tuple(body.inertia), tuple(body.cmass_local_pose.p), shapes

    before, components = physics(), list(mug.components)
    views = built.render_views()
    applier.apply(perturbation_for(scenario, "V4", 2))
    assert physics() == before
    assert len(mug.components) == len(components) + 1  # one render component, no physics
    applier.restore()
    assert list(mug.components) == components
    after = built.render_views()
    assert all(np.array_equal(views[name], after[name]) for name in views)
