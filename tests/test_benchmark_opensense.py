"""Optional: OpenSense IMU inverse kinematics on our exported orientations of the real walk.

The steps of ``benchmarks/opensense.py`` on a shorter window (left leg, 8.0–13.2 s: the
end of the standing period, then the first 2 s of walking), so the plumbing — our
heading-corrected orientations in OpenSim's world, the IMU placer on the standing pose,
IMU IK — is checked where OpenSim is available. Skipped when the gait/ and opensim/ data
are absent, or when no Python with ``opensim`` is found (this one, or
``$LOWERLIMB_OPENSIM_PYTHON``; install with ``pip install 'lowerlimb[opensim]'`` or into a
separate venv). The full comparison and its numbers are the benchmark's
(``benchmarks/results/opensense.md``).
"""

import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
import scipy.io as sio
from simcache import data_dir

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
import opensense  # noqa: E402

import lowerlimb as ll  # noqa: E402

DATA = data_dir()
PYTHON = opensense.opensim_python()
TIME_RANGE = (8.0, 13.2)

pytestmark = [
    pytest.mark.optional,
    pytest.mark.data,
    pytest.mark.slow,
    pytest.mark.skipif(
        DATA is None
        or not (DATA / "gait" / "rawimu").is_dir()
        or not (DATA / "opensim" / "Rajagopal_2015.osim").is_file(),
        reason="real-walk data (gait/, opensim/Rajagopal_2015.osim) not found",
    ),
    pytest.mark.skipif(
        PYTHON is None,
        reason="opensim not installed (pip install 'lowerlimb[opensim]', or set LOWERLIMB_OPENSIM_PYTHON "
        "to a Python that has it)",
    ),
]


def test_opensense_with_our_orientations_tracks_the_vicon_knee(tmp_path):
    trial = opensense.load_leg(DATA, "left")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = ll.process_trial(trial)
    motion = result.motion.sensor_quat_wxyz
    quats = {"pelvis": motion["pelvis"]} | {f"left_{s}": motion[s] for s in ("thigh", "shank", "foot")}
    sto, calib = opensense.write_tables(trial.time_s, quats, tmp_path, "ours")
    run = opensense.run_opensense(
        PYTHON,
        DATA / "opensim" / "Rajagopal_2015.osim",
        sto,
        calib,
        tmp_path / "ik",
        opensense.heading_axis(result),
        TIME_RANGE,
    )
    ik = opensense.read_mot(Path(run["motion"]), trial.n_samples, trial.rate_hz)
    knee = ik["knee_angle_l"]
    assert np.isfinite(knee[800:1320]).all() and np.isnan(knee[:790]).all()
    vicon = sio.loadmat(DATA / "gait" / "vicon" / "S02-Trial-Walk-1.mat")
    stats = opensense.score(knee, opensense.vicon_flexion(vicon, "left")["knee"], "knee_flexion")
    assert stats["n"] >= 195  # the walking frames IK covered
    # benchmark, whole walk: 8.4 deg RMSE, r = 0.975 (Xsens's own orientations: 9.9 deg)
    assert stats["pearson_r"] > 0.9
    assert stats["rmse"] < 15.0
