"""Vendor importers: Xsens MT Manager exports and mapped CSV (lowerlimb.io, ``lowerlimb import``)."""

from __future__ import annotations

import json
import math
import warnings

import numpy as np
import pytest
from simcache import data_dir

import lowerlimb
from lowerlimb.cli import main
from lowerlimb.conventions import GRAVITY_MPS2, SENSORS
from lowerlimb.errors import InputError, NonFiniteValueError, UnitError
from lowerlimb.io import (
    TWO_LEG_SENSORS,
    ColumnNotFoundError,
    CsvMapping,
    FilledPacketsWarning,
    ImportParams,
    MappingError,
    PacketGapError,
    SensorFileError,
    load_mapped_csv,
    load_xsens,
    read_mapped_csv,
    read_xsens,
)
from lowerlimb.io.trial import ImuTrial
from lowerlimb.io.uneven_clock import UnevenClockWarning
from lowerlimb.io.xsens import unwrap_counter

RATE = 100.0
IDS = {"pelvis": "00B40B91", "thigh": "00B40C45", "shank": "00B40C44", "foot": "00B40C55"}
TWO_IDS = {
    "pelvis": "00B40B91",
    "left_thigh": "00B40C45",
    "left_shank": "00B40C44",
    "left_foot": "00B40C55",
    "right_thigh": "00B40C3C",
    "right_shank": "00B40C47",
    "right_foot": "00B40C48",
}
MAG_NORMALISED = np.array([0.45, 0.1, -0.85])


def _signals(counter, k):
    """Acc (m/s²), gyr (rad/s), mag (normalised) of sensor number k as functions of the packet counter."""
    t = np.asarray(counter, dtype=float) / RATE
    acc = np.column_stack(
        [0.3 * np.sin(t) + 0.01 * k, 0.2 * np.cos(3 * t), GRAVITY_MPS2 + 0.1 * np.sin(2 * t)]
    )
    gyr = np.column_stack([0.5 * np.sin(5 * t), 0.02 * k + 0 * t, 0.4 * np.cos(2 * t)])
    mag = np.tile(MAG_NORMALISED, (t.size, 1)) + 0.001 * k
    return acc, gyr, mag


def _write_export(path, counter, k, *, rate=RATE, mag=True, drop=(), columns=None, empty_acc=()):
    """An MT Manager text export of sensor k at the given unwrapped counters (written mod 65536)."""
    acc, gyr, m = _signals(counter, k)
    header = columns or (
        ["PacketCounter", "SampleTimeFine"]
        + [f"Acc_{a}" for a in "XYZ"]
        + [f"Gyr_{a}" for a in "XYZ"]
        + ([f"Mag_{a}" for a in "XYZ"] if mag else [])
        + [f"Quat_q{i}" for i in range(4)]
    )
    lines = [
        "// Start Time: Unknown",
        f"// Update Rate: {rate:.1f}Hz",
        "// Filter Profile: human (46.1)",
        ",".join(header),
    ]
    for i, c in enumerate(counter):
        if c in drop:
            continue
        a = "," * 2 if c in empty_acc else ",".join(f"{v:.6f}" for v in acc[i])
        cells = [str(int(c) % 65536), "", a, ",".join(f"{v:.6f}" for v in gyr[i])]
        if mag:
            cells.append(",".join(f"{v:.6f}" for v in m[i]))
        cells.append("1.0,0.0,0.0,0.0")
        lines.append(",".join(cells))
    path.write_text("\n".join(lines) + "\n")


def _export_dir(tmp_path, ids=IDS, starts=None, n=400, **per_sensor):
    """One export per sensor in tmp_path/rec; per_sensor[segment] = extra kwargs of _write_export."""
    folder = tmp_path / "rec"
    folder.mkdir(parents=True)
    for k, (seg, sid) in enumerate(ids.items()):
        start = (starts or {}).get(seg, 1000)
        _write_export(
            folder / f"S01-Walk-000_{sid}.txt", np.arange(start, start + n), k, **per_sensor.get(seg, {})
        )
    return folder


# ------------------------------------------------------------------ Xsens


def test_unwrap_counter():
    raw = np.array([65533, 65534, 65535, 0, 1, 3, 65535, 0])
    assert unwrap_counter(raw).tolist() == [65533, 65534, 65535, 65536, 65537, 65539, 131071, 131072]


def test_xsens_wrapped_counter_alignment_and_missing_packet(tmp_path):
    # pelvis wraps at 65536; thigh starts 2 packets later, foot stops 3 packets earlier (after the wrap)
    starts = {"pelvis": 65400, "thigh": 65402, "shank": 65400, "foot": 65400}
    folder = tmp_path / "rec"
    folder.mkdir()
    lengths = {"pelvis": 400, "thigh": 398, "shank": 400, "foot": 397}
    missing = 65400 + 150  # counter 65550 (written as 14) is lost by the shank
    for k, (seg, sid) in enumerate(IDS.items()):
        c = np.arange(starts[seg], starts[seg] + lengths[seg])
        _write_export(folder / f"x_{sid}.txt", c, k, drop={missing} if seg == "shank" else ())
    rec = load_xsens(folder, IDS, side="right")
    first, last = 65402, 65400 + 397 - 1
    assert rec.n_samples == last - first + 1 == 395
    np.testing.assert_allclose(rec.time_s, np.arange(395) / RATE, atol=1e-12)
    assert rec.filled == {"pelvis": 0, "thigh": 0, "shank": 1, "foot": 0}
    grid = np.arange(first, last + 1)
    for k, seg in enumerate(IDS):
        acc, gyr, mag = _signals(grid, k)
        i = grid == missing
        if seg == "shank":  # the filled packet is the mean of its neighbours
            j = int(np.flatnonzero(i)[0])
            np.testing.assert_allclose(rec.acc[seg][j], (acc[j - 1] + acc[j + 1]) / 2, atol=1e-6)
            np.testing.assert_allclose(rec.gyr[seg][j], (gyr[j - 1] + gyr[j + 1]) / 2, atol=1e-6)
            acc, gyr, mag = acc[~i], gyr[~i], mag[~i]
            got_acc, got_gyr, got_mag = rec.acc[seg][~i], rec.gyr[seg][~i], rec.mag[seg][~i]
        else:
            got_acc, got_gyr, got_mag = rec.acc[seg], rec.gyr[seg], rec.mag[seg]
        np.testing.assert_allclose(got_acc, acc, atol=1e-6)
        np.testing.assert_allclose(got_gyr, gyr, atol=1e-6)
        np.testing.assert_allclose(got_mag, 50.0 * mag, atol=1e-4)  # default 50 µT per unit
    trial = rec.to_trial()
    assert isinstance(trial, ImuTrial) and trial.side == "right" and trial.has_mag


def test_xsens_mag_field_option_and_missing_mag(tmp_path):
    folder = _export_dir(tmp_path)
    trial = read_xsens(folder, IDS, mag_field_ut=48.0)
    np.testing.assert_allclose(
        np.linalg.norm(trial.mag["pelvis"], axis=1), 48.0 * np.linalg.norm(MAG_NORMALISED), rtol=1e-5
    )
    assert trial.side == "left"
    # one export without Mag columns: the trial has no magnetometer, with a warning naming it
    folder2 = _export_dir(tmp_path / "b", shank={"mag": False})
    with pytest.warns(UserWarning, match="no Mag data for shank"):
        trial2 = read_xsens(folder2, IDS)
    assert trial2.mag is None and trial2.n_samples == 400
    with pytest.raises(InputError, match="mag_field_ut must be a positive"):
        read_xsens(folder, IDS, mag_field_ut=-1.0)


def test_xsens_columns_found_by_name(tmp_path):
    # other column order, extra columns, no Mag, no Quat
    cols = ["Gyr_X", "Gyr_Y", "Gyr_Z", "PacketCounter", "Temperature", "Acc_X", "Acc_Y", "Acc_Z"]
    folder = tmp_path / "rec"
    folder.mkdir()
    c = np.arange(10, 310)
    for k, sid in enumerate(IDS.values()):
        acc, gyr, _ = _signals(c, k)
        rows = [",".join(map(str, [*gyr[i], c[i], 21.5, *acc[i]])) for i in range(c.size)]
        (folder / f"rec_{sid}.txt").write_text(
            "// Update Rate: 100.0Hz\n" + ",".join(cols) + "\n" + "\n".join(rows)
        )
    trial = read_xsens(folder, IDS)
    assert trial.mag is None and trial.n_samples == 300
    np.testing.assert_allclose(trial.acc["foot"], _signals(c, 3)[0], atol=1e-12)


def test_xsens_many_filled_packets_warn_and_long_gap_refused(tmp_path):
    drops = {1000 + 20 * j for j in range(1, 19)}  # 18 single lost packets of 1600 samples: > 1 %
    folder = _export_dir(tmp_path, thigh={"drop": drops, "empty_acc": {1333}})
    with pytest.warns(FilledPacketsWarning, match="19 of 1600 samples"):
        rec = load_xsens(folder, IDS)
    assert rec.filled["thigh"] == 19  # 18 missing rows and one row with empty Acc cells
    gap = set(range(1100, 1112))  # 12 packets = 0.12 s > 0.1 s
    folder = _export_dir(tmp_path / "g", foot={"drop": gap})
    with pytest.raises(PacketGapError, match=r"foot has a gap of 0.12 s at 1.000 s") as e:
        load_xsens(folder, IDS)
    assert e.value.sensor == "foot" and e.value.limit_s == 0.1
    assert load_xsens(folder, IDS, params=ImportParams(max_gap_s=0.2)).filled["foot"] == 12


def test_xsens_two_legs(tmp_path):
    folder = _export_dir(tmp_path, ids=TWO_IDS)
    rec = load_xsens(folder, TWO_IDS)
    assert rec.two_leg and rec.sensors == TWO_LEG_SENSORS and rec.side is None
    out = tmp_path / "two.csv"
    rec.to_csv(out)
    header = out.read_text().splitlines()[0].split(",")
    assert header[:4] == ["time", "pelvis_acc_x", "pelvis_acc_y", "pelvis_acc_z"]
    assert header[10:13] == ["left_thigh_acc_x", "left_thigh_acc_y", "left_thigh_acc_z"]
    assert header[-3:] == ["right_foot_mag_x", "right_foot_mag_y", "right_foot_mag_z"] and len(header) == 64
    data = np.loadtxt(out, delimiter=",", skiprows=1)
    np.testing.assert_allclose(data[:, header.index("right_shank_gyr_y")], 0.02 * 5, atol=1e-9)
    with pytest.raises(InputError, match="ImuTrial holds one leg"):
        read_xsens(folder, TWO_IDS)


@pytest.mark.parametrize(
    "setup, mapping, error, message",
    [
        ("none", IDS, SensorFileError, "no file in .* has sensor ID 00B40C55"),
        ("dup", IDS, SensorFileError, "2 files in .* have sensor ID 00B40C45"),
        ("ok", {**IDS, "knee": "00B40C47"}, MappingError, "field 'map.knee': unknown segment 'knee'"),
        ("ok", {k: v for k, v in IDS.items() if k != "foot"}, MappingError, "no sensor given for foot"),
        ("ok", {**IDS, "foot": IDS["shank"]}, MappingError, "sensor 00B40C44 is also mapped to shank"),
        ("ok", {**IDS, "left_thigh": "00B40C3C"}, MappingError, "mixes the single-leg and the two-leg"),
        ("ok", {**IDS, "side": "up"}, MappingError, "side must be left or right"),
        ("nogyr", IDS, ColumnNotFoundError, "has no column 'Gyr_Z'"),
        ("rate", IDS, InputError, r"different update rates \(pelvis 100 Hz, thigh 100 Hz, shank 60 Hz"),
        ("norate", IDS, InputError, "no '// Update Rate: …Hz' comment line"),
        ("apart", IDS, InputError, "share no packets"),
        ("badcell", IDS, InputError, r"line 7: Acc_Y is not a number \('abc'\)"),
        ("empty", IDS, InputError, "has 0 packet"),
    ],
)
def test_xsens_errors(tmp_path, setup, mapping, error, message):
    folder = _export_dir(tmp_path, shank={"rate": 60.0} if setup == "rate" else {})
    foot = folder / f"S01-Walk-000_{IDS['foot']}.txt"
    text = foot.read_text()
    if setup == "none":
        foot.unlink()
    elif setup == "dup":
        (folder / f"S01-Walk-001_{IDS['thigh']}.txt").write_text(text)
    elif setup == "nogyr":
        foot.write_text(text.replace(",Gyr_Z,", ",Gyr_W,"))
    elif setup == "norate":
        foot.write_text(text.replace("// Update Rate: 100.0Hz\n", ""))
    elif setup == "apart":
        _write_export(foot, np.arange(3000, 3400), 3)
    elif setup == "empty":
        foot.write_text("\n".join(text.splitlines()[:4]))
    elif setup == "badcell":
        lines = text.splitlines()
        cells = lines[6].split(",")
        cells[3] = "abc"
        lines[6] = ",".join(cells)
        foot.write_text("\n".join(lines))
    with pytest.raises(error, match=message):
        read_xsens(folder, mapping)


def test_xsens_missing_directory(tmp_path):
    with pytest.raises(FileNotFoundError, match="directory not found"):
        read_xsens(tmp_path / "nope", IDS)


# ------------------------------------------------------------------ mapped CSV


def _mapping(**over):
    sensors = {
        s: {
            "acc": {"columns": [f"{s}.ax", f"{s}.ay", f"{s}.az"], "unit": "g"},
            "gyr": {"columns": [f"{s}.gx", f"{s}.gy", f"{s}.gz"], "unit": "deg/s"},
            "mag": {"columns": [f"{s}.mx", f"{s}.my", f"{s}.mz"], "unit": "nT"},
        }
        for s in SENSORS
    }
    m = {"time": {"column": "Timestamp", "unit": "ms"}, "delimiter": ";", "decimal": ",", "sensors": sensors}
    m.update(over)
    return m


def _vendor_csv(path, t_ms):
    """A semicolon/decimal-comma CSV: acc in g, gyro in deg/s, mag in nT, all linear in time."""
    t = (t_ms - t_ms[0]) / 1000.0
    header = ["Timestamp"] + [f"{s}.{q}{a}" for s in SENSORS for q in "agm" for a in "xyz"]
    cols = [t_ms]
    for k, _ in enumerate(SENSORS):
        cols += [0.01 * t, 0.02 * k + 0 * t, 1.0 + 0.005 * t]  # g
        cols += [10.0 * t, -5.0 + 0 * t, 2.0 * k + 0 * t]  # deg/s
        cols += [20000.0 + 100.0 * t, -3000.0 + 0 * t, -40000.0 + 0 * t]  # nT
    rows = [";".join(f"{v:.6f}".replace(".", ",") for v in r) for r in np.column_stack(cols)]
    path.write_text(";".join(header) + "\n" + "\n".join(rows) + "\n")


def test_a_mapping_of_one_leg_under_its_two_leg_names_reads_that_leg(tmp_path):
    _vendor_csv(tmp_path / "v.csv", 1.7e6 + np.arange(0, 3000, 10.0))
    plain = _mapping()
    named = {("pelvis" if s == "pelvis" else f"right_{s}"): v for s, v in plain["sensors"].items()}
    trial = read_mapped_csv(tmp_path / "v.csv", _mapping(sensors=named))
    same = read_mapped_csv(tmp_path / "v.csv", _mapping(side="right"))
    assert trial.side == "right"
    for s in SENSORS:
        np.testing.assert_array_equal(trial.gyr[s], same.gyr[s])
    with pytest.raises(MappingError, match=r"sensors.right_shank.gyr.*unit"):
        named["right_shank"] = {**named["right_shank"], "gyr": {"columns": ["a", "b", "c"], "unit": "rpm"}}
        CsvMapping.from_dict(_mapping(sensors=named))
    with pytest.raises(MappingError, match="named as the right leg's; give 'right' or no side"):
        CsvMapping.from_dict(_mapping(sensors=named, side="left"))


def test_mapped_csv_units_and_time(tmp_path):
    t_ms = 1.7e6 + np.arange(0, 3000, 10.0)  # absolute clock, 100 Hz, in ms
    _vendor_csv(tmp_path / "v.csv", t_ms)
    trial = read_mapped_csv(tmp_path / "v.csv", _mapping(side="right"))
    assert trial.side == "right" and trial.n_samples == 300
    np.testing.assert_allclose(trial.time_s, np.arange(300) / 100.0, atol=1e-9)
    t = trial.time_s
    np.testing.assert_allclose(trial.acc["shank"][:, 2], GRAVITY_MPS2 * (1.0 + 0.005 * t), atol=1e-5)
    np.testing.assert_allclose(trial.acc["shank"][:, 1], GRAVITY_MPS2 * 0.04, atol=1e-5)
    np.testing.assert_allclose(trial.gyr["foot"][:, 0], np.deg2rad(10.0 * t), atol=1e-7)
    np.testing.assert_allclose(trial.gyr["foot"][:, 2], np.deg2rad(6.0), atol=1e-9)
    np.testing.assert_allclose(trial.mag["pelvis"][:, 0], 20.0 + 0.1 * t, atol=1e-6)  # µT
    np.testing.assert_allclose(trial.mag["pelvis"][:, 2], -40.0, atol=1e-9)


def test_mapped_csv_resampling(tmp_path):
    rng = np.random.default_rng(0)
    t_ms = np.cumsum(np.r_[0.0, rng.uniform(6.0, 14.0, 399)])  # jittered source clock, ms
    _vendor_csv(tmp_path / "v.csv", t_ms)
    mapping = _mapping(resample_hz=50)
    with pytest.warns(UnevenClockWarning, match="time steps vary"):  # onto the source's own mean rate
        own = read_mapped_csv(tmp_path / "v.csv", _mapping())
    assert own.rate_hz == pytest.approx(1000.0 / np.mean(np.diff(t_ms)), rel=0.05)
    assert np.ptp(np.diff(own.time_s)) < 1e-12
    trial = read_mapped_csv(tmp_path / "v.csv", mapping)
    end = (t_ms[-1] - t_ms[0]) / 1000.0
    assert trial.n_samples == math.floor(end * 50) + 1
    np.testing.assert_allclose(np.diff(trial.time_s), 0.02, atol=1e-12)
    t = trial.time_s  # signals are linear in time: interpolation is exact
    np.testing.assert_allclose(trial.gyr["thigh"][:, 0], np.deg2rad(10.0 * t), atol=2e-6)
    np.testing.assert_allclose(trial.acc["foot"][:, 0], GRAVITY_MPS2 * 0.01 * t, atol=1e-5)
    # a 0.16 s interval in the source (990 ms → 1150 ms) is refused
    t_gap = np.r_[np.arange(0, 1000, 10.0), np.arange(1150, 3000, 10.0)]
    _vendor_csv(tmp_path / "gap.csv", t_gap)
    with pytest.raises(PacketGapError, match=r"gap of 0.16 s at 0.990 s"):
        read_mapped_csv(tmp_path / "gap.csv", mapping)


def test_mapped_csv_from_json_file_and_two_legs(tmp_path):
    two = {
        "time": {"column": "time", "unit": "s"},
        "sensors": {
            s: {
                "acc": {"columns": [f"{s}_acc_{a}" for a in "xyz"], "unit": "m/s^2"},
                "gyr": {"columns": [f"{s}_gyr_{a}" for a in "xyz"], "unit": "rad/s"},
            }
            for s in TWO_LEG_SENSORS
        },
    }
    (tmp_path / "map.json").write_text(json.dumps(two))
    t = np.arange(300) / 100.0
    cols = [t]
    for k, _ in enumerate(TWO_LEG_SENSORS):
        acc, gyr, _ = _signals(np.arange(300), k)
        cols += [acc, gyr]
    header = ["time"] + [f"{s}_{q}_{a}" for s in TWO_LEG_SENSORS for q in ("acc", "gyr") for a in "xyz"]
    np.savetxt(
        tmp_path / "in.csv", np.column_stack(cols), delimiter=",", header=",".join(header), comments=""
    )
    rec = load_mapped_csv(tmp_path / "in.csv", tmp_path / "map.json")
    assert rec.two_leg and rec.mag is None
    rec.to_csv(tmp_path / "out.csv")
    assert (tmp_path / "out.csv").read_text().splitlines()[0] == ",".join(header)
    assert CsvMapping.from_json(tmp_path / "map.json").sensors["right_foot"]["gyr"].unit == "rad/s"


@pytest.mark.parametrize(
    "over, message",
    [
        (
            {"time": {"column": "Timestamp", "unit": "min"}},
            "field 'time.unit': unknown unit 'min'; use one of s, ms",
        ),
        ({"time": "Timestamp"}, "field 'time': give"),
        ({"delimiter": ";;"}, "field 'delimiter': give one character"),
        ({"decimal": ";"}, "field 'decimal': give '.' or ','"),
        ({"delimiter": ","}, "field 'decimal': the decimal mark ',' is also the delimiter"),
        ({"resample_hz": -5}, "field 'resample_hz': give a positive rate"),
        ({"side": "middle"}, "field 'side': give 'left' or 'right'"),
        ({"sensor": {}}, "field 'sensor': unknown key"),
        ({"format": "other/2"}, "field 'format': expected"),
    ],
)
def test_mapping_errors_name_the_field(over, message):
    with pytest.raises(MappingError, match=message):
        CsvMapping.from_dict(_mapping(**over))


@pytest.mark.parametrize(
    "edit, message",
    [
        (lambda s: s["thigh"]["acc"].update(unit="m/s"), "'sensors.thigh.acc.unit': unknown unit 'm/s'"),
        (lambda s: s["foot"]["gyr"].update(columns=["a", "b"]), "'sensors.foot.gyr.columns': give three"),
        (lambda s: s["shank"].pop("gyr"), "'sensors.shank.gyr': missing"),
        (lambda s: s["pelvis"].pop("mag"), "'sensors.pelvis.mag': give mag for every sensor or for none"),
        (lambda s: s.update(knee=s.pop("shank")), "'sensors.knee': unknown segment 'knee'"),
        (lambda s: s["foot"].update(quat={}), "'sensors.foot.quat': unknown quantity"),
    ],
)
def test_mapping_sensor_errors_name_the_field(edit, message):
    m = _mapping()
    edit(m["sensors"])
    with pytest.raises(MappingError, match=message) as e:
        CsvMapping.from_dict(m)
    assert e.value.field in message


def test_mapped_csv_data_errors(tmp_path):
    t_ms = np.arange(0, 3000, 10.0)
    _vendor_csv(tmp_path / "v.csv", t_ms)
    m = _mapping()
    m["sensors"]["foot"]["acc"]["columns"][0] = "foot.accx"
    with pytest.raises(ColumnNotFoundError, match="has no column 'foot.accx'"):
        read_mapped_csv(tmp_path / "v.csv", m)
    bad = _mapping()
    for q in SENSORS:  # magnetometer columns (nT) taken for a gyro in rad/s: ImuTrial.validate objects
        bad["sensors"][q]["gyr"] = {"columns": [f"{q}.mx", f"{q}.my", f"{q}.mz"], "unit": "rad/s"}
        del bad["sensors"][q]["mag"]  # each source column feeds one signal
    with pytest.raises(UnitError, match="pelvis gyro values up to 44956 look like deg/s"):
        read_mapped_csv(tmp_path / "v.csv", bad)
    text = (tmp_path / "v.csv").read_text().splitlines()
    cells = text[5].split(";")
    cells[4] = "x1"
    text[5] = ";".join(cells)
    (tmp_path / "cell.csv").write_text("\n".join(text))
    with pytest.raises(InputError, match=r"data row 5: column 'pelvis.gx' is not a number \('x1'\)"):
        read_mapped_csv(tmp_path / "cell.csv", _mapping())
    cells[4] = ""
    text[5] = ";".join(cells)
    (tmp_path / "nan.csv").write_text("\n".join(text))
    with pytest.raises(NonFiniteValueError, match="'pelvis_gyr_x' has a NaN or infinite value at data row 5"):
        read_mapped_csv(tmp_path / "nan.csv", _mapping())
    with pytest.raises(NonFiniteValueError, match="'pelvis.gx' has a NaN or infinite value at data row 5"):
        read_mapped_csv(tmp_path / "nan.csv", _mapping(resample_hz=100))
    with pytest.raises(FileNotFoundError, match="mapping file not found"):
        read_mapped_csv(tmp_path / "v.csv", tmp_path / "none.json")
    (tmp_path / "broken.json").write_text("{")
    with pytest.raises(MappingError, match="is not valid JSON"):
        read_mapped_csv(tmp_path / "v.csv", tmp_path / "broken.json")


def test_top_level_exports():
    assert lowerlimb.read_xsens is read_xsens and lowerlimb.read_mapped_csv is read_mapped_csv


# ------------------------------------------------------------------ CLI


def test_cli_import_xsens_and_csv(tmp_path, capsys):
    folder = _export_dir(tmp_path)
    out = tmp_path / "trial.csv"
    argv = ["import", "xsens", str(folder), "--map", ",".join(f"{k}={v}" for k, v in IDS.items())]
    assert main([*argv, "--side", "right", "--out", str(out), "--mag-field-ut", "40"]) == 0
    printed = capsys.readouterr().out
    assert "400 samples at 100 Hz, right leg, with magnetometer, 0 samples filled" in printed
    # the written columns carry no side: the user is told to give it to calibrate
    assert "calibrate it with --side right" in printed
    trial = ImuTrial.from_csv(out, side="right")
    np.testing.assert_allclose(trial.mag["foot"][0], 40.0 * (MAG_NORMALISED + 0.003), atol=1e-4)
    # an existing output is kept without --force, replaced with it
    before = out.read_text()
    assert main([*argv, "--out", str(out), "--mag-field-ut", "60"]) == 2
    assert "already exists; choose another --out or pass --force" in capsys.readouterr().err
    assert out.read_text() == before
    assert main([*argv, "--out", str(out), "--mag-field-ut", "60", "--force"]) == 0
    assert ImuTrial.from_csv(out).mag["foot"][0] == pytest.approx(60.0 * (MAG_NORMALISED + 0.003), abs=1e-4)
    _vendor_csv(tmp_path / "v.csv", np.arange(0, 3000, 10.0))
    (tmp_path / "map.json").write_text(json.dumps(_mapping()))
    out2 = tmp_path / "t2.csv"
    assert (
        main(
            [
                "import",
                "csv",
                str(tmp_path / "v.csv"),
                "--mapping",
                str(tmp_path / "map.json"),
                "--out",
                str(out2),
            ]
        )
        == 0
    )
    assert ImuTrial.from_csv(out2).n_samples == 300
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temp files left


@pytest.mark.parametrize(
    "argv, message",
    [
        (["import", "xsens", "nope", "--map", "pelvis=1,thigh=2,shank=3,foot=4"], "directory not found"),
        (["import", "xsens", "REC", "--map", "pelvis"], "'pelvis' is not SEGMENT=ID"),
        (
            [
                "import",
                "xsens",
                "REC",
                "--map",
                "pelvis=00B40B91,thigh=00B40C45,shank=00B40C44,foot=00B40C99",
            ],
            "no file in",
        ),
        (
            ["import", "xsens", "REC", "--map", "pelvis=00B40B91,thigh=00B40C45,shank=00B40C44"],
            "no sensor given for foot",
        ),
        (
            [
                "import",
                "xsens",
                "REC",
                "--map",
                "pelvis=00B40B91,thigh=00B40C45,shank=00B40C44,foot=00B40C55",
                "--mag-field-ut",
                "0",
            ],
            "must be positive",
        ),
        (["import", "csv", "REC/none.csv", "--mapping", "MAP"], "CSV file not found"),
        (["import", "csv", "V", "--mapping", "BADMAP"], "field 'time.unit'"),
        (["import", "csv", "V", "--mapping", "MAP", "--side", "left"], "unrecognized arguments: --side"),
        (["import", "tsv", "V"], "invalid choice: 'tsv'"),
        (
            [
                "import",
                "xsens",
                "REC",
                "--map",
                ",".join(f"{k}={v}" for k, v in TWO_IDS.items()),
                "--side",
                "left",
            ],
            "--side is for a one-leg map",
        ),
        (["import", "xsens", "REC", "--map", "pelvis=A,pelvis=B"], "segment 'pelvis' is given twice"),
    ],
)
def test_cli_import_bad_input_is_one_line_exit_2_no_output(argv, message, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    folder = _export_dir(tmp_path)
    _vendor_csv(tmp_path / "v.csv", np.arange(0, 3000, 10.0))
    (tmp_path / "map.json").write_text(json.dumps(_mapping()))
    (tmp_path / "bad.json").write_text(json.dumps(_mapping(time={"column": "Timestamp", "unit": "h"})))
    subst = {"REC": str(folder), "V": str(tmp_path / "v.csv"), "MAP": "map.json", "BADMAP": "bad.json"}
    argv = [subst.get(a, a.replace("REC", str(folder))) for a in argv]
    assert main([*argv, "--out", "x.csv"]) == 2
    err = capsys.readouterr().err
    assert message in err
    assert err.count("\n") == 1 and err.startswith("lowerlimb: error:") and "Traceback" not in err
    assert not (tmp_path / "x.csv").exists()
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".x.csv")]


# ------------------------------------------------------------------ real data

GAIT = data_dir() / "gait" / "rawimu" if data_dir() is not None else None
GAIT_LEFT = {"pelvis": "00B40B91", "thigh": "00B40C45", "shank": "00B40C44", "foot": "00B40C55"}


@pytest.mark.data
@pytest.mark.skipif(GAIT is None or not GAIT.is_dir(), reason="gait/rawimu (real Xsens walk) not found")
def test_real_walk_imports():
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no filled packets, no missing Mag
        trial = read_xsens(GAIT, GAIT_LEFT, side="left")
        rec = load_xsens(GAIT, {**TWO_IDS})
    assert trial.n_samples == rec.n_samples == 2503 and rec.n_filled == 0
    assert trial.rate_hz == pytest.approx(100.0)
    standing = slice(0, 300)  # the subject stands for the first ~11 s
    for s in SENSORS:
        acc_norm = np.linalg.norm(trial.acc[s][standing], axis=1)
        assert np.median(acc_norm) == pytest.approx(9.81, abs=0.2)
        gyr = trial.gyr[s]
        assert np.max(np.abs(gyr[standing])) < 0.2  # rad/s, still
        assert 2.0 < np.max(np.linalg.norm(gyr, axis=1)) < 20.0  # walking: rad/s, not deg/s
        mag_norm = np.linalg.norm(trial.mag[s], axis=1)
        assert 25.0 < np.median(mag_norm) < 70.0  # µT: a plausible Earth field
    np.testing.assert_allclose(rec.acc["left_thigh"], trial.acc["thigh"])


def test_cli_import_gap_refused_names_max_gap_and_max_gap_bridges_it(tmp_path, capsys):
    folder = _export_dir(tmp_path, foot={"drop": set(range(1100, 1112))})  # 0.12 s lost
    out = tmp_path / "trial.csv"
    argv = ["import", "xsens", str(folder), "--map", ",".join(f"{k}={v}" for k, v in IDS.items())]
    assert main([*argv, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "foot has a gap of 0.12 s" in err and "--max-gap 0.13" in err
    assert not out.exists()
    assert main([*argv, "--out", str(out), "--max-gap", "0.11"]) == 2
    assert main([*argv, "--out", str(out), "--max-gap", "0.13"]) == 0
    assert "12 samples filled" in capsys.readouterr().out
    assert main([*argv, "--out", str(out), "--force", "--max-gap", "0"]) == 2
    assert "must be positive" in capsys.readouterr().err


def test_mapped_csv_bridges_a_half_rate_magnetometer_or_drops_an_empty_one(tmp_path):
    """Empty magnetometer cells (``lowerlimb.io.mag_cells``), with and without resampling."""
    from lowerlimb.io.mag_cells import MagnetometerCellsWarning

    t_ms = np.arange(0, 3000, 10.0)
    _vendor_csv(tmp_path / "v.csv", t_ms)
    full = read_mapped_csv(tmp_path / "v.csv", _mapping())
    lines = (tmp_path / "v.csv").read_text().splitlines()
    header = lines[0].split(";")
    mag = [i for i, h in enumerate(header) if ".m" in h]

    def emptied(rows: range, cols: list[int]) -> list[str]:
        out = list(lines)
        for r in rows:
            cells = out[r].split(";")
            for c in cols:
                cells[c] = ""
            out[r] = ";".join(cells)
        return out

    (tmp_path / "half.csv").write_text("\n".join(emptied(range(2, len(lines), 2), mag)) + "\n")
    for resample in (None, 100):
        with pytest.warns(MagnetometerCellsWarning, match="interpolated"):
            half = read_mapped_csv(tmp_path / "half.csv", _mapping(resample_hz=resample))
        assert half.mag is not None and full.mag is not None
        # linear in time, so interpolated exactly; the last row, empty, takes its neighbour's value
        np.testing.assert_allclose(half.mag["shank"][:-1], full.mag["shank"][:-1], atol=1e-6)
    foot = [i for i in mag if header[i].startswith("foot.")]
    (tmp_path / "nofoot.csv").write_text("\n".join(emptied(range(1, len(lines)), foot)) + "\n")
    with pytest.warns(MagnetometerCellsWarning, match="foot magnetometer columns are empty"):
        trial = read_mapped_csv(tmp_path / "nofoot.csv", _mapping())
    assert trial.mag is None
    np.testing.assert_array_equal(trial.gyr["foot"], full.gyr["foot"])
