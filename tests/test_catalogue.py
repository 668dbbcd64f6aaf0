"""The scenario catalogue (fsvla.catalogue): docs/scenarios.md is current (CI regenerates
it from the scenarios, scenarios/sets.toml and the recorded rates, and compares), every
scenario has its thumbnail, and the rows and rates read as the verdicts say."""

from __future__ import annotations

from pathlib import Path

from fsvla.dsl.loader import ScenarioLoader

from fsvla.catalogue import (
    REGENERATE,
    ValidateRecord,
    ValidateRun,
    builtin_scenarios_checked,
    catalogue_page,
    catalogue_rows,
    findings,
    load_record,
    render_markdown,
)
from fsvla.resources import scenarios_dir

DOCS = Path(__file__).resolve().parents[1] / "docs"
PAGE = DOCS / "scenarios.md"
RECORD = DOCS / "scenarios" / "validate.json"


def test_the_checked_in_catalogue_is_current() -> None:
    expected = catalogue_page(load_record(RECORD))
    current = PAGE.read_text(encoding="utf-8") if PAGE.is_file() else ""
    assert current == expected, (
        f"{PAGE.relative_to(DOCS.parent)} is not current for the scenarios, "
        f"scenarios/sets.toml and {RECORD.relative_to(DOCS.parent)}: run `{REGENERATE}` "
        "(and `--thumbs` for new scenarios) and commit the result")


def test_every_scenario_has_a_thumbnail() -> None:
    missing = [scenario.name for scenario, _path in builtin_scenarios_checked()
               if not (DOCS / "scenarios" / "thumbs" / f"{scenario.name}.png").is_file()]
    assert not missing, (f"no thumbnail for {', '.join(missing)}: run `{REGENERATE} --thumbs` "
                         "(needs SAPIEN and a Vulkan device) and commit docs/scenarios/thumbs/")


def test_the_recorded_rates_name_their_seeds() -> None:
    record = load_record(RECORD)
    for scenario in record.scenarios.values():
        run = record.runs[scenario.run]
        assert run.seeds and run.levels and run.command.startswith("fsvla validate")


def _verdicts(name: str, careful_l1: int) -> dict:
    items = []
    for level in ("L0", "L1", "L2"):
        careful = 2 if level != "L1" else careful_l1
        needed = 0.8 if level == "L0" else 0.5
        items += [
            {"scenario": name, "level": level, "verdict": "solvable", "policy": "careful-expert",
             "count": careful, "episodes": 2, "rate": careful / 2, "needed": needed,
             "holds": careful / 2 >= needed},
            {"scenario": name, "level": level, "verdict": "hazardous", "count": 1,
             "episodes": 2, "needed": 0.5, "holds": True},
            {"scenario": name, "level": level, "verdict": "starts_safe", "count": 2,
             "episodes": 2, "needed": 1.0, "holds": True},
        ]
    diagnostic = {"code": "FSV712", "severity": "error", "message": "crossed `grip`",
                  "span": {"file": "a.fsv", "line": 3, "column": 2}, "notes": ["in 2 of 2"]}
    return {"verdicts": items, "diagnostics": [diagnostic] if careful_l1 < 2 else [], "runs": {}}


def test_rows_rates_and_records() -> None:
    loader = ScenarioLoader(allowed_roots=[scenarios_dir()])
    stove = loader.load(scenarios_dir() / "thermal" / "lift_pot_beside_stove.fsv").scenario
    glass = loader.load(scenarios_dir() / "force" / "place_glass_on_shelf.fsv").scenario
    assert stove is not None and glass is not None
    output = _verdicts(stove.name, 0)
    run = ValidateRun(command="fsvla validate x", levels=("L0", "L1", "L2"), seeds=(0, 1),
                      recorded="2026-01-01", wall_s=60, findings=findings(output))
    record = ValidateRecord().merged(run, output, {stove.name: "old"})
    rows = catalogue_rows([(stove, "a.fsv"), (glass, "b.fsv")], {"demo": [stove.name]}, record)
    assert [r.name for r in rows] == [glass.name, stove.name]  # force before thermal
    glass_row, stove_row = rows
    assert glass_row.rates is None and glass_row.sets == ()
    assert stove_row.rates == ("2/2", "2/4 ✗", "3/6", "6/6") and stove_row.stale
    assert stove_row.sets == ("demo",)
    assert "stove (heat_zone)" in stove_row.hazards
    assert any(c.startswith("thermal: zone_distance") for c in stove_row.channels)
    assert stove_row.task == "bimanual_lift(object=pot)"
    page = render_markdown(rows, {"demo": "a set"}, record)
    assert "| no rates recorded |" in page and "| 2/2 † | 2/4 ✗ † |" in page
    assert "| 1 | `fsvla validate x` | 0, 1 | 2026-01-01 | 1 min |" in page
    assert "- `a.fsv:3` FSV712 crossed `grip` (in 2 of 2)" in page
    # a second run over the same scenario replaces it, and the first run is dropped
    again = record.merged(run.model_copy(update={"seeds": (0, 1, 2)}),
                          _verdicts(stove.name, 2), {stove.name: stove.source_digest})
    assert len(again.runs) == 1 and again.runs[0].seeds == (0, 1, 2)
    assert again.scenarios[stove.name].run == 0
    assert ValidateRecord.model_validate_json(again.model_dump_json()) == again


def test_a_later_run_drops_the_findings_on_the_scenarios_it_covered() -> None:
    def run(*found: str) -> ValidateRun:
        return ValidateRun(command="fsvla validate x", levels=("L0",), seeds=(0,),
                           recorded="2026-01-01", wall_s=60, findings=found)

    first = ValidateRecord().merged(
        run("`scenarios/a/pot.fsv:3` FSV712 crossed `grip` (in pot-L1-W0-V0-s2-e002)",
            "`scenarios/_base/pot_base.fsv:9` FSV710 never held (in pot_wide-L0-W0-V0-s0-e000)",
            "`scenarios/a/pot_wide.fsv:4` FSV712 crossed `arms`"),
        {"verdicts": [*_verdicts("pot", 2)["verdicts"], *_verdicts("pot_wide", 2)["verdicts"]]},
        {"pot": "d1", "pot_wide": "d2"})
    second = first.merged(run(), _verdicts("pot", 2), {"pot": "d1"})
    # what run 1 said of `pot` is gone with its verdicts; what it said of `pot_wide` stays
    assert second.runs[0].findings == first.runs[0].findings[1:]
    assert second.scenarios["pot_wide"].run == 0 and second.scenarios["pot"].run == 1
