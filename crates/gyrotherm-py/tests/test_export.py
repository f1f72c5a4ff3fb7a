"""``Model.export`` of a single gyro and of a unit: the files ``gyrotherm export --target`` writes,
byte for byte, for every target, and the same refusals."""

import warnings

import pytest

import gyrotherm as gt

from test_unit import GYROS, TEMPS, unit_logs  # noqa: F401  (the unit fixture)


@pytest.fixture(scope="module")
def models(cli, logs, unit_logs, tmp_path_factory):  # noqa: F811
    """A single-gyro and a unit model file, trained by the CLI."""
    d = tmp_path_factory.mktemp("export")
    single = d / "single.json"
    cli("train", "--method", "thermal", "--input", logs["static"], "--out", single)
    unit = d / "unit.json"
    cli(
        "train", "--method", "thermal", "--gyro-col", ",".join(GYROS), "--temp-col",
        ",".join(TEMPS), "--input", unit_logs["static"], "--out", unit,
    )
    return {"single": single, "unit": unit}


def files(folder):
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir())}


@pytest.mark.parametrize("kind", ["single", "unit"])
@pytest.mark.parametrize(
    "target,options,cli_options",
    [
        ("c", {}, []),
        ("rust", {}, []),
        ("ardupilot", {"instance": 1}, ["--instance", "1"]),
        ("px4", {"device_id": 0x2A0012}, ["--device-id", "0x2A0012"]),
    ],
)
def test_export_writes_what_the_cli_writes(cli, models, tmp_path, kind, target, options, cli_options):
    path = models[kind]
    cli("export", "--model", path, "--target", target, *cli_options, "--out", tmp_path / "cli")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", gt.GyrothermWarning)
        lines = gt.Model.load(path).export(target, tmp_path / "py", **options)
    assert files(tmp_path / "py") == files(tmp_path / "cli")
    assert any(line.startswith("wrote ") for line in lines), lines
    if target in ("ardupilot", "px4"):
        # The polynomial's fit and what it does not carry are said, as on the command line.
        assert any("fit error" in line for line in lines), lines
        assert "not carried by the polynomial:" in lines


def test_export_refuses_what_the_cli_refuses(models, tmp_path):
    m = gt.Model.load(models["single"])
    with pytest.raises(gt.ModelError, match="instance is for target ardupilot or px4"):
        m.export("c", tmp_path / "a", instance=1)
    with pytest.raises(gt.ModelError, match="target: unknown value"):
        m.export("arduplane", tmp_path / "b")
    with pytest.raises(gt.ModelError, match="device"):
        m.export("px4", tmp_path / "c")
    with pytest.raises(gt.ModelError):
        m.export("ardupilot", tmp_path / "d", axis="w")
    assert not any((tmp_path / n).exists() for n in "abcd")
