"""A Ray cluster of two nodes on this machine, started with Ray's CLI as a user starts one
(``ray start --head``, then ``ray start --address``), for the scale-out test.

Each node is one ``ray start --block`` in a session of its own: its processes (raylet,
agents, the head's GCS) share that session's process group, so ``os.killpg`` takes one
node down while the other runs on, which ``ray stop`` (every node of the machine) cannot
do. Ray's worker processes have process groups of their own and exit when their raylet
is gone. Every node has its own ``--temp-dir`` under a short folder (Ray's sockets live
there, and a socket path may not be longer than 107 bytes). The cluster asks for a token
of its own (``RAY_AUTH_MODE=token``, ``RAY_AUTH_TOKEN``; Ray versions without token
authentication ignore both), so it neither reads nor writes ``~/.ray``: :attr:`env` is
what a driver needs to join it.
"""

from __future__ import annotations

import os
import secrets
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

#: Seconds a node is given to go down after SIGTERM before it is killed.
STOP_WAIT_S = 15.0


def ray_command() -> str | None:
    """The ``ray`` command of this Python environment (or on PATH); None if missing."""
    beside = Path(sys.executable).with_name("ray")
    return str(beside) if beside.is_file() else shutil.which("ray")


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


class TwoNodeCluster:
    """A head node and a second node, ``cpus`` CPUs each; ``second_env`` is added to the
    second node's environment (its worker processes inherit it)."""

    def __init__(self, ray: str, *, cpus: int = 1, second_env: dict[str, str] | None = None,
                 ) -> None:
        self.ray = ray
        self.cpus = cpus
        self.second_env = dict(second_env or {})
        short = "/tmp" if os.path.isdir("/tmp") else None  # not a long $TMPDIR
        self.root = Path(tempfile.mkdtemp(prefix="fsvla-ray-", dir=short))
        self.port = free_port()
        self.env = {key: value for key, value in os.environ.items()
                    if not key.startswith("RAY_")}
        self.env.update(RAY_AUTH_MODE="token", RAY_AUTH_TOKEN=secrets.token_hex(32),
                        RAY_USAGE_STATS_ENABLED="0")
        self.nodes: dict[str, subprocess.Popen] = {}

    @property
    def address(self) -> str:
        return f"127.0.0.1:{self.port}"

    def __enter__(self) -> TwoNodeCluster:  # noqa: PYI034 (typing.Self needs 3.11)
        try:
            self.start()
        except BaseException:
            self.stop()
            raise
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def start(self) -> None:
        self._start("head", ["--head", f"--port={self.port}", "--include-dashboard=false"],
                    self.env)
        self._await_head()
        self._start("second", [f"--address={self.address}"], {**self.env, **self.second_env})

    def kill(self, name: str) -> None:
        """Kill node ``name`` at once (SIGKILL to its process group), as a machine that
        fails would go."""
        process = self.nodes[name]
        try:
            os.killpg(process.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        process.wait()

    def log(self, name: str) -> str:
        path = self.root / f"{name}.log"
        return path.read_text(errors="replace") if path.exists() else ""

    def stop(self) -> None:
        """Stop both nodes (SIGTERM, then SIGKILL) and remove their folders."""
        for name in ("second", "head"):
            process = self.nodes.get(name)
            if process is None or process.poll() is not None:
                continue
            try:
                os.killpg(process.pid, signal.SIGTERM)
                process.wait(STOP_WAIT_S)
            except subprocess.TimeoutExpired:
                self.kill(name)
            except ProcessLookupError:
                pass
        shutil.rmtree(self.root, ignore_errors=True)

    # ------------------------------------------------------------------ internals
    def _start(self, name: str, options: list[str], env: dict[str, str]) -> None:
        command = [self.ray, "start", *options, "--block", "--node-ip-address=127.0.0.1",
                   f"--num-cpus={self.cpus}", "--num-gpus=0", "--disable-usage-stats",
                   f"--dashboard-agent-listen-port={free_port()}",
                   f"--temp-dir={self.root / name}"]
        with open(self.root / f"{name}.log", "wb") as log:
            self.nodes[name] = subprocess.Popen(command, env=env, stdout=log,
                                                stderr=subprocess.STDOUT, start_new_session=True)

    def _await_head(self, timeout: float = 60.0) -> None:
        """Until the head's GCS takes connections."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if self.nodes["head"].poll() is not None:
                raise RuntimeError(f"the Ray head node exited:\n{self.log('head')[-3000:]}")
            try:
                socket.create_connection(("127.0.0.1", self.port), timeout=1).close()
                return
            except OSError:
                time.sleep(0.2)
        raise RuntimeError(f"the Ray head node did not start in {timeout:.0f} s:\n"
                           f"{self.log('head')[-3000:]}")
