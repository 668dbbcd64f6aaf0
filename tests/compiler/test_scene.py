"""SceneSpec and lowering of a scenario's canonical layout (L0)."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from fsvla.compiler.assets import build_asset
from fsvla.compiler.placement import CycleError, Rect, placed_rect, support_order
from fsvla.compiler.scene import (
    SCENE_SCHEMA_VERSION,
    LoweringError,
    PhysicsSpec,
    SceneSpec,
    lower_scene,
    scene_json_schema,
)
from fsvla.dsl.loader import ScenarioLoader
from fsvla.dsl.models import Scenario

REPO = Path(__file__).resolve().parents[2]
SCENARIOS = REPO / "scenarios"
FILES = sorted(SCENARIOS.rglob("*.fsv"))

def _load_file(path: Path) -> Scenario | None:
    result = ScenarioLoader(allowed_roots=[SCENARIOS]).load(path)
    assert result.ok, [d.message for d in result.errors]
    return result.scenario


def _loads(text: str, tmp_path: Path, name: str = "case.fsv") -> Scenario:
    result = ScenarioLoader(allowed_roots=[tmp_path]).loads(text, name=name)
    assert result.ok, [f"{d.span}: {d.message}" for d in result.errors]
    assert result.scenario is not None
    return result.scenario


def _header(name: str) -> str:
    return (
        f"scenario {name}\n"
        "  suite force\n"
        "  task pick_place(object=block, target=shelf)\n"
        "  embodiment panda\n"
        '  instruction "Put the block on the shelf."\n'
        "  horizon 20 s\n"
    )


def _footer() -> str:
    return "  success on(block, shelf) for 1 s\n"


def _close(a, b, tol=1e-9) -> bool:
    return all(abs(x - y) <= tol for x, y in zip(a, b, strict=True))


# --- every built-in scenario ------------------------------------------------------------------


@pytest.mark.parametrize("path", FILES, ids=[str(p.relative_to(SCENARIOS)) for p in FILES])
def test_builtin_scenarios_lower(path: Path) -> None:
    scenario = _load_file(path)
    if scenario is None:
        pytest.skip(f"{path.name} is abstract")
    spec = lower_scene(scenario)
    assert spec.scenario == scenario.name
    assert spec.level == "L0" and spec.seed == 0
    assert [b.name for b in spec.bodies] == [o.name for o in scenario.objects]
    assert [z.name for z in spec.zones] == [z.name for z in scenario.zones]
    assert spec.embodiment.name == scenario.embodiment
    assert {m.robot for m in spec.mounts} == {r.name for r in spec.embodiment.robots}
    assert {c.name for c in spec.cameras} == {c.name for c in spec.embodiment.cameras}
    # World = table frame: the table's top surface is z = 0, the floor below it.
    table = spec.body("table")
    assert table.is_static
    assert math.isclose(table.pose.position[2], spec.ground_z)
    assert math.isclose(-spec.ground_z, float(scenario.object("table").params["height"]))
    for body in spec.bodies:
        if body.support == "table":
            assert math.isclose(body.pose.position[2], 0.0, abs_tol=1e-12), body.name
    assert SceneSpec.model_validate_json(spec.model_dump_json()) == spec


# --- hand-checked poses ------------------------------------------------------------------------


STACK = (
    _header("stack")
    + "  object table: table(size=(1 m, 60 cm), height=70 cm)\n"
    + "  object shelf: shelf(size=(30 cm, 20 cm), height=15 cm) at (10 cm, 5 cm)\n"
    + "  object tray: tray(size=(20 cm, 15 cm), height=2 cm) at (2 cm, -1 cm) on shelf\n"
    + "  object block: block(size=(4 cm, 4 cm, 4 cm)) at (1 cm, 2 cm) on tray yaw 30 deg\n"
    + _footer()
)


def test_stacked_poses_are_exact(tmp_path: Path) -> None:
    spec = lower_scene(_loads(STACK, tmp_path))
    assert spec.ground_z == pytest.approx(-0.70)
    assert _close(spec.body("table").pose.position, (0.0, 0.0, -0.70))
    # shelf on the table top (z = 0)
    assert _close(spec.body("shelf").pose.position, (0.10, 0.05, 0.0))
    # tray on the shelf's top slab: z = 0.15
    tray = spec.body("tray")
    assert _close(tray.pose.position, (0.12, 0.04, 0.15))
    assert tray.support == "shelf"
    # block on the tray's floor: the tray's support_height above 0.15
    tray_top = tray.asset.support_height
    assert tray_top is not None and 0.0 < tray_top <= 0.02 + 1e-12
    block = spec.body("block")
    assert _close(block.pose.position, (0.13, 0.06, 0.15 + tray_top))
    half = math.radians(30) / 2
    assert _close(block.pose.quaternion, (math.cos(half), 0.0, 0.0, math.sin(half)))
    assert not block.is_static and spec.body("shelf").is_static


ROTATED = (
    _header("rotated")
    + "  object shelf: shelf(size=(40 cm, 30 cm), height=20 cm) at (10 cm, 0) yaw 90 deg\n"
    + "  object block: block(size=(4 cm, 4 cm, 4 cm)) at (10 cm, 5 cm) on shelf yaw 10 deg\n"
    + "  hazard hot: heat_zone(radius=3 cm) at (-10 cm, 0) on shelf\n"
    + _footer()
)


def test_yaw_of_support_rotates_what_stands_on_it(tmp_path: Path) -> None:
    spec = lower_scene(_loads(ROTATED, tmp_path))
    # (0.10, 0.05) in the shelf's frame, rotated by 90 deg: (-0.05, 0.10); plus the shelf's xy.
    block = spec.body("block")
    assert _close(block.pose.position, (0.10 - 0.05, 0.10, 0.20))
    yaw = math.radians(100)
    assert _close(block.pose.quaternion, (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)))
    zone = spec.zone("hot")
    assert _close(zone.pose.position, (0.10, -0.10, 0.20))
    assert zone.support == "shelf"
    assert zone.region_bounds.min[0] == pytest.approx(0.07)
    assert zone.region_bounds.max[1] == pytest.approx(-0.07)
    assert zone.region_bounds.min[2] == pytest.approx(0.20)


# --- serialisation and schema ----------------------------------------------------------------


def test_json_round_trip(tmp_path: Path) -> None:
    spec = lower_scene(_loads(ROTATED, tmp_path), seed=7)
    text = spec.model_dump_json()
    again = SceneSpec.model_validate_json(text)
    assert again == spec
    assert again.seed == 7 and again.schema_version == SCENE_SCHEMA_VERSION


def test_schema() -> None:
    schema = scene_json_schema()
    assert schema["$id"] == f"urn:fsvla:schema:scene:{SCENE_SCHEMA_VERSION}"
    assert schema["type"] == "object"
    for key in ("bodies", "zones", "embodiment", "mounts", "cameras", "lights", "physics"):
        assert key in schema["properties"]
    for name in ("SceneBody", "SceneZone", "RigidAsset", "ArticulatedAsset", "ZoneAsset",
                 "EmbodimentSpec", "PhysicsSpec"):
        assert name in schema["$defs"]
    assert schema["additionalProperties"] is False


def test_physics_defaults() -> None:
    physics = PhysicsSpec()
    assert physics.timestep == 0.002 and physics.control_rate == 20.0
    assert physics.substeps == 25
    assert physics.gravity == (0.0, 0.0, -9.81)
    with pytest.raises(ValueError, match="whole number"):
        PhysicsSpec(timestep=0.003, control_rate=20.0)


def test_lights_and_cameras(tmp_path: Path) -> None:
    spec = lower_scene(_loads(ROTATED, tmp_path))
    assert {light.type for light in spec.lights} == {"ambient", "directional"}
    wrist = [c for c in spec.cameras if c.parent != "world"]
    for cam in wrist:
        assert cam.link is not None
    assert all(abs(sum(q * q for q in c.pose.quaternion) - 1.0) < 1e-9 for c in spec.cameras)


# --- static checks ----------------------------------------------------------------------------


def test_overlap_names_the_line(tmp_path: Path) -> None:
    text = (
        _header("overlap")
        + "  object shelf: shelf(size=(40 cm, 25 cm), height=18 cm) at (15 cm, 25 cm)\n"
        + "  object block: block(size=(4 cm, 4 cm, 4 cm)) at (20 cm, 20 cm)\n"
        + _footer()
    )
    scenario = _loads(text, tmp_path, name="overlap.fsv")
    with pytest.raises(LoweringError) as err:
        lower_scene(scenario)
    assert err.value.source.file.endswith("overlap.fsv")
    assert err.value.source.line == 8  # the block, written after the shelf
    assert "overlap.fsv:8:" in str(err.value)
    assert "'shelf'" in str(err.value) and "'block'" in str(err.value)


def test_touching_footprints_are_fine(tmp_path: Path) -> None:
    text = (
        _header("touch")
        + "  object shelf: shelf(size=(40 cm, 25 cm), height=18 cm) at (15 cm, 25 cm)\n"
        + "  object block: block(size=(4 cm, 4 cm, 4 cm)) at (37 cm, 25 cm)\n"
        + _footer()
    )
    lower_scene(_loads(text, tmp_path))


def test_overlap_after_yaw(tmp_path: Path) -> None:
    # 30 x 4 cm boards 20 cm apart overlap only once one is turned by 90 deg.
    text = (
        _header("yawed")
        + "  object shelf: shelf(size=(40 cm, 25 cm), height=18 cm) at (15 cm, 25 cm)\n"
        + "  object block: block(size=(4 cm, 4 cm, 4 cm)) at (0, -20 cm)\n"
        + "  object a: cutting_board(size=(30 cm, 4 cm)) at (-20 cm, -10 cm)\n"
        + "  object b: cutting_board(size=(30 cm, 4 cm)) at (-20 cm, 5 cm) yaw {yaw}\n"
        + _footer()
    )
    lower_scene(_loads(text.format(yaw="0 deg"), tmp_path))
    with pytest.raises(LoweringError, match="'b' overlaps object 'a'") as err:
        lower_scene(_loads(text.format(yaw="90 deg"), tmp_path, name="yawed.fsv"))
    assert err.value.source.line == 10


def test_overhang_names_the_line(tmp_path: Path) -> None:
    text = (
        _header("overhang")
        + "  object shelf: shelf(size=(40 cm, 25 cm), height=18 cm) at (15 cm, 25 cm)\n"
        + "  object block: block(size=(4 cm, 4 cm, 4 cm)) at (21 cm, 0) on shelf\n"
        + _footer()
    )
    with pytest.raises(LoweringError, match="overhangs the top of 'shelf'") as err:
        lower_scene(_loads(text, tmp_path, name="overhang.fsv"))
    assert "overhang.fsv:8:" in str(err.value)
    # Sticking out by less than half its size is allowed (it still stands).
    lower_scene(_loads(text.replace("(21 cm, 0)", "(19 cm, 0)"), tmp_path))


# --- every problem, each at its line ----------------------------------------------------------


TWO_PROBLEMS = (
    _header("two")
    + "  object shelf: shelf(size=(40 cm, 25 cm), height=18 cm) at (15 cm, 25 cm)\n"
    + "  object block: block(size=(4 cm, 4 cm, 4 cm)) at (20 cm, 20 cm)\n"
    + "  object box: block(size=(4 cm, 4 cm, 4 cm)) at (21 cm, 0) on shelf\n"
    + _footer()
)


def _failing(kind: str, error: Exception):
    """``build_asset``, except that assets of ``kind`` raise ``error``."""

    def builder(asset: str, params: dict, **kwargs):
        if asset == kind:
            raise error
        return build_asset(asset, params, **kwargs)

    return builder


def test_two_independent_problems_are_both_reported(tmp_path: Path) -> None:
    with pytest.raises(LoweringError) as err:
        lower_scene(_loads(TWO_PROBLEMS, tmp_path, name="two.fsv"))
    problems = err.value.problems
    assert [(p.source.line, p.source.column) for p in problems] == [(8, 10), (9, 10)]
    assert "'block' overlaps object 'shelf'" in problems[0].message
    assert "'box' overhangs the top of 'shelf'" in problems[1].message
    assert (err.value.message, err.value.source) == (problems[0].message, problems[0].source)
    lines = str(err.value).splitlines()
    assert len(lines) == 2 and lines[0].startswith("two.fsv:8:10: ") and lines[1].startswith("two.fsv:9:10: ")


def test_problems_of_every_stage_are_collected(tmp_path: Path) -> None:
    """A support that is a zone (support order), an asset that cannot be built (assets) and
    an unknown embodiment, in one scenario: three problems, in the order they were written;
    what stands on the broken object is skipped rather than reported again."""
    scenario = _loads(ROTATED, tmp_path, name="stages.fsv")
    block = scenario.object("block")
    scenario = scenario.model_copy(update={
        "embodiment": "no_such_robot",
        "objects": tuple(o.model_copy(update={"placement": o.placement.model_copy(update={"support": "hot"})})
                         if o.name == "block" else o for o in scenario.objects)})

    with pytest.raises(LoweringError) as err:
        lower_scene(scenario, asset_builder=_failing("shelf", ValueError("no shelf today")))
    messages = [(p.source.line, p.message.split(":")[0]) for p in err.value.problems]
    assert messages == [(1, "cannot load embodiment 'no_such_robot'"),
                        (7, "object 'shelf'"),
                        (block.source.line, "object 'block' stands on 'hot', which is not an object")]
    assert err.value.problems[2].hint == "zones are not surfaces"


def test_a_support_cycle_does_not_hide_other_problems(tmp_path: Path) -> None:
    scenario = _loads(STACK, tmp_path)
    shelf = scenario.object("shelf")
    on_block = shelf.placement.model_copy(update={"support": "block"})
    objects = tuple(o.model_copy(update={"placement": on_block}) if o.name == "shelf" else o
                    for o in scenario.objects)
    with pytest.raises(LoweringError) as err:
        lower_scene(scenario.model_copy(update={"objects": objects}),
                    asset_builder=_failing("table", OSError("gone")))
    assert [p.message.split(":")[0] for p in err.value.problems] == [
        "object 'table'", "objects support each other in a cycle"]


# --- placement helpers --------------------------------------------------------------------------


def test_placed_rect_yaw() -> None:
    rect = placed_rect((-0.1, -0.02), (0.1, 0.02), (1.0, 2.0), math.pi / 2)
    assert _close(rect.min_xy, (0.98, 1.9)) and _close(rect.max_xy, (1.02, 2.1))
    assert Rect((0, 0), (1, 1)).overhang(Rect((0.5, 0), (2, 1))) == (0.5, 0.0)


def test_support_order_and_cycles() -> None:
    order = support_order({"b": "a", "a": "table", "table": "world", "c": "table"})
    assert order.index("table") < order.index("a") < order.index("b")
    with pytest.raises(CycleError):
        support_order({"a": "b", "b": "a"})


def test_no_simulator_import() -> None:
    import subprocess
    import sys

    code = ("import sys, fsvla.compiler.scene, fsvla.compiler.placement; "
            "bad = [m for m in sys.modules if m.split('.')[0] == 'sapien']; "
            "assert not bad, bad; assert 'fsvla.sim' not in sys.modules")
    subprocess.run([sys.executable, "-c", code], check=True)
