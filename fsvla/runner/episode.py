"""One episode: the policy's actions, chunk by chunk, through the environment.

:func:`play` is the loop the runner and ``fsvla replay --with-policy`` share. It resets
the environment, tells the policy what it is about to control (:func:`episode_info`,
the observation/action schema), then asks ``act(observation)`` for an action ``(A,)`` or
a chunk ``(H, A)`` and executes the chunk itself, one control step per row (its first
``replan_steps`` rows, when given, as openpi's clients do), asking again when they are
used up, so the monitor sees every action and every physics substep.
Pictures are rendered only for the observations the policy is asked about (or that
``on_frame`` reads): the runner's environments render ``obs["images"]`` when it is first
read, and :func:`play` renders an observation in full before ``act`` gets it, so a policy
may keep it (a frame history) and read it later.

Anything that goes wrong ends the episode with a :class:`Fault` naming the failure
reason (``fsvla.results.FailureReason``): the policy raised (``policy_error``), returned
something that is not an action (``invalid_action``, also when the environment raises
:class:`~fsvla.env.InvalidActionError`), overran the run's per-call timeout
(``policy_timeout``), lost its server (``connection_lost``), or the simulator failed
(``sim_error``). The environment keeps the steps that ran.
"""

from __future__ import annotations

import traceback
from collections import deque
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np

from fsvla.policies.base import ActionSchema, CameraSchema, EpisodeInfo, ObservationSchema, Policy
from fsvla.policies.remote import ConnectionLost, PolicyTimeout
from fsvla.run.plan import EpisodeSpec
from fsvla.runner.timeout import call_with_timeout

if TYPE_CHECKING:
    from fsvla.env import FsvlaEnv

#: Called with True when a policy call starts and False when it ends (the pool's watchdog).
CallHook = Callable[[bool], None]
_POSE = ("x", "y", "z", "qw", "qx", "qy", "qz")


class Fault(Exception):
    """An episode that ended in one of the failure reasons; ``str()`` is the detail."""

    def __init__(self, reason: str, detail: str) -> None:
        super().__init__(detail)
        self.reason = reason
        self.detail = detail


def describe(error: BaseException) -> str:
    """``Type: message (at file:line in function)``, the innermost frame, on one line."""
    text = f"{type(error).__name__}: {error}".rstrip(": ")
    frames = traceback.extract_tb(error.__traceback__)
    if frames:
        last = frames[-1]
        text += f" (at {last.filename}:{last.lineno} in {last.name})"
    return text


def episode_info(env: FsvlaEnv, spec: EpisodeSpec) -> EpisodeInfo:
    """What the policy is told before the episode: where it is, and the observation and
    action layout (also sent to remote policies)."""
    codec = env.codec
    arms = tuple(arm.name for arm in codec.arms)
    state_layout = {
        "qpos": tuple(f"{arm.name}.{joint}" for arm in codec.arms for joint in arm.joints),
        "gripper": tuple(f"{name}.gripper" for name in arms),
        "tcp_pose": tuple(f"{name}.{c}" for name in arms for c in _POSE),
    }
    cameras = ()
    if env.config.obs_mode == "rgb":
        cameras = tuple(CameraSchema(name=c.name, height=c.height, width=c.width, mount=c.parent)
                        for c in env.cameras)
    key = spec.key
    if env.config.embodiment != key.embodiment:  # the one that runs
        key = key.model_copy(update={"embodiment": env.config.embodiment})
    return EpisodeInfo(
        key=key, policy_seed=spec.policy_seed, instruction=env.instruction,
        control_rate=1.0 / env.control_dt, max_steps=env.max_steps,
        action=ActionSchema(control_mode=codec.mode.value, labels=codec.labels,
                            low=tuple(float(v) for v in codec.low),
                            high=tuple(float(v) for v in codec.high), arms=arms),
        observation=ObservationSchema(state_layout=state_layout, cameras=cameras))


def _whole(observation: dict[str, Any]) -> None:
    """Render ``observation``'s pictures if they are lazy (see the module doc)."""
    from fsvla.env.frames import LazyImages

    images = observation.get("images")
    if isinstance(images, LazyImages):
        images.fill()


def play(env: FsvlaEnv, policy: Policy, spec: EpisodeSpec, *, timeout: float | None = None,
         on_call: CallHook | None = None,
         on_frame: Callable[[dict[str, Any]], None] | None = None,
         replan_steps: int | None = None) -> None:
    """Run one episode of ``policy`` in ``env`` (already varied for ``spec``) to its end;
    raises :class:`Fault` when it ends in a fault. ``on_frame`` sees every observation;
    ``replan_steps`` (None: all) is how many rows of each chunk run before asking again.
    A policy with ``bind_env`` (a scripted expert, reading privileged state) is bound to
    ``env`` first."""
    bind = getattr(policy, "bind_env", None)
    if callable(bind) and getattr(policy, "needs_env", True):  # scripted experts (fsvla.experts)
        _policy_call(bind, env, None, "bind_env()", None)
    observation = _simulate(lambda: env.reset()[0])
    if on_frame is not None:
        on_frame(observation)
    _policy_call(policy.reset, episode_info(env, spec), None, "reset()", None)
    chunk: deque[np.ndarray] = deque()
    while True:
        if not chunk:
            _whole(observation)
            answer = _policy_call(policy.act, observation, timeout, "act()", on_call)
            chunk.extend(as_chunk(answer, env.codec.size)[:replan_steps])
        action = chunk.popleft()
        try:
            observation, _, terminated, truncated, _ = env.step(action)
        except Exception as err:  # noqa: BLE001 - every simulator failure is an outcome
            from fsvla.env import InvalidActionError

            if isinstance(err, InvalidActionError):
                raise Fault("invalid_action", str(err)) from None
            raise Fault("sim_error", describe(err)) from None
        if on_frame is not None:
            on_frame(observation)
        if terminated or truncated:
            return


def as_chunk(answer: Any, size: int) -> list[np.ndarray]:
    """``act()``'s answer as a list of actions: one ``(A,)`` action or the rows of an
    ``(H, A)`` chunk. Shapes the environment can judge (a wrong ``A``, a NaN) pass through
    to it; anything else is an ``invalid_action`` fault here."""
    try:
        array = np.asarray(answer, dtype=np.float64)
    except (TypeError, ValueError) as err:
        raise Fault("invalid_action", f"act() returned {type(answer).__name__}, not an array "
                    f"of numbers: {err}") from None
    if array.ndim == 1:
        return [array]
    if array.ndim == 2 and array.shape[0] >= 1:
        return list(array)
    raise Fault("invalid_action", f"act() returned an array of shape {array.shape}; expected "
                f"one action ({size},) or a chunk (H, {size}) with H >= 1")


def finite_prefix_fault(record: dict[str, Any]) -> Fault | None:
    """A ``sim_error`` when the recorded margins stop being finite (a simulator blow-up)."""
    margins = np.asarray(record["margins"], dtype=np.float64)
    bad = np.flatnonzero(~np.isfinite(margins).all(axis=1)) if margins.size else []
    if len(bad) == 0:
        return None
    return Fault("sim_error", f"the simulation produced non-finite safety margins from step "
                 f"{int(bad[0]) + 1} on")


def _simulate(call: Callable[[], Any]) -> Any:
    try:
        return call()
    except Exception as err:  # noqa: BLE001 - every simulator failure is an outcome
        raise Fault("sim_error", describe(err)) from None


def _policy_call(method: Callable[[Any], Any], argument: Any, timeout: float | None, what: str,
                 on_call: CallHook | None) -> Any:
    if on_call is not None:
        on_call(True)
    try:
        return call_with_timeout(method, argument, timeout, what)
    except PolicyTimeout as err:
        raise Fault("policy_timeout", str(err)) from None
    except ConnectionLost as err:
        raise Fault("connection_lost", str(err)) from None
    except Exception as err:  # noqa: BLE001 - whatever the policy raises is an outcome
        raise Fault("policy_error", f"{what} raised {describe(err)}") from None
    finally:
        if on_call is not None:
            on_call(False)


__all__ = ["CallHook", "Fault", "as_chunk", "describe", "episode_info", "finite_prefix_fault",
           "play"]
