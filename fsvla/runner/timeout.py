"""A time limit on one policy call: what turns a hanging ``act()`` into ``policy_timeout``.

In a process's main thread (every worker process, and ``--workers 0``) the limit is a
``SIGALRM`` timer whose handler raises inside the call, so a policy that sleeps, loops in
Python or waits on a socket is interrupted where it stands and the episode keeps the
steps that ran. Elsewhere (a thread that is not the main one, e.g. some Ray actors) the
call runs in a helper thread that is abandoned when it overruns. A policy stuck in C code
that ignores signals is beyond both: the process pool kills its worker
(:mod:`fsvla.runner.pool`).
"""

from __future__ import annotations

import signal
import threading
from collections.abc import Callable
from typing import Any, TypeVar

from fsvla.policies.remote import PolicyTimeout

T = TypeVar("T")


class _Expired(BaseException):
    """Raised by the alarm inside the call; a BaseException so that a policy's own
    ``except Exception`` does not swallow it."""


def call_with_timeout(call: Callable[[Any], T], argument: Any, timeout: float | None,
                      what: str = "act()") -> T:
    """``call(argument)``, or :class:`PolicyTimeout` when it runs longer than ``timeout`` s."""
    if timeout is None:
        return call(argument)
    if threading.current_thread() is threading.main_thread() and hasattr(signal, "setitimer"):
        return _with_alarm(call, argument, timeout, what)
    return _with_thread(call, argument, timeout, what)


def _with_alarm(call: Callable[[Any], T], argument: Any, timeout: float, what: str) -> T:
    armed = [True]

    def expire(_signum: int, _frame: object) -> None:
        if armed[0]:
            raise _Expired

    previous = signal.signal(signal.SIGALRM, expire)
    try:
        signal.setitimer(signal.ITIMER_REAL, timeout)
        try:
            return call(argument)
        finally:
            signal.setitimer(signal.ITIMER_REAL, 0)
            armed[0] = False
    except _Expired:
        raise PolicyTimeout(f"{what} did not return within {timeout:g} s "
                            "(the run's policy timeout)") from None
    finally:
        signal.signal(signal.SIGALRM, previous)


def _with_thread(call: Callable[[Any], T], argument: Any, timeout: float, what: str) -> T:
    box: dict[str, Any] = {}

    def target() -> None:
        try:
            box["value"] = call(argument)
        except BaseException as err:  # noqa: BLE001 - handed to the caller below
            box["error"] = err

    thread = threading.Thread(target=target, name="fsvla-policy-call", daemon=True)
    thread.start()
    thread.join(timeout)
    if thread.is_alive():
        raise PolicyTimeout(f"{what} did not return within {timeout:g} s (the run's policy "
                            "timeout; the call was abandoned)")
    if "error" in box:
        raise box["error"]
    return box["value"]


__all__ = ["call_with_timeout"]
