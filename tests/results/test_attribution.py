"""Safe-Vis attribution from what an episode applied: the row records the kinds of
perturbation, and the V3 categories count only the episodes that applied theirs."""

from __future__ import annotations

from pathlib import Path

from fsvla.metrics import breakdown
from fsvla.results import ResultStore
from fsvla.run import RunConfig, plan_episodes
from fsvla.variation.vision import CameraShift, Occluder, VisionPerturbation

from .conftest import SCENARIOS, make_outcome, make_record

CAMERA = CameraShift(offset=(0.04, 0.0, 0.0), yaw=0.05, pitch=0.0)
OCCLUDER = Occluder(target="stove", coverage=0.4)
# episode index -> what its V3 perturbation holds
V3 = {0: {"camera": CAMERA}, 1: {"occluders": (OCCLUDER,)},
      2: {"camera": CAMERA, "occluders": (OCCLUDER,)}}


def test_rows_record_what_was_applied_and_v3_categories_follow_it(tmp_path: Path) -> None:
    config = RunConfig(policy="p", scenarios=("s",), visions=("V3",), episodes=3, warmup=0,
                       obs_mode="rgb")
    plan = plan_episodes(config, SCENARIOS[:1])
    with ResultStore.create(tmp_path / "run", config) as store:
        for spec in plan:
            perturbation = VisionPerturbation(level="V3", **V3[spec.key.index])
            store.record(spec, make_outcome(make_record(seed=spec.key.index), spec=spec,
                                            perturbation=perturbation))
        rows = {row.key.index: row for row in store.episodes()}
        metrics = store.metrics()
    assert [rows[i].vision_applied for i in range(3)] == [
        ("camera",), ("occluder",), ("camera", "occluder")]
    assert [rows[i].vision_category for i in range(3)] == [
        "perspective_pose", "occlusion_visibility", None]
    groups = breakdown(metrics, by="category", n_resamples=10)
    assert (groups["perspective_pose"].n, groups["occlusion_visibility"].n) == (2, 2)
    by_index = {m.meta.key.index: m for m in metrics}
    assert groups["perspective_pose"].cc.estimate == (by_index[0].cc + by_index[2].cc) / 2
    assert groups["occlusion_visibility"].cc.estimate == (by_index[1].cc + by_index[2].cc) / 2
