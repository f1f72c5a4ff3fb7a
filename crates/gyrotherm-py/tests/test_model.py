"""fit → save → load → compensate against the CLI's `train` and `compensate` on the same
logs: the same model file bytes, the same compensated numbers to the last bit."""

import csv
import json
import pathlib
import warnings

import numpy as np
import pytest

import gyrotherm as gt

OUTPUT_COLUMNS = ["bias_dps", "scale", "gyro_comp_dps"]


def read_csv_columns(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    header = rows[0]
    return {h: [r[i] for r in rows[1:]] for i, h in enumerate(header)}


FITS = [
    ("linear", {}),
    ("poly", {}),
    ("published", {"epochs": 3}),
    ("residual", {"epochs": 3}),
]


def cli_train_args(method, kw):
    args = ["--method", method]
    if "epochs" in kw:
        args += ["--epochs", kw["epochs"]]
    return args


@pytest.mark.parametrize("method,kw", FITS, ids=[m for m, _ in FITS])
def test_fit_writes_the_cli_model_file(cli, logs, tmp_path, method, kw):
    model = gt.fit(static=[str(logs["static"])], table=[str(logs["table"])], method=method, **kw)
    model.save(tmp_path / "py.json")
    cli(
        "train", "--input", logs["static"], "--input", logs["table"],
        *cli_train_args(method, kw), "--out", tmp_path / "cli.json",
    )
    assert (tmp_path / "py.json").read_bytes() == (tmp_path / "cli.json").read_bytes()
    assert model.to_json().encode() == (tmp_path / "cli.json").read_bytes()


@pytest.mark.parametrize("method,kw", FITS, ids=[m for m, _ in FITS])
def test_round_trip_equals_cli_compensate_to_the_last_bit(cli, logs, tmp_path, method, kw):
    model = gt.fit(static=logs["static"], table=logs["table"], method=method, **kw)
    path = tmp_path / "model.json"
    model.save(path)
    loaded = gt.Model.load(path)
    assert loaded.to_json() == model.to_json()
    for name in ["heldout", "table"]:
        cli("compensate", "--model", path, "--input", logs[name], "--out", tmp_path / "cli.csv")
        want = read_csv_columns(tmp_path / "cli.csv")
        log = gt.read_log(logs[name], as_frame=False)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", gt.GyrothermWarning)
            got = loaded.compensate(log["time_s"], log["gyro_dps"], log["temp_c"])
        assert isinstance(got, tuple) and len(got) == 4
        bias, scale, rate, status = got
        # Columns both have; the CLI prints shortest round-trip decimals, so float() is exact.
        for col, arr in zip(OUTPUT_COLUMNS, (bias, scale, rate)):
            np.testing.assert_array_equal(
                arr, np.array([float(v) for v in want[col]]), err_msg=f"{name} {col}"
            )
        assert status.dtype == np.uint8
        if "status" in want:  # the CLI's status column, by name
            assert [gt.STATUS_NAMES[int(s)] for s in status] == want["status"], name
        # The coverage verdict, as the CLI's coverage and sigma_dph columns (empty: none).
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", gt.GyrothermWarning)
            cov = loaded.coverage(log["time_s"], log["gyro_dps"], log["temp_c"])
        assert cov.coverage.dtype == np.uint8
        assert [gt.COVERAGE_NAMES.get(int(c), "") for c in cov.coverage] == want["coverage"], name
        np.testing.assert_array_equal(
            cov.sigma_dph,
            np.array([float(v) if v else np.nan for v in want["sigma_dph"]]),
            err_msg=f"{name} sigma_dph",
        )


def test_compensate_csv_writes_the_cli_bytes(cli, logs, tmp_path):
    model = gt.fit(static=logs["static"], table=logs["table"], method="poly")
    model.save(tmp_path / "m.json")
    cli("compensate", "--model", tmp_path / "m.json", "--input", logs["table"], "--out", tmp_path / "cli.csv")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", gt.GyrothermWarning)
        res = model.compensate_csv(logs["table"], tmp_path / "py.csv")
    assert res["rows"] == 4801
    assert (tmp_path / "py.csv").read_bytes() == (tmp_path / "cli.csv").read_bytes()


def test_extrapolation_warns(logs):
    """A run hotter than training warns with the numbers, as `compensate` does."""
    model = gt.fit(static=logs["static"], method="linear")
    log = gt.read_log(logs["heldout"], as_frame=False)
    with pytest.warns(gt.GyrothermWarning, match="leaves the training range"):
        model.compensate(log["time_s"], log["gyro_dps"], log["temp_c"] + 30.0)


def test_model_properties_and_summary(logs):
    model = gt.fit(static=logs["static"], table=logs["table"], method="published", epochs=2)
    assert model.method == "published"
    assert model.bias_kind == "lstm" and model.scale_kind == "lstm"
    t = model.training
    assert t["epochs"] == 2 and t["inputs"] == [str(logs["static"]), str(logs["table"])]
    s = model.summary()
    assert "method published" in s and "bias model: lstm" in s and "2 epochs" in s
    static_only = gt.fit(static=logs["static"], method="linear")
    assert static_only.scale_kind is None
    assert "none (no rate-table log)" in static_only.summary()


def test_progress_only_when_asked(logs, capfd):
    seen = []
    gt.fit(static=logs["static"], table=logs["table"], method="published", epochs=3,
           progress=lambda target, epoch, loss: seen.append((target, epoch)))
    assert sorted(seen) == sorted([(t, e) for t in ("bias", "scale") for e in range(3)])
    capfd.readouterr()
    gt.fit(static=logs["static"], method="published", epochs=3)
    assert capfd.readouterr().err == ""
    gt.fit(static=logs["static"], method="published", epochs=3, progress=True)
    err = capfd.readouterr().err
    assert "gyrotherm: bias epoch 3/3, loss" in err


def test_progress_callback_error_is_raised(logs):
    def boom(target, epoch, loss):
        raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        gt.fit(static=logs["static"], method="published", epochs=2, progress=boom)


def test_read_log_column_mapping_units_and_frame(tmp_path):
    p = tmp_path / "renamed.csv"
    p.write_text("# comment\nt,w_dph,T,label,x\n0,3600,20,a,1.5\n1,7200,20.5,b,2\n2,0,21,c,3\n")
    cols = gt.read_log(p, as_frame=False, time_col="t", gyro_col="w_dph", temp_col="T", gyro_unit="dph")
    # Under the file's names (the gyro converted to °/s), not renamed to gyro_dps.
    np.testing.assert_array_equal(cols["w_dph"], [1.0, 2.0, 0.0])
    np.testing.assert_array_equal(cols["T"], [20.0, 20.5, 21.0])
    np.testing.assert_array_equal(cols["t"], [0.0, 1.0, 2.0])
    assert "gyro_dps" not in cols and "table_dps" not in cols
    assert cols["label"] == ["a", "b", "c"]
    np.testing.assert_array_equal(cols["x"], [1.5, 2.0, 3.0])
    pd = pytest.importorskip("pandas")
    df = gt.read_log(p, time_col="t", gyro_col="w_dph", temp_col="T", gyro_unit="dph")
    assert isinstance(df, pd.DataFrame)
    assert list(df.columns) == ["t", "w_dph", "T", "label", "x"]
    assert df.attrs["rows"] == 3 and df.attrs["sample_period_s"] == 1.0


def test_read_log_fills_gaps_when_asked(tmp_path):
    p = tmp_path / "gap.csv"
    p.write_text("time_s,gyro_dps,temp_c\n0,0,20\n1,0,20\n3,0,20\n")
    cols = gt.read_log(p, as_frame=False, fill_gaps_max_s=2)
    np.testing.assert_array_equal(cols["time_s"], [0.0, 1.0, 2.0, 3.0])


def test_summary_of_a_least_squares_model_gives_lags_and_cross_validated_rms(cli, logs, tmp_path):
    # A least-squares fit trains no LSTM: no "epochs: 0" or "final loss 0"; the lags and the
    # cross-validated RMS `gyrotherm train` prints instead, in its words.
    m = gt.fit(static=logs["static"], table=logs["table"], method="thermal")
    text = m.summary()
    assert "epochs" not in text and "final loss" not in text, text
    out = tmp_path / "m.json"
    train = cli("train", "--method", "thermal", "--input", logs["static"], "--input",
                logs["table"], "--out", out)
    said = [l.strip() for l in train.stderr.splitlines()[1:] if l.startswith("  ")]
    assert said and all(l in text for l in said), (said, text)
    assert "lag" in text and "cross-validated" in text, text
    # From the file: the lags and the coverage map's cross-validated residual.
    loaded = gt.Model.load(out).summary()
    assert "epochs" not in loaded and "thermal lags:" in loaded, loaded
    assert "cross-validated bias residual" in loaded, loaded


def test_evaluate_one_column_is_the_cli_json(cli, logs, tmp_path):
    # Parity with `gyrotherm evaluate --json` on a single-axis log, also with renamed columns.
    want = json.loads(cli("evaluate", "--input", logs["heldout"], "--json").stdout)
    assert gt.evaluate(logs["heldout"]) == want
    text = pathlib.Path(logs["heldout"]).read_text()
    header, rest = text.split("\n", 1)
    renamed = tmp_path / "renamed.csv"
    renamed.write_text(header.replace("gyro_dps", "w_dps").replace("temp_c", "T") + "\n" + rest)
    got = gt.evaluate(renamed, gyro_col="w_dps", temp_col="T")
    cli_got = json.loads(
        cli("evaluate", "--input", renamed, "--gyro-col", "w_dps", "--temp-col", "T",
            "--json").stdout
    )
    assert got == cli_got
    assert got["column"] == "w_dps"
    assert {k: v for k, v in got.items() if k != "column"} == {
        k: v for k, v in want.items() if k != "column"
    }


def test_a_model_remembers_its_columns(cli, logs, tmp_path):
    # Trained on renamed columns, the model reads them again without being told, in Python
    # as in `gyrotherm compensate`; the file's names key read_log's arrays.
    def renamed(name):
        text = pathlib.Path(logs[name]).read_text()
        header, rest = text.split("\n", 1)
        p = tmp_path / f"{name}_renamed.csv"
        p.write_text(header.replace("time_s", "t").replace("gyro_dps", "w_dps")
                     .replace("temp_c", "T") + "\n" + rest)
        return p

    cols = dict(time_col="t", gyro_col="w_dps", temp_col="T")
    m = gt.fit(static=renamed("static"), method="linear", **cols)
    path = tmp_path / "m.json"
    m.save(path)
    assert json.loads(path.read_text())["columns"]["gyro_col"] == "w_dps"
    held = renamed("heldout")
    py_out, cli_out = tmp_path / "py.csv", tmp_path / "cli.csv"
    gt.Model.load(path).compensate_csv(held, py_out)
    cli("compensate", "--model", path, "--input", held, "--out", cli_out)
    assert py_out.read_bytes() == cli_out.read_bytes()
    log = gt.read_log(held, as_frame=False, **cols)
    assert {"t", "w_dps", "T"} <= set(log)
