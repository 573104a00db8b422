"""Every demo runs with --quick and writes its table and picture; numbers stay within their goals."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from types import ModuleType

DEMOS = Path(__file__).resolve().parents[1] / "demos"
# the scripts import their shared helpers (demos/_common.py) as when run from demos/
if str(DEMOS) not in sys.path:
    sys.path.insert(0, str(DEMOS))


def load(name: str) -> ModuleType:
    spec = importlib.util.spec_from_file_location(f"demo_{name}", DEMOS / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def run(name: str, tmp_path: Path) -> tuple[object, Path]:
    result = load(name).main(["--quick", "--out", str(tmp_path)])
    out = tmp_path / name
    assert (out / f"{name}.md").read_text(encoding="utf-8").startswith("# ")
    assert (out / f"{name}.png").stat().st_size > 10_000
    return result, out


def test_every_demo_is_listed_and_documented() -> None:
    readme = (DEMOS / "README.md").read_text(encoding="utf-8")
    scripts = sorted(p for p in DEMOS.glob("*.py") if not p.name.startswith("_"))
    assert len(scripts) == 6
    for script in scripts:
        assert f"python demos/{script.name}" in readme
        doc = load(script.stem).__doc__
        assert doc is not None and len(doc.strip().splitlines()) == 1
        assert 'if __name__ == "__main__":' in script.read_text(encoding="utf-8")


def test_calibrate_walk(tmp_path: Path) -> None:
    result, _ = run("calibrate_walk", tmp_path)
    assert isinstance(result, dict)
    assert result["knee_flexion"] < 3.0
    assert result["hip_to_ankle_mm"] < 40.0


def test_compare_solvers(tmp_path: Path) -> None:
    result, _ = run("compare_solvers", tmp_path)
    assert isinstance(result, dict)
    # the local solvers agree to well within a millimetre on the same data
    assert abs(result["gn"]["worst_mm"] - result["casadi"]["worst_mm"]) < 1.0
    assert result["casadi"]["worst_mm"] < 30.0


def test_sensor_slip(tmp_path: Path) -> None:
    result, _ = run("sensor_slip", tmp_path)
    assert isinstance(result, dict)
    tilt = [k for k in result if "tilt" in k]
    old = next(k for k in tilt if k.endswith(": old calibration"))
    new = next(k for k in tilt if k.endswith(": re-calibrated"))
    # a 10° tilt about the flexion axis is a ~10° knee flexion offset until re-calibration
    assert result[old][0] > 5.0
    assert result[new][0] < 3.0


def test_s2j_squat(tmp_path: Path) -> None:
    result, _ = run("s2j_squat", tmp_path)
    assert isinstance(result, dict)
    m1 = next(v for k, v in result.items() if "default" in k)
    m3 = next(v for k, v in result.items() if k.startswith("M3"))
    for test in m1:
        assert m3[test] < m1[test]


def test_inverse_dynamics(tmp_path: Path) -> None:
    result, out = run("inverse_dynamics", tmp_path)
    assert isinstance(result, dict)
    assert (out / "calibrated.urdf").is_file()
    true_angles = next(v for k, v in result.items() if k.endswith("true angles"))
    assert true_angles["hip_percent"] <= 5.0
    assert true_angles["knee_percent"] <= 5.0
    estimated = next(v for k, v in result.items() if "estimated angles" in k)
    assert max(estimated.values()) <= 5.0


def test_inverse_dynamics_both_legs(tmp_path: Path) -> None:
    result, out = run("inverse_dynamics_both_legs", tmp_path)
    assert isinstance(result, dict)
    assert (out / "lower_body.urdf").is_file()
    # the ISB y-up single leg under default gravity vs the z-up lower body (REP 103)
    assert result["phantom_hip_torque_single_leg_isb_Nm"] > 40.0
    assert result["phantom_hip_torque_lower_body_Nm"] < 1.0
    # the split ground reaction balances the whole body in every contact sample
    assert result["base_residual_without_grf_N"] > 500.0
    assert result["base_residual_with_grf_N"] < 1e-6
    assert 5.0 < result["double_support_pct"] < 40.0
    # the right leg walks the left leg's gait: symmetric peak moments
    assert result["hip_flexion_si_pct"] < 15.0 and result["knee_flexion_si_pct"] < 15.0
