"""``generate_variant``: a seeded, feasibility-checked layout of a scenario at L0, L1 or L2.

L0 is the canonical layout with a small nuisance jitter: the scenario's ``L0`` jitters when
it writes them (none for ``L0: none``), else every rigid task object jittered by
``NUISANCE_DISTANCE`` and ``NUISANCE_YAW``. L1 applies the scenario's ``L1`` rules; L2
applies the L1 rules and then the ``L2`` rules (cumulative; the L0 nuisance is L0's own).
Each sample draws every rule in order — jitters, approaches and clutter move or add
things; tightens and couples change the limits and requirements — and is accepted when
it passes every check of
:mod:`.feasibility`. Static checks run first and fail without sampling. The random
generator is seeded from SHA-256 of (source digest, "L", level, seed), so a layout is
the same on every machine.
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Callable, Mapping, Sequence
from functools import lru_cache
from pathlib import Path

import numpy as np
from fsvla.compiler.assets import (
    ArticulatedAsset,
    RigidAsset,
    ZoneAsset,
    build_asset,
    build_zone_marker,
)
from fsvla.dsl.catalog import ASSETS, AssetClass
from fsvla.dsl.models import (
    Approach,
    Clutter,
    Couple,
    Jitter,
    ParamValue,
    Scenario,
    Tighten,
    VariantRule,
)

from fsvla.embodiments import EmbodimentSpec, load_embodiment

from ..collision import min_distance
from ..placement import placed_rect
from ..scene import WORLD, Level, LoweringError, SceneSpec
from ..seeding import stable_rng
from .errors import Infeasibility, VariantError, cm, describe_rule, shares
from .feasibility import (
    CLUTTER_CLEARANCE,
    REACH_MARGIN,
    Checker,
    Rejection,
    workspace_text,
)
from .layout import CLUTTER_PALETTE, ClutterItem, Draw, Layout, clutter_params, disc_sample
from .start import SafeStart, keeps_of

#: A ``clutter N near X`` object's centre lies within X's footprint half-diagonal plus this (m).
NEAR_DISTANCE = 0.15
#: Tries to place one clutter object within one sample before the sample is rejected.
CLUTTER_TRIES = 20
#: The share of a free area that random placement can fill (random sequential packing).
PACKING_DENSITY = 0.5
#: Grid step (m) for measuring free area.
AREA_STEP = 0.01
#: L0's default nuisance: each task object moves within this radius (m) and turns within
#: ± this angle (rad), as RoboTwin randomises object poses in its clean setting.
NUISANCE_DISTANCE = 0.01
NUISANCE_YAW = math.radians(5.0)

LeveledRule = tuple[Level, VariantRule]


# --- caches: assets and embodiments are pure functions of their parameters --------------------


def cached_build_asset(kind: str, params: Mapping[str, ParamValue] | None = None, *,
                       base_dir: Path | None = None, allowed_roots: Sequence[Path] = ()
                       ) -> RigidAsset | ArticulatedAsset:
    """``build_asset``, memoised for procedural kinds (file assets are always re-read)."""
    entry = ASSETS.get(kind)
    key = _freeze(params or {})
    if entry is None or entry.asset_class is AssetClass.FILE or key is None:
        return build_asset(kind, params, base_dir=base_dir, allowed_roots=allowed_roots)
    return _build(kind, key)


def cached_build_zone_marker(kind: str, params: Mapping[str, ParamValue] | None = None, *,
                             support_size: Sequence[float] | None = None) -> ZoneAsset:
    key = _freeze(params or {})
    size = tuple(float(v) for v in support_size) if support_size is not None else None
    if key is None:
        return build_zone_marker(kind, params, support_size=support_size)
    return _marker(kind, key, size)


@lru_cache(maxsize=512)
def _build(kind: str, key: tuple) -> RigidAsset | ArticulatedAsset:
    return build_asset(kind, dict(key))


@lru_cache(maxsize=256)
def _marker(kind: str, key: tuple, size: tuple[float, ...] | None) -> ZoneAsset:
    return build_zone_marker(kind, dict(key), support_size=size)


@lru_cache(maxsize=32)
def _embodiment(name: str) -> EmbodimentSpec:
    return load_embodiment(name)


def _freeze(params: Mapping[str, ParamValue]) -> tuple | None:
    key = tuple(sorted(params.items()))
    try:
        hash(key)
    except TypeError:
        return None
    return key


# --- rules -----------------------------------------------------------------------------------


def nuisance_rules(scenario: Scenario) -> tuple[VariantRule, ...]:
    """L0's nuisance jitter: the scenario's ``L0`` rules when it writes them (``L0: none``
    gives none), else each rigid task object (not the articulated furniture, a cabinet or
    a lidded box, which is the scene the task is done in) within ``NUISANCE_DISTANCE`` and
    ``NUISANCE_YAW``, on the line of its ``task``."""
    if "L0" in scenario.variants:
        return scenario.variants["L0"]
    objects = [name for name in dict.fromkeys(scenario.task.roles.values())
               if name != "table" and _rigid(scenario, name)]
    return tuple(Jitter(target=name, distance=NUISANCE_DISTANCE, yaw=NUISANCE_YAW,
                        source=scenario.task.source) for name in objects)


def _rigid(scenario: Scenario, name: str) -> bool:
    spec = scenario.object(name)
    entry = ASSETS.get(spec.asset) if spec is not None else None
    return entry is not None and entry.asset_class is AssetClass.RIGID


def rules_of(scenario: Scenario, level: Level) -> list[LeveledRule]:
    """The rules a level applies, in order: the nuisance jitter at L0, L1's at L1, L1's
    then L2's at L2."""
    if level == "L0":
        return [("L0", rule) for rule in nuisance_rules(scenario)]
    levels: tuple[Level, ...] = ("L1", "L2")[:("L0", "L1", "L2").index(level)]
    return [(lvl, rule) for lvl in levels for rule in scenario.variants.get(lvl, ())]


def vary_limits(scenario: Scenario, rules: Sequence[LeveledRule]) -> Scenario:
    """``scenario`` with its ``tighten`` and ``couple`` rules applied."""
    if not any(isinstance(rule, (Tighten, Couple)) for _, rule in rules):
        return scenario
    limits = {lim.name: lim for lim in scenario.limits}
    requirements = {req.name: req for req in scenario.requirements}
    for _, rule in rules:
        if isinstance(rule, Tighten) and rule.target in limits:
            limits[rule.target] = limits[rule.target].model_copy(update={"limit": rule.limit})
        elif isinstance(rule, Couple) and rule.requirement in requirements:
            requirements[rule.requirement] = requirements[rule.requirement].model_copy(
                update={"within": rule.within})
    return scenario.model_copy(update={"limits": tuple(limits.values()),
                                       "requirements": tuple(requirements.values())})


class Generator(SafeStart):
    """Draws layouts of one scenario at one level until one is feasible."""

    def __init__(self, scenario: Scenario, level: Level, canonical: SceneSpec,
                 embodiment: EmbodimentSpec, budget: int):
        self.scenario, self.level, self.budget = scenario, level, budget
        self.embodiment, self.canonical = embodiment, canonical
        self.rules = rules_of(scenario, level)
        self.varied = vary_limits(scenario, self.rules)
        assets = {b.name: b.asset for b in canonical.bodies}
        markers = {z.name: z.marker for z in canonical.zones}
        clutter = {i: cached_build_asset(*clutter_params(i)) for i in range(len(CLUTTER_PALETTE))} \
            if any(isinstance(r, Clutter) for _, r in self.rules) else {}
        self.layout = Layout(scenario, assets, markers, clutter)  # type: ignore[arg-type]
        approached = [(r.hazard, r.toward) for _, r in self.rules if isinstance(r, Approach)]
        self.checker = Checker(self.layout, embodiment, keeps_of(self.varied, approached),
                               scenario.task.roles.values())
        self.tightened = {r.target: i for i, (_, r) in enumerate(self.rules) if isinstance(r, Tighten)}

    @property
    def samples_needed(self) -> bool:
        return any(isinstance(r, (Jitter, Approach, Clutter)) for _, r in self.rules)

    # --- one sample ------------------------------------------------------------------------

    def sample(self, rng: np.random.Generator) -> tuple[Draw, Rejection | None]:
        draw = Draw()
        for index, (_, rule) in enumerate(self.rules):
            if isinstance(rule, Jitter):
                draw.shift(rule.target, disc_sample(rng, rule.distance), index)
                if rule.yaw > 0.0:
                    draw.turn(rule.target, float(rng.uniform(-rule.yaw, rule.yaw)), index)
            elif isinstance(rule, Approach):
                self._approach(draw, rule, index, rule.distance)
            elif isinstance(rule, Clutter):
                rejection = self._clutter(draw, rule, index, rng)
                if rejection is not None:
                    return draw, rejection
        return draw, self.checker.check(draw)

    def _approach(self, draw: Draw, rule: Approach, index: int, distance: float) -> None:
        frames = self.layout.frames(draw)
        h, o = frames[rule.hazard], frames[rule.toward]
        dx, dy = o.x - h.x, o.y - h.y
        norm = math.hypot(dx, dy)
        if norm < 1e-9:
            return
        support_yaw = frames[self.layout.entities[rule.hazard].support].yaw
        c, s = math.cos(-support_yaw), math.sin(-support_yaw)
        wx, wy = distance * dx / norm, distance * dy / norm
        draw.shift(rule.hazard, np.array([c * wx - s * wy, s * wx + c * wy]), index)

    def _clutter(self, draw: Draw, rule: Clutter, index: int, rng: np.random.Generator) -> Rejection | None:
        support, centre, radius = self.clutter_region(draw, rule)
        top = self.layout.entities[support].top
        for _ in range(rule.count):
            name = self._clutter_name(draw)
            draw.moved_by[name] = {index}
            failures: list[Rejection] = []
            for _ in range(CLUTTER_TRIES):
                palette = int(rng.integers(len(CLUTTER_PALETTE)))
                if centre is not None:
                    xy = np.asarray(centre) + disc_sample(rng, radius)
                else:
                    xy = rng.uniform(top.min_xy, top.max_xy)  # type: ignore[union-attr]
                yaw = float(rng.uniform(-math.pi, math.pi))
                draw.clutter.append(ClutterItem(name, palette, support, (float(xy[0]), float(xy[1])), yaw,
                                                index, rule.source))
                rejection = self.checker.check(draw, focus={name})
                if rejection is None:
                    break
                draw.clutter.pop()
                failures.append(rejection)
            else:
                return Counter(failures).most_common(1)[0][0]
        return None

    def clutter_region(self, draw: Draw, rule: Clutter) -> tuple[str, tuple[float, float] | None, float]:
        """Where a clutter rule puts things: (support, centre or None for anywhere, radius)."""
        if rule.near is None:
            return "table", None, 0.0
        near = self.layout.entities[rule.near]
        if near.support == WORLD:
            return rule.near, None, 0.0
        half_diagonal = 0.5 * math.hypot(*near.footprint.size)
        return near.support, self.layout.position(draw, rule.near), half_diagonal + NEAR_DISTANCE

    def _clutter_name(self, draw: Draw) -> str:
        taken = set(self.layout.entities) | {c.name for c in draw.clutter}
        k = len(draw.clutter) + 1
        while f"clutter_{k}" in taken:
            k += 1
        return f"clutter_{k}"

    # --- the whole search ------------------------------------------------------------------

    def search(self, rng: np.random.Generator,
               lower: Callable[[Scenario], SceneSpec]) -> tuple[Scenario, SceneSpec, int]:
        """The first feasible sample, lowered by ``lower``; raises :class:`VariantError`."""
        self.start_checks()
        if not self.samples_needed or self.level == "L0":
            draw, rejection = Draw(), self.checker.check(Draw())
            if rejection is not None:  # L0: the canonical layout first, on its own lines
                raise VariantError(self.canonical_failure(rejection))
        if not self.samples_needed:
            scenario = self.layout.apply(draw, self.varied)
            return scenario, lower(scenario), 0
        self.static_checks()
        tally = _Tally()
        for sample in range(1, self.budget + 1):
            draw, rejection = self.sample(rng)
            if rejection is None:
                scenario = self.layout.apply(draw, self.varied)
                try:
                    return scenario, lower(scenario), sample
                except LoweringError as err:  # a criterion of lower_scene the checks missed
                    rejection = Rejection("overlap", err.message, (), err.source)
            tally.add(rejection, self._involved(draw, rejection))
        raise VariantError(self.exhausted(tally))

    def _involved(self, draw: Draw, rejection: Rejection) -> set[int]:
        rules = set()
        for name in rejection.entities:
            rules |= self.layout.movers(draw, name)
        if rejection.limit in self.tightened:
            rules.add(self.tightened[rejection.limit])
        return rules

    # --- static checks ---------------------------------------------------------------------

    def static_checks(self) -> None:
        """Rules that no sample can satisfy fail here, before any sampling (FSV601)."""
        for index, (lvl, rule) in enumerate(self.rules):
            if isinstance(rule, Jitter):
                self._static_jitter(lvl, rule)
            elif isinstance(rule, Approach):
                self._static_approach(lvl, rule, index)
                self._static_approach_band(lvl, rule, index)
            elif isinstance(rule, Clutter):
                self._static_clutter(lvl, rule)

    def _static_jitter(self, lvl: Level, rule: Jitter) -> None:
        support = self.layout.entities[rule.target].support
        top = self.layout.entities[support].top if support != WORLD else None
        if top is None or rule.distance <= 0.5 * math.hypot(*top.size):
            return
        w, h = top.size
        self._static_failure(
            lvl, rule, f"its disc (radius {cm(rule.distance)}) is larger than the top of "
                       f"'{support}' ({cm(w)} x {cm(h)})", "jitter disc larger than the support",
            ((f"reduce the jitter of '{rule.target}' (now {cm(rule.distance)}; the top of "
              f"'{support}' is {cm(w)} x {cm(h)})"), f"put '{rule.target}' on a larger support"))

    def _static_approach(self, lvl: Level, rule: Approach, index: int) -> None:
        frames = self.layout.frames(Draw())
        h, o = frames[rule.hazard], frames[rule.toward]
        apart = math.hypot(o.x - h.x, o.y - h.y)
        slack = sum(r.distance for _, r in self.rules[:index]
                    if isinstance(r, Jitter) and r.target in self._with_anchors(rule.hazard, rule.toward))
        if rule.distance < apart + slack:
            return
        self.checker.check(Draw())  # places every solid at the canonical layout
        solids = self.checker.regions if rule.hazard in self.checker.regions else self.checker.solids
        hazard = solids[rule.hazard]
        gap = max(0.0, min_distance(hazard.fcl_pieces(), self.checker.solids[rule.toward].fcl_pieces()))
        reach = f"{cm(apart)}" + (f" (at most {cm(apart + slack)} with the jitter)" if slack else "")
        self._static_failure(
            lvl, rule, f"it would move '{rule.hazard}' past '{rule.toward}': their centres are "
                       f"{reach} apart, the approach is {cm(rule.distance)}",
            "approach past its target",
            ((f"reduce the approach of '{rule.hazard}' to '{rule.toward}' below their gap of "
              f"{cm(gap)} (now {cm(rule.distance)})"),
             f"place '{rule.hazard}' farther from '{rule.toward}' in the canonical layout"))

    def _static_clutter(self, lvl: Level, rule: Clutter) -> None:
        support, centre, radius = self.clutter_region(Draw(), rule)
        free = self.free_area(support, centre, radius)
        each = min(_padded_area(a) for a in self.layout.clutter_assets.values())
        fits = int(free * PACKING_DENSITY / each)
        if rule.count <= fits:
            return
        where = f"within {cm(radius)} of '{rule.near}'" if centre is not None else f"on '{support}'"
        second = (f"make room around '{rule.near}', or drop `near {rule.near}`" if centre is not None
                  else f"make room on '{support}'")
        self._static_failure(
            lvl, rule, f"{rule.count} clutter objects cannot fit {where}: {free:.3f} m² is free, "
                       f"room for at most {fits}", "more clutter than fits",
            (f"ask for at most {fits} clutter objects (now {rule.count})", second))

    def _static_failure(self, lvl: Level, rule: VariantRule, why: str, label: str,
                        remedies: tuple[str, ...]) -> None:
        raise VariantError(Infeasibility(
            code="FSV601", level=self.level, source=rule.source, label=label,
            message=f"{lvl} rule `{describe_rule(rule, self.scenario)}` of '{self.scenario.name}' "
                    f"can never hold: {why}",
            remedies=remedies))

    def _with_anchors(self, *names: str) -> set[str]:
        found, pending = set(), list(names)
        while pending:
            name = pending.pop()
            entity = self.layout.entities.get(name)
            if name in found or entity is None:
                continue
            found.add(name)
            pending += [n for n in (entity.anchor, entity.support) if n is not None and n != WORLD]
        return found

    def free_area(self, support: str, centre: tuple[float, float] | None, radius: float) -> float:
        """Area (m²) of ``support``'s top, within ``radius`` of ``centre`` when given, that no
        footprint of the canonical layout covers (a 1 cm grid; clearance added round each)."""
        top = self.layout.entities[support].top
        if top is None:
            return 0.0
        xs = np.arange(top.min_xy[0] + AREA_STEP / 2, top.max_xy[0], AREA_STEP)
        ys = np.arange(top.min_xy[1] + AREA_STEP / 2, top.max_xy[1], AREA_STEP)
        gx, gy = np.meshgrid(xs, ys)
        free = np.ones(gx.shape, dtype=bool)
        if centre is not None:
            free &= (gx - centre[0]) ** 2 + (gy - centre[1]) ** 2 <= radius ** 2
        for entity in self.layout.entities.values():
            if entity.support != support:
                continue
            rect = placed_rect(entity.footprint.min_xy, entity.footprint.max_xy, entity.xy, entity.yaw)
            free &= ~((gx >= rect.min_xy[0]) & (gx <= rect.max_xy[0])
                      & (gy >= rect.min_xy[1]) & (gy <= rect.max_xy[1]))
        return float(free.sum()) * AREA_STEP ** 2

    # --- failures --------------------------------------------------------------------------

    def canonical_failure(self, rejection: Rejection) -> Infeasibility:
        """FSV603: the one layout of a level that moves nothing is infeasible."""
        tighten = self.tightened.get(rejection.limit) if rejection.limit else None
        source = self.rules[tighten][1].source if tighten is not None else rejection.source
        at = "" if self.level == "L0" else f" at {self.level}"
        notes, remedies = self.start_notes(rejection, self._canonical_remedies(rejection, tighten), tighten)
        return Infeasibility(
            code="FSV603", level=self.level, source=source, label=rejection.reason,
            message=f"the canonical layout of '{self.scenario.name}' is infeasible{at}: {rejection.cause}",
            notes=notes, remedies=remedies)

    def _canonical_remedies(self, rejection: Rejection, tighten: int | None) -> tuple[str, ...]:
        names = rejection.entities
        if rejection.reason == "unreachable":
            return ((f"move '{names[0]}' closer to the arms' workspace "
                     f"({workspace_text(self.embodiment)}; up to {cm(REACH_MARGIN)} beyond it counts)"),)
        if rejection.reason == "off support":
            return (f"move '{names[0]}' onto the top of '{self.layout.entities[names[0]].support}'",)
        if rejection.reason in ("hazard violated", "warning band"):
            other = f"'{names[1]}'" if len(names) == 2 else "the edge of its support"
            if tighten is None:
                return (f"move '{names[0]}' farther from {other}",)
            return (f"loosen `{describe_rule(self.rules[tighten][1], self.scenario)}`",
                    f"move '{names[0]}' farther from {other} in the canonical layout")
        if len(names) == 2:
            return (f"move '{names[0]}' and '{names[1]}' apart",)
        return (f"move '{names[0]}' to a free spot",) if names else ("move the objects apart",)

    def exhausted(self, tally: _Tally) -> Infeasibility:
        """FSV602: every sample was rejected; blame the rule most rejections involve."""
        index = tally.blamed(default=next(i for i, (_, r) in enumerate(self.rules)
                                          if isinstance(r, (Jitter, Approach, Clutter))),
                             prefer={i for i, (_, r) in enumerate(self.rules) if isinstance(r, Approach)})
        lvl, rule = self.rules[index]
        n = tally.samples
        cause, count = tally.causes.most_common(1)[0]
        return Infeasibility(
            code="FSV602", level=self.level, source=rule.source, label="no feasible layout with this rule",
            message=f"no feasible {self.level} layout of '{self.scenario.name}' in {n} samples; "
                    f"{tally.rules[index]} of the rejections involve {lvl} rule "
                    f"`{describe_rule(rule, self.scenario)}`",
            samples=n, rejected=dict(tally.reasons),
            notes=(f"rejected {n} of {n} samples: {shares(tally.reasons)}",
                   f"most often: {cause} ({count} of {n})"),
            remedies=tuple(dict.fromkeys((*self._rule_remedies(rule, tally.examples.get(index)),
                                          *self._other_remedies(index, tally),
                                          *self._nuisance_remedy(),
                                          f"raise the budget (now {self.budget} samples)"))))

    def _nuisance_remedy(self) -> tuple[str, ...]:
        if self.level != "L0":
            return ()
        return ("write `L0: none` under `variants` to keep the canonical layout exactly",)

    def _other_remedies(self, blamed: int, tally: _Tally) -> tuple[str, ...]:
        """The first remedy of each other rule that half the rejections or more involve."""
        found = []
        for index, count in sorted(tally.rules.items()):
            if index != blamed and 2 * count >= tally.samples:
                found += self._rule_remedies(self.rules[index][1], tally.examples.get(index))[:1]
        return tuple(found)

    def _rule_remedies(self, rule: VariantRule, example: Rejection | None) -> tuple[str, ...]:
        if isinstance(rule, Jitter):
            return (f"reduce the jitter of '{rule.target}' (now {cm(rule.distance)})",
                    self._move_remedy(rule.target, example))
        if isinstance(rule, Approach) and example is not None and self._approach_keeps(rule) and \
                example.reason in ("hazard violated", "warning band"):
            index = next(i for i, (_, r) in enumerate(self.rules) if r is rule)
            return self._approach_remedies(rule, self._approach_room(rule, index))
        if isinstance(rule, Approach):
            return (f"reduce the approach of '{rule.hazard}' to '{rule.toward}' (now {cm(rule.distance)})",
                    f"place '{rule.hazard}' farther from '{rule.toward}' in the canonical layout")
        if isinstance(rule, Clutter):
            room = (f"make room around '{rule.near}', or drop `near {rule.near}`" if rule.near
                    else "make room on 'table'")
            return (f"ask for fewer clutter objects (now {rule.count})", room)
        if isinstance(rule, Tighten):
            names = example.entities if example is not None else ()
            move = (f"place '{names[0]}' farther from '{names[1]}' in the canonical layout"
                    if len(names) == 2 else "move the hazard farther away in the canonical layout")
            return (f"loosen `{describe_rule(rule, self.scenario)}`", move)
        return ()

    def _move_remedy(self, target: str, example: Rejection | None) -> str:
        reason = example.reason if example is not None else "overlap"
        if reason == "unreachable":
            return (f"move '{target}' closer to the arms' workspace ({workspace_text(self.embodiment)}; "
                    f"up to {cm(REACH_MARGIN)} beyond it counts)")
        if reason == "off support":
            return f"move '{target}' toward the middle of '{self.layout.entities[target].support}'"
        others = [n for n in (example.entities if example else ()) if n != target]
        if others:
            return f"move '{target}' farther from '{others[0]}' in the canonical layout"
        return f"move '{target}' to a freer spot in the canonical layout"


class _Tally:
    """Counts of rejected samples: per reason, per cause, per rule involved."""

    def __init__(self) -> None:
        self.samples = 0
        self.reasons: Counter[str] = Counter()
        self.causes: Counter[str] = Counter()
        self.rules: Counter[int] = Counter()
        self._by_rule: dict[int, Counter[Rejection]] = {}

    def add(self, rejection: Rejection, rules: set[int]) -> None:
        self.samples += 1
        self.reasons[rejection.reason] += 1
        self.causes[rejection.cause] += 1
        for index in rules:
            self.rules[index] += 1
            self._by_rule.setdefault(index, Counter())[rejection] += 1

    def blamed(self, default: int, prefer: set[int] = frozenset()) -> int:
        """The rule the most rejections involve; among equals one of ``prefer`` (the
        approaches: they move a pair strictly closer, a jitter spreads it both ways), then
        the first."""
        if not self.rules:
            return default
        return min(self.rules, key=lambda i: (-self.rules[i], i not in prefer, i))

    @property
    def examples(self) -> dict[int, Rejection]:
        """Each rule's most frequent rejection."""
        return {i: c.most_common(1)[0][0] for i, c in self._by_rule.items()}


def _padded_area(asset: RigidAsset) -> float:
    w, h = (asset.footprint.max_xy[i] - asset.footprint.min_xy[i] for i in range(2))
    return (w + CLUTTER_CLEARANCE) * (h + CLUTTER_CLEARANCE)


def rng_for(scenario: Scenario, level: Level, seed: int) -> np.random.Generator:
    """The generator of (scenario, level, seed): the same on every machine."""
    return stable_rng(scenario.source_digest, "L", level, seed)


def load_spec(scenario: Scenario, embodiment: EmbodimentSpec | None) -> EmbodimentSpec:
    if embodiment is not None:
        return embodiment
    try:
        return _embodiment(scenario.embodiment)
    except Exception as err:  # unknown name, bad file: point at the scenario
        raise LoweringError(f"cannot load embodiment {scenario.embodiment!r}: {err}",
                            scenario.source) from err


__all__ = ["CLUTTER_TRIES", "NEAR_DISTANCE", "NUISANCE_DISTANCE", "NUISANCE_YAW", "PACKING_DENSITY",
           "Generator", "cached_build_asset", "cached_build_zone_marker", "load_spec",
           "nuisance_rules", "rng_for", "rules_of", "vary_limits"]
