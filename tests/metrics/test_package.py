"""fsvla.metrics stays cheap: numpy and pydantic only, never the simulator or geometry."""

import subprocess
import sys

import fsvla.metrics


def test_import_pulls_in_no_simulator_or_geometry():
    probe = (
        "import sys, fsvla.metrics; "
        "print(sorted(m for m in ('sapien', 'fcl', 'trimesh', 'scipy', 'gymnasium') "
        "if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_public_names_resolve():
    assert all(hasattr(fsvla.metrics, name) for name in fsvla.metrics.__all__)
    assert {"EpisodeTrace", "episode_metrics", "aggregate", "breakdown",
            "CC_NORMALISATION"} <= set(fsvla.metrics.__all__)
