"""Joint centre and hinge axis on a real two-segment rig, ours beside the peers (issue 9/12).

Data: ``DIR/rig`` (see ``../shared/data/README.md``; Weygers & Kok 2020, the
dfjimu data): two IMUs at 50 Hz on two rigid segments joined by a hinge
(``1D_01``), a 2-DoF joint (``2D_01``) or a ball joint (``3D_01``), moved by
hand, with optical truth: ``r_12`` / ``r_21`` = the joint centre in sensor 1's
and sensor 2's frame (m), and the optical sensor-to-global quaternions.

Methods (sensor 1 = parent, sensor 2 = child):

- ``ours centre``: :func:`lowerlimb.estimate_joint_center` (defaults) on every trial;
- ``dfjimu``: ``dfjimu.estimate_lever_arms(gyr1, gyr2, acc1, acc2, Fs)`` (PyPI
  ``dfjimu``, defaults); its vectors point from the joint to the sensor, so
  they are negated;
- ``ours axis``: :func:`lowerlimb.estimate_hinge_axis` with the
  accelerometers (defaults), hinge trial only;
- ``qmt``: ``qmt.jointAxisEstHingeOlsson(acc1, acc2, gyr1, gyr2)`` (PyPI ``qmt``,
  Olsson et al. 2020, default settings), hinge trial only.

Accuracy:

- centre, 2D and 3D trials: ``‖ĉ_1 − r_12‖`` and ``‖ĉ_2 − r_21‖``, mm;
- centre, hinge trial: every point of the hinge axis satisfies the constraint,
  so the error is the distance of ``ĉ_S`` to the true axis line through
  ``r_12`` (``r_21``), mm;
- true hinge axis in each sensor frame, from the optical relative rotation
  ``R_12(t) = R_1(t)ᵀ R_2(t)``: for a hinge ``R_12(t) j_2 = j_1`` for all t,
  so ``j_2`` is the eigenvector of the smallest eigenvalue of
  ``Σ_t (R_12(t) − R̄)ᵀ (R_12(t) − R̄)`` and ``j_1 = R̄ j_2 / ‖R̄ j_2‖``;
  the spread ``‖R_12(t) j_2 − j_1‖`` is reported as a check of the truth;
- axis error: unsigned angle to the true axis in each frame (a hinge axis has
  no preferred sign), deg.

Diagnosis (second table, ours only, in this process): the centre error under
variants of the preparation (no prefilter; fixed 5 / 8 / 12 Hz cut-offs; a
0.14 s or a degree-2 Savitzky–Golay α; no gyro-bias removal), with the
accelerometers shifted by ±1 sample against the gyros, the RMS residual of
eq. 3 at the optical truth against the one at our estimate, and the linear
least-squares solution of the stronger 3-D constraint ``g_1 = R_12 g_2``
with the *optical* relative rotation (no norm, no orientation filter).

Time: each (method, trial) runs in a fresh worker process (``--worker``):
``import`` = importing the library, ``cold`` = its first call in that
process (CasADi construction, numba compilation or cache load, lazy imports),
``warm`` = median of ``--repeats`` further calls; the cold goal is judged on
import + cold (``import lowerlimb`` is lazy, so a user's first
``ll.estimate_joint_center`` call pays both). NumPy and ``scipy.io`` are
already imported (the worker read the data) and are not counted. Workers run with
``OPENBLAS_NUM_THREADS=1`` on a shared 2-core machine, so times are
indicative to ~20 %.

Environment: the peers are kept out of the project venv (qmt 0.2.4 pulls in a
web stack: aiohttp, transplant, qasync, orjson, ...). They live in a separate
venv made with ``python -m venv /work/venv-peers && /work/venv-peers/bin/pip
install "numpy<2" qmt==0.2.4 dfjimu==0.4.1 && /work/venv-peers/bin/pip
install -e <this checkout>`` (PyPI wheels; no sdist build was needed). The
last step upgraded that venv's NumPy to 2.4.6 (the project's dependencies
need NumPy 2). Under NumPy 2 qmt's compiled extensions (``qmt.cpp.*``) fail to
import ("numpy.core.multiarray failed to import"), but
``jointAxisEstHingeOlsson`` is pure Python/NumPy and runs; ``import qmt``
works. A worker first tries the interpreter running this script and, when
the import fails there, ``--peer-python`` (default
``/work/venv-peers/bin/python`` if present); a method that imports nowhere
is reported with the exact import error instead of numbers. Our methods
always run in the interpreter running this script, with this checkout first
on ``sys.path`` / ``PYTHONPATH`` (the venv's editable install may point at
another checkout).

Usage: ``python benchmarks/rig.py [--data DIR] [--repeats 7] [--peer-python PY] [--out DIR]``
(``--data`` defaults to ``$LOWERLIMB_DATA`` or ``../shared/data`` beside
the checkout). Writes ``rig.{md,json}`` into ``--out`` and prints the Markdown.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import json  # noqa: E402
import statistics  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402
from collections.abc import Callable  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

import numpy as np  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
# Measure this checkout's lowerlimb, not whatever the venv's editable install points at.
sys.path.insert(0, str(REPO))

TRIALS = ("1D_01", "2D_01", "3D_01")
HINGE_TRIAL = "1D_01"
#: method -> (module to import, what it estimates, trials it runs on)
METHODS: dict[str, tuple[str, str, tuple[str, ...]]] = {
    "ours centre": ("lowerlimb", "centre", TRIALS),
    "dfjimu": ("dfjimu", "centre", TRIALS),
    "ours axis": ("lowerlimb", "axis", (HINGE_TRIAL,)),
    "qmt": ("qmt", "axis", (HINGE_TRIAL,)),
}
#: Goals of issue 9 / 12: centre ≤ 5 mm, axis ≤ 1°, cold ≤ 0.5 s, warm ≤ dfjimu's.
GOAL_CENTER_MM = 5.0
GOAL_AXIS_DEG = 1.0
GOAL_COLD_S = 0.5
DEFAULT_PEER_PYTHON = Path("/work/venv-peers/bin/python")


def default_data_dir() -> Path:
    env = os.environ.get("LOWERLIMB_DATA")
    return Path(env) if env else REPO.parent / "shared" / "data"


def load_trial(data_dir: Path, trial: str) -> dict[str, Any]:
    """Signals (N, 3) each, rate (Hz), optical quaternions (N, 4) wxyz and the true centres (m)."""
    from scipy.io import loadmat

    d = loadmat(str(data_dir / "rig" / f"data_{trial}.mat"))["data"][0, 0]
    s = np.asarray(d["sensorData"], dtype=float)
    ref = np.asarray(d["ref"], dtype=float)
    return {
        "rate_hz": float(np.asarray(d["rate"]).ravel()[0]),
        "acc1": np.ascontiguousarray(s[:, 0:3]),
        "gyr1": np.ascontiguousarray(s[:, 3:6]),
        "acc2": np.ascontiguousarray(s[:, 6:9]),
        "gyr2": np.ascontiguousarray(s[:, 9:12]),
        "q1": ref[:, 0:4],
        "q2": ref[:, 4:8],
        "r_12": np.asarray(d["r_12"], dtype=float).ravel(),
        "r_21": np.asarray(d["r_21"], dtype=float).ravel(),
    }


def quat_wxyz_to_matrix(q: np.ndarray) -> np.ndarray:
    """(N, 4) unit quaternions, scalar first -> (N, 3, 3) rotation matrices."""
    q = q / np.linalg.norm(q, axis=1, keepdims=True)
    w, x, y, z = q.T
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], axis=-1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], axis=-1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=-1),
        ],
        axis=-2,
    )


def true_hinge_axes(q1: np.ndarray, q2: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """True hinge axis in sensor 1 and sensor 2 frames from the optical quaternions.

    Returns:
        ``(j_1, j_2, spread_deg)``: unit axes (same physical direction) and the
        RMS angle between ``R_12(t) j_2`` and ``j_1`` over the trial, deg.
    """
    ok = np.isfinite(q1).all(axis=1) & np.isfinite(q2).all(axis=1)
    R1, R2 = quat_wxyz_to_matrix(q1[ok]), quat_wxyz_to_matrix(q2[ok])
    R12 = np.einsum("nji,njk->nik", R1, R2)  # R_1ᵀ R_2: sensor-2 coordinates -> sensor-1 coordinates
    Rm = R12.mean(axis=0)
    D = R12 - Rm
    _, V = np.linalg.eigh(np.einsum("nji,njk->ik", D, D))
    j2 = V[:, 0]
    j1 = Rm @ j2
    j1 /= np.linalg.norm(j1)
    cosang = np.clip(R12 @ j2 @ j1, -1.0, 1.0)
    return j1, j2, float(np.degrees(np.sqrt(np.mean(np.arccos(cosang) ** 2))))


def distance_to_line(p: np.ndarray, point: np.ndarray, direction: np.ndarray) -> float:
    d = direction / np.linalg.norm(direction)
    v = p - point
    return float(np.linalg.norm(v - (v @ d) * d))


def unsigned_angle_deg(a: np.ndarray, b: np.ndarray) -> float:
    c = abs(float(a @ b)) / (np.linalg.norm(a) * np.linalg.norm(b))
    return float(np.degrees(np.arccos(min(1.0, c))))


# ---------------------------------------------------------------- worker (one fresh process)


def _estimator(method: str) -> Callable[[dict[str, Any]], dict[str, list[float]]]:
    """Import the method's library and return ``trial -> estimate`` (vectors in sensor frames)."""
    if method == "ours centre":
        from lowerlimb import estimate_joint_center

        def ours_centre(t: dict[str, Any]) -> dict[str, list[float]]:
            c1, c2 = estimate_joint_center(t["acc1"], t["gyr1"], t["acc2"], t["gyr2"], rate_hz=t["rate_hz"])
            return {"center_1": c1.tolist(), "center_2": c2.tolist()}

        return ours_centre
    if method == "ours axis":
        from lowerlimb import estimate_hinge_axis

        def ours_axis(t: dict[str, Any]) -> dict[str, list[float]]:
            j1, j2 = estimate_hinge_axis(
                t["gyr1"], t["gyr2"], rate_hz=t["rate_hz"], acc_parent=t["acc1"], acc_child=t["acc2"]
            )
            return {"axis_1": j1.tolist(), "axis_2": j2.tolist()}

        return ours_axis
    if method == "dfjimu":
        import dfjimu

        def dfj(t: dict[str, Any]) -> dict[str, list[float]]:
            r1, r2 = dfjimu.estimate_lever_arms(t["gyr1"], t["gyr2"], t["acc1"], t["acc2"], t["rate_hz"])
            # dfjimu's lever arms point from the joint to the sensor: negate.
            return {"center_1": (-np.asarray(r1)).tolist(), "center_2": (-np.asarray(r2)).tolist()}

        return dfj
    if method == "qmt":
        import qmt

        def olsson(t: dict[str, Any]) -> dict[str, list[float]]:
            j1, j2 = qmt.jointAxisEstHingeOlsson(t["acc1"], t["acc2"], t["gyr1"], t["gyr2"])
            return {"axis_1": np.ravel(j1).tolist(), "axis_2": np.ravel(j2).tolist()}

        return olsson
    raise SystemExit(f"unknown method {method!r}; use one of {', '.join(METHODS)}")


def _version(module: str) -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version(module)
    except PackageNotFoundError:
        return "?"


def worker(method: str, data_dir: Path, trial: str, repeats: int) -> dict[str, Any]:
    """Time one method on one trial in this (fresh) process."""
    t = load_trial(data_dir, trial)
    t0 = time.perf_counter()
    try:
        fn = _estimator(method)
    except ImportError as e:
        return {"error": f"{type(e).__name__}: {e}", "python": sys.executable}
    import_s = time.perf_counter() - t0
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        t0 = time.perf_counter()
        est = fn(t)
        cold_s = time.perf_counter() - t0
        warm = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            fn(t)
            warm.append(time.perf_counter() - t0)
    return {
        "estimate": est,
        "import_s": import_s,
        "cold_s": cold_s,
        "warm_s": statistics.median(warm) if warm else None,
        "warm_all_s": warm,
        "warnings": sorted({str(w.message) for w in caught}),
        "python": sys.executable,
        "numpy": np.__version__,
        "package": f"{METHODS[method][0]} {_version(METHODS[method][0])}",
    }


# ---------------------------------------------------------------- diagnosis (ours, in process)

#: (label, CalibrationOptions keywords)
VARIANTS: tuple[tuple[str, dict[str, Any]], ...] = (
    ("defaults", {}),
    ("fitted at the recorded 50 Hz (no interpolation)", {"min_fit_rate_hz": None}),
    ("no prefilter", {"prefilter": False}),
    ("cut-off 5 Hz", {"cutoff_hz": 5.0}),
    ("cut-off 8 Hz", {"cutoff_hz": 8.0}),
    ("cut-off 12 Hz", {"cutoff_hz": 12.0}),
    ("α window 0.14 s", {"angacc_window_s": 0.14}),
    ("α degree 2, 0.06 s", {"angacc_polyorder": 2, "angacc_window_s": 0.06}),
    ("no gyro-bias removal", {"remove_gyro_bias": False}),
)


def centre_errors_mm(t: dict[str, Any], trial: str, c1: np.ndarray, c2: np.ndarray) -> tuple[float, float]:
    if trial == HINGE_TRIAL:
        j1, j2, _ = true_hinge_axes(t["q1"], t["q2"])
        return 1000 * distance_to_line(c1, t["r_12"], j1), 1000 * distance_to_line(c2, t["r_21"], j2)
    return 1000 * float(np.linalg.norm(c1 - t["r_12"])), 1000 * float(np.linalg.norm(c2 - t["r_21"]))


def diagnose(t: dict[str, Any], trial: str) -> list[dict[str, Any]]:
    """Centre errors of our estimator under the variants above, and two truth checks."""
    from lowerlimb.calibration import CalibrationOptions, calibrate_spherical_joint
    from lowerlimb.calibration._prepare import prepare_pair
    from lowerlimb.constraints.spherical import spherical_residual

    a1, g1, a2, g2, rate = t["acc1"], t["gyr1"], t["acc2"], t["gyr2"], t["rate_hz"]
    rows: list[dict[str, Any]] = []

    def add(label: str, c1: np.ndarray, c2: np.ndarray, rms: float | None) -> None:
        e1, e2 = centre_errors_mm(t, trial, c1, c2)
        rows.append({"trial": trial, "variant": label, "err_1": e1, "err_2": e2, "rms_residual": rms})

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for label, kw in VARIANTS:
            r = calibrate_spherical_joint(a1, g1, a2, g2, rate_hz=rate, options=CalibrationOptions(**kw))
            add(label, r.center_in_parent_sensor, r.center_in_child_sensor, r.rms_residual)
        for shift in (-1, 1):
            n = a1.shape[0] - 1
            sa, sg = (slice(1, None), slice(0, n)) if shift > 0 else (slice(0, n), slice(1, None))
            r = calibrate_spherical_joint(a1[sa], g1[sg], a2[sa], g2[sg], rate_hz=rate)
            add(
                f"acc shifted {shift:+d} sample",
                r.center_in_parent_sensor,
                r.center_in_child_sensor,
                r.rms_residual,
            )
        # the truth checks run on the recorded samples, those of the optical R_12
        _, data = prepare_pair(a1, g1, a2, g2, rate, CalibrationOptions(min_fit_rate_hz=None))
        x_true = np.r_[t["r_12"], t["r_21"]]
        rms_true = float(np.sqrt(np.mean(spherical_residual(x_true, data) ** 2)))
        rows.append(
            {
                "trial": trial,
                "variant": "optical truth itself",
                "err_1": 0.0,
                "err_2": 0.0,
                "rms_residual": rms_true,
            }
        )
        R1, R2 = quat_wxyz_to_matrix(t["q1"]), quat_wxyz_to_matrix(t["q2"])
        R12 = np.einsum("nji,njk->nik", R1, R2)
        A = np.concatenate([data.K_parent, -R12 @ data.K_child], axis=2).reshape(-1, 6)
        b = -(data.acc_parent - np.einsum("nij,nj->ni", R12, data.acc_child)).reshape(-1)
        x = np.linalg.lstsq(A, b, rcond=None)[0]
        add("3-D constraint, optical R_12", x[:3], x[3:], None)
    return rows


def diagnosis_markdown(rows: list[dict[str, Any]]) -> str:
    lines = [
        "### Diagnosis: our centre error under variants of the preparation, and truth checks",
        "",
        "Error as above (hinge trial: distance to the axis line), mm. RMS residual of eq. 3 (m/s²) at",
        "that estimate on that variant's signals; the truth row: at r_12 / r_21 on the recorded signals.",
        "Without gyro-bias removal there is no still-period noise level either, so the adaptive",
        "cut-off is found from the top of the spectrum (it then filters; with it, it does not).",
        "",
        "| trial | variant | err sensor 1 mm | err sensor 2 mm | RMS residual |",
        "|---|---|---|---|---|",
    ]
    for r in rows:
        rms = "–" if r["rms_residual"] is None else f"{r['rms_residual']:.3f}"
        lines.append(f"| {r['trial']} | {r['variant']} | {r['err_1']:.1f} | {r['err_2']:.1f} | {rms} |")
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------- driver


def run_worker(python: str, method: str, data_dir: Path, trial: str, repeats: int) -> dict[str, Any]:
    cmd = [python, str(Path(__file__).resolve()), "--worker", method, "--trial", trial]
    cmd += ["--data", str(data_dir), "--repeats", str(repeats)]
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(REPO), *filter(None, [env.get("PYTHONPATH")])])
    p = subprocess.run(cmd, capture_output=True, text=True, cwd=REPO, env=env)
    if p.returncode != 0:
        tail = (p.stderr.strip().splitlines() or ["(no output)"])[-1]
        return {"error": f"worker failed ({python}): {tail}", "python": python}
    out: dict[str, Any] = json.loads(p.stdout.strip().splitlines()[-1])
    return out


def measure(method: str, data_dir: Path, trial: str, repeats: int, peer_python: str | None) -> dict[str, Any]:
    res = run_worker(sys.executable, method, data_dir, trial, repeats)
    if "error" in res and not method.startswith("ours") and peer_python:
        first = res["error"]
        res = run_worker(peer_python, method, data_dir, trial, repeats)
        if "error" in res:
            res["error"] = f"here: {first}; in {peer_python}: {res['error']}"
    return res


def score(method: str, t: dict[str, Any], trial: str, res: dict[str, Any]) -> dict[str, Any]:
    row: dict[str, Any] = {"trial": trial, "method": method, **res}
    if "error" in res:
        return row
    est = {k: np.asarray(v) for k, v in res["estimate"].items()}
    if METHODS[method][1] == "centre":
        if trial == HINGE_TRIAL:
            j1, j2, _ = true_hinge_axes(t["q1"], t["q2"])
            row["err_1"] = 1000 * distance_to_line(est["center_1"], t["r_12"], j1)
            row["err_2"] = 1000 * distance_to_line(est["center_2"], t["r_21"], j2)
            row["metric"] = "distance to true axis line, mm"
        else:
            row["err_1"] = 1000 * float(np.linalg.norm(est["center_1"] - t["r_12"]))
            row["err_2"] = 1000 * float(np.linalg.norm(est["center_2"] - t["r_21"]))
            row["metric"] = "distance to r_12 / r_21, mm"
    else:
        j1, j2, _ = true_hinge_axes(t["q1"], t["q2"])
        row["err_1"] = unsigned_angle_deg(est["axis_1"], j1)
        row["err_2"] = unsigned_angle_deg(est["axis_2"], j2)
        row["metric"] = "angle to true axis, deg"
    return row


def _f(v: float | None, fmt: str) -> str:
    return "–" if v is None else format(v, fmt)


def to_markdown(rows: list[dict[str, Any]], truth: dict[str, Any]) -> str:
    lines = [
        "## Rig (real IMUs, 50 Hz, optical truth): joint centre and hinge axis, ours vs peers",
        "",
        "Centre: distance to the optical `r_12` / `r_21` (hinge trial: to the true axis line), mm.",
        "Axis: unsigned angle to the optical hinge axis, deg. Times: warm = median of repeats,",
        "cold = first call in a fresh process; import = importing the function (NumPy and",
        "scipy.io already loaded, as the data were read); first use = import + cold.",
        "",
        "| trial | estimate | method | err sensor 1 | err sensor 2 | warm s | cold s | import s "
        "| first use s | environment | notes |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        kind = METHODS[r["method"]][1]
        unit = "mm" if kind == "centre" else "°"
        if "error" in r:
            lines.append(
                f"| {r['trial']} | {kind} | {r['method']} |" + " – |" * 7 + f" not run: {r['error']} |"
            )
            continue
        fmt = ".1f" if kind == "centre" else ".2f"
        env = f"{r['package']}, numpy {r['numpy']}"
        notes = "; ".join(w[:90] for w in r["warnings"]) or ""
        lines.append(
            f"| {r['trial']} | {kind} | {r['method']} | {_f(r['err_1'], fmt)} {unit} | "
            f"{_f(r['err_2'], fmt)} {unit} | {_f(r['warm_s'], '.3f')} | {_f(r['cold_s'], '.3f')} | "
            f"{_f(r['import_s'], '.2f')} | {r['import_s'] + r['cold_s']:.2f} | {env} | {notes} |"
        )
    lines += [
        "",
        f"True hinge axis ({HINGE_TRIAL}, from the optical relative rotation): "
        f"j_1 = {np.round(truth['j_1'], 4).tolist()}, j_2 = {np.round(truth['j_2'], 4).tolist()}; "
        f"RMS deviation of R_12(t) j_2 from j_1: {truth['spread_deg']:.2f}°.",
        "",
        "Goals (issue 9/12): " + goals_text(rows),
    ]
    return "\n".join(lines) + "\n"


def _met(ok: bool) -> str:
    return "met" if ok else "missed"


def goals_text(rows: list[dict[str, Any]]) -> str:
    ours = [r for r in rows if r["method"].startswith("ours") and "error" not in r]
    cen = [r for r in ours if r["method"] == "ours centre"]
    ax = [r for r in ours if r["method"] == "ours axis"]
    dfj = {r["trial"]: r for r in rows if r["method"] == "dfjimu" and "error" not in r}
    qmt = {r["trial"]: r for r in rows if r["method"] == "qmt" and "error" not in r}
    worst_c = max((max(r["err_1"], r["err_2"]) for r in cen), default=float("nan"))
    worst_a = max((max(r["err_1"], r["err_2"]) for r in ax), default=float("nan"))
    parts = [
        f"centre ≤ {GOAL_CENTER_MM:g} mm on every trial: {_met(worst_c <= GOAL_CENTER_MM)} "
        f"(worst {worst_c:.1f} mm)",
        f"axis ≤ {GOAL_AXIS_DEG:g}°: {_met(worst_a <= GOAL_AXIS_DEG)} (worst {worst_a:.2f}°)",
    ]
    beats = [
        max(r["err_1"], r["err_2"]) < max(dfj[r["trial"]]["err_1"], dfj[r["trial"]]["err_2"])
        for r in cen
        if r["trial"] in dfj
    ]
    parts.append(
        "centre more accurate than dfjimu (worse frame): "
        + (f"{sum(beats)}/{len(beats)} trials" if beats else "dfjimu not run")
    )
    beats_q = [
        max(r["err_1"], r["err_2"]) < max(qmt[r["trial"]]["err_1"], qmt[r["trial"]]["err_2"])
        for r in ax
        if r["trial"] in qmt
    ]
    parts.append(
        "axis more accurate than qmt: " + (f"{sum(beats_q)}/{len(beats_q)}" if beats_q else "qmt not run")
    )
    slower = [r["trial"] for r in cen if r["trial"] in dfj and r["warm_s"] > dfj[r["trial"]]["warm_s"]]
    parts.append(
        "warm no slower than dfjimu: "
        + ("met" if not slower and dfj else f"missed on {', '.join(slower)}" if dfj else "dfjimu not run")
    )
    worst_cold = max((r["import_s"] + r["cold_s"] for r in ours), default=float("nan"))
    parts.append(
        f"first use (import + cold) ≤ {GOAL_COLD_S:g} s: {_met(worst_cold <= GOAL_COLD_S)} "
        f"(worst {worst_cold:.2f} s)"
    )
    return "; ".join(parts) + "."


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", default=str(default_data_dir()), help="folder holding rig/")
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument(
        "--peer-python",
        default=str(DEFAULT_PEER_PYTHON) if DEFAULT_PEER_PYTHON.is_file() else None,
        help="interpreter with dfjimu and qmt, used when they do not import here",
    )
    ap.add_argument("--methods", default=",".join(METHODS))
    ap.add_argument("--out", default=str(Path(__file__).parent / "results"))
    ap.add_argument("--worker", help=argparse.SUPPRESS)
    ap.add_argument("--trial", help=argparse.SUPPRESS)
    args = ap.parse_args()
    data_dir = Path(args.data).resolve()
    if args.worker:
        print(json.dumps(worker(args.worker, data_dir, args.trial, args.repeats)))
        return
    if not (data_dir / "rig").is_dir():
        raise SystemExit(f"no rig/ folder in {data_dir}; pass --data pointing at the data folder")
    trials = {name: load_trial(data_dir, name) for name in TRIALS}
    rows = []
    for method in args.methods.split(","):
        for trial in METHODS[method][2]:
            res = measure(method, data_dir, trial, args.repeats, args.peer_python)
            rows.append(score(method, trials[trial], trial, res))
            done = rows[-1]
            print(f"{method} {trial}: {done.get('err_1', '-')} {done.get('error', '')}", file=sys.stderr)
    rows.sort(key=lambda r: (r["trial"], METHODS[r["method"]][1], r["method"]))
    j1, j2, spread = true_hinge_axes(trials[HINGE_TRIAL]["q1"], trials[HINGE_TRIAL]["q2"])
    truth = {"j_1": j1.tolist(), "j_2": j2.tolist(), "spread_deg": spread}
    diag = [d for name in TRIALS for d in diagnose(trials[name], name)]
    text = to_markdown(rows, truth) + "\n" + diagnosis_markdown(diag)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "rig.md").write_text(text)
    (out / "rig.json").write_text(json.dumps({"truth": truth, "rows": rows, "diagnosis": diag}, indent=1))
    print(text)


if __name__ == "__main__":
    main()
