"""An inertial unit judged per axis from Python: ``evaluate`` (figures and spec verdicts per
axis, the unit's verdict) and ``compare`` (the methods per axis, with the unit's own
multi-sensor fit; and a single gyro's table through the same entry), against the CLI's JSON
on the same logs and against figures computed
another way (each axis's column through ``bias_stability``)."""

import json

import numpy as np
import pytest

import gyrotherm as gt

from test_unit import GYROS, TEMPS, unit_logs  # noqa: F401 (the module fixture)


@pytest.fixture(scope="module")
def unit_model(cli, unit_logs, tmp_path_factory):  # noqa: F811
    path = tmp_path_factory.mktemp("judge") / "unit.json"
    cli(
        "train", "--method", "linear", "--gyro-col", ",".join(GYROS), "--temp-col",
        ",".join(TEMPS), "--input", unit_logs["static"], "--input", unit_logs["table"],
        "--out", path,
    )
    return path


def spec_file(tmp_path, name, limits):
    p = tmp_path / name
    p.write_text(f'name = "unit acceptance"\n[limits]\n{limits}')
    return p


LOOSE = "bias_dph = { min = -1e6, max = 1e6 }\nbias_stability_dph = { max = 1e6 }\n"


def test_evaluate_per_axis_is_the_cli_json(cli, unit_logs, unit_model, tmp_path):  # noqa: F811
    spec = spec_file(tmp_path, "loose.toml", LOOSE)
    got = gt.evaluate(unit_logs["heldout"], gt.Model.load(unit_model), spec=spec)
    want = json.loads(
        cli("evaluate", "--json", "--model", unit_model, "--input", unit_logs["heldout"],
            "--spec", spec).stdout
    )
    assert got == want
    assert [a["gyro"] for a in got["axes"]] == GYROS
    assert got["verdict"]["pass"] is True and got["verdict"]["judged"] == "compensated"
    # A path to the model is the same as the loaded model.
    assert gt.evaluate(unit_logs["heldout"], unit_model, spec=spec) == got


def test_evaluate_raw_axes_equal_each_column_through_bias_stability(unit_logs):  # noqa: F811
    got = gt.evaluate(unit_logs["heldout"], gyro_col=GYROS, temp_col=TEMPS, tau_s=100)
    log = gt.read_log(unit_logs["heldout"], gyro_col=GYROS, temp_col=TEMPS, as_frame=False)
    period = float(np.median(np.diff(log["time_s"])))
    for a in got["axes"]:
        assert a["compensated"] is None and a["temps"] == []
        want = gt.bias_stability(log[a["gyro"]], 1.0 / period, 100.0)
        assert a["raw"]["bias_stability_dph"] == pytest.approx(want, rel=1e-12), a["gyro"]
        # The bias, °/h: the column's mean (an independent computation).
        assert a["raw"]["bias_dph"] == pytest.approx(np.mean(log[a["gyro"]]) * 3600, rel=1e-9)


def test_evaluate_unit_fails_when_one_axis_misses(unit_logs, unit_model, tmp_path):  # noqa: F811
    first = gt.evaluate(unit_logs["heldout"], unit_model)
    values = [a["compensated"]["bias_stability_dph"] for a in first["axes"]]
    order = np.argsort(values)
    limit = (values[order[1]] + values[order[2]]) / 2
    spec = spec_file(tmp_path, "tight.toml", f"bias_stability_dph = {{ max = {limit!r} }}\n")
    got = gt.evaluate(unit_logs["heldout"], unit_model, spec=spec)
    worst = GYROS[order[2]]
    assert got["verdict"]["pass"] is False
    assert got["verdict"]["failed_axes"] == [worst]
    for a in got["axes"]:
        assert a["verdict"]["pass"] is (a["gyro"] != worst)
        f = a["verdict"]["figures"][0]
        assert f["figure"] == "bias_stability_dph" and f["unit"] == "°/h"


def test_evaluate_says_what_to_do(unit_logs, tmp_path):  # noqa: F811
    # Without column lists a log is judged as one column, as `gyrotherm evaluate` does: a
    # unit's log has no gyro_dps, and the error says so.
    with pytest.raises(gt.LogError, match="gyro_dps"):
        gt.evaluate(unit_logs["heldout"])
    bad = tmp_path / "bad.toml"
    bad.write_text("[limits]\nbias_stabilty_dph = { max = 1 }\n")
    with pytest.raises(gt.MetricsError, match="did you mean `bias_stability_dph`"):
        gt.evaluate(unit_logs["heldout"], gyro_col=GYROS, temp_col=TEMPS, spec=bad)
    with pytest.raises(gt.LogError, match="temp_q_c"):
        gt.evaluate(unit_logs["heldout"], gyro_col=GYROS, temp_col=["temp_q_c"])


def test_compare_per_axis_is_the_cli_json(cli, unit_logs):  # noqa: F811
    # The unit's own fit `thermal` (the default `auto` takes a minute an axis).
    got = gt.compare(
        train=[unit_logs["static"], unit_logs["table"]], test=unit_logs["heldout"],
        methods=["linear", "thermal"], method="thermal", gyro_col=GYROS, temp_col=TEMPS,
    )
    want = json.loads(
        cli("compare", "--json", "--methods", "linear,thermal", "--method", "thermal",
            "--gyro-col", ",".join(GYROS),
            "--temp-col", ",".join(TEMPS), "--train", unit_logs["static"], "--train",
            unit_logs["table"], "--test", unit_logs["heldout"]).stdout
    )
    assert got == want
    for a in got["axes"]:
        u = a["unit_fit"]
        assert a["temp"] == u["temps"][0]
        assert f"({len(u['temps'])} sensor" in u["label"]
        assert "lstm" not in u["label"].lower()
    # A unit's log read with one column each names a column the log lacks: a LogError.
    with pytest.raises(gt.LogError, match="gyro_dps"):
        gt.compare(train=unit_logs["static"], test=unit_logs["heldout"])


def test_compare_of_a_single_gyro_is_the_cli_json(cli, logs):
    # One entry for both: a single gyro's logs give `gyrotherm compare --json`'s table.
    got = gt.compare(
        train=[logs["static"], logs["table"]], test=logs["heldout"], methods=["linear", "poly"],
    )
    want = json.loads(
        cli("compare", "--json", "--methods", "linear,poly", "--train", logs["static"],
            "--train", logs["table"], "--test", logs["heldout"]).stdout
    )
    assert got == want
    assert "axes" not in got


def test_compare_spec_is_the_cli_json_and_fails_a_column(cli, unit_logs, tmp_path):  # noqa: F811
    # The verdicts equal `compare --spec --json`'s (the CLI's path); a limit between the
    # columns' bias stabilities fails some column and passes another.
    train = [unit_logs["static"], unit_logs["table"]]
    args = dict(methods=["linear", "thermal"], method="thermal", gyro_col=GYROS, temp_col=TEMPS)
    loose = spec_file(tmp_path, "loose.toml", "bias_stability_dph = { max = 1e6 }\n")
    got = gt.compare(train=train, test=unit_logs["heldout"], spec=loose, **args)
    want = json.loads(
        cli("compare", "--json", "--methods", "linear,thermal", "--method", "thermal",
            "--gyro-col", ",".join(GYROS),
            "--temp-col", ",".join(TEMPS), "--train", unit_logs["static"], "--train",
            unit_logs["table"], "--test", unit_logs["heldout"], "--spec", loose).stdout
    )
    assert got == want
    values = []
    for a in got["verdicts"]:
        values += [c["verdict"]["figures"][0]["value"] for c in a["columns"]]
        values.append(a["unit_fit"][1]["figures"][0]["value"])
        assert all(c["verdict"]["pass"] for c in a["columns"]) and a["unit_fit"][1]["pass"]
    mid = (min(values) + max(values)) / 2
    tight = spec_file(tmp_path, "tight.toml", f"bias_stability_dph = {{ max = {mid} }}\n")
    got = gt.compare(train=train, test=unit_logs["heldout"], spec=tight, **args)
    passes = [c["verdict"]["pass"] for a in got["verdicts"] for c in a["columns"]]
    passes += [a["unit_fit"][1]["pass"] for a in got["verdicts"]]
    assert True in passes and False in passes
