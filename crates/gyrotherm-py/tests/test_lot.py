"""read_lot: a lot filled by the CLI (`gyrotherm lot add`) read back as columns."""

import numpy as np
import pytest

import gyrotherm as gt


@pytest.fixture(scope="module")
def lot(cli, logs, tmp_path_factory):
    d = tmp_path_factory.mktemp("lot")
    model = d / "model.json"
    cli("train", "--method", "linear", "--input", logs["static"], "--input", logs["table"],
        "--out", model)
    spec = d / "spec.toml"
    # The held-out log's bias stability after a linear fit is far below 1 °/h (gyrotherm
    # evaluate on it), so U1 passes; 1e-9 °/h is out of reach, so U2 fails.
    spec.write_text("[limits]\nbias_stability_dph = { max = 1.0 }\n")
    strict = d / "strict.toml"
    strict.write_text("[limits]\nbias_stability_dph = { max = 1e-9 }\n")
    db = d / "lot.sqlite"
    for unit, sheet, code in [("U1", spec, 0), ("U2", strict, 1), ("U1", spec, 0)]:
        p = cli("lot", "add", "--db", db, "--unit", unit, "--model", model,
                "--test", logs["heldout"], "--spec", sheet, check=False)
        assert p.returncode == code, p.stderr
    return db


def test_read_lot_columns(lot):
    cols = gt.read_lot(lot, as_frame=False)
    n = len(cols["figure"])
    assert all(len(v) == n for v in cols.values())
    bs = [i for i, f in enumerate(cols["figure"]) if f == "bias_stability_dph"]
    assert [cols["unit"][i] for i in bs] == ["U1", "U2", "U1"]
    assert [cols["verdict"][i] for i in bs] == ["pass", "fail", "pass"]
    assert list(cols["latest"][bs]) == [False, True, True]
    assert np.all(cols["limit_max"][bs] > 0)
    # Unlimited figures carry NaN limits and no verdict.
    other = [i for i, f in enumerate(cols["figure"]) if f == "bias_dph"]
    assert np.all(np.isnan(cols["limit_max"][other]))
    assert all(cols["verdict"][i] is None for i in other)


def test_read_lot_frame(lot):
    pd = pytest.importorskip("pandas")
    df = gt.read_lot(lot)
    assert isinstance(df, pd.DataFrame)
    latest = df[df.latest & (df.figure == "bias_stability_dph")]
    assert sorted(latest.unit) == ["U1", "U2"]


def test_read_lot_errors(tmp_path):
    with pytest.raises(gt.GyrothermError, match="no such lot database"):
        gt.read_lot(tmp_path / "none.sqlite")
    junk = tmp_path / "junk.sqlite"
    junk.write_bytes(b"x" * 4096)
    with pytest.raises(gt.GyrothermError, match="not an SQLite database"):
        gt.read_lot(junk)


@pytest.fixture(scope="module")
def unit_lot(cli, tmp_path_factory):
    """A lot holding one inertial unit (three axes) added by the CLI from a unit model."""
    d = tmp_path_factory.mktemp("unit_lot")
    sim = ["simulate", "--imu", "--unit", "random", "--unit-seed", "1000", "--profile",
           "fast-cycle"]
    s, t, h = d / "s.csv", d / "t.csv", d / "h.csv"
    cli(*sim, "--seed", "1", "--out", s)
    cli(*sim, "--seed", "2", "--table-rate", "20", "--table-axis", "y", "--out", t)
    cli(*sim, "--seed", "3", "--out", h)
    model = d / "unit.json"
    cli("train", "--method", "linear", "--gyro-col", "gyro_x_dps,gyro_y_dps,gyro_z_dps",
        "--temp-col", "temp_case_c", "--input", s, "--input", t, "--out", model)
    spec = d / "spec.toml"
    spec.write_text("[limits]\nbias_stability_dph = { max = 1e6 }\n")
    db = d / "lot.sqlite"
    cli("lot", "add", "--db", db, "--unit", "IMU-1", "--model", model, "--test", h,
        "--spec", spec)
    return db, model, h, spec


def test_read_lot_of_a_unit_names_each_axis(cli, unit_lot):
    db, model, h, spec = unit_lot
    cols = gt.read_lot(db, as_frame=False)
    bs = [i for i, f in enumerate(cols["figure"]) if f == "bias_stability_dph"]
    assert [cols["axis"][i] for i in bs] == ["gyro_x_dps", "gyro_y_dps", "gyro_z_dps"]
    assert [cols["axis_verdict"][i] for i in bs] == ["pass"] * 3
    assert {cols["run_verdict"][i] for i in bs} == {"pass"}
    # Each axis's value is the one evaluate --model UNIT.json measures on the same log.
    ev = gt.evaluate(h, model=model, spec=spec)
    want = [next(f["value"] for f in a["verdict"]["figures"]
                 if f["figure"] == "bias_stability_dph") for a in ev["axes"]]
    assert list(cols["value"][bs]) == want


def test_read_lot_single_axis_rows_have_no_axis(lot):
    cols = gt.read_lot(lot, as_frame=False)
    assert all(a is None for a in cols["axis"])
    assert all(v is None for v in cols["axis_verdict"])


@pytest.mark.parametrize("url", [
    "postgres://gyro:s3cret@127.0.0.1:1/lot",
    "postgres://gyro@127.0.0.1:1/lot?password=s3cret",
    "postgresql://127.0.0.1:1/lot?user=gyro&password=s3cret&connect_timeout=2",
])
def test_read_lot_masks_every_form_of_password(url):
    # Port 1 on the loopback refuses the connection: the error names the lot, password masked.
    with pytest.raises(gt.GyrothermError) as e:
        gt.read_lot(url)
    msg = str(e.value)
    assert "s3cret" not in msg and "***" in msg, msg
