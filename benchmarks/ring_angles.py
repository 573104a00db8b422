"""Hinge angles from real IMUs against optical motion capture on the RING chain.

Data: ``DIR/ring`` (see ``../shared/data/README.md``; Bachhuber, Weygers,
Seel 2024, trial 1): a 5-segment mechanical chain, seg2–seg3, seg3–seg4 and
seg4–seg5 joined by hinges about x, y and z of the parent segment; one IMU
per segment, axes nominally aligned with it (true misalignment a few
degrees); 40 Hz; "rigid" IMUs and "nonrigid" ones on foam. The optical
stream (``trial1_omc.csv``, 30 Hz) gives each segment's orientation
(segment → lab), with gaps.

Pipeline under test, per hinge (parent p, child c) and per recording:

1. orientation of each IMU, :func:`lowerlimb.orientation.estimate_orientation`
   (``mahony``, ``ftecf``, ``madgwick``), variants
   ``6ax`` (gyro + acc, each sensor's heading free),
   ``6ax+hdg`` (6-axis, then the child's heading turned about the vertical
   with :func:`lowerlimb.segments.heading.relative_heading` /
   :func:`~lowerlimb.segments.heading.rotate_about_vertical` so that ``u = R_p j_p``
   and ``v = R_c j_c`` agree horizontally, as the library does at the knee,
   Gaussian kernel 4 s as in :func:`~lowerlimb.segments.heading.correct_headings`),
   ``9ax`` (with the magnetometer, arbitrary units) and ``9ax+hdg``, and
   ``6ax+hdg, nominal axis`` (the nominal x / y / z instead of the
   estimated axis, for heading correction and angle: isolates the axis
   estimate's share of the error);
2. the hinge axis ``j_p``, ``j_c`` from the IMUs,
   :func:`lowerlimb.estimate_hinge_axis` (with both accelerometers for the
   sign), its sign fixed to point along the nominal axis (the sign convention
   of a mechanical hinge is arbitrary);
3. IMU hinge angle: the relative orientation ``R_pc(t) = R_p(t)ᵀ R_c(t)``
   against its mean over the initial still samples ``R_pc(0)``; the angle is
   the twist of ``R_pc(0)ᵀ R_pc(t)`` (child frame) about ``j_c`` (swing–twist
   decomposition, ``2 atan2(q_v · j, q_w)``, unwrapped);
4. optical hinge angle: the same with the optical segment orientations and
   the nominal axis (x, y, z of the segment), interpolated (linearly, gaps
   left out) onto the IMU time base after shifting by the time offset found
   by cross-correlating the angular-speed magnitudes of all five segments
   (gyro norm against the norm of the rate differentiated from the optical
   quaternions, ±2 s, 5 ms steps refined by a parabola); the optical
   reference ``R_pc(0)`` is its mean over the same still interval;
5. RMSE after removing the mean difference (the zero references of the two
   systems differ by the unknown mounting), and Pearson correlation, over the
   samples where the optical angle exists.

Also reported, filter-free: ``gyro`` integrates the relative rate about the
axis, ``∫ (j_c·ω_c − j_p·ω_p) dt`` (bias from the still start removed):
what the gyros alone say, without any orientation estimate.

Sanity checks: the angle between the rotation axis of ``R_pc(0)ᵀ R_pc(t)``
and the hinge axis (median over samples with a relative rotation above
10°; large values mean the relative motion is not a rotation about the
estimated axis), the same for the optical data against the nominal axis,
the functional axis of the optical data, and the magnetometer field's
disturbance (spread of the norm and of the dip angle).

Usage: ``python benchmarks/ring_angles.py --data DIR [--methods mahony,ftecf,madgwick] [--out DIR]``.
Writes ``ring_angles.{md,json}`` into ``--out`` (the JSON also records the
git commit, since the filters are still being tuned) and prints the Markdown.
Takes about 10 s.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import json  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

import numpy as np  # noqa: E402

from lowerlimb import estimate_hinge_axis  # noqa: E402
from lowerlimb.conventions import (  # noqa: E402
    quat_conjugate,
    quat_make_continuous,
    quat_multiply,
    quat_normalize,
    quat_rotate,
    quat_to_rotvec,
)
from lowerlimb.orientation import estimate_orientation  # noqa: E402
from lowerlimb.segments.heading import relative_heading, rotate_about_vertical  # noqa: E402
from lowerlimb.stillness import initial_still_samples  # noqa: E402

IMU_RATE_HZ = 40.0
OMC_RATE_HZ = 30.0
#: (parent segment, child segment, nominal hinge axis index in both segment frames)
HINGES = ((2, 3, 0), (3, 4, 1), (4, 5, 2))
VARIANTS = ("6ax", "6ax+hdg", "9ax", "9ax+hdg")
#: 6-axis + heading correction with the nominal axis (x, y, z) instead of the estimated one.
NOMINAL_VARIANT = "6ax+hdg, nominal axis"
#: Heading-correction kernel, s (the default of lowerlimb.segments.heading.correct_headings).
HEADING_WINDOW_S = 4.0
#: Smallest relative rotation counted in the axis sanity check, deg.
AXIS_CHECK_MIN_DEG = 10.0


# --------------------------------------------------------------------------- data


def load_imu(path: Path) -> dict[int, dict[str, np.ndarray]]:
    """``{segment: {"acc", "gyr", "mag": (N, 3)}}`` from a RING IMU CSV (2 comment lines)."""
    data = np.genfromtxt(path, delimiter=",", names=True, skip_header=2)
    return {
        seg: {k: np.stack([data[f"seg{seg}_{k}_{a}"] for a in "xyz"], axis=1) for k in ("acc", "gyr", "mag")}
        for seg in range(1, 6)
    }


def load_omc_quats(path: Path) -> dict[int, np.ndarray]:
    """``{segment: (M, 4)}`` optical segment orientations (segment → lab), NaN rows where missing."""
    data = np.genfromtxt(path, delimiter=",", names=True, skip_header=2)
    out = {}
    for seg in range(1, 6):
        q = np.stack([data[f"seg{seg}_quat_{a}"] for a in "wxyz"], axis=1)
        ok = np.isfinite(q).all(axis=1)
        q[ok] = quat_normalize(q[ok])
        q[~ok] = np.nan
        out[seg] = q
    return out


# --------------------------------------------------------------------------- geometry


def continuous(q: np.ndarray) -> np.ndarray:
    """Sign-continuous quaternions across NaN gaps."""
    q = q.copy()
    ok = np.flatnonzero(np.isfinite(q).all(axis=1))
    q[ok] = quat_make_continuous(q[ok])
    return q


def mean_quat(q: np.ndarray) -> np.ndarray:
    """Mean of a few close, sign-continuous unit quaternions (n, 4): normalised average."""
    return np.asarray(quat_normalize(q.mean(axis=0)))


def twist_angle(q_rel: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """Unwrapped twist angle (rad) of rotations (N, 4) about a unit ``axis`` (NaN rows kept)."""
    ang = 2.0 * np.arctan2(q_rel[:, 1:] @ axis, q_rel[:, 0])
    ang = np.angle(np.exp(1j * ang))  # wrap to (-π, π]
    ok = np.isfinite(ang)
    ang[ok] = np.unwrap(ang[ok])
    return ang


def relative_from_ref(q_p: np.ndarray, q_c: np.ndarray, ref: slice) -> np.ndarray:
    """``R_pc(ref)ᵀ R_pc(t)`` as quaternions (N, 4), ``R_pc = R_pᵀ R_c``; ``ref`` mean as reference."""
    q_pc = continuous(quat_multiply(quat_conjugate(q_p), q_c))
    valid = q_pc[ref][np.isfinite(q_pc[ref]).all(axis=1)]
    q0 = mean_quat(valid)
    q = quat_multiply(quat_conjugate(q0), q_pc)
    return np.where(q[:, :1] < 0, -q, q)


def axis_misfit_deg(q_rel: np.ndarray, axis: np.ndarray) -> dict[str, float]:
    """Angle between the rotation axis of ``q_rel`` and ``±axis`` where the rotation exceeds 10°."""
    rv = quat_to_rotvec(q_rel[np.isfinite(q_rel).all(axis=1)])
    ang = np.linalg.norm(rv, axis=1)
    big = ang > np.radians(AXIS_CHECK_MIN_DEG)
    if not big.any():
        return {"median": float("nan"), "p90": float("nan"), "n": 0}
    c = np.abs(rv[big] @ axis) / ang[big]
    d = np.degrees(np.arccos(np.clip(c, 0.0, 1.0)))
    return {"median": float(np.median(d)), "p90": float(np.percentile(d, 90)), "n": int(big.sum())}


def functional_axis(q_rel: np.ndarray) -> np.ndarray:
    """Principal direction of the rotation vectors of ``q_rel`` (unit, sign arbitrary)."""
    rv = quat_to_rotvec(q_rel[np.isfinite(q_rel).all(axis=1)])
    return np.asarray(np.linalg.eigh(rv.T @ rv)[1][:, -1])


def angle_deg(a: np.ndarray, b: np.ndarray) -> float:
    """Unsigned angle between two directions (``a`` and ``−a`` alike), deg."""
    c = abs(float(a @ b)) / (np.linalg.norm(a) * np.linalg.norm(b))
    return float(np.degrees(np.arccos(min(1.0, c))))


def omc_body_rate(q: np.ndarray, rate_hz: float) -> np.ndarray:
    """Body-frame angular velocity (M, 3) rad/s from orientations (segment → lab); NaN in gaps."""
    qc = continuous(q)
    dq = np.gradient(qc, axis=0) * rate_hz
    return np.asarray(2.0 * quat_multiply(quat_conjugate(qc), dq)[:, 1:])


def interp_nan(t_new: np.ndarray, t: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Linear interpolation of ``x`` (M,) or (M, k) at ``t_new``; NaN where a neighbour is NaN or outside."""
    x2 = x.reshape(len(x), -1)
    out = np.full((len(t_new), x2.shape[1]), np.nan)
    inside = (t_new >= t[0]) & (t_new <= t[-1])
    idx = np.clip(np.searchsorted(t, t_new[inside], side="right") - 1, 0, len(t) - 2)
    w = (t_new[inside] - t[idx]) / (t[idx + 1] - t[idx])
    out[inside] = (1 - w)[:, None] * x2[idx] + w[:, None] * x2[idx + 1]  # NaN propagates
    return out.reshape((len(t_new),) + x.shape[1:])


def time_offset(imu: dict[int, dict[str, np.ndarray]], omc: dict[int, np.ndarray]) -> dict[str, Any]:
    """Lag (s) to add to optical times to match the IMU, from angular-speed cross-correlation.

    Both speeds are put on a 1 ms grid over the common span; the lag maximising
    the (NaN-aware) Pearson correlation summed over the five segments within
    ±2 s is refined by a parabola through the best three lags.
    """
    t_imu = np.arange(len(imu[1]["gyr"])) / IMU_RATE_HZ
    t_omc = np.arange(len(omc[1])) / OMC_RATE_HZ
    lags = np.arange(-2.0, 2.0 + 1e-9, 0.005)
    score = np.zeros(len(lags))
    for seg in range(1, 6):
        s_imu = np.linalg.norm(imu[seg]["gyr"], axis=1)
        s_omc = np.linalg.norm(omc_body_rate(omc[seg], OMC_RATE_HZ), axis=1)
        for i, lag in enumerate(lags):
            o = interp_nan(t_imu, t_omc + lag, s_omc)
            ok = np.isfinite(o)
            score[i] += np.corrcoef(o[ok], s_imu[ok])[0, 1]
    score /= 5
    k = int(np.clip(np.argmax(score), 1, len(lags) - 2))
    y0, y1, y2 = score[k - 1 : k + 2]
    denom = y0 - 2 * y1 + y2
    frac = 0.5 * (y0 - y2) / denom if denom < 0 else 0.0
    lag = float(lags[k] + frac * (lags[1] - lags[0]))
    return {"lag_s": lag, "correlation": float(score[k]), "search_s": [float(lags[0]), float(lags[-1])]}


# --------------------------------------------------------------------------- the pipeline


def orientations(
    imu: dict[int, dict[str, np.ndarray]], method: str, nine_axis: bool
) -> tuple[dict[int, np.ndarray], float]:
    """Orientation of every IMU (segments 2..5) with one filter; also the run time, s."""
    t0 = time.perf_counter()
    out = {}
    for seg in range(2, 6):
        s = imu[seg]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            q = estimate_orientation(
                s["gyr"], s["acc"], s["mag"] if nine_axis else None, rate_hz=IMU_RATE_HZ, method=method
            )
        out[seg] = np.asarray(q)
    return out, time.perf_counter() - t0


def fit_axes(imu: dict[int, dict[str, np.ndarray]]) -> dict[tuple[int, int], dict[str, Any]]:
    """Hinge axes in both IMU frames, sign towards the nominal axis."""
    out = {}
    for p, c, k in HINGES:
        e = np.eye(3)[k]
        t0 = time.perf_counter()
        with warnings.catch_warnings(record=True) as w:
            warnings.simplefilter("always")
            j_p, j_c = estimate_hinge_axis(
                imu[p]["gyr"],
                imu[c]["gyr"],
                rate_hz=IMU_RATE_HZ,
                acc_parent=imu[p]["acc"],
                acc_child=imu[c]["acc"],
            )
        j_p, j_c = np.asarray(j_p), np.asarray(j_c)
        flipped = bool(j_p @ e + j_c @ e < 0)
        if flipped:
            j_p, j_c = -j_p, -j_c
        out[(p, c)] = {
            "j_p": j_p,
            "j_c": j_c,
            "flipped_to_nominal": flipped,
            "err_parent_deg": angle_deg(j_p, e),
            "err_child_deg": angle_deg(j_c, e),
            "warnings": sorted({str(x.message) for x in w}),
            "runtime_s": time.perf_counter() - t0,
        }
    return out


def compare(a_imu: np.ndarray, a_omc: np.ndarray) -> dict[str, float]:
    """RMSE (deg) after removing the mean difference, correlation, and the offset removed."""
    ok = np.isfinite(a_imu) & np.isfinite(a_omc)
    d = np.degrees(a_imu[ok] - a_omc[ok])
    off = float(d.mean())
    return {
        "rmse_deg": float(np.sqrt(np.mean((d - off) ** 2))),
        "max_abs_deg": float(np.max(np.abs(d - off))),
        "corr": float(np.corrcoef(a_imu[ok], a_omc[ok])[0, 1]),
        "offset_deg": off,
        "n": int(ok.sum()),
    }


def gyro_angle(
    imu: dict[int, dict[str, np.ndarray]], p: int, c: int, axes: dict[str, Any], n_still: int
) -> np.ndarray:
    """Filter-free hinge angle: integrated relative rate about the axis, rad."""
    rate = imu[c]["gyr"] @ axes["j_c"] - imu[p]["gyr"] @ axes["j_p"]
    rate = rate - rate[:n_still].mean()
    return np.concatenate([[0.0], np.cumsum(0.5 * (rate[1:] + rate[:-1]))]) / IMU_RATE_HZ


def imu_hinge_angle(
    q: dict[int, np.ndarray], p: int, c: int, axes: dict[str, Any], n_still: int, heading: bool
) -> tuple[np.ndarray, dict[str, float], float]:
    """IMU hinge angle (rad), the axis misfit, and the RMS heading correction (deg) applied."""
    q_p, q_c = q[p], q[c]
    dh = 0.0
    if heading:
        u = quat_rotate(q_p, axes["j_p"])
        v = quat_rotate(q_c, axes["j_c"])
        delta = relative_heading(u, v, IMU_RATE_HZ, window_s=HEADING_WINDOW_S)
        q_c = rotate_about_vertical(q_c, delta)
        dh = float(np.degrees(np.sqrt(np.mean(np.angle(np.exp(1j * (delta - delta[:n_still].mean()))) ** 2))))
    q_rel = relative_from_ref(q_p, q_c, slice(0, n_still))
    return twist_angle(q_rel, axes["j_c"]), axis_misfit_deg(q_rel, axes["j_c"]), dh


def mag_disturbance(imu: dict[int, dict[str, np.ndarray]]) -> dict[int, dict[str, float]]:
    """Spread of the field norm and of the dip angle, raw and after a hard-iron sphere fit.

    The dip angle is the elevation of the field above the sensor's horizontal
    plane, taken from the accelerometer at low acceleration (‖a‖ within
    0.3 m/s² of g, ‖ω‖ < 0.5 rad/s); a homogeneous field gives one dip for
    every sample and every IMU (about −65° in central Europe).
    """
    out = {}
    for seg in range(2, 6):
        a, g = imu[seg]["acc"], imu[seg]["gyr"]
        an = np.linalg.norm(a, axis=1)
        calm = (np.abs(an - 9.81) < 0.3) & (np.linalg.norm(g, axis=1) < 0.5)
        m_raw = imu[seg]["mag"]
        x = np.linalg.lstsq(np.c_[2 * m_raw, np.ones(len(m_raw))], np.sum(m_raw**2, axis=1), rcond=None)[0]
        row = {}
        for tag, m in (("raw", m_raw), ("sphere", m_raw - x[:3])):
            mn = np.linalg.norm(m, axis=1)
            dip = np.degrees(np.arcsin(np.clip(np.sum(m * a, 1) / (mn * an), -1, 1)))[calm]
            row |= {
                f"{tag}_norm_p5_rel": float(np.percentile(mn, 5) / np.median(mn)),
                f"{tag}_norm_p95_rel": float(np.percentile(mn, 95) / np.median(mn)),
                f"{tag}_dip_median_deg": float(np.median(dip)),
                f"{tag}_dip_p5_deg": float(np.percentile(dip, 5)),
                f"{tag}_dip_p95_deg": float(np.percentile(dip, 95)),
            }
        out[seg] = row
    return out


def run_recording(
    imu: dict[int, dict[str, np.ndarray]], omc: dict[int, np.ndarray], lag_s: float, methods: list[str]
) -> dict[str, Any]:
    """Every hinge × method × variant of one recording."""
    n = len(imu[1]["gyr"])
    t_imu = np.arange(n) / IMU_RATE_HZ
    t_omc = np.arange(len(omc[1])) / OMC_RATE_HZ + lag_s
    n_still = initial_still_samples(
        [imu[s]["gyr"] for s in range(2, 6)], [imu[s]["acc"] for s in range(2, 6)], IMU_RATE_HZ
    )
    n_still = max(n_still, 10)
    # optical reference over the same (IMU-time) still window, on the optical grid
    omc_ref = slice(0, int(np.searchsorted(t_omc, t_imu[n_still - 1], side="right")))
    axes = fit_axes(imu)
    nominal = {(p, c): {"j_p": np.eye(3)[k], "j_c": np.eye(3)[k]} for p, c, k in HINGES}
    res: dict[str, Any] = {"n_still": n_still, "axes": {}, "omc": {}, "rows": []}
    omc_angles = {}
    for p, c, k in HINGES:
        e = np.eye(3)[k]
        q_rel = relative_from_ref(omc[p], omc[c], omc_ref)
        a_omc = interp_nan(t_imu, t_omc, twist_angle(q_rel, e))
        omc_angles[(p, c)] = a_omc
        fa = functional_axis(q_rel)
        res["omc"][f"seg{p}-seg{c}"] = {
            "axis_misfit_nominal_deg": axis_misfit_deg(q_rel, e),
            "functional_axis": fa.tolist(),
            "functional_vs_nominal_deg": angle_deg(fa, e),
            "range_deg": [float(np.nanmin(np.degrees(a_omc))), float(np.nanmax(np.degrees(a_omc)))],
        }
        ax = axes[(p, c)]
        res["axes"][f"seg{p}-seg{c}"] = {
            k2: (v.tolist() if isinstance(v, np.ndarray) else v) for k2, v in ax.items()
        }
        for variant, axx in (("integrated", ax), ("integrated, nominal axis", nominal[(p, c)])):
            a = gyro_angle(imu, p, c, axx, n_still)
            res["rows"].append(
                {"hinge": f"seg{p}-seg{c}", "method": "gyro", "variant": variant, **compare(a, a_omc)}
            )
    for method in methods:
        for nine in (False, True):
            q, rt = orientations(imu, method, nine)
            for variant in VARIANTS[2:] if nine else VARIANTS[:2] + (NOMINAL_VARIANT,):
                hdg = "+hdg" in variant
                for p, c, _ in HINGES:
                    axx = nominal[(p, c)] if variant == NOMINAL_VARIANT else axes[(p, c)]
                    a, mis, dh = imu_hinge_angle(q, p, c, axx, n_still, hdg)
                    res["rows"].append(
                        {
                            "hinge": f"seg{p}-seg{c}",
                            "method": method,
                            "variant": variant,
                            **compare(a, omc_angles[(p, c)]),
                            "axis_misfit_deg": mis,
                            "heading_corr_rms_deg": dh,
                            "orientation_runtime_s": rt,
                        }
                    )
    return res


# --------------------------------------------------------------------------- report


def to_markdown(out: dict[str, Any]) -> str:
    """Markdown summary."""
    md = ["## RING chain: hinge angles from IMUs (lowerlimb orientation + hinge axis) vs optical\n"]
    lags = ", ".join(
        f"{rec} {1000 * v['lag_s']:+.1f} ms (r = {v['correlation']:.3f})"
        for rec, v in out["time_offset"].items()
    )
    md.append(
        f"Time offset optical → IMU from angular-speed cross-correlation: {lags}; applied. "
        "RMSE after removing the mean difference (zero references differ), deg; "
        "r = Pearson correlation; misfit = median angle between the rotation axis of "
        "R_pc(0)ᵀR_pc(t) and the hinge axis used (rotations > 10°), deg. "
        "`gyro` = integrated relative rate about the axis, no orientation filter.\n"
    )
    methods = sorted({r["method"] for rec in out["recordings"].values() for r in rec["rows"]} - {"gyro"})
    methods = [m for m in ("mahony", "ftecf", "madgwick", "quest_kf") if m in methods]
    hinges = [f"seg{p}-seg{c}" for p, c, _ in HINGES]
    for rec, res in out["recordings"].items():
        md.append(f"### {rec}\n")
        md.append("| method | variant | " + " | ".join(f"{h} RMSE ° (r, misfit °)" for h in hinges) + " |")
        md.append("|---|---|" + "---|" * len(hinges))
        rows = {(r["method"], r["variant"], r["hinge"]): r for r in res["rows"]}
        keys = [("gyro", "integrated"), ("gyro", "integrated, nominal axis")]
        keys += [(m, v) for m in methods for v in VARIANTS + (NOMINAL_VARIANT,)]
        for m, v in keys:
            cells = []
            for h in hinges:
                r = rows.get((m, v, h))
                if r is None:
                    cells.append("–")
                    continue
                mis = r.get("axis_misfit_deg", {}).get("median")
                extra = f", {mis:.1f}" if mis is not None else ""
                cells.append(f"{r['rmse_deg']:.2f} ({r['corr']:.4f}{extra})")
            md.append(f"| {m} | {v} | " + " | ".join(cells) + " |")
        md.append("")
        md.append(
            "| hinge | IMU axis err parent / child ° | optical range ° | optical misfit to nominal ° "
            "(median, p90) | optical functional axis vs nominal ° | warnings |"
        )
        md.append("|---|---|---|---|---|---|")
        for h in hinges:
            ax, om = res["axes"][h], res["omc"][h]
            mis = om["axis_misfit_nominal_deg"]
            md.append(
                f"| {h} | {ax['err_parent_deg']:.2f} / {ax['err_child_deg']:.2f} | "
                f"{om['range_deg'][0]:.0f} … {om['range_deg'][1]:.0f} | "
                f"{mis['median']:.2f}, {mis['p90']:.2f} | "
                f"{om['functional_vs_nominal_deg']:.2f} | {len(ax['warnings'])} |"
            )
        md.append("")
    md.append("### Magnetometer (rigid recording)\n")
    md.append(
        "Dip angle: field elevation above the sensor's horizontal (from the accelerometer at low "
        "acceleration); a homogeneous field gives one value for all samples and IMUs. "
        "'sphere': after removing a least-squares hard-iron offset.\n"
    )
    md.append("| IMU | ‖m‖ p5 / p95 ÷ median, raw | sphere | dip median (p5 … p95) °, raw | sphere |")
    md.append("|---|---|---|---|---|")
    for seg, m in out["magnetometer"].items():
        cells = [f"{m[f'{t}_norm_p5_rel']:.2f} / {m[f'{t}_norm_p95_rel']:.2f}" for t in ("raw", "sphere")]
        cells += [
            f"{m[f'{t}_dip_median_deg']:.0f} ({m[f'{t}_dip_p5_deg']:.0f} … {m[f'{t}_dip_p95_deg']:.0f})"
            for t in ("raw", "sphere")
        ]
        md.append(f"| {seg} | " + " | ".join(cells) + " |")
    return "\n".join(md) + "\n"


def git_state() -> str:
    """``git describe --always --dirty`` of the checkout, or ``"unknown"``."""
    import subprocess

    try:
        r = subprocess.run(
            ["git", "describe", "--always", "--dirty"],
            cwd=Path(__file__).parent, capture_output=True, text=True, check=True,
        )  # fmt: skip
        return r.stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", required=True, help="folder holding ring/ (e.g. ../shared/data)")
    ap.add_argument("--methods", default="mahony,ftecf,madgwick")
    ap.add_argument("--out", default=str(Path(__file__).parent / "results"))
    args = ap.parse_args()
    ring = Path(args.data) / "ring"
    if not ring.is_dir():
        raise SystemExit(f"no ring/ folder in {args.data}; pass --data pointing at the data folder")
    omc = load_omc_quats(ring / "trial1_omc.csv")
    imus = {rec: load_imu(ring / f"trial1_imu_{rec}.csv") for rec in ("rigid", "nonrigid")}
    out: dict[str, Any] = {"git": git_state(), "time_offset": {}, "recordings": {}}
    for rec, imu in imus.items():
        lag = time_offset(imu, omc)
        out["time_offset"][rec] = lag
        out["recordings"][rec] = run_recording(imu, omc, lag["lag_s"], args.methods.split(","))
    out["magnetometer"] = {f"imu{s}": v for s, v in mag_disturbance(imus["rigid"]).items()}
    text = to_markdown(out)
    dst = Path(args.out)
    dst.mkdir(parents=True, exist_ok=True)
    (dst / "ring_angles.md").write_text(text)
    (dst / "ring_angles.json").write_text(json.dumps(out, indent=1))
    print(text)


if __name__ == "__main__":
    main()
