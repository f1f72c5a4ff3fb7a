"""An inertial unit from Python: ``read_log`` and ``fit`` with gyro and temperature column
lists, its ``Model`` (load, save, compensate per axis; the class a single gyro's model has),
against the CLI on the same logs: the same model file bytes, the same compensated numbers to
the last bit."""

import csv
import json
import warnings

import numpy as np
import pytest

import gyrotherm as gt

from conftest import PROFILE

GYROS = ["gyro_x_dps", "gyro_y_dps", "gyro_z_dps"]
TEMPS = ["temp_case_c", "temp_x_c"]


@pytest.fixture(scope="module")
def unit_logs(cli, tmp_path_factory):
    """Unit 1000 of the design family on the short profile: a static run, a ±20 °/s table
    run turning y, and a held-out static run."""
    d = tmp_path_factory.mktemp("unit")
    prof = d / "profile.csv"
    prof.write_text(PROFILE)
    unit = ["--imu", "--unit", "random", "--unit-seed", "1000", "--profile-file", prof]
    out = {}
    for name, seed, extra in [
        ("static", 3, []),
        ("table", 4, ["--table-rate", "20", "--table-axis", "y"]),
        ("heldout", 5, []),
    ]:
        path = d / f"{name}.csv"
        cli("simulate", *unit, "--seed", seed, *extra, "--out", path)
        out[name] = path
    return out


def read_csv_columns(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return {h: [r[i] for r in rows[1:]] for i, h in enumerate(rows[0])}


def test_read_log_takes_the_lists(unit_logs):
    log = gt.read_log(unit_logs["table"], gyro_col=GYROS, temp_col=TEMPS, as_frame=False)
    text = gt.read_log(
        unit_logs["table"], gyro_col=",".join(GYROS), temp_col=",".join(TEMPS), as_frame=False
    )
    raw = read_csv_columns(unit_logs["table"])
    for name in GYROS + TEMPS + ["time_s", "table_dps"]:
        np.testing.assert_array_equal(log[name], text[name])
        # The file's numbers (°/s already), parsed by Python's float.
        np.testing.assert_array_equal(log[name], np.array(raw[name], dtype=float))
    frame = gt.read_log(unit_logs["table"], gyro_col=GYROS, temp_col=TEMPS, as_frame=True)
    assert frame.attrs["gyro_cols"] == GYROS
    assert frame.attrs["temp_cols"] == TEMPS
    # The gyro whose output follows the table rate, or the one named.
    assert frame.attrs["table_axis"] == "gyro_y_dps"
    named = gt.read_log(
        unit_logs["table"], gyro_col=GYROS, temp_col=TEMPS, table_axis="gyro_y_dps",
        as_frame=False,
    )
    np.testing.assert_array_equal(named["table_dps"], log["table_dps"])
    with pytest.raises(gt.LogError, match="temp_q_c"):
        gt.read_log(unit_logs["static"], gyro_col=GYROS, temp_col=["temp_q_c"])


@pytest.mark.parametrize("method", ["linear", "thermal"])
def test_fit_with_lists_writes_the_cli_unit_file(cli, unit_logs, tmp_path, method):
    model = gt.fit(
        static=unit_logs["static"], table=unit_logs["table"], method=method,
        gyro_col=GYROS, temp_col=TEMPS,
    )
    assert isinstance(model, gt.UnitModel)
    model.save(tmp_path / "py.json")
    cli(
        "train", "--method", method, "--gyro-col", ",".join(GYROS), "--temp-col",
        ",".join(TEMPS), "--input", unit_logs["static"], "--input", unit_logs["table"],
        "--out", tmp_path / "cli.json",
    )
    want = (tmp_path / "cli.json").read_bytes()
    assert (tmp_path / "py.json").read_bytes() == want
    assert model.to_json().encode() == want
    assert model.gyro_cols == GYROS and model.temp_cols == TEMPS
    axes = model.axes
    assert [a["gyro"] for a in axes] == GYROS
    for a in axes:
        assert a["method"] == method
        assert len(a["temps"]) >= 1 and set(a["temps"]) <= set(TEMPS)
        assert set(a["cv_rms"]) == set(TEMPS)
    assert "gyro_y_dps: reads" in model.summary()


def test_one_gyro_and_one_sensor_as_lists_are_the_single_axis_fit(unit_logs):
    one = gt.fit(
        static=unit_logs["static"], method="linear", gyro_col=["gyro_x_dps"],
        temp_col=["temp_case_c"],
    )
    text = gt.fit(
        static=unit_logs["static"], method="linear", gyro_col="gyro_x_dps",
        temp_col="temp_case_c",
    )
    assert isinstance(one, gt.Model) and isinstance(text, gt.Model)
    assert one.to_json() == text.to_json()


def test_unit_compensate_equals_cli_compensate_to_the_last_bit(cli, unit_logs, tmp_path):
    path = tmp_path / "unit.json"
    cli(
        "train", "--method", "linear", "--gyro-col", ",".join(GYROS), "--temp-col",
        ",".join(TEMPS), "--input", unit_logs["static"], "--input", unit_logs["table"],
        "--out", path,
    )
    model = gt.Model.load(path)
    assert isinstance(model, gt.UnitModel)
    assert gt.UnitModel.load(path).to_json() == model.to_json() == path.read_text()
    cli("compensate", "--model", path, "--input", unit_logs["heldout"], "--out", tmp_path / "c.csv")
    want = read_csv_columns(tmp_path / "c.csv")
    log = gt.read_log(
        unit_logs["heldout"], gyro_col=model.gyro_cols, temp_col=model.temp_cols, as_frame=False
    )
    got = model.compensate_log(log)
    assert list(got) == GYROS
    for g, c in got.items():
        for field, suffix in [("bias_dps", "bias"), ("scale", "scale"), ("rate_dps", "comp")]:
            cli_values = np.array(want[f"{g}_{suffix}"], dtype=float)
            np.testing.assert_array_equal(getattr(c, field), cli_values, err_msg=f"{g}_{suffix}")
        assert [gt.STATUS_NAMES[s] for s in c.status] == want[f"{g}_status"]
    # Sequences in the model's order give the same numbers as the dict.
    seq = model.compensate(
        log["time_s"], [log[g] for g in GYROS], [log[t] for t in TEMPS]
    )
    for g in GYROS:
        np.testing.assert_array_equal(seq[g].rate_dps, got[g].rate_dps)


def test_unit_compensate_names_what_is_missing(cli, unit_logs, tmp_path):
    model = gt.fit(static=unit_logs["static"], method="linear", gyro_col=GYROS, temp_col=TEMPS)
    log = gt.read_log(unit_logs["heldout"], gyro_col=GYROS, temp_col=TEMPS, as_frame=False)
    temps = {"temp_case_c": log["temp_case_c"]}
    with pytest.raises(gt.CompensationError, match="temp_x_c"):
        model.compensate(log["time_s"], {g: log[g] for g in GYROS}, temps)
    with pytest.raises(gt.CompensationError, match="2 arrays given, the model needs 3"):
        model.compensate(log["time_s"], [log["gyro_x_dps"], log["gyro_y_dps"]], [log[t] for t in TEMPS])
    with pytest.raises(gt.CompensationError, match="gyro_y_dps: 10 values"):
        model.compensate(
            log["time_s"], [log["gyro_x_dps"], log["gyro_y_dps"][:10], log["gyro_z_dps"]],
            [log[t] for t in TEMPS],
        )


def test_unit_fit_reports_each_axis_and_sensor(unit_logs, capfd):
    events = []
    gt.fit(
        static=unit_logs["static"], method="linear", gyro_col=GYROS, temp_col=TEMPS,
        progress=lambda *e: events.append(e),
    )
    for g in GYROS:
        mine = [e for e in events if e[1] == g]
        # The axis starts, per sensor a start then its finish, then the axis with the sensor
        # it reads.
        assert [(e[0], e[2]) for e in mine] == [
            ("axis_start", None), ("start", TEMPS[0]), ("done", TEMPS[0]), ("start", TEMPS[1]), ("done", TEMPS[1]),
            ("axis", mine[-1][2]),
        ]
    capfd.readouterr()
    gt.fit(static=unit_logs["static"], method="linear", gyro_col=GYROS, temp_col=TEMPS, progress=True)
    err = capfd.readouterr().err
    for g in GYROS:
        for line in (f"{g}: axis starts", f"{g}: fitting on temp_case_c", f"{g}: axis done, reads"):
            assert line in err, err


def test_unit_progress_callback_error_is_raised(unit_logs):
    def boom(*_):
        raise KeyError("stop")

    with pytest.raises(KeyError, match="stop"):
        gt.fit(static=unit_logs["static"], method="linear", gyro_col=GYROS, temp_col=TEMPS,
               progress=boom)


def test_unsealed_unit_model_file_loads_with_a_warning_naming_it(unit_logs, tmp_path):
    good = gt.fit(
        static=unit_logs["static"], table=unit_logs["table"], method="linear",
        gyro_col=GYROS, temp_col=TEMPS,
    )
    doc = json.loads(good.to_json())
    del doc["content_sha256"]
    path = tmp_path / "unsealed.json"
    path.write_text(json.dumps(doc))
    # As a single-axis file without its checksum (test_errors.py).
    with pytest.warns(gt.GyrothermWarning, match="unsealed.json: no content_sha256"):
        loaded = gt.UnitModel.load(path)
    assert loaded.to_json() == good.to_json()
    sealed = tmp_path / "sealed.json"
    good.save(sealed)
    with warnings.catch_warnings():
        warnings.simplefilter("error", gt.GyrothermWarning)
        gt.UnitModel.load(sealed)


def test_one_class_holds_a_single_gyro_and_a_unit(cli, unit_logs, tmp_path):
    """A single gyro is a unit of one axis: its model answers what a unit's does (columns,
    axes, per-axis compensation with a dict), with the numbers of its plain-array call; the
    old unit class name is the same class."""
    assert gt.UnitModel is gt.Model
    one = gt.fit(
        static=unit_logs["static"], method="linear", gyro_col="gyro_x_dps",
        temp_col="temp_case_c",
    )
    assert one.gyro_cols == ["gyro_x_dps"] and one.temp_cols == ["temp_case_c"]
    (axis,) = one.axes
    assert axis["gyro"] == "gyro_x_dps" and axis["temps"] == ["temp_case_c"]
    assert axis["method"] == one.method == "linear"
    assert axis["training"] == one.training
    log = gt.read_log(
        unit_logs["heldout"], gyro_col=GYROS, temp_col=TEMPS, as_frame=False
    )
    plain = one.compensate(log["time_s"], log["gyro_x_dps"], log["temp_case_c"])
    keyed = one.compensate(log["time_s"], {"gyro_x_dps": log["gyro_x_dps"]},
                           {"temp_case_c": log["temp_case_c"]})
    assert list(keyed) == ["gyro_x_dps"]
    for field in plain._fields:
        np.testing.assert_array_equal(getattr(keyed["gyro_x_dps"], field), getattr(plain, field))
    cov = one.coverage(log["time_s"], {"gyro_x_dps": log["gyro_x_dps"]},
                       {"temp_case_c": log["temp_case_c"]})
    flat = one.coverage(log["time_s"], log["gyro_x_dps"], log["temp_case_c"])
    np.testing.assert_array_equal(cov["gyro_x_dps"].coverage, flat.coverage)

    unit = gt.fit(static=unit_logs["static"], method="linear", gyro_col=GYROS, temp_col=TEMPS)
    assert unit.training is None and unit.method == "linear"
    with pytest.raises(gt.CompensationError, match="one array given, the model has 3 axes"):
        unit.compensate(log["time_s"], log["gyro_x_dps"], log["temp_case_c"])


def test_unit_compensate_csv_counts_each_axis_as_the_cli_writes_it(cli, unit_logs, tmp_path):
    path = tmp_path / "unit.json"
    cli(
        "train", "--method", "linear", "--gyro-col", ",".join(GYROS), "--temp-col",
        ",".join(TEMPS), "--input", unit_logs["static"], "--out", path,
    )
    model = gt.Model.load(path)
    cli("compensate", "--model", path, "--input", unit_logs["heldout"], "--out", tmp_path / "c.csv")
    res = model.compensate_csv(unit_logs["heldout"], tmp_path / "py.csv")
    assert (tmp_path / "py.csv").read_bytes() == (tmp_path / "c.csv").read_bytes()
    want = read_csv_columns(tmp_path / "c.csv")
    assert res["rows"] == len(want["time_s"])
    for g in GYROS:
        for status, n in res["axes"][g].items():
            assert n == want[f"{g}_status"].count(status), (g, status)
    assert res["ok"] == sum(a["ok"] for a in res["axes"].values())


def test_unit_auto_fit_tells_each_fold_and_lstm_training(unit_logs, capfd):
    """``auto`` on a unit whose axes read one sensor, with two static runs, scores both
    candidates with each run left out (a ``scoring`` event per fold), training
    ``thermal-lstm`` as it goes (``lstm``)."""
    events = []
    gt.fit(
        static=[unit_logs["static"], unit_logs["heldout"]], method="auto", epochs=3,
        gyro_col=GYROS, temp_col=TEMPS[:1], progress=lambda *e: events.append(e),
    )
    kinds = [e[0] for e in events]
    assert [e[1] for e in events if e[0] == "scoring"].count("gyro_x_dps") == 2, events
    assert all(e[2] is None for e in events if e[0] == "scoring")
    assert "lstm" in kinds and all(e[2] in TEMPS for e in events if e[0] == "lstm"), events
    capfd.readouterr()
    gt.fit(
        static=[unit_logs["static"], unit_logs["heldout"]], method="auto", epochs=3,
        gyro_col=GYROS, temp_col=TEMPS[:1], progress=True,
    )
    err = capfd.readouterr().err
    assert "gyro_x_dps: auto: fitting thermal and thermal-lstm without a static run" in err, err
    assert "gyro_x_dps: auto: training thermal-lstm on temp_" in err, err


def test_unit_coverage_per_axis_on_one_sensor_or_several(unit_logs):
    """A unit's coverage comes per gyro column, each axis with its map's verdicts and σ: an
    axis reading one sensor, and one reading several (its first sensor's cells, its σ scaled
    to the several-sensor fit), without a warning."""
    log = gt.read_log(unit_logs["heldout"], gyro_col=GYROS, temp_col=TEMPS, as_frame=False)
    seen = set()
    for temps in (TEMPS, TEMPS[:1]):
        model = gt.fit(
            static=unit_logs["static"], table=unit_logs["table"], method="thermal",
            gyro_col=GYROS, temp_col=temps,
        )
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            cov = model.coverage(
                log["time_s"], {g: log[g] for g in GYROS}, {t: log[t] for t in temps}
            )
        assert list(cov) == GYROS
        notes = [str(w.message) for w in caught if issubclass(w.category, gt.GyrothermWarning)]
        seen |= check_axes(model, cov, notes, log)
    # Both kinds of axis were met.
    assert seen == {1, 2}, seen


def check_axes(model, cov, notes, log):
    seen = set()
    for a in model.axes:
        seen.add(min(len(a["temps"]), 2))
        c = cov[a["gyro"]]
        assert len(c.coverage) == len(log["time_s"]) == len(c.sigma_dph)
        codes = set(c.coverage.tolist())
        assert codes <= set(gt.COVERAGE_NAMES) | {gt.NO_COVERAGE}
        assert codes - {gt.NO_COVERAGE}, "an axis with a map gives verdicts"
        judged = c.coverage != gt.NO_COVERAGE
        assert np.isfinite(c.sigma_dph[judged]).all() and (c.sigma_dph[judged] > 0).all()
    assert not notes, notes
    return seen
