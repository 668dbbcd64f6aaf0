"""Building SceneSpecs in SAPIEN: every built-in scenario builds physics-only, rests
stably for 1,000 steps, resets, and builds deterministically; rendering where a Vulkan
device exists."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from fsvla.compiler.assets.model import CylinderShape, Material, Pose
from fsvla.compiler.scene import SceneSpec, lower_scene

from fsvla.sim import BuiltScene, build
from fsvla.sim.builder import start_qpos
from fsvla.sim.shapes import collision_shapes, physx_material
from tests.conftest import require_sapien

sapien = require_sapien()
pytestmark = pytest.mark.sim

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
FILES = sorted(SCENARIOS.rglob("*.fsv"))
IDS = [str(p.relative_to(SCENARIOS)) for p in FILES]

REST_STEPS = 1000
REST_DRIFT = 0.02  # m: a resting body stays within this of its start
REST_SPEED = 0.05  # m/s and rad/s after REST_STEPS
HOME_DRIFT = 0.01  # rad or m: the robots hold home


@pytest.fixture(scope="module", params=FILES, ids=IDS)
def spec(request: pytest.FixtureRequest, load_scenario) -> SceneSpec:
    scenario = load_scenario(request.param)
    if scenario is None:
        pytest.skip(f"{request.param.name} is abstract")
    return lower_scene(scenario)


def _dynamic(built: BuiltScene) -> dict[str, object]:
    out = {}
    for name, entity in built.bodies.items():
        for component in entity.components:
            if isinstance(component, sapien.physx.PhysxRigidDynamicComponent):
                out[name] = component
    return out


def test_builds_physics_only(spec: SceneSpec) -> None:
    built = build(spec, render=False)
    assert not built.renders and built.cameras == {}
    rigid = [b.name for b in spec.bodies if b.asset.asset_type == "rigid"]
    articulated = [b.name for b in spec.bodies if b.asset.asset_type == "articulated"]
    assert list(built.bodies) == rigid
    assert list(built.articulations) == articulated
    assert set(built.robot.articulations) == {m.robot for m in spec.mounts}
    assert built.scene.get_timestep() == pytest.approx(spec.physics.timestep)
    for body in spec.bodies:
        if body.name in built.bodies:
            pose = built.bodies[body.name].pose
            assert np.allclose(pose.p, body.pose.position, atol=1e-6)
            assert np.allclose(np.abs(np.dot(pose.q, body.pose.quaternion)), 1.0, atol=1e-6)
    for name, component in _dynamic(built).items():
        asset = spec.body(name).asset
        assert component.mass == pytest.approx(asset.mass, rel=1e-5)
        assert np.allclose(component.inertia, asset.inertia, rtol=1e-4)
        assert np.allclose(component.cmass_local_pose.p, asset.center_of_mass, atol=1e-6)
    for mount in spec.mounts:
        root = built.robot.articulations[mount.robot].get_root_pose()
        assert np.allclose(root.p, mount.pose.position, atol=1e-6)


def test_rests_stably(spec: SceneSpec) -> None:
    built = build(spec, render=False)
    start = {name: np.array(e.pose.p) for name, e in built.bodies.items()}
    built.step(REST_STEPS)
    for name, component in _dynamic(built).items():
        moved = np.linalg.norm(np.array(built.bodies[name].pose.p) - start[name])
        assert moved < REST_DRIFT, f"{name} moved {moved:.4f} m"
        assert np.linalg.norm(component.linear_velocity) < REST_SPEED, name
        assert np.linalg.norm(component.angular_velocity) < REST_SPEED, name
    for name, articulation in built.articulations.items():
        start = start_qpos(articulation, spec.body(name).asset)
        assert np.all(np.abs(articulation.get_qpos() - start) < REST_DRIFT), name
    for robot, articulation in built.robot.articulations.items():
        home = built.robot.home_qpos(robot)
        assert np.max(np.abs(articulation.get_qpos() - home)) < HOME_DRIFT, robot


def test_reset_restores_spec_state(spec: SceneSpec) -> None:
    built = build(spec, render=False)
    for entity in built.bodies.values():  # disturb everything
        entity.pose = sapien.Pose(np.array(entity.pose.p) + [0.01, -0.02, 0.05])
    for articulation in [*built.articulations.values(), *built.robot.articulations.values()]:
        articulation.set_qpos(np.asarray(articulation.get_qpos()) + 0.01)
    built.step(50)
    built.reset()
    for body in spec.bodies:
        if body.name in built.bodies:
            assert np.allclose(built.bodies[body.name].pose.p, body.pose.position, atol=1e-6)
        else:
            articulation = built.articulations[body.name]
            assert np.allclose(articulation.get_qpos(), start_qpos(articulation, body.asset), atol=1e-6)
    for component in _dynamic(built).values():
        assert np.allclose(component.linear_velocity, 0.0)
        assert np.allclose(component.angular_velocity, 0.0)
    for robot, articulation in built.robot.articulations.items():
        assert np.allclose(articulation.get_qpos(), built.robot.home_qpos(robot), atol=1e-5)
        assert np.allclose(articulation.get_qvel(), 0.0)


def test_builds_deterministically(spec: SceneSpec) -> None:
    first, second = build(spec, render=False), build(spec, render=False)
    assert np.array_equal(first.state(), second.state())
    first.step(200)
    second.step(200)
    assert np.array_equal(first.state(), second.state())


def test_cylinders_stand_along_z() -> None:
    material = physx_material(Material(static_friction=0.5, dynamic_friction=0.4, density=1000))
    [shape] = collision_shapes([CylinderShape(radius=0.05, half_length=0.1, pose=Pose())], material)
    axis = shape.local_pose.to_transformation_matrix()[:3, 0]  # SAPIEN's cylinder axis (+x)
    assert np.allclose(np.abs(axis), [0.0, 0.0, 1.0], atol=1e-6)


def test_step_rejects_negative(spec: SceneSpec) -> None:
    built = build(spec, render=False)
    with pytest.raises(ValueError, match="non-negative"):
        built.step(-1)


@pytest.mark.render
def test_renders_every_camera(render_device, load_scenario) -> None:
    spec = lower_scene(load_scenario(SCENARIOS / "force" / "place_glass_on_shelf.fsv"))
    built = build(spec)  # render=None: a device exists, so it renders
    assert built.renders and set(built.cameras) == {c.name for c in spec.cameras}
    views = built.render_views()
    for camera in spec.cameras:
        view = views[camera.name]
        assert view.shape == (camera.height, camera.width, 3) and view.dtype == np.uint8
        assert view.std() > 5.0, f"{camera.name} is blank"
    with pytest.raises(KeyError, match="no camera"):
        built.render_views(["nope"])


def test_render_true_without_device_fails_clearly() -> None:
    """With no Vulkan device (none found through a bogus ICD path), render=True raises
    RenderUnavailable naming the installer, and render=None falls back to physics only."""
    probe = (
        "from fsvla.compiler.scene import PhysicsSpec\n"
        "from fsvla.sim.builder import _has_render, _new_scene\n"
        "from fsvla.sim.render import RenderUnavailable\n"
        "try:\n"
        "    _new_scene(PhysicsSpec(), True)\n"
        "except RenderUnavailable as err:\n"
        "    print('RAISED', err)\n"
        "print('FALLBACK', _has_render(_new_scene(PhysicsSpec(), None)))\n"
    )
    env = {**os.environ, "VK_ICD_FILENAMES": "/nonexistent/icd.json"}
    done = subprocess.run([sys.executable, "-c", probe], check=False, capture_output=True, text=True, env=env,
                          timeout=120)
    assert done.returncode == 0, done.stderr
    assert "RAISED no Vulkan rendering device" in done.stdout
    assert ".ci/install-vulkan" in done.stdout
    assert "FALLBACK False" in done.stdout
