"""allantools' own tests of the six functions gyrotherm stands in for (adev, oadev, mdev,
hdev, ohdev, tdev), run against gyrotherm.

Vendored from the allantools 2024.6 sdist (https://github.com/aewallin/allantools,
``pip download allantools==2024.6 --no-deps --no-binary :all:``), the parts that call the
six functions and need no data file; the file each test came from is named above it. The
changes: ``allantools`` is replaced by ``gyrotherm`` for the six functions, NBS14 tests of
functions gyrotherm does not provide (totdev, mtotdev, ttotdev, htotdev) and of allantools
internals (tau_reduction, remove_small_ns, trim_data) are left out, and test_ns checks the
six functions only.

This file is a modified copy of allantools test code:
Copyright (C) Anders E.E. Wallin and the allantools contributors.
It is free software: you can redistribute it and/or modify it under the terms of the GNU
Lesser General Public License as published by the Free Software Foundation, either version
3 of the License, or (at your option) any later version; without any warranty. The license
text is in allantools_LICENSE.txt beside this file. The rest of gyrotherm is not under the
LGPL; this test file is not shipped in the wheel.

``test_allantools_full_suite`` (opt-in, GYROTHERM_ALLANTOOLS_SUITE=1) runs allantools'
whole suite from its sdist, once as it is and once with gyrotherm's six functions in
allantools' place, and requires every test that passes the first way to pass the second.
"""

import os
import pathlib
import subprocess
import sys
import tarfile
import xml.etree.ElementTree as ET

import allantools
import numpy as np
import pytest

import gyrotherm as at

# --- tests/functional_tests/test_tau_generator.py -------------------------------------------

N = 128
d = np.random.random(N)
r = 1.0

expected_all = np.arange(1, 43)
expected_octave = [1.0, 2.0, 4.0, 8.0, 16.0, 32.0]
expected_decade = [1.0, 2.0, 4.0, 10.0, 20.0, 40.0]


def test_tau_generator_empty():
    (taus_used, adev, adeverror, adev_n) = at.adev(d)
    np.testing.assert_allclose(taus_used, expected_octave)


def test_tau_generator_empty_list():
    (taus_used, adev, adeverror, adev_n) = at.adev(d, taus=[])
    np.testing.assert_allclose(taus_used, expected_octave)


def test_tau_generator_all():
    (taus_used, adev, adeverror, adev_n) = at.adev(d, rate=r, taus="all")
    np.testing.assert_allclose(taus_used, expected_all)


def test_tau_generator_octave():
    (taus_used, adev, adeverror, adev_n) = at.adev(d, rate=r, taus="octave")
    np.testing.assert_allclose(taus_used, expected_octave)


def test_tau_generator_decade():
    (taus_used, adev, adeverror, adev_n) = at.adev(d, rate=r, taus="decade")
    np.testing.assert_allclose(taus_used, expected_decade)


def test_tau_generator_1234():
    wanted_taus = [1, 2, 3, 4]
    (taus_used, adev, adeverror, adev_n) = at.adev(d, rate=r, taus=wanted_taus)
    np.testing.assert_allclose(taus_used, wanted_taus)


def test_tau_generator_numpy1234():
    wanted_taus = np.array([1, 2, 3, 4])
    (taus_used, adev, adeverror, adev_n) = at.adev(d, rate=r, taus=wanted_taus)
    np.testing.assert_allclose(taus_used, wanted_taus)


def test_zero_rate():
    with pytest.raises(RuntimeError):
        at.adev(d, rate=0.0)


# --- tests/nbs14/test_nbs14_10point.py (Stable32 values of the NBS14 10-point set) ----------

nbs14_phase = [0.00000, 103.11111, 123.22222, 157.33333,
               166.44444, 48.55555, -96.33333, -2.22222, 111.88889, 0.00000]
nbs14_f = [892.0, 809.0, 823.0, 798.0, 671.0, 644.0, 883.0, 903.0, 677.0]

nbs14_devs = {
    "adev": (91.22945, 115.8082),
    "oadev": (91.22945, 85.95287),
    "mdev": (91.22945, 74.78849),
    "hdev": (70.80608, 116.7980),
    "tdev": (52.67135, 86.35831),
    "ohdev": (70.80607, 85.61487),
}


def check_devs(dev2, dev1):
    rel_error = (dev2 - dev1) / dev1
    tol = 1e-4
    return abs(rel_error) < tol


@pytest.mark.parametrize("name", sorted(nbs14_devs))
def test_nbs14_10point(name):
    function = getattr(at, name)
    ref_devs = nbs14_devs[name]
    taus = [1, 2]
    (taus1, adevs1, aerrs1, ns1) = function(nbs14_phase, rate=1.0, taus=taus)
    (taus2, adevs2, aerrs2, ns2) = function(nbs14_f, rate=1.0, data_type="freq", taus=taus)
    assert check_devs(adevs1[0], ref_devs[0])  # tau=1 from phase data
    assert check_devs(adevs1[1], ref_devs[1])  # tau=2 from phase data
    assert check_devs(adevs2[0], ref_devs[0])  # tau=1 from frequency data
    assert check_devs(adevs2[1], ref_devs[1])  # tau=2 from frequency data


# --- tests/functional_tests/test_ns.py -----------------------------------------------------


@pytest.mark.parametrize("name", ["adev", "oadev", "mdev", "tdev", "hdev", "ohdev"])
def test_ns(name):
    # this test asks for results at unreasonable tau-values
    # either zero, not an integer multiple of the data-interval
    # or too large, given the length of the dataset
    function = getattr(at, name)
    phase_white = allantools.noise.white(500)
    taus_try = [x for x in np.logspace(0, 4, 4000)]  # try insane tau values
    (taus2, devs2, errs2, ns2) = function(phase_white, rate=1.0, taus=taus_try)
    assert len(taus2) == len(devs2)
    assert len(taus2) == len(errs2)
    assert len(taus2) == len(ns2)
    for n in ns2:
        assert n > 1  # n should be 2 or more for each tau


# --- gyrotherm's own: the error is both kinds, with its message ------------------------------


def test_zero_rate_error_is_a_value_and_a_runtime_error():
    for kind in (RuntimeError, ValueError, at.AllanError, at.GyrothermError):
        with pytest.raises(kind, match="rate = 0.0 Hz is not a positive finite sample rate"):
            at.adev(d, rate=0.0)
    assert issubclass(at.LogError, RuntimeError) and issubclass(at.LogError, ValueError)
    assert repr(at.GyrothermError("x")) == "GyrothermError('x')"
    assert at.GyrothermError.__module__ == "gyrotherm"


# --- allantools' whole suite, opt-in ---------------------------------------------------------

SIX = ("adev", "oadev", "mdev", "hdev", "ohdev", "tdev")

# Written into the sdist's tests/ folder: with GYROTHERM_SWAP set, allantools' six functions
# become gyrotherm's (counting the calls, so a swap that never happens cannot pass).
SWAP_CONFTEST = '''
import os
import allantools
if os.environ.get("GYROTHERM_SWAP"):
    import gyrotherm
    calls = [0]
    def counted(f):
        def wrapper(*a, **k):
            calls[0] += 1
            return f(*a, **k)
        return wrapper
    for name in %r:
        g = counted(getattr(gyrotherm, name))
        setattr(allantools, name, g)
        setattr(allantools.allantools, name, g)
    def pytest_sessionfinish(session, exitstatus):
        with open(os.environ["GYROTHERM_SWAP"], "w") as f:
            f.write(str(calls[0]))
''' % (SIX,)


def _outcomes(tests_dir: pathlib.Path, xml: pathlib.Path, env: dict) -> dict:
    """Run allantools' non-slow tests; {test id: passed?}."""
    subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-m", "not slow",
         "-W", "ignore", f"--junitxml={xml}", "."],
        cwd=tests_dir, env=env, capture_output=True, text=True, timeout=1200,
    )
    out = {}
    for case in ET.parse(xml).iter("testcase"):
        key = f"{case.get('classname')}::{case.get('name')}"
        bad = any(c.tag in ("failure", "error") for c in case)
        skipped = any(c.tag == "skipped" for c in case)
        if not skipped:
            out[key] = not bad
    return out


@pytest.mark.skipif(
    not os.environ.get("GYROTHERM_ALLANTOOLS_SUITE"),
    reason="opt-in (GYROTHERM_ALLANTOOLS_SUITE=1): downloads allantools' sdist from the "
    "package index and runs its suite twice (about a minute)",
)
def test_allantools_full_suite(tmp_path):
    version = allantools.__version__
    dl = subprocess.run(
        [sys.executable, "-m", "pip", "download", f"allantools=={version}", "--no-deps",
         "--no-binary", ":all:", "-d", str(tmp_path), "-q"],
        capture_output=True, text=True, timeout=600,
    )
    assert dl.returncode == 0, f"pip download of the allantools {version} sdist failed: {dl.stderr}"
    (sdist,) = tmp_path.glob("allantools-*.tar.gz")
    with tarfile.open(sdist) as tar:
        tar.extractall(tmp_path)
    (tests_dir,) = tmp_path.glob("allantools-*/tests")
    (tests_dir / "conftest.py").write_text(SWAP_CONFTEST)
    env = {k: v for k, v in os.environ.items() if k != "GYROTHERM_SWAP"}
    theirs = _outcomes(tests_dir, tmp_path / "theirs.xml", env)
    calls = tmp_path / "calls.txt"
    ours = _outcomes(tests_dir, tmp_path / "ours.xml", {**env, "GYROTHERM_SWAP": str(calls)})
    assert int(calls.read_text()) > 100, "gyrotherm's functions were not called"
    passing = sorted(k for k, ok in theirs.items() if ok)
    assert len(passing) > 300, f"only {len(passing)} allantools tests pass as they are"
    broken = [k for k in passing if not ours.get(k, False)]
    assert not broken, f"{len(broken)} of {len(passing)} allantools tests fail with gyrotherm: {broken}"
