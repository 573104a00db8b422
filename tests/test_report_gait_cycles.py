"""A walking trial's report shows gait-cycle curves; a trial without gait does not."""

from __future__ import annotations

import warnings

from simcache import cached_simulation

import lowerlimb as ll
from lowerlimb.outputs import gait_cycles_html


def _result(motion: str):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return ll.process_trial(cached_simulation(motion, 30.0, 4).trial)


def test_walk_report_has_gait_cycles():
    html = gait_cycles_html(_result("walk"))
    assert "id='gait-cycles'" in html and "data:image/png;base64," in html
    strides = int(html.split("Strides: left ")[1].split(".")[0])
    assert strides >= 10  # a 30 s simulated walk at ~1 Hz stride, minus the standing start


def test_squat_report_has_none():
    assert gait_cycles_html(_result("squat")) == ""
