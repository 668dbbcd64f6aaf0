"""The Ray backend's handling of lost workers, against a stand-in for Ray (fast, no Ray
needed): a lost episode runs again, once per loss up to ``max_retries``, then is recorded
as ``sim_error``; a replacement gets episodes only once it has started; a cluster left
without any worker stops the run instead of hanging it. The real thing, a node killed on a
two-node cluster, is test_ray_cluster.py."""

from __future__ import annotations

from dataclasses import dataclass
from datetime import datetime, timezone
from typing import Any

import pytest

from fsvla.results.models import EpisodeOutcome
from fsvla.runner.backend import BackendError
from fsvla.runner.ray_backend import RayBackend


class RayActorError(Exception):
    pass


class StandInRay:
    """What RayBackend.run calls of ``ray``: ``wait``, ``get``, ``kill``, ``exceptions``.
    ``lose(actor, episode_id)`` says whether that call is lost; actors numbered from
    ``placeable`` on never start (the cluster has no room for them)."""

    class exceptions:  # as in ray.exceptions
        RayError = Exception

    def __init__(self, lose, placeable: int = 99) -> None:
        self.lose = lose
        self.placeable = placeable
        self.actors: list[Actor] = []
        self.killed: list[int] = []

    def new_actor(self) -> Actor:
        actor = Actor(self, len(self.actors))
        self.actors.append(actor)
        return actor

    def wait(self, refs: list[Ref], num_returns: int, timeout: float | None = None):
        done = [ref for ref in refs if ref.done]
        if not done and timeout is None:
            raise AssertionError("would wait for ever")
        return done[:num_returns], [ref for ref in refs if ref not in done[:num_returns]]

    def get(self, ref: Ref) -> Any:
        if isinstance(ref.value, Exception):
            raise ref.value
        return ref.value

    def kill(self, actor: Actor) -> None:
        self.killed.append(actor.number)


@dataclass(eq=False)
class Ref:
    value: Any
    done: bool = True


class Method:
    def __init__(self, call) -> None:
        self.remote = call


class Actor:
    def __init__(self, ray: StandInRay, number: int) -> None:
        self.number = number
        placed = number < ray.placeable
        self.ready = Method(lambda: Ref(("ready", number), done=placed))
        self.run = Method(lambda spec: Ref(RayActorError(f"actor {number} died")
                                           if ray.lose(number, spec.episode_id)
                                           else played(spec, number)))


@dataclass(frozen=True)
class Spec:
    episode_id: str


def played(spec: Spec, actor: int) -> EpisodeOutcome:
    now = datetime.now(timezone.utc)
    return EpisodeOutcome(failure_reason="policy_error", failure_detail=f"{spec.episode_id} on "
                          f"{actor}", started_at=now, finished_at=now, wall_time_s=0.0)


def backend_on(ray: StandInRay, workers: int, **options: Any) -> RayBackend:
    """A RayBackend past start(), its actors and Ray stood in for."""
    backend = RayBackend(None, workers, **options)  # type: ignore[arg-type]
    backend._ray, backend._lost = ray, (RayActorError,)
    backend._new_actor = ray.new_actor  # type: ignore[method-assign]
    backend._actors = [ray.new_actor() for _ in range(workers)]
    return backend


SPECS = [Spec(f"e{i}") for i in range(5)]


def test_a_lost_episode_runs_again_on_another_actor() -> None:
    ray = StandInRay(lambda actor, episode: actor == 1)  # actor 1 dies at once
    backend = backend_on(ray, 2, max_retries=2)
    finished = list(backend.run(SPECS))
    assert sorted(spec.episode_id for spec, _ in finished) == [s.episode_id for s in SPECS]
    assert all(outcome.failure_reason == "policy_error" for _, outcome in finished)
    lost = [(r.episode_id, r.attempt) for r in backend.reruns]
    assert len(lost) >= 1 and all(attempt <= 2 for _, attempt in lost)
    assert 1 in ray.killed  # the lost actor is killed and replaced
    assert "1" not in {outcome.failure_detail.split(" on ")[1] for _, outcome in finished}


def test_an_episode_lost_past_its_retries_is_a_sim_error() -> None:
    ray = StandInRay(lambda actor, episode: episode == "e0")
    backend = backend_on(ray, 1, max_retries=2)
    finished = {spec.episode_id: outcome for spec, outcome in backend.run(SPECS[:2])}
    assert finished["e1"].failure_reason == "policy_error"
    lost = finished["e0"]
    assert lost.failure_reason == "sim_error" and "lost 3 times" in lost.failure_detail
    assert "attempt 3: RayActorError: actor 2 died" in lost.failure_detail
    assert [(r.episode_id, r.attempt) for r in backend.reruns] == [("e0", 1), ("e0", 2)]


def test_a_replacement_that_cannot_be_placed_leaves_the_run_to_the_others() -> None:
    ray = StandInRay(lambda actor, episode: actor == 1 and episode == "e0", placeable=2)
    backend = backend_on(ray, 2)
    assert len(list(backend.run(SPECS))) == len(SPECS)


def test_no_worker_left_stops_the_run() -> None:
    ray = StandInRay(lambda actor, episode: actor == 0, placeable=1)
    backend = backend_on(ray, 1, placement_timeout_s=0.01)
    with pytest.raises(BackendError, match="no replacement was placed in 0 s"):
        list(backend.run(SPECS))


@pytest.mark.parametrize(("option", "value"), [("max_retries", -1),
                                               ("placement_timeout_s", 0.0)])
def test_bad_retry_settings_are_refused(option: str, value: float) -> None:
    with pytest.raises(ValueError, match=f"Expect `{option}`"):
        RayBackend(None, 1, **{option: value})  # type: ignore[arg-type]
