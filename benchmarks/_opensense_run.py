"""Run OpenSense (IMU placer, then IMU inverse kinematics) on one orientation table; stdlib + opensim only.

Run by ``benchmarks/opensense.py`` with a Python that has the ``opensim`` package (4.6):
``python _opensense_run.py CONFIG.json`` where CONFIG holds ``model`` (the .osim),
``calibration_sto`` (the standing posture: the IMU placer uses its first row),
``orientations_sto`` (the trial), ``out_dir``, ``base_heading_axis`` (the pelvis IMU axis
that points forward, e.g. ``"-z"``) and optionally ``time_range`` ``[t0, t1]``. Both
tables are already in OpenSim's y-up world, so ``sensor_to_opensim_rotations`` is 0 0 0.
Prints one JSON line: the calibrated model, the IK motion file and the wall times, s.
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path


def main(config_path: str) -> None:
    import opensim as osim

    cfg = json.loads(Path(config_path).read_text(encoding="utf-8"))
    out = Path(cfg["out_dir"])
    out.mkdir(parents=True, exist_ok=True)
    osim.Logger.setLevelString("Warn")
    zero = osim.Vec3(0, 0, 0)

    t0 = time.perf_counter()
    placer = osim.IMUPlacer()
    placer.set_model_file(cfg["model"])
    placer.set_orientation_file_for_calibration(cfg["calibration_sto"])
    placer.set_sensor_to_opensim_rotations(zero)
    placer.set_base_imu_label("pelvis_imu")
    placer.set_base_heading_axis(cfg["base_heading_axis"])
    calibrated = out / "calibrated_model.osim"
    placer.set_output_model_file(str(calibrated))
    placer.run(False)
    t_place = time.perf_counter() - t0

    t0 = time.perf_counter()
    ik = osim.IMUInverseKinematicsTool()
    ik.set_model_file(str(calibrated))
    ik.set_orientations_file(cfg["orientations_sto"])
    ik.set_sensor_to_opensim_rotations(zero)
    ik.set_results_directory(str(out))
    motion = out / "ik.mot"
    ik.set_output_motion_file(str(motion))
    if cfg.get("time_range"):
        ik.set_time_range(0, float(cfg["time_range"][0]))
        ik.set_time_range(1, float(cfg["time_range"][1]))
    ik.run(False)
    t_ik = time.perf_counter() - t0
    result = {
        "calibrated_model": str(calibrated),
        "motion": str(motion),
        "placer_s": t_place,
        "ik_s": t_ik,
        "opensim_version": osim.GetVersion(),
    }
    print(json.dumps(result))


if __name__ == "__main__":
    main(sys.argv[1])
