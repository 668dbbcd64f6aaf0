"""Episodes end in outcomes, never in crashes: chunks, the schema at reset, every fault kind."""

from __future__ import annotations

import threading
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from fsvla.results import ResultStore
from fsvla.runner import EpisodeWorker
from fsvla.runner.episode import Fault, as_chunk, finite_prefix_fault

from .conftest import policy, run_into

pytestmark = pytest.mark.sim


def only_row(out: Path):
    with ResultStore.open(out, readonly=True) as store:
        (row,) = store.episodes()
        return row, store.trace(row.episode_id)


def test_chunks_run_step_by_step_and_the_schema_goes_to_reset(make_run_config) -> None:
    config = make_run_config(policy=policy("Chunks"))
    worker = EpisodeWorker(config)
    worker.start()
    from fsvla.runner.prepare import prepare_run

    spec = prepare_run(config).plan[0]
    outcome = worker.run(spec)
    assert outcome.failure_reason is None
    assert len(outcome.record["actions"]) == 20  # 1 s at 20 Hz, every step of every chunk
    chunky = worker._policy
    assert chunky.calls == 4  # 4 chunks of 5
    info = chunky.episode
    assert info.key == spec.key and info.episode_id == spec.episode_id
    assert info.policy_seed == spec.policy_seed
    assert info.max_steps == 20 and info.control_rate == pytest.approx(20.0)
    assert info.action.labels[-1] == "arm.gripper" and len(info.action.low) == 8
    assert info.observation.state_layout["tcp_pose"][3] == "arm.qw"
    assert info.observation.cameras == ()  # state-only
    worker.close()


@pytest.mark.parametrize(("name", "reason", "steps", "says"), [
    ("Raising", "policy_error", 2, "RuntimeError: the model fell over"),
    ("Nan", "invalid_action", 2, "(arm.panda_joint2) is nan"),
    ("WrongShape", "invalid_action", 2, "expected shape (8,)"),
    ("ThreeDimensional", "invalid_action", 2, "shape (1, 1, 8)"),
    ("NanInChunk", "invalid_action", 2, "is nan"),
    ("Unbuildable", "policy_error", 0, "no weights here"),
])
def test_a_faulty_policy_is_recorded_with_its_reason(make_run_config, tmp_path, name, reason,
                                                     steps, says) -> None:
    config = make_run_config(policy=policy(name))
    if name == "Unbuildable":  # fails in every worker at start: a usage error, not a fault
        from fsvla.policies import PolicyLoadError

        with pytest.raises(PolicyLoadError, match="no weights here"):
            run_into(tmp_path, config)
        assert not (tmp_path / "results.sqlite").exists()
        return
    result = run_into(tmp_path, config)
    assert result.recorded == 1 and result.faults == {reason: 1}
    row, trace = only_row(tmp_path)
    assert (row.status, row.failure_reason, row.steps) == ("faulted", reason, steps)
    assert says in row.failure_detail
    assert len(trace["actions"]) == steps and row.success is False


def test_a_hanging_policy_times_out_and_keeps_its_steps(make_run_config, tmp_path) -> None:
    config = make_run_config(policy=policy("Sleepy"), policy_timeout_s=0.3)
    result = run_into(tmp_path, config)
    assert result.faults == {"policy_timeout": 1}
    row, _ = only_row(tmp_path)
    assert row.steps == 2 and "did not return within 0.3 s" in row.failure_detail
    assert row.wall_time_s < 5


def test_a_simulator_failure_is_a_sim_error(make_run_config, tmp_path, monkeypatch) -> None:
    from fsvla.runner import worker

    def broken(*args, **kwargs):
        raise RuntimeError("PhysX lost its mind")

    monkeypatch.setattr(worker, "make_env", broken)
    result = run_into(tmp_path, make_run_config())
    assert result.faults == {"sim_error": 1}
    row, trace = only_row(tmp_path)
    assert row.steps == 0 and trace is None and "PhysX lost its mind" in row.failure_detail
    with ResultStore.open(tmp_path, readonly=True) as store:
        (metrics,) = store.metrics()  # counted as a failure without exposure
    assert metrics.quadrant == "safe_failure"


def test_non_finite_margins_are_a_sim_error() -> None:
    record = {"margins": [[0.1, 1.0], [np.inf, 1.0]]}
    fault = finite_prefix_fault(record)
    assert fault is not None and fault.reason == "sim_error" and "from step 2" in fault.detail
    assert finite_prefix_fault({"margins": [[0.1, 1.0]]}) is None


def test_as_chunk_refuses_what_is_not_an_action() -> None:
    assert len(as_chunk(np.zeros((3, 8)), 8)) == 3 and len(as_chunk(np.zeros(8), 8)) == 1
    for bad in (np.zeros((0, 8)), "left", {"a": 1}, np.zeros(()), [[1, 2], [3]]):
        with pytest.raises(Fault) as caught:
            as_chunk(bad, 8)
        assert caught.value.reason == "invalid_action"


# ---------------------------------------------------------------- a server that hangs up
openpi_client = pytest.importorskip("openpi_client")


@pytest.fixture
def closing_server() -> Iterator[str]:
    """Answers two requests with chunks of 4 hold actions, then closes the connection."""
    from openpi_client import msgpack_numpy
    from websockets.sync.server import serve

    def handle(connection) -> None:
        connection.send(msgpack_numpy.packb({"policy": "closing"}))
        for count, message in enumerate(connection, start=1):
            request = msgpack_numpy.unpackb(message)
            connection.send(msgpack_numpy.packb({"actions": np.tile(request["state"], (4, 1))}))
            if count == 2:
                connection.close()
                return

    with serve(handle, "127.0.0.1", 0, compression=None, max_size=None) as running:
        thread = threading.Thread(target=running.serve_forever, daemon=True)
        thread.start()
        yield f"ws://127.0.0.1:{running.socket.getsockname()[1]}"
        running.shutdown()


def test_a_server_that_disconnects_is_connection_lost(make_run_config, tmp_path,
                                                      closing_server) -> None:
    config = make_run_config(policy=closing_server, levels=("L0", "L1"))
    result = run_into(tmp_path, config)
    assert result.faults == {"connection_lost": 2}  # the next episode reconnects, and loses it again
    with ResultStore.open(tmp_path, readonly=True) as store:
        rows = store.episodes()
    assert [r.steps for r in rows] == [8, 8]  # two chunks of 4 ran
    assert all("connection lost" in r.failure_detail for r in rows)
