"""Bad input raises a Python exception with the CLI's message (file, line, column, what to
do), never a crash of the interpreter."""

import json
import warnings

import numpy as np
import pytest

import gyrotherm as gt


def cli_error(cli, *args):
    p = cli(*args, check=False)
    assert p.returncode == 2, p.stderr
    return p.stderr


BAD_LOGS = {
    "not a number": ("time_s,gyro_dps,temp_c\n0,0.1,20\n1,0.1,4;5\n", "bad.csv:3: column temp_c"),
    "time backwards": ("time_s,gyro_dps,temp_c\n0,0,20\n2,0,20\n1,0,20\n", "bad.csv:4: column time_s"),
    "missing column": ("time_s,gyro,temp_c\n0,0,20\n1,0,20\n", "column gyro_dps"),
    "gap": ("time_s,gyro_dps,temp_c\n0,0,20\n1,0,20\n5,0,20\n", "bad.csv:4: column time_s: gap"),
    "empty": ("", "bad.csv"),
}


@pytest.mark.parametrize("case", sorted(BAD_LOGS))
def test_bad_log_raises_the_cli_message(cli, tmp_path, case):
    text, where = BAD_LOGS[case]
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(gt.LogError) as e:
        gt.read_log(path)
    msg = str(e.value)
    assert where in msg
    assert msg in cli_error(cli, "evaluate", "--input", path)
    with pytest.raises(gt.LogError) as e2:
        gt.fit(static=[path], method="linear")
    assert str(e2.value) == msg
    assert msg in cli_error(cli, "train", "--input", path, "--method", "linear", "--out", tmp_path / "m.json")


def test_missing_log_raises_the_cli_message(cli, tmp_path):
    path = tmp_path / "nope.csv"
    with pytest.raises(gt.LogError, match="nope.csv: cannot open") as e:
        gt.read_log(path)
    assert str(e.value) in cli_error(cli, "evaluate", "--input", path)


def test_bad_model_file_raises_the_cli_message(cli, logs, tmp_path):
    good = gt.fit(static=logs["static"], method="linear")
    doc = json.loads(good.to_json())
    doc["format_version"] = 99
    bad = tmp_path / "future.json"
    bad.write_text(json.dumps(doc))
    with pytest.raises(gt.ModelError, match="unsupported format_version 99") as e:
        gt.Model.load(bad)
    assert str(e.value) in cli_error(cli, "compensate", "--model", bad, "--input", logs["static"], "--out", tmp_path / "o.csv")
    (tmp_path / "junk.json").write_text("{not json")
    with pytest.raises(gt.ModelError, match="junk.json: not valid JSON"):
        gt.Model.load(tmp_path / "junk.json")
    with pytest.raises(gt.ModelError, match="cannot read model file"):
        gt.Model.load(tmp_path / "absent.json")


def test_model_file_with_a_key_named_twice_raises_the_cli_message(cli, logs, tmp_path):
    # A decoy array before the real one: JSON readers disagree on which counts, and the
    # content checksum covered only the last, so the loader refuses the file.
    text = gt.fit(static=logs["static"], method="linear").to_json()
    assert '"coefficients": [' in text
    dup = text.replace('"coefficients": [', '"coefficients": [0.5, 0, 0],\n      "coefficients": [', 1)
    path = tmp_path / "dup.json"
    path.write_text(dup)
    where = 'bias.baseline.coefficients: key "coefficients" appears twice'
    with pytest.raises(gt.ModelError, match="dup.json: " + where) as e:
        gt.Model.load(path)
    assert str(e.value) in cli_error(cli, "model", "check", path)
    with pytest.raises(gt.ModelError, match=where):
        gt.Model.from_json(dup)


def test_fit_refuses_bad_settings_and_misfiled_logs(logs):
    with pytest.raises(gt.FitError, match="method: unknown value \"spline\""):
        gt.fit(static=logs["static"], method="spline")
    with pytest.raises(gt.FitError, match="epochs must be a whole number from 1 to 1000000, not 0"):
        gt.fit(static=logs["static"], epochs=0)
    with pytest.raises(gt.FitError, match="epochs must be a whole number from 1 to 1000000, not 100000000000"):
        gt.fit(static=logs["static"], epochs=100_000_000_000)
    with pytest.raises(gt.FitError, match="given as a static log but its table_dps column has non-zero rates"):
        gt.fit(static=logs["table"], method="linear")
    with pytest.raises(gt.FitError, match="given as a rate-table log"):
        gt.fit(table=logs["static"], method="linear")
    with pytest.raises(gt.FitError, match="no training logs given"):
        gt.fit()
    with pytest.raises(TypeError, match="unknown log option"):
        gt.fit(static=logs["static"], time_column="t")
    with pytest.raises(gt.LogError, match="unknown gyro unit"):
        gt.read_log(logs["static"], gyro_unit="mrad")
    with pytest.raises(gt.LogError, match="fill_gaps_max_s = -1 is not a positive number of seconds"):
        gt.read_log(logs["static"], fill_gaps_max_s=-1)


@pytest.mark.parametrize(
    "call,exc,match",
    [
        (lambda: gt.oadev([1.0, 2.0, np.nan, 4.0, 5.0] * 10, data_type="freq"), gt.AllanError,
         "sample 2 is NaN or infinite; clean or fill the log first"),
        (lambda: gt.adev([1.0, np.inf] * 10), gt.AllanError, "sample 1 is NaN or infinite"),
        (lambda: gt.oadev(np.ones(100), data_type="rate"), gt.AllanError, "data_type = 'rate'; use 'phase' or 'freq'"),
        (lambda: gt.oadev(np.ones(100), taus="octaves"), gt.AllanError, "taus = 'octaves' is not a τ set"),
        (lambda: gt.oadev(np.ones(100), taus=["a"]), gt.AllanError, "taus: not an array"),
        (lambda: gt.oadev(np.ones(100), taus=[np.nan]), gt.AllanError, "finite number of seconds"),
        (lambda: gt.oadev(np.ones(100), rate=0), gt.AllanError, "rate = 0.0 Hz is not a positive finite sample rate"),
        (lambda: gt.oadev(np.ones(100), rate="fast"), gt.AllanError, "rate = 'fast' is not a number"),
        (lambda: gt.oadev([]), gt.AllanError, "data is empty"),
        (lambda: gt.hdev([1.0, 2.0, 3.0], data_type="freq"), gt.AllanError, "too short"),
        (lambda: gt.oadev(np.ones((10, 10))), gt.AllanError, "need a 1-D array"),
        (lambda: gt.oadev(["x", "y"]), gt.AllanError, "not an array of numbers"),
        (lambda: gt.oadev(np.ones(100), taus=[1e6]), gt.AllanError, "too short"),
        (lambda: gt.deviation(np.ones(100), kind="tdev"), gt.AllanError, "unknown deviation kind `tdev`"),
        (lambda: gt.deviation(np.ones(100), alpha=0.5), gt.AllanError, "integer noise exponent"),
        (lambda: gt.bias_stability(np.ones(1000), 1.0, 2.5), gt.MetricsError,
         "τ = 2.5 s is not a positive integer multiple of the sample period 1 s"),
        (lambda: gt.bias_stability(np.ones(150), 1.0, 100), gt.MetricsError,
         "τ = 100 s is longer than half the log .*: the bias stability needs at least two "
         "τ-means; give τ at most 75 s"),
        (lambda: gt.bias_stability(np.ones(150), 0.0), gt.MetricsError, "rate_hz = 0 is not a positive finite sample rate"),
        (lambda: gt.noise_terms([np.nan] * 10, 1.0), gt.AllanError, "sample 0 is NaN"),
        (lambda: gt.scale_factor(time_s=np.arange(10.0), gyro_dps=np.zeros(10), table_dps=np.zeros(9)),
         gt.MetricsError, "columns differ in length"),
    ],
)
def test_bad_arguments_raise_with_the_message(call, exc, match):
    with pytest.raises(exc, match=match) as e:
        call()
    assert isinstance(e.value, gt.GyrothermError) and isinstance(e.value, ValueError)
    # allantools raises RuntimeError for the same faults; code catching that must still work.
    assert isinstance(e.value, RuntimeError)


def test_scale_factor_of_a_static_log_says_why(logs):
    with pytest.raises(gt.MetricsError, match="need two distinct rates, one non-zero"):
        gt.scale_factor(time_s=np.arange(1000.0), gyro_dps=np.zeros(1000), table_dps=np.zeros(1000))


def test_compensate_gives_bad_samples_a_status(logs):
    """The flight compensator never stops: a non-finite gyro sample is "invalid" (no rate),
    the others go on; mismatched arrays are refused."""
    model = gt.fit(static=logs["static"], method="linear")
    t = np.arange(100.0)
    with pytest.raises(gt.CompensationError, match="differ in length"):
        model.compensate(t, np.zeros(99), np.full(100, 20.0))
    g = np.zeros(100)
    g[5] = np.nan
    out = model.compensate(t, g, np.full(100, 20.0))
    names = [gt.STATUS_NAMES[int(s)] for s in out.status]
    assert names[5] == "invalid" and out.rate_dps[5] == 0.0
    assert names[:5] == ["ok"] * 5 and names[6:] == ["ok"] * 94
    assert set(gt.STATUS_NAMES.values()) == {"ok", "held", "degraded", "invalid", "fallback"}
    with pytest.raises(TypeError):
        gt.Model("not a model")


def test_unsealed_model_file_loads_with_a_warning_naming_it(cli, logs, tmp_path):
    good = gt.fit(static=logs["static"], method="linear")
    doc = json.loads(good.to_json())
    del doc["content_sha256"]
    path = tmp_path / "unsealed.json"
    path.write_text(json.dumps(doc))
    with pytest.warns(gt.GyrothermWarning, match="unsealed.json: no content_sha256"):
        loaded = gt.Model.load(path)
    assert loaded.to_json() == good.to_json()
    sealed = tmp_path / "sealed.json"
    good.save(sealed)
    with warnings.catch_warnings():
        warnings.simplefilter("error", gt.GyrothermWarning)
        gt.Model.load(sealed)
