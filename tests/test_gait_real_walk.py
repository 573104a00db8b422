"""The gait benchmark on the real walk (gait/ in the shared data), with bounds ~2-3x the measured errors."""

import importlib.util
from pathlib import Path

import pytest
from simcache import data_dir

DATA = data_dir()
pytestmark = [
    pytest.mark.data,
    pytest.mark.skipif(DATA is None or not (DATA / "gait").is_dir(), reason="real-walk data absent"),
]


def _benchmark():
    path = Path(__file__).resolve().parents[1] / "benchmarks" / "gait_events.py"
    spec = importlib.util.spec_from_file_location("gait_events_benchmark", path)
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_real_walk_events_stationary_and_strides():
    assert DATA is not None
    res = _benchmark().run(DATA)
    for side in ("left", "right"):
        ic = res["events"][f"{side}_initial_contact"]["straight"]
        to = res["events"][f"{side}_toe_off"]["straight"]
        assert ic["n"] >= 4 and to["n"] >= 4
        # IC from the foot's heel-rocker onset vs Zeni contacts: issue 11 goal (measured 14-15 ms
        # median, 19-37 ms worst; the shank minimum used before was ~60 ms late)
        assert ic["median_abs_ms"] <= 20 and ic["worst_abs_ms"] <= 40
        assert to["median_abs_ms"] < 100 and to["worst_abs_ms"] < 150
        # IC precedes the heel marker coming to rest (end of the heel rocker, measured ~-50 ms)
        hs = res["events"][f"{side}_initial_contact_vs_heel_stop"]["straight"]
        assert hs["bias_ms"] < -20
        st = res["stationary"][side]
        assert st["agreement_pct"] > 80.0  # measured ~92-94 %
        assert abs(st["onset_median_ms"]) < 150 and abs(st["offset_median_ms"]) < 100
    sp = res["spatial"]
    assert sp["n_straight_strides"] >= 5
    assert sp["stride_length_err_pct"]["median_abs"] < 3.0  # measured ~1.2 %
    assert sp["stride_length_err_pct"]["worst_abs"] < 10.0
    assert abs(sp["cadence_imu_from_strides"] - sp["cadence_vicon"]) < 5.0
    assert abs(sp["speed_imu_m_s"] - sp["speed_vicon_m_s"]) < 0.15
