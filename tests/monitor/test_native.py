"""The native contact reader: it reads what the Python reader reads, and it steps aside,
saying why, where it cannot be built."""

from __future__ import annotations

import logging

import numpy as np
import pytest

sapien = pytest.importorskip("sapien")

import fsvla
from fsvla.experts import make_expert
from fsvla.monitor import native as native_module
from fsvla.monitor import probe as probe_module
from fsvla.monitor.native import NativeUnavailable, build, native_library

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
