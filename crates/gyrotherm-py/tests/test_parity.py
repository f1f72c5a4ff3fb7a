"""Parity of every option: the library's description of the settings (exposed to Python as
``gyrotherm.settings()`` and printed by the hidden ``gyrotherm settings --json``), the CLI's
``--help`` (flags, defaults, possible values) and Python's signatures and default dicts must
agree; and with defaults, ``fit()`` + ``save()`` writes the bytes ``gyrotherm train`` writes.

The expected values come from the library alone (``gyrotherm::settings::describe``); nothing
here restates a default."""

import inspect
import json
import re

import pytest

import gyrotherm as gt

# Flags that name files or pick an output format: not settings.
NOT_SETTINGS = {"--input", "--out", "--model", "--spec", "--json", "--plot", "--stream", "--help",
                "--kalibr"}
# Python's fit() keywords that are not settings of the model.
PY_NOT_SETTINGS = {"static", "table", "progress", "log_options"}


def help_options(cli, command):
    """{flag: {"default": str|None, "values": [names], "switch": bool}} from ``--help``."""
    text = cli(command, "--help").stdout
    out = {}
    blocks = re.split(r"\n(?=  (?:-\w, )?\s*--[\w-]+)", text)
    for b in blocks:
        m = re.match(r"\s*(?:-\w, )?(--[\w-]+)( <[^>]+>)?", b)
        if not m:
            continue
        default = re.search(r"\[default: ([^\]]*)\]", b)
        listed = re.search(r"\[possible values: ([^\]]*)\]", b)
        if listed:
            values = [v.strip() for v in listed.group(1).split(",")]
        else:
            values = re.findall(r"^\s+- ([^:\s]+):", b, flags=re.M)
        out[m.group(1)] = {
            "default": default.group(1) if default else None,
            "values": values,
            "switch": m.group(2) is None,
            "text": b,
        }
    return out


def flag_of(spec):
    if spec["name"] == "cross":
        return "--no-cross"
    return "--" + spec["name"].replace("_", "-")


def as_python(text, like):
    """The library's default text as a value of the type of ``like`` (Python's default)."""
    if text is None:
        return None
    if isinstance(like, bool):
        return {"true": True, "false": False}[text]
    if isinstance(like, int):
        return int(text)
    if isinstance(like, float):
        return float(text)
    return text


@pytest.fixture(scope="module")
def described(cli):
    return json.loads(cli("settings", "--json").stdout)


def test_the_cli_and_python_describe_the_same_settings(described):
    assert described == gt.settings()


def test_every_cli_option_has_the_library_default_and_values(cli, described):
    checked = 0
    for command, specs in described.items():
        shown = help_options(cli, command)
        wanted = set()
        for spec in specs:
            flag = flag_of(spec)
            wanted.add(flag)
            if spec["deprecated"]:
                assert flag not in shown, f"{command} {flag}: deprecated, must be hidden"
                continue
            assert flag in shown, f"{command}: {flag} missing from --help"
            got = shown[flag]
            if spec["switch"]:
                assert got["switch"], f"{command} {flag}: should be a switch"
            else:
                assert got["default"] == spec["default"], (
                    f"{command} {flag}: --help default {got['default']!r}, "
                    f"library {spec['default']!r}"
                )
                if spec["open"]:
                    # Names or free values (τ in seconds): --help names each.
                    for v in spec["values"]:
                        assert v in got["text"], f"{command} {flag}: --help omits {v}"
                    checked += 1
                    continue
                assert got["values"] == spec["values"], (
                    f"{command} {flag}: --help values {got['values']}, library {spec['values']}"
                )
            checked += 1
        extra = set(shown) - wanted - NOT_SETTINGS
        assert not extra, f"{command}: options the library does not describe: {sorted(extra)}"
    # Every non-deprecated option of the four commands was compared.
    assert checked == sum(not s["deprecated"] for v in described.values() for s in v)
    assert checked >= 50, checked


def test_python_signatures_have_the_library_defaults(described):
    train = {s["name"]: s for s in described["train"]}
    params = inspect.signature(gt.fit).parameters
    fit_names = [n for n in params if n not in PY_NOT_SETTINGS]
    # fit() takes every fit setting (the sensor limits are the CLI's only: `train
    # --temp-min-c …`; Python fits with the defaults, which the byte test below checks).
    fit_specs = [s for s in described["train"] if s["name"] in gt.FIT_DEFAULTS]
    assert sorted(fit_names) == sorted(s["name"] for s in fit_specs)
    for s in fit_specs:
        default = params[s["name"]].default
        assert default == gt.FIT_DEFAULTS[s["name"]]
        assert default == as_python(s["default"], default), s["name"]
    assert gt.METHOD_NAMES == train["method"]["values"]
    logs = [s for s in described["train"] if s["name"] in gt.READ_DEFAULTS]
    assert [s["name"] for s in logs] == list(gt.READ_DEFAULTS)
    for s in logs:
        d = gt.READ_DEFAULTS[s["name"]]
        assert d == as_python(s["default"], d), s["name"]
    assert gt.GYRO_UNIT_NAMES == train["gyro_unit"]["values"]
    assert gt.DELIMITER_NAMES == train["delimiter"]["values"]
    # The log options are the same for every command.
    for command in ("compensate", "allan", "evaluate"):
        names = [s["name"] for s in described[command]]
        assert names[-len(logs):] == [s["name"] for s in logs], command
    # Allan: Python has one function per deviation of the library's list, and the default.
    allan = {s["name"]: s for s in described["allan"]}
    for kind in allan["kind"]["values"]:
        assert callable(getattr(gt, kind)), kind
    assert inspect.signature(gt.deviation).parameters["kind"].default == allan["kind"]["default"]


def test_fit_with_defaults_writes_the_bytes_train_writes(cli, logs, tmp_path):
    s, t = str(logs["static"]), str(logs["table"])
    for extra, kw in [([], {}), (["--method", "poly"], {"method": "poly"})]:
        a, b = tmp_path / "cli.json", tmp_path / "py.json"
        cli("train", "--input", s, "--input", t, *extra, "--out", a)
        gt.fit(static=s, table=t, **kw).save(b)
        assert a.read_bytes() == b.read_bytes(), extra


def test_the_removed_spellings_are_refused_in_both(cli, logs, tmp_path):
    s = str(logs["static"])
    a = tmp_path / "cli.json"
    p = cli("train", "--input", s, "--method", "lstm", "--out", a, check=False)
    assert p.returncode == 2 and "invalid value 'lstm'" in p.stderr, p.stderr
    p = cli("train", "--input", s, "--recipe", "generic", "--out", a, check=False)
    assert p.returncode == 2 and "unexpected argument '--recipe'" in p.stderr, p.stderr
    assert not a.exists()
    with pytest.raises(gt.FitError, match='method: unknown value "lstm"'):
        gt.fit(static=s, method="lstm")
    for old in ("recipe", "bias_window", "settle", "fill_gaps", "sample_period"):
        with pytest.raises(TypeError, match=old):
            gt.fit(static=s, **{old: 1})


def test_unit_evaluate_and_compare_take_the_library_defaults(described):
    # evaluate(): τ, settle time and reference scale as the library's `evaluate` settings.
    evaluate = {s["name"]: s for s in described["evaluate"]}
    params = inspect.signature(gt.evaluate).parameters
    for name in ("tau_s", "settle_s", "reference_scale"):
        default = params[name].default
        assert default == gt.EVALUATE_DEFAULTS[name], name
        assert default == as_python(evaluate[name]["default"], default), name
    # compare(): every fit keyword of fit(), with fit()'s (the library's) defaults.
    fit_params = inspect.signature(gt.fit).parameters
    cmp_params = inspect.signature(gt.compare).parameters
    for name in gt.FIT_DEFAULTS:
        assert cmp_params[name].default == fit_params[name].default == gt.FIT_DEFAULTS[name]
