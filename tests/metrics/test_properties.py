"""The paper's identities, checked on random traces with hypothesis."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fsvla.metrics.aggregate import aggregate
from fsvla.metrics.episode import episode_metrics
from fsvla.metrics.shaping import SHAPINGS
from fsvla.metrics.trace import FAMILIES, ChannelInfo, EpisodeMeta, EpisodeTrace
from fsvla.run.key import EpisodeKey

META = EpisodeMeta(key=EpisodeKey(scenario="s", suite="force", embodiment="panda", seed=0),
                   policy="p")

channel_specs = st.tuples(
    st.sampled_from(FAMILIES),
    st.floats(min_value=0.05, max_value=2.0),  # ε
    st.floats(min_value=0.0, max_value=3.0),  # w
    st.sampled_from(SHAPINGS),
)


@st.composite
def traces(draw) -> EpisodeTrace:
    specs = draw(st.lists(channel_specs, min_size=1, max_size=4))
    horizon = draw(st.integers(min_value=1, max_value=25))
    # margins from a small grid around the thresholds so that q = 0 and q = ε occur
    cells = st.sampled_from([-1.0, -0.05, 0.0, 0.05, 0.5, 1.0, 2.0, 3.0])
    margins = draw(st.lists(st.lists(cells, min_size=len(specs), max_size=len(specs)),
                            min_size=horizon, max_size=horizon))
    channels = tuple(
        ChannelInfo(name=f"c{k}", family=fam, soft_threshold=eps, weight=w, shaping=g)
        for k, (fam, eps, w, g) in enumerate(specs)
    )
    return EpisodeTrace(channels=channels, margins=margins, success=draw(st.booleans()),
                        meta=META)


@settings(max_examples=150, deadline=None)
@given(traces())
def test_episode_identities(trace):
    m = episode_metrics(trace)
    q, eps = trace.margins, np.array([c.soft_threshold for c in trace.channels])
    rets = [ch.ret for ch in m.channels]
    assert m.cc >= 0 and m.cc_normalised >= 0
    assert all(m.ret >= r for r in rets)  # RET >= RET_k
    assert m.ret <= sum(rets)  # RET <= Σ RET_k
    assert m.ret <= m.horizon == q.shape[0]
    assert m.violation == any(ch.hard_crossed for ch in m.channels) == bool((q < 0).any())
    assert m.cc == pytest.approx(sum(ch.cc for ch in m.channels), rel=1e-12)
    for k, ch in enumerate(m.channels):
        assert ch.ret == int((q[:, k] < eps[k]).sum())
        assert ch.hard_crossed == (ch.first_violation_step is not None)
        if ch.first_violation_step is not None:
            assert q[ch.first_violation_step, k] < 0 <= q[: ch.first_violation_step, k].min(
                initial=np.inf)
        # a weighted channel costs something exactly when it is exposed
        if trace.channels[k].weight > 0:
            assert (ch.cc > 0) == (ch.ret > 0)
    # a family's exposure is at least each member's and at most their sum
    for fam in m.families:
        members = [ch.ret for ch in m.channels if ch.family == fam.family]
        assert max(members) <= fam.ret <= sum(members)
    # with no hard violation, normalised CC lies in [0, 1] ([0, e - 1] with exponential)
    if not m.violation:
        bound = math.e - 1 if any(c.shaping == "exponential" for c in trace.channels) else 1.0
        assert m.cc_normalised <= bound + 1e-12
    assert 0.0 <= m.sasr() <= m.sasr(0.0) == float(m.quadrant == "safe_success")


@settings(max_examples=40, deadline=None)
@given(st.lists(traces(), min_size=1, max_size=12), st.floats(min_value=0.0, max_value=5.0))
def test_aggregate_identities(batch, lam):
    episodes = [episode_metrics(t) for t in batch]
    agg = aggregate(episodes, lam=lam, n_resamples=200)
    rates = [agg.ssr, agg.usr, agg.sfr, agg.ufr]
    assert sum(r.estimate for r in rates) == pytest.approx(1.0, abs=1e-12)  # a partition
    counts = [sum(ep.quadrant == q for ep in episodes) for q in
              ("safe_success", "unsafe_success", "safe_failure", "unsafe_failure")]
    assert sum(counts) == len(episodes)
    assert [r.estimate for r in rates] == [c / len(episodes) for c in counts]
    assert 0.0 <= agg.sasr.estimate <= agg.ssr.estimate + 1e-12  # SASR <= SSR
    zero = aggregate(episodes, lam=0.0, n_resamples=200)
    assert zero.sasr.estimate == pytest.approx(agg.ssr.estimate, abs=1e-12)  # SASR(0) = SSR
    assert agg.cc.estimate >= 0
    for interval in [*rates, agg.cc, agg.cc_normalised, agg.ret_fraction, agg.sasr]:
        assert interval.low - 1e-12 <= interval.estimate <= interval.high + 1e-12
