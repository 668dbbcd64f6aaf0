"""EpisodeTrace / ChannelInfo / EpisodeMeta: validation and the JSON round trip."""

import json

import numpy as np
import pytest
from pydantic import ValidationError

from fsvla.metrics.trace import (
    FAMILIES,
    TRACE_FORMAT_VERSION,
    ChannelInfo,
    EpisodeMeta,
    EpisodeTrace,
)
from fsvla.run.key import EpisodeKey

KEY = EpisodeKey(scenario="lift_pot", suite="thermal", embodiment="dual_panda", level="L2",
                 language="W3", vision="V3", seed=7, index=3)
META = EpisodeMeta(key=KEY, policy="act", language_category="ambiguous_instruction",
                   vision_category="perspective_pose")
CHANNELS = (
    ChannelInfo(name="grip_force", family="force", soft_threshold=8.0, weight=0.5),
    ChannelInfo(name="stove", family="thermal", soft_threshold=0.04, shaping="exponential"),
)


def _trace(margins, channels=CHANNELS, success=True):
    return EpisodeTrace(channels=channels, margins=margins, success=success, meta=META)


def test_families_are_the_five_suites_plus_side_effects():
    assert FAMILIES == ("force", "thermal", "boundary", "collaborative", "temporal", "side_effect")


def test_json_round_trip_is_exact():
    trace = _trace([[12.5, 0.1], [3.25, -0.015625], [0.1 + 0.2, 1e-9]])
    text = json.dumps(trace.to_dict())
    data = json.loads(text)
    assert data["version"] == TRACE_FORMAT_VERSION
    assert data["margins"] == [[12.5, 0.1], [3.25, -0.015625], [0.1 + 0.2, 1e-9]]
    back = EpisodeTrace.from_dict(data)
    assert back == trace
    assert back.margins.dtype == np.float64
    assert back.meta.language_category == "ambiguous_instruction"
    assert back.channels[1].shaping == "exponential"


def test_margins_are_a_read_only_copy():
    source = np.array([[1.0, 2.0]])
    trace = _trace(source)
    source[0, 0] = -5.0
    assert trace.margins[0, 0] == 1.0
    with pytest.raises(ValueError):
        trace.margins[0, 0] = 3.0
    assert trace.horizon == 1


def test_traces_differ_by_margins():
    assert _trace([[1.0, 2.0]]) != _trace([[1.0, 2.5]])
    assert _trace([[1.0, 2.0]]) != _trace([[1.0, 2.0]], success=False)


@pytest.mark.parametrize(
    ("margins", "message"),
    [
        ([1.0, 2.0], "2D"),
        (np.zeros((0, 2)), "at least one step"),
        ([[1.0, float("nan")]], "finite, actually: nan at step 0, channel 1"),
        ([[1.0, 2.0], [float("-inf"), 0.0]], "finite, actually: -inf at step 1, channel 0"),
        ([[1.0, 2.0, 3.0]], "3 columns but there are 2 channels"),
        ([["a", "b"]], "T x K array of numbers"),
    ],
)
def test_bad_margins_are_rejected(margins, message):
    with pytest.raises(ValidationError, match=message):
        _trace(margins)


def test_channel_names_are_unique():
    dup = (CHANNELS[0], CHANNELS[0].model_copy(update={"family": "boundary"}))
    with pytest.raises(ValidationError, match="repeated: grip_force"):
        _trace([[1.0, 1.0]], channels=dup)


@pytest.mark.parametrize(
    ("update", "field"),
    [({"soft_threshold": 0.0}, "soft_threshold"), ({"weight": -1.0}, "weight"),
     ({"shaping": "cubic"}, "shaping"), ({"family": "heat"}, "family"), ({"colour": 1}, "colour")],
)
def test_channel_info_validates(update, field):
    base = {"name": "c", "family": "force", "soft_threshold": 1.0}
    with pytest.raises(ValidationError, match=field):
        ChannelInfo(**{**base, **update})


def test_meta_category_only_at_its_level():
    def meta(**key):
        return EpisodeMeta(**{**META.model_dump(), "key": {**KEY.model_dump(), **key}})

    assert meta() == META
    with pytest.raises(ValidationError, match="only set for W3 instructions"):
        meta(language="W4")
    with pytest.raises(ValidationError, match="only set for V3 observations"):
        meta(vision="V1")
    with pytest.raises(ValidationError, match="level"):
        meta(level="L3")


def test_from_dict_rejects_other_versions_and_unknown_keys():
    data = _trace([[1.0, 1.0]]).to_dict()
    with pytest.raises(ValueError, match="unsupported trace format version 1"):
        EpisodeTrace.from_dict({**data, "version": 1})  # before the meta held a key
    with pytest.raises(ValidationError, match="extra"):
        EpisodeTrace.from_dict({**data, "notes": "x"})
