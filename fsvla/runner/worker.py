"""The episode worker: what runs episodes, in whatever process the backend puts it.

An :class:`EpisodeWorker` holds one policy and the scenarios it has loaded. Every episode
gets a freshly built environment (scene, monitor): SAPIEN keeps physics state that
``reset`` does not clear (contact caches), so an episode played in a reused scene is not
bit-identical to the same episode in a fresh one, and ``fsvla replay`` (which builds a
fresh one) could not reproduce it. What is cached is what costs nothing to reuse: the
parsed and checked scenario of each ``scenario_ref``. After a fault the policy is closed
and a fresh one loaded for the next episode (a policy that timed out may still be
answering the old request).

:meth:`EpisodeWorker.run` never raises: every episode ends in an
:class:`~fsvla.results.EpisodeOutcome`, faulted or not.
"""

from __future__ import annotations

import time
from datetime import datetime, timezone
from typing import TYPE_CHECKING, Any

from fsvla.policies.base import Policy
from fsvla.results.models import EpisodeOutcome, layout_digest
from fsvla.run.config import RunConfig
from fsvla.run.plan import EpisodeSpec
from fsvla.runner.episode import CallHook, Fault, describe, finite_prefix_fault, play

if TYPE_CHECKING:
    from fsvla.dsl.models import Scenario
    from fsvla.env import FsvlaEnv

#: Seconds a remote policy's own reply timeout exceeds the run's, so that the run's
#: timeout (the same for every policy) is what fires.
REMOTE_SLACK_S = 1.0

def load_run_policy(config: RunConfig) -> Policy:
    """The run's policy (raises ``PolicyLoadError``), speaking the run's profile, with the
    run's timeout given to a remote policy as its own reply timeout."""
    from fsvla.policies import load_policy

    policy = load_policy(config.policy, profile=config.policy_profile)
    if config.policy_timeout_s is not None and hasattr(policy, "reply_timeout"):
        policy.reply_timeout = config.policy_timeout_s + REMOTE_SLACK_S  # type: ignore[attr-defined]
    return policy


def make_env(spec: EpisodeSpec, config: RunConfig, *, render: bool = False,
             scenario: Scenario | None = None) -> FsvlaEnv:
    """A fresh environment for ``spec`` under ``config``, at its W and V (``scenario``: the
    already loaded ``spec.scenario_ref``)."""
    from fsvla.env import make

    key = spec.key
    return make(scenario or spec.scenario_ref, key.level, spec.layout_seed,
                embodiment=config.embodiment,
                obs_mode=config.obs_mode, control_mode=config.control_mode,
                language=key.language, vision=key.vision, language_seed=spec.language_seed,
                vision_seed=spec.vision_seed, terminate_on_violation=config.terminate_on_violation,
                cameras=config.cameras, resolution=config.resolution, shader=config.shader,
                patch=config.patch,
                render_mode="rgb_array" if render else None, lazy_images=True)


class EpisodeWorker:
    """Runs the episodes of one run, one after another (see the module doc)."""

    def __init__(self, config: RunConfig, *, on_call: CallHook | None = None) -> None:
        self.config = config
        self.on_call = on_call
        self._scenarios: dict[str, Scenario] = {}
        self._policy: Policy | None = None

    def start(self) -> None:
        """Load the policy (so a bad ``--policy`` shows before any episode) and the
        simulator (so the first episode's time is the episode's)."""
        import fsvla.env  # noqa: F401 - imports SAPIEN

        self.load_policy()

    def load_policy(self) -> None:
        if self._policy is None:
            self._policy = load_run_policy(self.config)

    def run(self, spec: EpisodeSpec) -> EpisodeOutcome:
        """Play ``spec``'s episode; its outcome, faulted or not (never raises)."""
        started = datetime.now(timezone.utc)
        clock = time.perf_counter()
        env: FsvlaEnv | None = None
        fault: Fault | None = None
        try:
            self.load_policy()
            env = make_env(spec, self.config, scenario=self._scenario(spec.scenario_ref))
            assert self._policy is not None
            play(env, self._policy, spec, timeout=self.config.policy_timeout_s,
                 on_call=self.on_call, replan_steps=self.config.replan_steps)
        except Fault as raised:
            fault = raised
        except Exception as err:  # noqa: BLE001 - building the env, loading the policy
            from fsvla.policies import PolicyLoadError

            reason = "policy_error" if isinstance(err, PolicyLoadError) else "sim_error"
            fault = Fault(reason, describe(err))
        record = None
        try:
            record = env.episode_record().to_dict() if env is not None else None
        except Exception as err:  # noqa: BLE001 - a recorder bug must not stop the run
            fault = Fault("sim_error", f"the episode's record could not be read: {describe(err)}")
        if fault is None and record is not None:
            fault = finite_prefix_fault(record)
        if fault is not None:
            self._after_fault(fault)
        outcome = EpisodeOutcome(
            failure_reason=fault.reason if fault else None,  # type: ignore[arg-type]
            failure_detail=fault.detail if fault else None,
            instruction=env.language if env is not None else None,
            perturbation=env.vision if env is not None else None,
            layout_digest=layout_digest(env.scene_spec) if env else None,
            embodiment=env.config.embodiment if env is not None else None,
            record=record, started_at=started, finished_at=datetime.now(timezone.utc),
            wall_time_s=time.perf_counter() - clock)
        if env is not None:
            env.close()
        return outcome

    def close(self) -> None:
        self._drop_policy()

    # ------------------------------------------------------------------ internals
    def _scenario(self, ref: str) -> Scenario:
        if ref not in self._scenarios:
            from fsvla.library import load_scenario

            self._scenarios[ref] = load_scenario(ref)
        return self._scenarios[ref]

    def _after_fault(self, fault: Fault) -> None:
        if fault.reason != "sim_error":
            self._drop_policy()

    def _drop_policy(self) -> None:
        policy, self._policy = self._policy, None
        close: Any = getattr(policy, "close", None)
        if callable(close):
            try:
                close()
            except Exception:  # noqa: BLE001, S110 - a broken policy's close() changes nothing
                pass


__all__ = ["EpisodeWorker", "load_run_policy", "make_env"]
