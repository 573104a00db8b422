import numpy as np
import pytest
from rigid_pair import rigid_pair

from lowerlimb.calibration import ExcitationWarning, calibrate_hinge_axis, estimate_hinge_axis
from lowerlimb.calibration.geometry import angle_between_deg
from lowerlimb.errors import InputError


def _noisy(seed, **kw):
    return rigid_pair(
        "hinge",
        seed=seed,
        duration_s=30.0,
        still_s=1.5,
        gyro_noise=0.015,
        acc_noise=0.08,
        gyro_bias=0.01,
        **kw,
    )


@pytest.mark.parametrize("method", ["casadi", "gn"])
def test_recovers_axes_noise_free(method):
    p = rigid_pair("hinge", seed=1, duration_s=20.0, still_s=1.0, one_sided=True)
    jp, jc = estimate_hinge_axis(p.gyr_parent, p.gyr_child, rate_hz=p.rate_hz, method=method)
    assert angle_between_deg(jp, p.axis_parent) < 0.05
    assert angle_between_deg(jc, p.axis_child) < 0.05


@pytest.mark.parametrize("seed", [2, 3])
def test_recovers_axes_with_noise_and_consistent_signs(seed):
    p = _noisy(seed, one_sided=True)
    res = calibrate_hinge_axis(p.gyr_parent, p.gyr_child, rate_hz=p.rate_hz)
    jp, jc = res.axis_in_parent_sensor, res.axis_in_child_sensor
    # signed: same physical direction, and the rotation is negative about it
    assert angle_between_deg(jp, p.axis_parent) < 0.5
    assert angle_between_deg(jc, p.axis_child) < 0.5
    assert res.sign_coherence[0] > 0.9
    assert res.sign_coherence[0] - res.sign_coherence[1] > 0.2
    assert np.all(res.axis_std_deg < 0.5)
    assert res.warnings == []


def test_overall_sign_follows_the_rotation_sense():
    # the same motion described with the axes reversed: q >= 0 about -j, the rule flips
    p = rigid_pair(
        "hinge",
        seed=4,
        duration_s=20.0,
        still_s=1.0,
        one_sided=True,
        axis_parent=(-0.2, -0.1, -0.97),
        axis_child=(0.1, -0.3, -0.95),
    )
    jp, jc = estimate_hinge_axis(p.gyr_parent, p.gyr_child, rate_hz=p.rate_hz)
    assert angle_between_deg(jp, p.axis_parent) < 0.1
    assert angle_between_deg(jc, p.axis_child) < 0.1


def test_accelerometers_cross_check_the_sign():
    p = _noisy(5, one_sided=True)
    res = calibrate_hinge_axis(
        p.gyr_parent, p.gyr_child, rate_hz=p.rate_hz, acc_parent=p.acc_parent, acc_child=p.acc_child
    )
    assert res.acc_sign_correlation > 0.9
    assert angle_between_deg(res.axis_in_child_sensor, p.axis_child) < 0.5


@pytest.mark.parametrize("method", ["dwpso+casadi", "gwo+casadi", "dwpso"])
def test_swarm_methods(method):
    p = rigid_pair("hinge", seed=6, duration_s=20.0, still_s=1.0, one_sided=True)
    jp, jc = estimate_hinge_axis(p.gyr_parent, p.gyr_child, rate_hz=p.rate_hz, method=method)
    tol = 2.0 if method == "dwpso" else 0.05
    assert angle_between_deg(jp, p.axis_parent) < tol
    assert angle_between_deg(jc, p.axis_child) < tol


def test_no_motion_warns_and_stays_finite():
    rng = np.random.default_rng(1)
    w = [0.01 + 0.015 * rng.normal(size=(800, 3)) for _ in range(2)]
    with pytest.warns(ExcitationWarning) as rec:
        res = calibrate_hinge_axis(w[0], w[1], rate_hz=100.0, joint="knee")
    assert any("hardly rotates" in str(r.message) for r in rec)
    assert np.all(np.isfinite(res.axis_in_parent_sensor))
    assert np.isclose(np.linalg.norm(res.axis_in_child_sensor), 1.0)
    assert all(m.startswith("knee:") for m in res.warnings)


def test_input_errors():
    p = rigid_pair("hinge", seed=1, duration_s=3.0)
    with pytest.raises(InputError, match="both acc_parent and acc_child"):
        estimate_hinge_axis(p.gyr_parent, p.gyr_child, rate_hz=100.0, acc_parent=p.acc_parent)
    with pytest.raises(InputError, match="unknown calibration method"):
        estimate_hinge_axis(p.gyr_parent, p.gyr_child, rate_hz=100.0, method="pso")
    with pytest.raises(InputError, match="rate_hz"):
        estimate_hinge_axis(p.gyr_parent, p.gyr_child, rate_hz=-1)


def test_axis_result_serialises_strictly_and_round_trips():
    import json

    from lowerlimb.calibration import HingeAxisCalibration

    p = _noisy(7, one_sided=True)
    res = calibrate_hinge_axis(p.gyr_parent, p.gyr_child, rate_hz=p.rate_hz)
    d = json.loads(json.dumps(res.to_dict(), allow_nan=False))
    assert d["acc_sign_correlation"] is None  # not checked without accelerometers
    back = HingeAxisCalibration.from_dict(d)
    assert np.allclose(back.axis_in_parent_sensor, res.axis_in_parent_sensor)
    assert back.rms_residual == pytest.approx(res.rms_residual)
    assert back.to_dict() == d


def test_hinge_joint_centre_lies_on_the_axis():
    from lowerlimb.calibration import calibrate_hinge_joint
    from lowerlimb.calibration.geometry import distance_to_line

    p = _noisy(8, one_sided=True)
    h = calibrate_hinge_joint(
        p.acc_parent, p.gyr_parent, p.acc_child, p.gyr_child, rate_hz=p.rate_hz, joint="knee"
    )
    assert 1000 * distance_to_line(h.center_in_parent_sensor, p.center_parent, p.axis_parent) < 5
    assert 1000 * distance_to_line(h.center_in_child_sensor, p.center_child, p.axis_child) < 5
    # eq. 16: the point of the axis nearest the two sensors
    jp, jc = h.axis_in_parent_sensor, h.axis_in_child_sensor
    assert abs(jp @ h.center_in_parent_sensor + jc @ h.center_in_child_sensor) < 1e-9
    assert h.axis.acc_sign_correlation > 0.9
    assert h.warnings == []
    d = h.to_dict()
    assert d["type"] == "hinge" and d["rms_residual_axis"] == pytest.approx(h.axis.rms_residual)
