"""The Allan family against allantools (the function it replaces), NIST SP 1065's NBS-1000
values and Stable32's results on a real OCXO record."""

import json

import allantools
import numpy as np
import pytest

import gyrotherm as gt

FUNCS = ["adev", "oadev", "mdev", "hdev", "ohdev", "tdev"]
TOL = 1e-9  # relative, against allantools


def nbs1000():
    """NIST SP 1065 pp. 107-108 (docs/method.md §6): n0 = 1234567890, n_{i+1} = 16807·n_i mod
    2147483647, y_i = n_i / 2147483647, i = 0..999."""
    n = [1234567890]
    for _ in range(999):
        n.append(16807 * n[-1] % 2147483647)
    return np.array(n, dtype=np.float64) / 2147483647.0, n


def ocxo(path):
    """Fractional frequency f/1e7 − 1 of the OCXO record, from the decimal text."""
    out = []
    for line in path.read_text().splitlines():
        line = line.strip()
        if not line or line.startswith("#"):
            continue
        whole, _, frac = line.partition(".")
        out.append(((int(whole) - 10_000_000) + float("0." + (frac or "0"))) / 1e7)
    return np.array(out)


def assert_same(want, got, what):
    """(taus, devs, errs, ns) equal: τ and n exactly, deviations to TOL relative."""
    assert len(want) == len(got) == 4, what
    wt, wd, we, wn = (np.asarray(a) for a in want)
    gt_, gd, ge, gn = got
    assert gt_.shape == wt.shape, f"{what}: {len(gt_)} τ, allantools {len(wt)}"
    np.testing.assert_array_equal(gt_, wt, err_msg=f"{what}: τ")
    np.testing.assert_array_equal(gn, wn, err_msg=f"{what}: n")
    for name, w, g in [("dev", wd, gd), ("err", we, ge)]:
        rel = np.max(np.abs(g - w) / np.abs(w)) if len(w) else 0.0
        assert rel <= TOL, f"{what}: {name} off by {rel:.2e} relative"


def test_nbs1000_generator_matches_its_check_values():
    _, n = nbs1000()
    assert n[1:4] == [395529916, 1209410747, 633705974]


@pytest.mark.parametrize("func", FUNCS)
@pytest.mark.parametrize("data_type", ["freq", "phase"])
@pytest.mark.parametrize("taus", ["octave", "decade", "all", None])
def test_nbs1000_equals_allantools(func, data_type, taus):
    y, _ = nbs1000()
    want = getattr(allantools, func)(y, rate=1.0, data_type=data_type, taus=taus)
    got = getattr(gt, func)(y, rate=1.0, data_type=data_type, taus=taus)
    assert_same(want, got, f"{func} {data_type} {taus}")


# NIST SP 1065 table, restated in docs/method.md §6 (7 significant digits).
NBS_TABLE = {
    "adev": [2.922319e-01, 9.965736e-02, 3.897804e-02],
    "oadev": [2.922319e-01, 9.159953e-02, 3.241343e-02],
    "mdev": [2.922319e-01, 6.172376e-02, 2.170921e-02],
    "hdev": [2.943883e-01, 1.052754e-01, 3.910860e-02],
}


@pytest.mark.parametrize("func", sorted(NBS_TABLE))
def test_nbs1000_published_values(func):
    y, _ = nbs1000()
    taus, devs, _, _ = getattr(gt, func)(y, rate=1.0, data_type="freq", taus=[1, 10, 100])
    np.testing.assert_array_equal(taus, [1.0, 10.0, 100.0])
    # half a unit in the 7th digit is 5e-7 relative at worst.
    np.testing.assert_allclose(devs, NBS_TABLE[func], rtol=2e-6)


@pytest.mark.parametrize("func", FUNCS)
@pytest.mark.parametrize("data_type", ["freq", "phase"])
@pytest.mark.parametrize("taus", ["octave", "decade", "explicit"])
def test_ocxo_equals_allantools(reference, func, data_type, taus):
    y = ocxo(reference("allan/ocxo_frequency.txt"))
    assert len(y) == 19_982
    if taus == "explicit":
        taus = np.array([1.0, 3.0, 7.0, 30.0, 100.0, 1000.0, 3000.0, 5000.0])
    want = getattr(allantools, func)(y, rate=1.0, data_type=data_type, taus=taus)
    got = getattr(gt, func)(y, rate=1.0, data_type=data_type, taus=taus)
    assert_same(want, got, f"OCXO {func} {data_type} {taus}")


@pytest.mark.parametrize("func", ["adev", "oadev", "mdev", "hdev"])
def test_ocxo_equals_stable32_every_tau(reference, func):
    """Stable32's σ (5 significant digits) and term counts at every averaging factor."""
    y = ocxo(reference("allan/ocxo_frequency.txt"))
    rows = [
        line.split()
        for line in reference(f"allan/stable32_{func}_alltau.txt").read_text().splitlines()
        if line.strip() and not line.lstrip().startswith("#")
    ]
    m = np.array([float(r[0]) for r in rows])
    taus, devs, _, ns = getattr(gt, func)(y, rate=1.0, data_type="freq", taus=m)
    np.testing.assert_array_equal(taus, m)
    np.testing.assert_array_equal(ns, [float(r[2]) for r in rows])
    np.testing.assert_allclose(devs, [float(r[5]) for r in rows], rtol=1e-4)


TAU_FORMS = {
    "octave": "octave",
    "decade": "decade",
    "all": "all",
    "log10": "log10",
    "None": None,
    "empty list": [],
    "list": [1, 2, 3, 10, 50],
    "array, unsorted with duplicates, off-grid and out-of-range": np.array(
        [40.0, 2.0, 2.0, 0.05, 0.26, 7.3, 333.3, 1e9, -5.0]
    ),
    "scalar array": np.array([10.0]),
}


@pytest.mark.parametrize("func", FUNCS)
@pytest.mark.parametrize("data_type", ["freq", "phase"])
@pytest.mark.parametrize("form", sorted(TAU_FORMS))
@pytest.mark.parametrize("n,rate", [(1000, 1.0), (1001, 10.0), (37, 4.0)])
def test_random_data_equals_allantools_for_every_taus_form(func, data_type, form, n, rate):
    rng = np.random.default_rng(n * 7 + len(form))
    y = np.cumsum(rng.standard_normal(n)) * 1e-3 + rng.standard_normal(n)  # white + random walk
    taus = TAU_FORMS[form]
    try:
        want = getattr(allantools, func)(y, rate=rate, data_type=data_type, taus=taus)
    except UserWarning:  # allantools: "remove_small_ns() nothing remains!?"
        with pytest.raises(gt.AllanError, match="too short"):
            getattr(gt, func)(y, rate=rate, data_type=data_type, taus=taus)
        return
    got = getattr(gt, func)(y, rate=rate, data_type=data_type, taus=taus)
    assert_same(want, got, f"{func} {data_type} {form} n={n} rate={rate}")


def test_large_random_freq_record_equals_allantools():
    y = np.random.default_rng(5).standard_normal(300_000) * 1e-9 + 1e-6
    for func in FUNCS:
        want = getattr(allantools, func)(y, rate=100.0, data_type="freq", taus="octave")
        got = getattr(gt, func)(y, rate=100.0, data_type="freq", taus="octave")
        assert_same(want, got, f"{func} 3e5 samples")


def test_octave_tau_count_on_1e8_samples_is_allantools():
    """allantools keeps 2^k < len(phase) leaving ≥ 2 terms: m = 2^0 … 2^25 for OADEV of 1e8
    rate samples (1e8 + 1 phase points). `gyrotherm allan` stops at Stable32's N/4 =
    25,000,000, one octave earlier (25 τ)."""
    n = 100_000_000
    m = gt._allan.averaging_factors("oadev", n + 1, 1.0, "octave")
    assert len(m) == 26
    assert m[-1] == 2**25 and n + 1 - 2 * 2**25 > 1
    assert 2**25 > n // 4 >= 2**24  # the CLI's limit leaves 2^25 out


def test_deviation_bounds_equal_the_cli(cli, logs):
    """`deviation` is `gyrotherm allan`'s curve: same σ, α, EDF and 68.3 % bounds."""
    log = gt.read_log(logs["static"], as_frame=False)
    for kind in ["adev", "oadev", "mdev", "hdev", "ohdev"]:
        out = json.loads(
            cli("allan", "--input", logs["static"], "--kind", kind, "--taus", "1,2,4,10,100,500", "--json").stdout
        )
        d = gt.deviation(log["gyro_dps"], 1.0, "freq", kind, taus=[1, 2, 4, 10, 100, 500])
        pts = out["points"]
        np.testing.assert_array_equal(d.taus, [p["tau_s"] for p in pts])
        np.testing.assert_array_equal(d.ns, [p["n"] for p in pts])
        np.testing.assert_array_equal(d.alpha, [p["alpha"] for p in pts])
        for name, col in [("dev", d.devs), ("lo", d.lo), ("hi", d.hi), ("edf", d.edf)]:
            np.testing.assert_allclose(col, [p[name] for p in pts], rtol=1e-12, err_msg=f"{kind} {name}")


def test_deviation_bounds_bracket_the_deviation_and_take_alpha():
    y = np.random.default_rng(2).standard_normal(5000)
    d = gt.deviation(y, 1.0, "freq", "oadev")
    assert np.all(d.lo < d.devs) and np.all(d.devs < d.hi)
    # white frequency noise, identified as such where there are many averages (m ≤ 128)
    assert np.all(d.alpha[:8] == 0)
    fixed = gt.deviation(y, 1.0, "freq", "oadev", alpha=-1)
    assert np.all(fixed.alpha == -1)
    assert not np.allclose(fixed.edf, d.edf)


EDF_CASES = [
    (alpha, d, m, n, ov, mod)
    for alpha in [-4, -3, -2, -1, 0, 1, 2]
    for d in [2, 3]
    for m in [1, 2, 7, 64, 300]
    for n in [1001, 19983]
    for ov, mod in [(False, False), (True, False), (True, True)]
    if alpha + 2 * d > 1 and not (mod and d == 3)
]


def test_edf_greenhall_equals_allantools():
    compared = 0
    for alpha, d, m, n, ov, mod in EDF_CASES:
        try:
            want = allantools.edf_greenhall(alpha, d, m, n, overlapping=ov, modified=mod)
        except Exception:  # allantools refuses some corner cases
            continue
        got = gt.edf_greenhall(alpha, d, m, n, overlapping=ov, modified=mod)
        if not np.isfinite(want):
            continue
        compared += 1
        assert abs(got - want) <= 1e-9 * abs(want), (alpha, d, m, n, ov, mod, got, want)
    assert compared > 200


@pytest.mark.parametrize("edf", [1.0, 2.5, 10.0, 123.4, 5000.0])
@pytest.mark.parametrize("ci", [gt.ONE_SIGMA_CI, 0.9, 0.95])
def test_confidence_interval_equals_allantools(edf, ci):
    want = allantools.confidence_interval(2.5e-11, edf, ci=ci)
    got = gt.confidence_interval(2.5e-11, edf, ci=ci)
    np.testing.assert_allclose(got, want, rtol=1e-9)
