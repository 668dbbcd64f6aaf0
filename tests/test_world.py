"""The simulator seam (``fsvla.world``): its consumers (the monitor, the experts, the visual
variation) name no simulator, and the SAPIEN back-end (``fsvla.sim``) has every member of
every protocol, with the same parameters."""

from __future__ import annotations

import dataclasses
import inspect
import re
import subprocess
import sys
from pathlib import Path

import pytest

from fsvla import world
from fsvla.sim.appearance import SapienAppearance, SapienCamera, SapienLight, SapienMaterial
from fsvla.sim.builder import BuiltScene
from fsvla.sim.kinematics import ArmKinematics
from fsvla.sim.probe import Probe

FSVLA = Path(__file__).resolve().parents[1] / "fsvla"
#: What reads or changes the world through the seam, and must not name a simulator.
CONSUMERS = ("world.py", "monitor", "experts", "variation")
SIMULATOR = re.compile(r"^\s*(import|from)\s+sapien\b|\bsapien\.", re.MULTILINE)

BACK_END = [
    (world.MonitoredScene, BuiltScene),
    (world.StepProbe, Probe),
    (world.SceneState, BuiltScene),
    (world.ArmModel, ArmKinematics),
    (world.SceneAppearance, SapienAppearance),
    (world.Light, SapienLight),
    (world.Material, SapienMaterial),
    (world.Camera, SapienCamera),
]


def _sources(part: str) -> list[Path]:
    path = FSVLA / part
    return [path] if path.is_file() else sorted(path.rglob("*.py"))


@pytest.mark.parametrize("part", CONSUMERS)
def test_consumers_do_not_name_a_simulator(part: str) -> None:
    for path in _sources(part):
        assert not SIMULATOR.search(path.read_text(encoding="utf-8")), path


def test_importing_the_consumers_loads_no_simulator() -> None:
    code = ("import sys, fsvla.world, fsvla.monitor, fsvla.experts, fsvla.experts.world, "
            "fsvla.variation.apply; "
            "print(sorted(m for m in ('sapien', 'fsvla.sim') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def _members(protocol: type) -> dict[str, object]:
    members = {name: value for name, value in vars(protocol).items() if not name.startswith("_")}
    return {**dict.fromkeys(vars(protocol).get("__annotations__", {})), **members}


@pytest.mark.parametrize(("protocol", "implementation"), BACK_END,
                         ids=[p.__name__ for p, _ in BACK_END])
def test_the_sapien_back_end_implements_the_protocols(protocol: type, implementation: type) -> None:
    fields = {f.name for f in dataclasses.fields(implementation)} \
        if dataclasses.is_dataclass(implementation) else set()
    for name, member in _members(protocol).items():
        if name in fields:
            continue
        if not hasattr(implementation, name):  # an attribute its constructor sets
            init = inspect.getsource(implementation.__init__)
            assert re.search(rf"self\.{name}\s*[:=]", init), f"{implementation.__name__}.{name}"
            continue
        if inspect.isfunction(member):
            ours = list(inspect.signature(getattr(implementation, name)).parameters)
            assert ours == list(inspect.signature(member).parameters), f"{implementation.__name__}.{name}"
