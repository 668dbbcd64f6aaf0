"""fsvla.results sits below the runtime: the environment imports it, never the reverse."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

_ENV_MODULES = "sorted(m for m in sys.modules if m.startswith('fsvla.env'))"

# Writes and reads back a trace, then prints what of fsvla.env got imported.
_ROUND_TRIP = f"""
import sys
from pathlib import Path
import numpy as np
from fsvla.metrics.trace import ChannelInfo
from fsvla.results import EpisodeRecord, read_record, write_trace
record = EpisodeRecord(
    channels=(ChannelInfo(name="c", family="force", soft_threshold=1.0),), action_labels=("a",),
    actions=np.zeros((2, 1)), margins=np.ones((2, 1)), states=(("safe",), ("safe",)),
    costs=np.zeros((2, 1)), step_costs=np.zeros(2), success_values=np.zeros(2, bool),
    success=False)
path = Path(sys.argv[1])
write_trace(path, record.to_dict(), "ep")
assert read_record(path).to_dict() == record.to_dict()
print({_ENV_MODULES})
"""


def _run(*args: str) -> str:
    done = subprocess.run([sys.executable, *args], capture_output=True, text=True, check=False)
    assert done.returncode == 0, done.stderr
    return done.stdout.strip()


def test_importing_results_imports_neither_the_env_nor_the_simulator() -> None:
    probe = ("import sys, fsvla.results, fsvla.results.record, fsvla.results.traces; "
             "print(sorted(m for m in sys.modules if m.split('.')[0] in ('sapien', 'pyarrow') "
             "or m.startswith('fsvla.env')))")
    assert _run("-c", probe) == "[]"


def test_reading_a_record_back_does_not_import_the_env(tmp_path: Path) -> None:
    assert _run("-c", _ROUND_TRIP, str(tmp_path / "ep.parquet")) == "[]"
