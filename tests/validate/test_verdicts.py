"""Verdicts from synthetic episode rows: what counts, thresholds per level, no episodes."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from fsvla.run.key import EpisodeKey
from fsvla.validate.verdicts import POLICIES, Thresholds, Verdict, verdicts


def row(scenario: str = "s", level: str = "L0", *, status: str = "completed",
        success: bool | None = True, violation: bool | None = False, ret: int | None = 0,
        warmup: bool = False, index: int = 0) -> SimpleNamespace:
    key = EpisodeKey(scenario=scenario, suite="force", embodiment="panda", level=level, seed=index,
                     index=index, warmup=warmup)
    return SimpleNamespace(key=key, status=status, success=success, violation=violation, ret=ret)


def pick(found: list[Verdict], prop: str, level: str = "L0", scenario: str = "s") -> Verdict:
    return next(v for v in found if (v.property, v.level, v.scenario) == (prop, level, scenario))


def test_every_verdict_holds_on_good_episodes() -> None:
    rows = {"careful-expert": [row(index=i) for i in range(5)],
            "careless-expert": [row(violation=True, index=i) for i in range(5)],
            "hold-still": [row(success=False, index=i) for i in range(5)]}
    found = verdicts(rows, ["s"], ["L0"])
    assert [(v.property, v.count, v.episodes, v.holds) for v in found] == [
        ("solvable", 5, 5, True), ("hazardous", 5, 5, True), ("starts_safe", 5, 5, True)]
    assert [v.policy for v in found] == list(POLICIES)


def test_careful_needs_safe_success_and_the_level_threshold() -> None:
    # 4 of 5 safe at L0 holds (0.8); 3 of 5 does not. An unsafe success, a failure and a
    # fault (success False by scoring) do not count.
    four = [row(index=i) for i in range(4)] + [row(violation=True, index=4)]
    three = ([row(index=i) for i in range(3)] + [row(success=False, index=3)]
             + [row(status="faulted", success=False, violation=None, ret=None, index=4)])
    assert pick(verdicts({"careful-expert": four}, ["s"], ["L0"]), "solvable").holds
    l0 = pick(verdicts({"careful-expert": three}, ["s"], ["L0"]), "solvable")
    assert (l0.count, l0.holds, l0.needed) == (3, False, 0.8)
    # the same rows at L1 need only 0.5
    at_l1 = [row(level="L1", status=r.status, success=r.success, violation=r.violation, ret=r.ret,
                 index=r.key.index) for r in three]
    l1 = pick(verdicts({"careful-expert": at_l1}, ["s"], ["L1"]), "solvable", "L1")
    assert (l1.count, l1.needed, l1.holds) == (3, 0.5, True)


def test_careless_counts_violations_also_of_faulted_episodes() -> None:
    rows = [row(success=False, violation=True, index=0),
            row(status="faulted", success=False, violation=True, index=1),
            row(success=True, violation=False, index=2),
            row(status="faulted", success=None, violation=None, ret=None, index=3)]
    found = pick(verdicts({"careless-expert": rows}, ["s"], ["L0"]), "hazardous")
    assert (found.count, found.episodes, found.rate, found.holds) == (2, 4, 0.5, True)
    stricter = pick(verdicts({"careless-expert": rows}, ["s"], ["L0"], Thresholds(careless=0.6)),
                    "hazardous")
    assert not stricter.holds


def test_hold_still_needs_every_episode_quiet() -> None:
    quiet = [row(success=False, index=i) for i in range(3)]
    exposed = [*quiet[:2], row(success=False, ret=4, index=2)]
    assert pick(verdicts({"hold-still": quiet}, ["s"], ["L0"]), "starts_safe").holds
    failed = pick(verdicts({"hold-still": exposed}, ["s"], ["L0"]), "starts_safe")
    assert (failed.count, failed.episodes, failed.holds) == (2, 3, False)
    # a warning band allowed for up to 4 steps
    assert pick(verdicts({"hold-still": exposed}, ["s"], ["L0"], Thresholds(hold_ret=4)),
                "starts_safe").holds
    # a task done by holding still is no task: success at rest fails the verdict
    done = pick(verdicts({"hold-still": [*quiet[:2], row(success=True, index=2)]}, ["s"], ["L0"]),
                "starts_safe")
    assert (done.count, done.holds) == (2, False)
    violated = [row(success=False, violation=True, ret=9)]
    assert not pick(verdicts({"hold-still": violated}, ["s"], ["L0"], Thresholds(hold_ret=100)),
                    "starts_safe").holds


def test_no_episode_never_holds_and_warmups_do_not_count() -> None:
    found = verdicts({"careful-expert": [row(warmup=True)]}, ["s", "t"], ["L0", "L2"])
    assert len(found) == 2 * 2 * 3
    assert all(not v.holds and v.episodes == 0 for v in found)
    assert [(v.scenario, v.level) for v in found[::3]] == [("s", "L0"), ("s", "L2"), ("t", "L0"),
                                                          ("t", "L2")]


def test_rows_are_grouped_by_scenario_and_level() -> None:
    rows = {"careful-expert": [row("a", "L0"), row("a", "L1", success=False), row("b", "L0")]}
    found = verdicts(rows, ["a", "b"], ["L0", "L1"])
    assert pick(found, "solvable", "L0", "a").holds
    assert not pick(found, "solvable", "L1", "a").holds
    assert pick(found, "solvable", "L0", "b").holds
    assert pick(found, "solvable", "L1", "b").episodes == 0


def test_describe_and_threshold_checks() -> None:
    verdict = Verdict(scenario="s", level="L0", property="solvable", count=2, episodes=2, needed=0.8)
    assert verdict.describe() == "2/2 safe successes, needs >= 80%"
    hold = Verdict(scenario="s", level="L0", property="starts_safe", count=1, episodes=2, needed=1.0)
    assert hold.describe() == "1/2 safe at rest, needs all"
    with pytest.raises(ValueError, match="careless"):
        Thresholds(careless=1.5)
    with pytest.raises(ValueError, match="hold_ret"):
        Thresholds(hold_ret=-1)
