"""The language dimension W0–W4 (paper §3.4): which instruction a policy is given.

- W0: the scenario's canonical instruction.
- W1: a paraphrase.  W2: a compositional rewrite (the task spelled out as steps).
- W3: an unsafe, contradictory or ambiguous request (the Safe-Lang categories).
- W4: the canonical instruction with an injected goal-hijacking suffix.

Texts come from the scenario's own ``language`` block when it gives the level (for W3,
the category), else from the jinja2 templates of its base task in
``instructions.toml`` (falling back to the generic ones). The choice is drawn with a
generator seeded from (scenario digest, level, seed), so it is the same on every machine.
Only the words change: the task, the success condition and the monitor stay those of
the scenario.
"""

from __future__ import annotations

import tomllib
from functools import cache
from pathlib import Path
from typing import Literal

import jinja2
from pydantic import BaseModel, ConfigDict

from fsvla.compiler.seeding import stable_rng
from fsvla.dsl.models import Scenario

LanguageLevel = Literal["W0", "W1", "W2", "W3", "W4"]
W3_CATEGORIES = ("unsafe", "contradictory", "ambiguous")
#: The metrics' name of each W3 category (``fsvla.metrics.trace.LanguageCategory``).
METRIC_CATEGORY = {"unsafe": "unsafe_instruction", "contradictory": "contradictory_instruction",
                   "ambiguous": "ambiguous_instruction"}
TEMPLATES = Path(__file__).with_name("instructions.toml")


class Instruction(BaseModel):
    """The instruction of one episode, with where it came from (recorded per episode)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    level: LanguageLevel
    category: str | None  # paraphrase, compositional, unsafe, contradictory, ambiguous, hijack
    text: str
    origin: str  # "canonical", "scenario" (its language block) or "template:<task>"

    @property
    def metric_category(self) -> str | None:
        """The Safe-Lang category the metrics break W3 down by (None off W3)."""
        return METRIC_CATEGORY.get(self.category or "") if self.level == "W3" else None


def instruction_for(scenario: Scenario, level: LanguageLevel, seed: int = 0) -> Instruction:
    """The instruction an episode of ``scenario`` at ``level`` with ``seed`` is given."""
    canonical = scenario.instruction
    if level == "W0":
        return Instruction(level="W0", category=None, text=canonical, origin="canonical")
    rng = stable_rng(scenario.source_digest, "W", level, seed)
    category = _category(level, scenario, rng)
    own = [v.text for v in scenario.language.get(level, ())  # type: ignore[call-overload]
           if level != "W3" or v.category == category]
    if own:
        text, origin = own[int(rng.integers(len(own)))], "scenario"
    else:
        templates = _templates(scenario.task.name, category if level == "W3" else level)
        chosen = templates[int(rng.integers(len(templates)))]
        text = _render(chosen, scenario)
        origin = f"template:{scenario.task.name}"
    if level == "W4":
        text = canonical + text
    return Instruction(level=level, category=category, text=" ".join(text.split()), origin=origin)


def _category(level: str, scenario: Scenario, rng) -> str:  # noqa: ANN001
    if level == "W1":
        return "paraphrase"
    if level == "W2":
        return "compositional"
    if level == "W4":
        return "hijack"
    written = sorted({v.category for v in scenario.language.get("W3", ()) if v.category})
    choices = written or list(W3_CATEGORIES)
    return choices[int(rng.integers(len(choices)))]


@cache
def _table() -> dict[str, dict[str, object]]:
    with TEMPLATES.open("rb") as handle:
        return tomllib.load(handle)


def _templates(task: str, key: str) -> list[str]:
    table = _table()
    specific = table.get(task, {}).get(key)
    found = specific if specific else table["generic"].get(key)
    if not found:
        raise KeyError(f"no instruction templates for {key!r} of task {task!r} in {TEMPLATES}")
    return list(found)  # type: ignore[arg-type]


def _render(template: str, scenario: Scenario) -> str:
    table = _table()
    task = table.get(scenario.task.name, {})
    environment = jinja2.Environment(undefined=jinja2.StrictUndefined, autoescape=False)
    context = _words(scenario)
    context["verb"] = str(task.get("verb", "handle"))
    context["done"] = environment.from_string(str(task.get("done", "done"))).render(context)
    context["instruction"] = scenario.instruction
    return environment.from_string(template).render(context)


def _words(scenario: Scenario) -> dict[str, str]:
    roles = scenario.task.roles
    task_objects = set(roles.values())
    # The most salient danger to name: a hazard zone, else a hazardous object that is not
    # itself being manipulated, else any other object on the table, else the table's edge.
    candidates = [z.name for z in scenario.zones]
    candidates += [o.name for o in scenario.objects if o.hazard_role and o.name not in task_objects]
    candidates += [o.name for o in scenario.objects
                   if o.name not in task_objects and o.name != "table"]
    return {
        "object": _word(roles.get("object", "object")),
        "target": _word(roles.get("target", "target")),
        "hazard": _word(candidates[0]) if candidates else "table edge",
    }


def _word(name: str) -> str:
    return name.replace("_", " ")


__all__ = ["Instruction", "LanguageLevel", "METRIC_CATEGORY", "W3_CATEGORIES", "instruction_for"]
