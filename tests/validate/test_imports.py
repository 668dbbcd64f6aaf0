"""Registering `fsvla validate` and `check --deep` keeps `fsvla check` cheap: it imports
neither numpy nor SAPIEN (the static checks load them only with --deep)."""

from __future__ import annotations

import subprocess
import sys

from fsvla.resources import scenarios_dir

PROBE = """
import sys
from fsvla.cli import run
code = run(["check", sys.argv[1], "--format", "concise"])
print(code, *(name in sys.modules for name in ("numpy", "sapien", "fsvla.validate.static")))
"""


def test_check_without_deep_imports_no_numpy_nor_sapien() -> None:
    done = subprocess.run([sys.executable, "-c", PROBE, str(scenarios_dir())], capture_output=True,
                          text=True, check=True)
    assert done.stdout.split()[-4:] == ["0", "False", "False", "False"]
