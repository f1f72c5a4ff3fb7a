"""Gyro figures against NIST SP 1065's NBS-1000 values and the CLI (`allan`, `evaluate`)."""

import json

import numpy as np
import pytest

import gyrotherm as gt
from test_allan import nbs1000


@pytest.mark.parametrize("tau,want", [(1, 2.884664e-01), (10, 9.296352e-02), (100, 3.206656e-02)])
def test_bias_stability_is_the_std_of_tau_means(tau, want):
    """docs/method.md §6: std dev (n − 1) of τ-means of NBS-1000; bias_stability is in °/h of °/s."""
    y, _ = nbs1000()
    assert gt.bias_stability(y, 1.0, tau) / 3600.0 == pytest.approx(want, rel=2e-6)


def test_bias_stability_at_10_hz_and_default_tau():
    y, _ = nbs1000()
    y10 = np.repeat(y, 10)  # the same means at 10 Hz: 100 s = 1000 samples per mean
    assert gt.bias_stability(y10, 10.0) == pytest.approx(gt.bias_stability(y, 1.0, 100.0), rel=1e-12)


def test_noise_terms_equal_the_cli(cli, logs):
    want = json.loads(cli("allan", "--input", logs["static"], "--json").stdout)["noise"]
    log = gt.read_log(logs["static"], as_frame=False)
    got = gt.noise_terms(log["gyro_dps"], 1.0)
    assert set(got) == set(want) >= {"arw_deg_rt_h", "bias_instability_dph", "rrw_deg_h_rt_h"}
    for k, w in want.items():
        if w is None:
            assert got[k] is None, k
            continue
        assert set(got[k]) == set(w), k
        for field, v in w.items():
            assert got[k][field] == pytest.approx(v, rel=1e-12), (k, field)
    assert got["arw_deg_rt_h"]["value"] > 0


def test_scale_factor_equals_cli_evaluate(cli, logs):
    want = json.loads(cli("evaluate", "--input", logs["table"], "--json").stdout)
    from_path = gt.scale_factor(logs["table"])
    log = gt.read_log(logs["table"])
    from_frame = gt.scale_factor(log)
    from_arrays = gt.scale_factor(time_s=log["time_s"], gyro_dps=log["gyro_dps"], table_dps=log["table_dps"])
    for got in (from_path, from_frame, from_arrays):
        for k in ["scale_factor", "intercept_dps", "nonlinearity_ppm", "asymmetry_ppm",
                  "scale_positive", "scale_negative", "sf_thermal_error_ppm", "reference_scale"]:
            assert got[k] == pytest.approx(want[k], rel=1e-12), k
        assert len(got["scale_over_time"]) == len(want["scale_over_time"])
        assert [p["table_dps"] for p in got["rate_points"]] == [p["table_dps"] for p in want["rate_points"]]
