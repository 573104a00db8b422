"""The simulated lab's magnetic field (lowerlimb.simulation.magnetic_field)."""

from __future__ import annotations

import numpy as np

from lowerlimb.simulation import simulate_bilateral
from lowerlimb.simulation.magnetic_field import LabField, dipole_grid, field_enu_ut

EARTH = 50.0 * np.array([0.0, np.cos(np.deg2rad(65.0)), -np.sin(np.deg2rad(65.0))])


def _line(height_m: float) -> np.ndarray:
    return np.column_stack([np.linspace(-3.0, 3.0, 300), np.zeros(300), np.full(300, height_m)])


def test_the_disturbance_fades_with_height_above_the_floor() -> None:
    grid = dipole_grid(np.vstack([_line(0.0), _line(1.0)]), LabField(), np.random.default_rng(3))
    dev = {h: np.linalg.norm(field_enu_ut(_line(h), EARTH, grid) - EARTH, axis=1) for h in (0.1, 0.35, 1.0)}
    rms = {h: float(np.sqrt(np.mean(d**2))) for h, d in dev.items()}
    assert rms[0.1] > 1.5 * rms[0.35] and rms[0.35] > 2.0 * rms[1.0]
    assert 5.0 < rms[0.1] < 30.0 and rms[1.0] < 2.5  # µT: a lab, not a magnet on the sensor


def test_no_moment_no_disturbance_and_a_dipole_is_a_dipole() -> None:
    pts = _line(0.5)
    pos, mom = dipole_grid(pts, LabField(moment_am2=0.0), np.random.default_rng(0))
    assert np.allclose(field_enu_ut(pts, EARTH, (pos, mom)), EARTH)
    # one dipole of 1 A·m² along z, 1 m straight above it: μ0/4π · 2m / r³ = 0.2 µT along z
    one = (np.array([[0.0, 0.0, -0.5]]), np.array([[0.0, 0.0, 1.0]]))
    b = field_enu_ut(np.array([[0.0, 0.0, 0.5]]), np.zeros(3), one)
    assert np.allclose(b, [[0.0, 0.0, 0.2]], atol=1e-12)


def test_a_dipole_reaches_only_as_far_along_y_as_along_x() -> None:
    """The reach is a box under each stretch of path, so a long bending walk does not pay
    for every dipole of the lab's width (the 5-minute seven-IMU walk took 195 s, now ~15 s)."""
    one = (np.array([[0.0, 0.0, -0.5]]), np.array([[0.0, 0.0, 1.0]]))
    pts = np.array([[0.0, 2.9, 0.5], [0.0, 3.1, 0.5], [2.9, 0.0, 0.5], [3.1, 0.0, 0.5]])
    far_apart = np.vstack([pts, [[0.0, 40.0, 0.5]]])  # one block, far along y: the box widens
    for points in (pts[:1], pts[1:2], pts[2:3], pts[3:4]):
        b = field_enu_ut(points, np.zeros(3), one, reach_m=3.0)
        assert (np.abs(b).max() > 0) == (np.abs(points[0, :2]).max() < 3.0), points
    assert np.abs(field_enu_ut(far_apart, np.zeros(3), one, reach_m=3.0)[0]).max() > 0


def test_the_seven_imu_walk_reads_a_lab_that_the_check_rejects() -> None:
    from lowerlimb.orientation.magnetic import check_magnetic_field

    lab = simulate_bilateral(20.0, 5)
    uniform = simulate_bilateral(20.0, 5, lab_field=None)
    assert lab.trial.mag is not None and uniform.trial.mag is not None

    def cv(trial, s):
        n = np.linalg.norm(trial.mag[s][300:], axis=1)
        return float(n.std() / n.mean())

    assert cv(uniform.trial, "left_foot") < 0.03  # the magnetometer noise alone: ~1 %
    assert 0.08 < cv(lab.trial, "left_foot") < 0.3 and cv(lab.trial, "pelvis") < 0.05
    assert not check_magnetic_field(lab.trial.leg("left")).usable
    assert check_magnetic_field(uniform.trial.leg("left")).usable
    # the same seed draws the same walk and noise: only the field differs
    assert np.array_equal(lab.trial.gyr["left_thigh"], uniform.trial.gyr["left_thigh"])


def test_cli_simulates_the_lab_or_a_uniform_field(tmp_path) -> None:
    from lowerlimb.cli import main
    from lowerlimb.io.bilateral_trial import BilateralTrial

    cvs = {}
    for flag in ([], ["--uniform-field"]):
        out = tmp_path / f"t{len(flag)}.csv"
        argv = ["simulate", "--side", "both", "--duration", "8", "--seed", "2", "--out", str(out), *flag]
        assert main(argv) == 0
        trial = BilateralTrial.from_csv(out)
        assert trial.mag is not None
        n = np.linalg.norm(trial.mag["right_foot"][200:], axis=1)
        cvs[bool(flag)] = float(n.std() / n.mean())
    assert cvs[True] < 0.03 < 0.06 < cvs[False]  # noise alone: ~1 %
