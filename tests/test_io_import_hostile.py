"""Hostile input to the vendor importers (``lowerlimb import``) and the trial checks they share.

Each case is a file a user could hand over by mistake (a Latin-1 export, a mapping
with a column twice, acc and gyr exchanged, ...): it must end as one
:class:`~lowerlimb.errors.InputError` naming the problem and the fix, and on the
command line as one ``lowerlimb: error:`` line, exit 2 and no output file.
"""

from __future__ import annotations

import copy
import json
import re
import warnings

import numpy as np
import pytest
from simcache import data_dir
from test_io_import import IDS, TWO_IDS, _export_dir, _mapping, _vendor_csv

from lowerlimb.cli import main
from lowerlimb.conventions import SENSORS
from lowerlimb.errors import InputError, NonFiniteValueError, UnitError
from lowerlimb.io import (
    CsvMapping,
    MappingError,
    load_mapped_csv,
    load_xsens,
    read_mapped_csv,
    read_xsens,
    text_file,
)
from lowerlimb.io.bilateral_trial import BilateralTrial
from lowerlimb.io.bounds import INPUT_BOUNDS
from lowerlimb.io.errors import ColumnReusedError, NotTextError, UnreadableFileError
from lowerlimb.io.trial import IdenticalSensorsError, ImplausibleAccelerometerError, ImuTrial

MAP_ARG = ",".join(f"{k}={v}" for k, v in IDS.items())


def _foot_export(folder):
    return folder / f"S01-Walk-000_{IDS['foot']}.txt"


def _csv_case(tmp_path, mapping=None):
    """A vendor CSV (100 Hz, 3 s) and the path of its mapping JSON."""
    _vendor_csv(tmp_path / "v.csv", np.arange(0, 3000, 10.0))
    path = tmp_path / "map.json"
    path.write_text(json.dumps(mapping if mapping is not None else _mapping()))
    return tmp_path / "v.csv", path


def _refused(argv, capsys, out):
    """Run the CLI; assert one error line, exit 2, no output; return the line."""
    assert main([*argv, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("lowerlimb: error: ") and "Traceback" not in err
    assert not out.exists()
    assert not [p for p in out.parent.iterdir() if p.name.startswith(f".{out.name}")]
    return err


# ------------------------------------------------------------------ not UTF-8, not text, not a file


def test_xsens_latin1_comment_is_not_utf8(tmp_path, capsys):
    folder = _export_dir(tmp_path)
    foot = _foot_export(folder)
    foot.write_bytes(b"// Sensor: 20 \xb0C, \xb5T units\n" + foot.read_bytes())
    with pytest.raises(NotTextError, match=r"is not UTF-8 text \(byte 0xb0 at offset 14, line 1") as e:
        read_xsens(folder, IDS)
    assert e.value.problem == "encoding" and e.value.offset == 14 and e.value.path == str(foot)
    err = _refused(["import", "xsens", str(folder), "--map", MAP_ARG], capsys, tmp_path / "t.csv")
    assert foot.name in err and "save it as UTF-8" in err


def test_xsens_binary_export_and_folder_in_its_place(tmp_path, capsys):
    folder = _export_dir(tmp_path)
    foot = _foot_export(folder)
    foot.write_bytes(bytes(range(256)) * 8)
    err = _refused(["import", "xsens", str(folder), "--map", MAP_ARG], capsys, tmp_path / "t.csv")
    assert "is a binary file, not an MT Manager text export; export it again from MT Manager" in err
    foot.unlink()
    foot.mkdir()
    with pytest.raises(NotTextError, match="is a folder, not an MT Manager text export; move it out") as e:
        read_xsens(folder, IDS)
    assert e.value.problem == "folder"


def test_mapped_csv_latin1_header_is_not_utf8(tmp_path, capsys):
    csv_path, map_path = _csv_case(tmp_path)
    text = csv_path.read_text()
    csv_path.write_bytes(text.replace("pelvis.gx", "pelvis.gx °/s", 1).encode("latin-1"))
    m = _mapping()
    m["sensors"]["pelvis"]["gyr"]["columns"][0] = "pelvis.gx °/s"
    map_path.write_text(json.dumps(m))
    err = _refused(["import", "csv", str(csv_path), "--mapping", str(map_path)], capsys, tmp_path / "t.csv")
    assert f"{csv_path} is not UTF-8 text (byte 0xb0" in err and "save it as UTF-8" in err
    # a mapping JSON in Latin-1 too
    map_path.write_bytes(json.dumps(m, ensure_ascii=False).encode("latin-1"))
    with pytest.raises(NotTextError, match="map.json is not UTF-8 text"):
        CsvMapping.from_json(map_path)


@pytest.mark.parametrize(
    "encoding, bom, name",
    [
        ("utf-16-le", b"\xff\xfe", "UTF-16"),  # Excel's "Unicode Text"
        ("utf-16-be", b"\xfe\xff", "UTF-16"),
        ("utf-32-le", b"\xff\xfe\x00\x00", "UTF-32"),
    ],
)
def test_utf16_and_utf32_text_is_named_not_called_binary(tmp_path, capsys, encoding, bom, name):
    csv_path, map_path = _csv_case(tmp_path)
    csv_path.write_bytes(bom + csv_path.read_text().encode(encoding))
    with pytest.raises(NotTextError) as e:
        load_mapped_csv(csv_path, map_path)
    assert e.value.problem == "encoding" and e.value.offset == 0
    err = _refused(["import", "csv", str(csv_path), "--mapping", str(map_path)], capsys, tmp_path / "t.csv")
    assert f"{csv_path} is {name} text, not UTF-8; save it as UTF-8" in err and "binary" not in err
    folder = _export_dir(tmp_path)
    foot = _foot_export(folder)
    foot.write_bytes(bom + foot.read_text().encode(encoding))
    err = _refused(["import", "xsens", str(folder), "--map", MAP_ARG], capsys, tmp_path / "t.csv")
    assert f"{foot} is {name} text, not UTF-8; save it as UTF-8" in err


def test_a_file_without_read_permission_is_one_line(tmp_path, capsys, monkeypatch):
    """chmod 000 does not stop root, so open() is made to refuse the file as it would for a user."""
    csv_path, map_path = _csv_case(tmp_path)
    folder = _export_dir(tmp_path)
    foot = _foot_export(folder)

    def denied(path, *args, **kwargs):
        if str(path) in (str(csv_path), str(foot)):
            raise PermissionError(13, "Permission denied", str(path))
        return open(path, *args, **kwargs)

    monkeypatch.setattr(text_file, "open", denied, raising=False)
    with pytest.raises(UnreadableFileError) as e:
        load_mapped_csv(csv_path, map_path)
    assert e.value.path == str(csv_path)
    err = _refused(["import", "csv", str(csv_path), "--mapping", str(map_path)], capsys, tmp_path / "t.csv")
    assert err == (
        f"lowerlimb: error: cannot read {csv_path} (permission denied); give yourself read access "
        f"(chmod u+r {csv_path})\n"
    )
    err = _refused(["import", "xsens", str(folder), "--map", MAP_ARG], capsys, tmp_path / "t.csv")
    assert f"cannot read {foot} (permission denied); give yourself read access (chmod u+r {foot})" in err
    assert "Errno" not in err


def test_mapped_csv_folder_and_mapping_folder(tmp_path, capsys):
    csv_path, map_path = _csv_case(tmp_path)
    err = _refused(["import", "csv", str(csv_path), "--mapping", str(tmp_path)], capsys, tmp_path / "t.csv")
    assert f"{tmp_path} is a folder, not a CSV mapping (JSON)" in err and "not found" not in err
    with pytest.raises(NotTextError, match="is a folder, not a CSV file"):
        load_mapped_csv(tmp_path, map_path)


def test_mapped_csv_cell_over_the_csv_field_limit(tmp_path):
    csv_path, map_path = _csv_case(tmp_path)
    lines = csv_path.read_text().splitlines()
    lines[3] = '"' + "1" * 200_000 + '"' + lines[3][lines[3].index(";") :]
    csv_path.write_text("\n".join(lines))
    with pytest.raises(InputError, match=r"is not a readable CSV \(field larger than field limit"):
        load_mapped_csv(csv_path, map_path)


# ------------------------------------------------------------------ mapping value types and keys


@pytest.mark.parametrize(
    "edit, field, message",
    [
        (lambda m: m["sensors"]["thigh"]["acc"].update(unit=["g"]), "sensors.thigh.acc.unit", "as a string"),
        (lambda m: m["time"].update(unit=["ms"]), "time.unit", "give the unit as a string, not ['ms']"),
        (lambda m: m["sensors"]["foot"]["mag"].update(unit={"u": 1}), "sensors.foot.mag.unit", "a string"),
        (lambda m: m["sensors"]["shank"]["gyr"].pop("unit"), "sensors.shank.gyr.unit", "missing; use one of"),
        (
            lambda m: m["sensors"]["thigh"]["acc"].update(scale=2),
            "sensors.thigh.acc.scale",
            "unknown key; the keys are columns, unit",
        ),
        (lambda m: m["time"].update(offset=5), "time.offset", "unknown key; the keys are column, unit"),
        (lambda m: m.update(resample_hz=1e9), "resample_hz", "1e+09 Hz is out of range; give a sampling"),
        (lambda m: m.update(resample_hz=0.5), "resample_hz", "0.5 Hz is out of range"),
    ],
)
def test_mapping_value_types_keys_and_ranges(edit, field, message):
    m = _mapping()
    edit(m)
    with pytest.raises(MappingError, match=f"field '{field}'") as e:
        CsvMapping.from_dict(m)
    assert e.value.field == field and message in str(e.value)


def test_resample_hz_range_is_the_input_bounds_rate():
    lo, hi = INPUT_BOUNDS.rate_hz
    assert CsvMapping.from_dict(_mapping(resample_hz=lo)).resample_hz == lo
    assert CsvMapping.from_dict(_mapping(resample_hz=hi)).resample_hz == hi
    with pytest.raises(MappingError, match=f"from {lo:g} to {hi:g} Hz"):
        CsvMapping.from_dict(_mapping(resample_hz=hi * 1.01))


def test_cli_resample_hz_huge_or_tiny_names_the_key(tmp_path, capsys):
    for rate in (1e9, 0.5):
        csv_path, map_path = _csv_case(tmp_path, _mapping(resample_hz=rate))
        err = _refused(
            ["import", "csv", str(csv_path), "--mapping", str(map_path)], capsys, tmp_path / "t.csv"
        )
        assert "mapping field 'resample_hz'" in err and "milliseconds" not in err


# ------------------------------------------------------------------ a source column used twice


def _two_leg_mapping():
    m = _mapping()
    s = m["sensors"]
    for side in ("left", "right"):
        for seg in SENSORS[1:]:
            s[f"{side}_{seg}"] = copy.deepcopy(s[seg])
    for seg in SENSORS[1:]:
        del s[seg]
    return m


@pytest.mark.parametrize(
    "edit, column, first, second",
    [
        (
            lambda m: m["sensors"]["thigh"]["acc"].update(columns=["thigh.ax", "thigh.ax", "thigh.az"]),
            "thigh.ax",
            "sensors.thigh.acc.columns[0]",
            "sensors.thigh.acc.columns[1]",
        ),
        (
            lambda m: m["sensors"]["foot"]["mag"]["columns"].__setitem__(0, "Timestamp"),
            "Timestamp",
            "time.column",
            "sensors.foot.mag.columns[0]",
        ),
        (
            lambda m: m["sensors"]["shank"]["gyr"]["columns"].__setitem__(2, "pelvis.ax"),
            "pelvis.ax",
            "sensors.pelvis.acc.columns[0]",
            "sensors.shank.gyr.columns[2]",
        ),
    ],
)
def test_a_source_column_mapped_twice_is_refused(edit, column, first, second):
    m = _mapping()
    edit(m)
    with pytest.raises(ColumnReusedError) as e:
        CsvMapping.from_dict(m)
    assert (e.value.column, e.value.first, e.value.second, e.value.field) == (column, first, second, second)
    assert f"column '{column}' is also mapped as {first}" in str(e.value)


def test_two_legs_on_the_same_columns_are_refused(tmp_path, capsys):
    """Import wrote this two-leg trial (exit 0) and calibrate refused it."""
    m = _two_leg_mapping()
    m["sensors"]["right_thigh"] = copy.deepcopy(m["sensors"]["left_thigh"])
    with pytest.raises(ColumnReusedError, match="'sensors.right_thigh.acc.columns.0.'"):
        CsvMapping.from_dict(m)


def test_two_leg_recording_with_identical_legs_is_refused(tmp_path):
    rec = load_xsens(_export_dir(tmp_path, ids=TWO_IDS), TWO_IDS)
    rec.acc["right_shank"], rec.gyr["right_shank"] = rec.acc["left_shank"], rec.gyr["left_shank"]
    with pytest.raises(IdenticalSensorsError, match="the left_shank and right_shank columns hold identical"):
        rec.to_csv(tmp_path / "two.csv")
    assert not (tmp_path / "two.csv").exists()


# ------------------------------------------------------------------ an accelerometer that is not one


def _swapped_pelvis_mapping():
    m = _mapping()
    p = m["sensors"]["pelvis"]
    p["acc"]["columns"], p["gyr"]["columns"] = p["gyr"]["columns"], p["acc"]["columns"]
    return m


def test_acc_and_gyr_exchanged_are_refused_at_import(tmp_path, capsys):
    csv_path, map_path = _csv_case(tmp_path, _swapped_pelvis_mapping())
    with pytest.raises(ImplausibleAccelerometerError) as e:
        read_mapped_csv(csv_path, map_path)
    assert e.value.sensor == "pelvis" and e.value.signal == "pelvis_acc"
    assert e.value.median_mps2 > e.value.limit_mps2 == INPUT_BOUNDS.max_median_acc_mps2
    assert isinstance(e.value, UnitError) and e.value.value == e.value.median_mps2
    err = _refused(["import", "csv", str(csv_path), "--mapping", str(map_path)], capsys, tmp_path / "t.csv")
    assert "the pelvis accelerometer reads a median magnitude of" in err
    assert "gyro columns are mapped as the accelerometer" in err and "mm/s²" in err


def _trial(tmp_path):
    csv_path, map_path = _csv_case(tmp_path)
    return read_mapped_csv(csv_path, map_path)


@pytest.mark.parametrize("factor", [100.0, 1000.0])
def test_accelerometer_in_cm_or_mm_per_s2_is_refused_at_load(tmp_path, factor):
    """×1000 used to be a "glitch" at one sample; the median names the unit instead."""
    trial = _trial(tmp_path)
    trial.acc["shank"] = trial.acc["shank"] * factor
    trial.to_csv(tmp_path / "trial.csv")
    with pytest.raises(ImplausibleAccelerometerError, match=r"the shank accelerometer reads a median") as e:
        ImuTrial.from_csv(tmp_path / "trial.csv")
    assert e.value.median_mps2 == pytest.approx(np.median(np.linalg.norm(trial.acc["shank"], axis=1)))


def test_the_earlier_unit_checks_keep_their_order_and_words(tmp_path):
    trial = _trial(tmp_path)
    trial.acc["thigh"] = trial.acc["thigh"] * 100.0  # an implausible accelerometer and ...
    trial.gyr["thigh"] = np.rad2deg(trial.gyr["thigh"]) * 10  # ... a deg/s gyro: the gyro is named
    with pytest.raises(UnitError, match="thigh gyro values up to .* look like deg/s"):
        trial.validate()
    trial = _trial(tmp_path)
    trial.acc["pelvis"] = trial.acc["pelvis"] / 9.81
    with pytest.raises(UnitError, match=r"pelvis accelerometer median magnitude 1.0\d looks like g"):
        trial.validate()
    trial.acc["pelvis"] = trial.acc["pelvis"] * 9.81 * 2000
    with pytest.raises(UnitError, match="median magnitude .* is beyond any sensor's range in m/s²"):
        trial.validate()


def test_two_leg_trial_names_the_implausible_accelerometer(tmp_path):
    rec = load_xsens(_export_dir(tmp_path, ids=TWO_IDS), TWO_IDS)
    acc = dict(rec.acc)
    acc["right_thigh"] = acc["right_thigh"] * 100.0
    trial = BilateralTrial(rec.time_s, acc, rec.gyr, rec.mag)
    with pytest.raises(ImplausibleAccelerometerError, match="the right_thigh accelerometer reads") as e:
        trial.validate()
    assert e.value.sensor == "right_thigh" and e.value.signal == "right_thigh_acc"


def test_simulated_walk_stays_well_below_the_accelerometer_bound(walk_noisy):
    for sensor in SENSORS:
        median = np.median(np.linalg.norm(walk_noisy.trial.acc[sensor], axis=1))
        assert median < 0.75 * INPUT_BOUNDS.max_median_acc_mps2, sensor


GAIT = data_dir() / "gait" / "rawimu" if data_dir() is not None else None


@pytest.mark.data
@pytest.mark.skipif(GAIT is None or not GAIT.is_dir(), reason="gait/rawimu (real Xsens walk) not found")
def test_real_walk_stays_well_below_the_accelerometer_bound():
    rec = load_xsens(GAIT, TWO_IDS)
    walking = slice(1120, 2074)  # the authors' walking window (data/README.md)
    for sensor, acc in rec.acc.items():
        median = np.median(np.linalg.norm(acc[walking], axis=1))
        assert median < 0.4 * INPUT_BOUNDS.max_median_acc_mps2, sensor


# ------------------------------------------------------------------ minor: the right reason


def test_xsens_update_rate_zero_is_named(tmp_path):
    folder = _export_dir(tmp_path)
    foot = _foot_export(folder)
    foot.write_text(foot.read_text().replace("// Update Rate: 100.0Hz", "// Update Rate: 0Hz"))
    with pytest.raises(InputError, match=r"says '// Update Rate: 0Hz', not a sampling rate"):
        read_xsens(folder, IDS)


@pytest.mark.parametrize("value", ["1e30", "-3", "1500.5"])
def test_xsens_corrupt_packet_counter_is_named_by_line(tmp_path, value):
    folder = _export_dir(tmp_path)
    foot = _foot_export(folder)
    lines = foot.read_text().splitlines()
    lines[9] = value + lines[9][lines[9].index(",") :]
    foot.write_text("\n".join(lines))
    shown = re.escape(f"{float(value):.10g}")
    with pytest.raises(InputError, match=rf"line 10: PacketCounter {shown} is not a packet number"):
        read_xsens(folder, IDS)


def test_time_unit_us_for_ms_data_names_the_unit(tmp_path):
    m = _mapping(time={"column": "Timestamp", "unit": "us"})
    csv_path, map_path = _csv_case(tmp_path, m)
    with pytest.raises(UnitError, match=r'if the time column is in ms, set "unit": "ms"') as e:
        load_mapped_csv(csv_path, map_path)
    assert e.value.signal == "time.unit" and "longer trial" not in str(e.value)
    # resampled to a plausible rate, the clock's unit is still wrong: the trial lasts 3 ms
    with pytest.raises(UnitError, match="time steps of 10 us give a rate of 1e"):
        load_mapped_csv(csv_path, _mapping(time={"column": "Timestamp", "unit": "us"}, resample_hz=100))


def test_empty_last_time_cell_with_resampling_is_named(tmp_path):
    csv_path, map_path = _csv_case(tmp_path, _mapping(resample_hz=100))
    lines = csv_path.read_text().splitlines()
    lines[-1] = lines[-1][lines[-1].index(";") :]
    csv_path.write_text("\n".join(lines))
    with pytest.raises(NonFiniteValueError, match="'Timestamp' has a NaN or infinite value at data row 300"):
        load_mapped_csv(csv_path, map_path)


# ------------------------------------------------------------------ Xsens cells and locales


@pytest.mark.parametrize("written", ["inf", "nan", "-inf", "NaN"])
@pytest.mark.parametrize("column", ["Acc_Y", "Gyr_Z", "Mag_X"])
def test_xsens_written_inf_or_nan_is_refused_not_filled(tmp_path, capsys, written, column):
    folder = _export_dir(tmp_path)
    foot = _foot_export(folder)
    lines = foot.read_text().splitlines()
    header = lines[3].split(",")
    cells = lines[50].split(",")
    cells[header.index(column)] = written
    lines[50] = ",".join(cells)
    foot.write_text("\n".join(lines) + "\n")
    message = (
        f"{foot} line 51: {column} is '{written}', not a measured value; empty the cell (a missing "
        f"sample, filled by interpolation) or remove the row"
    )
    with pytest.raises(InputError) as e:
        load_xsens(folder, IDS)
    assert str(e.value) == message
    err = _refused(["import", "xsens", str(folder), "--map", MAP_ARG], capsys, tmp_path / "t.csv")
    assert err == f"lowerlimb: error: {message}\n"


def test_xsens_empty_cell_is_still_a_filled_packet_and_nan_counter_is_refused(tmp_path):
    folder = _export_dir(tmp_path, foot={"empty_acc": {1050}})
    assert load_xsens(folder, IDS).filled["foot"] == 1
    foot = _foot_export(folder)
    lines = foot.read_text().splitlines()
    lines[9] = "nan" + lines[9][lines[9].index(",") :]
    foot.write_text("\n".join(lines))
    with pytest.raises(
        InputError, match="line 10: PacketCounter is 'nan', not a measured value; fix or remove"
    ):
        load_xsens(folder, IDS)


def _localised(path, delimiter):
    """Rewrite an export as a decimal-comma locale writes it: ``delimiter`` between cells, ',' in numbers."""
    out = []
    for line in path.read_text().splitlines():
        if line.startswith("//"):
            out.append(line.replace("100.0Hz", "100,0Hz"))
        else:
            out.append(line.replace(",", delimiter).replace(".", ","))
    path.write_text("\n".join(out) + "\n")


@pytest.mark.parametrize("delimiter", [";", "\t"])
def test_xsens_decimal_comma_export_is_read(tmp_path, delimiter):
    plain = load_xsens(_export_dir(tmp_path / "a"), IDS)
    folder = _export_dir(tmp_path / "b")
    for p in folder.iterdir():
        _localised(p, delimiter)
    assert "100,0Hz" in _foot_export(folder).read_text()
    rec = load_xsens(folder, IDS)
    np.testing.assert_array_equal(rec.time_s, plain.time_s)
    for s in SENSORS:
        np.testing.assert_array_equal(rec.acc[s], plain.acc[s])
        np.testing.assert_array_equal(rec.gyr[s], plain.gyr[s])
        np.testing.assert_array_equal(rec.mag[s], plain.mag[s])


def test_xsens_decimal_comma_mixed_with_a_point_is_refused(tmp_path):
    folder = _export_dir(tmp_path)
    foot = _foot_export(folder)
    _localised(foot, ";")
    lines = foot.read_text().splitlines()
    cells = lines[20].split(";")
    cells[2] = cells[2].replace(",", ".")
    lines[20] = ";".join(cells)
    foot.write_text("\n".join(lines))
    with pytest.raises(InputError, match=r"line 21: Acc_X is '-?0\.\d+', with '.' although the file's other"):
        load_xsens(folder, IDS)


def test_xsens_update_rate_with_a_decimal_comma(tmp_path):
    folder = _export_dir(tmp_path)
    foot = _foot_export(folder)
    foot.write_text(foot.read_text().replace("// Update Rate: 100.0Hz", "// Update Rate: 100,0Hz"))
    assert load_xsens(folder, IDS).n_samples == 400


def test_xsens_column_names_in_any_case(tmp_path, capsys):
    plain = load_xsens(_export_dir(tmp_path / "a"), IDS)
    folder = _export_dir(tmp_path / "b")
    foot = _foot_export(folder)
    lines = foot.read_text().splitlines()
    lines[3] = lines[3].lower()
    foot.write_text("\n".join(lines))
    rec = load_xsens(folder, IDS)
    np.testing.assert_array_equal(rec.acc["foot"], plain.acc["foot"])
    np.testing.assert_array_equal(rec.mag["foot"], plain.mag["foot"])
    foot.write_text(foot.read_text().replace("gyr_z", "gyr_w"))
    err = _refused(["import", "xsens", str(folder), "--map", MAP_ARG], capsys, tmp_path / "t.csv")
    assert f"{foot} has no column 'Gyr_Z'" in err and "mapping" not in err
    assert "export the recording again from MT Manager with PacketCounter, Acc and Gyr enabled" in err


def test_xsens_comma_in_a_column_not_read_leaves_the_decimal_point(tmp_path):
    plain = load_xsens(_export_dir(tmp_path / "a"), IDS)
    folder = _export_dir(tmp_path / "b")
    foot = _foot_export(folder)
    text = foot.read_text().splitlines()
    lines = [line if line.startswith("//") else line.replace(",", "\t") for line in text]
    lines[3] += "\tNote"
    lines[4:] = [line + "\twalk, slow" for line in lines[4:]]
    foot.write_text("\n".join(lines))
    np.testing.assert_array_equal(load_xsens(folder, IDS).acc["foot"], plain.acc["foot"])


# ------------------------------------------------------------------ a wrong unit of the mapping names it


def _time_case(tmp_path, values, unit, **over):
    """A vendor CSV whose Timestamp column holds ``values`` and a mapping declaring them ``unit``."""
    _vendor_csv(tmp_path / "v.csv", np.asarray(values, dtype=float))
    path = tmp_path / "map.json"
    path.write_text(json.dumps(_mapping(time={"column": "Timestamp", "unit": unit}, **over)))
    return tmp_path / "v.csv", path


@pytest.mark.parametrize(
    "values, unit, message",
    [
        (
            np.arange(0, 3000, 10.0),  # ms declared s
            "s",
            "time steps of 10 s give a rate of 0.1 Hz, slower than the 5 Hz a trial may have; if the "
            'time column is in ms, set "unit": "ms" in the mapping\'s "time" (a rate of 100 Hz)',
        ),
        (
            1.7e18 + np.arange(0, 3e9, 1e7),  # epoch nanoseconds declared ms
            "ms",
            "time steps of 1e+07 ms give a rate of 0.0001 Hz, slower than the 5 Hz a trial may have; if "
            'the time column is in ns, set "unit": "ns" in the mapping\'s "time" (a rate of 100 Hz)',
        ),
        (
            np.arange(0, 30000, 100.0),  # 10 Hz in ms, 10 kHz in us: no unit gives a trial's rate
            "s",
            "time steps of 100 s give a rate of 0.01 Hz, slower than the 5 Hz a trial may have; "
            'check the "unit" of the mapping\'s "time" (s, ms, us or ns), or map a column of times',
        ),
    ],
)
def test_time_unit_too_slow_names_the_mapping_unit(tmp_path, capsys, values, unit, message):
    csv_path, map_path = _time_case(tmp_path, values, unit)
    with pytest.raises(UnitError) as e:
        load_mapped_csv(csv_path, map_path)
    assert str(e.value) == message and e.value.signal == "time.unit"
    err = _refused(["import", "csv", str(csv_path), "--mapping", str(map_path)], capsys, tmp_path / "t.csv")
    assert err == f"lowerlimb: error: {message}\n" and "divide" not in err
    # resampling does not turn it into a gap of 10 s
    with pytest.raises(UnitError, match="slower than the 5 Hz"):
        load_mapped_csv(csv_path, _mapping(time={"column": "Timestamp", "unit": unit}, resample_hz=100))


def test_sample_numbers_declared_s_say_to_map_times(tmp_path):
    csv_path, map_path = _time_case(tmp_path, np.arange(300.0), "s")
    with pytest.raises(
        UnitError, match='set "unit": "ms" .*; if it holds sample numbers, map a column of times'
    ):
        load_mapped_csv(csv_path, map_path)


def _scaled_csv(tmp_path, gyr_factor=1.0, acc_factor=1.0):
    """The vendor CSV with the pelvis gyro (deg/s) and accelerometer (g) columns multiplied."""
    csv_path, _ = _csv_case(tmp_path)
    lines = csv_path.read_text().splitlines()
    header = lines[0].split(";")
    out = [lines[0]]
    for line in lines[1:]:
        cells = line.split(";")
        for c, f in ((0, acc_factor), (1, acc_factor), (2, acc_factor), (3, gyr_factor)):
            i = header.index(f"pelvis.{'ag'[c // 3]}{'xyzx'[c]}")
            cells[i] = f"{float(cells[i].replace(',', '.')) * f:.6f}".replace(".", ",")
        out.append(";".join(cells))
    csv_path.write_text("\n".join(out) + "\n")
    return csv_path


def test_gyro_unit_rad_s_for_deg_s_data_names_the_mapping(tmp_path, capsys):
    csv_path = _scaled_csv(tmp_path, gyr_factor=5.0)  # pelvis gyro up to 150 deg/s
    m = _mapping()
    m["sensors"]["pelvis"]["gyr"]["unit"] = "rad/s"
    (tmp_path / "rads.json").write_text(json.dumps(m))
    message = (
        "pelvis gyro values up to 150 rad/s are beyond a gyro's range (35 rad/s) and look like deg/s; "
        'set "unit": "deg/s" in the mapping\'s pelvis "gyr"'
    )
    with pytest.raises(UnitError) as e:
        load_mapped_csv(csv_path, m)
    assert str(e.value) == message and e.value.signal == "sensors.pelvis.gyr.unit"
    argv = ["import", "csv", str(csv_path), "--mapping", str(tmp_path / "rads.json")]
    err = _refused(argv, capsys, tmp_path / "t.csv")
    assert err == f"lowerlimb: error: {message}\n" and "multiply" not in err
    # read as deg/s (the trial's own check then finds a pelvis gyro 5 times too fast for its
    # accelerometer: the test data, not the mapping, are at fault there)
    x = load_mapped_csv(csv_path, _mapping()).gyr["pelvis"][:, 0]
    assert x.max() == pytest.approx(np.deg2rad(149.5))


def test_acc_unit_m_s2_for_g_data_names_the_mapping(tmp_path):
    csv_path, _ = _csv_case(tmp_path)
    m = _mapping()
    m["sensors"]["shank"]["acc"]["unit"] = "m/s^2"
    with pytest.raises(
        UnitError, match=r"shank accelerometer median magnitude 1.0\d m/s\^2 is too small"
    ) as e:
        load_mapped_csv(csv_path, m)
    assert str(e.value).endswith('looks like g; set "unit": "g" in the mapping\'s shank "acc"')
    assert e.value.signal == "sensors.shank.acc.unit"


# ------------------------------------------------------------------ import csv as strict as the trial reader


def test_mapped_csv_interrupted_last_row_is_refused(tmp_path, capsys):
    csv_path, map_path = _csv_case(tmp_path)
    text = csv_path.read_text()
    csv_path.write_text(text[: text.rstrip("\n").rindex(";") - 3])  # the row cut inside a number
    width = len(text.splitlines()[0].split(";"))
    message = (
        f"{csv_path}: the last data row 300 has {width - 1} of {width} values: an interrupted "
        f"recording? delete that row"
    )
    with pytest.raises(InputError) as e:
        load_mapped_csv(csv_path, map_path)
    assert str(e.value) == message
    err = _refused(["import", "csv", str(csv_path), "--mapping", str(map_path)], capsys, tmp_path / "t.csv")
    assert err == f"lowerlimb: error: {message}\n" and "magnetometer" not in err


def test_mapped_csv_rows_all_shorter_than_the_header_are_read(tmp_path):
    """A writer that leaves out trailing empty cells: not an interrupted recording."""
    csv_path, map_path = _csv_case(tmp_path)
    lines = csv_path.read_text().splitlines()
    lines[0] += ";Note"
    csv_path.write_text("\n".join(lines) + "\n")
    assert read_mapped_csv(csv_path, map_path).n_samples == 300


def test_mapped_csv_column_twice_in_the_header_is_refused_when_mapped(tmp_path, capsys):
    csv_path, map_path = _csv_case(tmp_path)
    lines = csv_path.read_text().splitlines()
    header = lines[0].split(";")
    k = header.index("thigh.ax")
    lines = [";".join([*c[:4], c[k], *c[4:]]) for c in (line.split(";") for line in lines)]
    csv_path.write_text("\n".join(lines) + "\n")
    message = (
        f"{csv_path} has the column 'thigh.ax' 2 times in its header (columns 5 and {k + 2}); the "
        f"mapping reads columns by name, so rename or delete all but one"
    )
    with pytest.raises(InputError) as e:
        load_mapped_csv(csv_path, map_path)
    assert str(e.value) == message
    err = _refused(["import", "csv", str(csv_path), "--mapping", str(map_path)], capsys, tmp_path / "t.csv")
    assert err == f"lowerlimb: error: {message}\n"
    # a repeated column the mapping does not read is no concern
    lines = [";".join([*c[:2], "x", *c[2:]]) for c in (line.split(";") for line in lines)]
    lines[0] = lines[0].replace("thigh.ax", "unused", 1).replace(";x;", ";unused;", 1)
    csv_path.write_text("\n".join(lines) + "\n")
    assert read_mapped_csv(csv_path, map_path).n_samples == 300


def test_xsens_a_repeated_packet_with_other_readings_is_warned(tmp_path):
    """A repeated packet is dropped; with other readings than the first, it may be a counter that
    skipped instead of repeating, so that sensor may be one sample off: said once."""
    from lowerlimb.io.xsens import RepeatedPacketsWarning

    folder = _export_dir(tmp_path)
    foot = _foot_export(folder)
    lines = foot.read_text().splitlines()
    first_data = next(k for k, ln in enumerate(lines) if ln[:1].isdigit())
    same = lines[first_data + 50]
    cells = same.split(",")
    changed = ",".join([cells[0], *(f"{float(c) + 0.5:.6f}" if c else c for c in cells[1:])])
    foot.write_text("\n".join([*lines[: first_data + 51], same, *lines[first_data + 51 :]]) + "\n")
    with warnings.catch_warnings():
        warnings.simplefilter("error", RepeatedPacketsWarning)
        load_xsens(folder, IDS)  # an identical repeat: dropped without a word
    foot.write_text("\n".join([*lines[: first_data + 51], changed, *lines[first_data + 51 :]]) + "\n")
    with pytest.warns(RepeatedPacketsWarning, match="1 PacketCounter value"):
        load_xsens(folder, IDS)
