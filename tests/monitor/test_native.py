"""The native contact reader: it reads what the Python reader reads, and it steps aside,
saying why, where it cannot be built."""

from __future__ import annotations

import functools
import logging

import numpy as np
import pytest

sapien = pytest.importorskip("sapien")

import fsvla
from fsvla.experts import make_expert
from fsvla.monitor import native as native_module
from fsvla.monitor import probe as probe_module
from fsvla.monitor.native import NativeUnavailable, build, native_library
from fsvla.monitor.probe import ContactFilter, Probe

pytestmark = pytest.mark.sim


def _careful_episode(scenario: str, native: bool, actions: list[np.ndarray] | None = None):
    """(actions, record) of a careful-expert episode, or of ``actions`` replayed."""
    env = fsvla.make(scenario, level="L0", seed=0)
    obs, _ = env.reset(seed=0)
    if actions is None:
        expert, actions = make_expert(env, "careful"), []
        expert.reset(None)
        done = False
        while not done:
            for action in expert.act(obs):
                actions.append(action)
                obs, _, terminated, truncated, _ = env.step(action)
                done = terminated or truncated
                if done:
                    break
    else:
        for action in actions:
            env.step(action)
    assert env.monitor.probe.native == native
    return actions, env.episode_record()


@pytest.mark.slow
@pytest.mark.parametrize("scenario", ["place_glass_on_shelf", "handover_block"])
def test_native_and_python_readers_give_the_same_episode(scenario, monkeypatch):
    """A careful grasp of a torque-watched glass (16 wall pieces) and a two-arm handover:
    every margin of every step agrees, so every force, torque and contact predicate did."""
    if native_library() is None:
        pytest.skip("the native reader cannot be built here")
    actions, fast = _careful_episode(scenario, True)
    monkeypatch.setattr(probe_module, "native_library", lambda: None)
    _, slow = _careful_episode(scenario, False, actions)
    assert fast.success and slow.success
    assert fast.channels == slow.channels
    np.testing.assert_array_equal(fast.margins, slow.margins)
    assert fast.states == slow.states


def test_a_missing_compiler_is_reported_not_raised(tmp_path, monkeypatch):
    if native_module._sapien_include is None:
        pytest.skip("no SAPIEN")
    monkeypatch.setenv("CXX", str(tmp_path / "no-such-compiler"))
    monkeypatch.setenv("EIGEN_INCLUDE_DIR", str(tmp_path))  # found or not, the compiler is missing
    with pytest.raises(NativeUnavailable, match="Eigen|could not run the C.. compiler"):
        build(tmp_path)


def test_the_switch_turns_the_reader_off(monkeypatch, caplog):
    native_library.cache_clear()
    monkeypatch.setenv(native_module.SWITCH, "0")
    try:
        with caplog.at_level(logging.INFO, logger=native_module.__name__):
            assert native_library() is None
        assert native_module.SWITCH in caplog.text
    finally:
        native_library.cache_clear()


def test_a_build_is_cached_and_reused():
    if native_library() is None:
        pytest.skip("the native reader cannot be built here")
    first = build()
    stamp = first.stat().st_mtime_ns
    assert build() == first and first.stat().st_mtime_ns == stamp
    assert not [p for p in first.parent.iterdir() if p.name.startswith(".contacts-")]  # no partial builds


def _bound_or_skip():
    bound = native_module.bound_calls()
    if bound is None:
        pytest.skip("the bound-call module cannot be built here (no compiler or no Python headers)")
    return bound


def test_a_bound_call_passes_its_bound_arguments():
    import ctypes
    import sys

    bound, calls = _bound_or_skip(), []
    callback = ctypes.CFUNCTYPE(None, ctypes.c_void_p, ctypes.c_double, ctypes.c_int32)(
        lambda handle, value, flag: calls.append((handle, value, flag)))
    keep = object()
    held = sys.getrefcount(keep)
    call = bound.bind(ctypes.cast(callback, ctypes.c_void_p).value, 0xF5, 2.5, 7, keep)
    assert sys.getrefcount(keep) == held + 1  # the owner of the handle lives as long as the call
    assert call() is None and call() is None
    assert calls == [(0xF5, 2.5, 7), (0xF5, 2.5, 7)]
    with pytest.raises(TypeError):
        call(1)
    del call
    assert sys.getrefcount(keep) == held


def test_a_bound_call_refuses_a_null_function():
    with pytest.raises(ValueError, match="null"):
        _bound_or_skip().bind(0, 1, 0.0, 0, None)


def test_missing_python_headers_are_reported_not_raised(tmp_path, monkeypatch):
    monkeypatch.setattr(native_module.sysconfig, "get_paths", lambda: {"include": str(tmp_path)})
    with pytest.raises(NativeUnavailable, match="python3-dev"):
        native_module.build_bound(tmp_path)


@pytest.mark.parametrize(("scenario", "folds"), [("handover_block", True), ("move_bowl_around_no_go", False)])
def test_the_env_records_substeps_through_the_native_fold(scenario, folds):
    """What the env calls after a substep is the reader's fold itself, and nothing when the
    fold would do nothing. handover_block watches the block's net force (a free body);
    move_bowl_around_no_go has no free body, and no robot link is near the bowl at home,
    so the gate keeps the scan off."""
    if native_library() is None:
        pytest.skip("the native reader cannot be built here")
    env = fsvla.make(scenario)
    env.reset(seed=0)
    probe = env.monitor.probe
    assert bool(probe._free or (probe.scan and probe._filter)) == folds
    recorder = env.monitor.substep_recorder()
    if not folds:
        assert recorder is None
    else:
        assert recorder is probe._fold_native
        if native_module.bound_calls() is not None:
            assert type(recorder).__name__ == "builtin_function_or_method"


def _boxes_on_ground(count: int):
    scene = sapien.Scene([sapien.physx.PhysxCpuSystem()])
    scene.set_timestep(0.002)
    builder = scene.create_actor_builder()
    builder.add_box_collision(half_size=[1.0, 1.0, 0.05])
    ground = builder.build_static(name="ground")
    ground.set_pose(sapien.Pose([0, 0, -0.05]))
    components = {"ground": ground.find_component_by_type(sapien.physx.PhysxRigidStaticComponent)}
    for k in range(count):
        builder = scene.create_actor_builder()
        builder.add_box_collision(half_size=[0.04, 0.04, 0.04], density=500.0 + 100.0 * k)
        box = builder.build(name=f"box{k}")
        box.set_pose(sapien.Pose([0.2 * k - 0.4, 0.1 * k, 0.045], [0.9962, 0.0, 0.0, 0.0872]))
        components[f"box{k}"] = box.find_component_by_type(sapien.physx.PhysxRigidDynamicComponent)
    return scene, components


@pytest.mark.parametrize("bound", [True, False], ids=["bound", "ctypes"])
def test_the_one_call_snapshot_reads_what_the_python_reader_reads_even_past_its_buffers(bound, monkeypatch):
    """Five boxes landing on the ground: five scanned pairs, five last-substep pairs, with
    the native readers' buffers cut to one row, so the one-call snapshot overflows, grows
    them and reads again. Its maxima, contacts and poses are the Python reader's, whether
    the native calls are bound in C or made through ctypes."""
    if native_library() is None:
        pytest.skip("the native reader cannot be built here")
    if not bound:
        monkeypatch.setattr(native_module, "bound_calls", lambda: None)
    scene, components = _boxes_on_ground(5)
    boxes = sorted(f for f in components if f != "ground")
    ground = ContactFilter(any_pair=frozenset({"ground"}))
    probes = [Probe(scene, 0.002, components, pose_frames=boxes, free_bodies=boxes[:2], scan=ground,
                    last=ground, native=native) for native in (True, False)]
    fast, slow = probes
    assert fast.native and not slow.native
    assert isinstance(fast._fold_native, functools.partial) != bound
    fast._native_scan._grow(1)
    fast._native_last._grow(1)
    for probe in probes:
        probe.guards = False
        probe.reset()
    kept = []  # every step's poses, both readers: a later reading must not overwrite them
    for step in range(1, 4):
        for _ in range(25):
            scene.step()
            for probe in probes:
                probe.record_substep()
        ours, theirs = (p.snapshot(step, 0.05 * step, contacts=True) for p in probes)
        assert len(theirs.contact_force) == 7  # five pairs with the ground, two net forces
        assert ours.contact_force == theirs.contact_force
        assert ours.contact_torque == theirs.contact_torque
        assert ours.last_contacts.keys() == theirs.last_contacts.keys() and len(ours.last_contacts) == 10
        for key, value in theirs.last_contacts.items():
            np.testing.assert_array_equal(ours.last_contacts[key], value)
        np.testing.assert_array_equal(ours.poses.stack, theirs.poses.stack)
        kept.append((ours.poses.stack, theirs.poses.stack.copy()))
    assert fast._native_scan._rows >= 5 and fast._native_last._rows >= 5  # both overflowed and grew
    assert not np.array_equal(kept[0][1], kept[-1][1])  # the boxes moved
    for ours, theirs in kept:
        np.testing.assert_array_equal(ours, theirs)
