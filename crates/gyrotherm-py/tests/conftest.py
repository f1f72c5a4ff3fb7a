"""Shared fixtures: the reference data (../shared/reference beside the checkout), the
`gyrotherm` CLI binary the Python results are compared with, and small simulated logs."""

import os
import pathlib
import subprocess

import pytest

HERE = pathlib.Path(__file__).resolve().parent
REPO = HERE.parents[2]


def _must_have(why: str):
    """Skip with the reason, except under CI=true, where a missing input is a failure."""
    if os.environ.get("CI") == "true":
        pytest.fail(why)
    pytest.skip(why)


def shared_dir():
    env = os.environ.get("GYROTHERM_SHARED")
    if env:
        return pathlib.Path(env)
    for d in [HERE, *HERE.parents]:
        if (d / "shared" / "reference").is_dir():
            return d / "shared"
    return None


@pytest.fixture(scope="session")
def reference():
    """reference("allan/x.txt") -> path; skipped (failed under CI=true) when missing."""

    def get(rel: str) -> pathlib.Path:
        d = shared_dir()
        p = d / "reference" / rel if d else None
        if p is None or not p.is_file():
            _must_have(
                f"reference file {rel} not found (looked for ../shared/reference beside the "
                "checkout; set GYROTHERM_SHARED to its folder)"
            )
        return p

    return get


@pytest.fixture(scope="session")
def cli():
    """Run the `gyrotherm` binary: cli("train", "--input", ...) -> CompletedProcess."""
    exe = pathlib.Path(os.environ.get("GYROTHERM_BIN", REPO / "target" / "release" / "gyrotherm"))
    if not exe.is_file():
        _must_have(
            f"the gyrotherm CLI is not built at {exe} (cargo build --release -p gyrotherm-cli, "
            "or set GYROTHERM_BIN)"
        )

    def run(*args, check=True):
        p = subprocess.run([str(exe), *map(str, args)], capture_output=True, text=True)
        if check and p.returncode != 0:
            raise AssertionError(f"gyrotherm {' '.join(map(str, args))} failed:\n{p.stderr}")
        return p

    return run


# A short chamber profile (4801 s at 1 Hz): warm, soak, cold, soak, back. Rows are
# duration_s,target_c as `gyrotherm simulate --profile-file` reads them.
PROFILE = "1,22\n900,40\n900,40\n1200,0\n900,0\n900,22\n"


@pytest.fixture(scope="session")
def logs(cli, tmp_path_factory):
    """Simulated static and ±20 °/s rate-table logs, and a held-out static log."""
    d = tmp_path_factory.mktemp("logs")
    prof = d / "profile.csv"
    prof.write_text(PROFILE)
    out = {}
    for name, seed, extra in [
        ("static", 3, []),
        ("table", 4, ["--table-rate", "20"]),
        ("heldout", 5, []),
    ]:
        path = d / f"{name}.csv"
        cli("simulate", "--profile-file", prof, "--seed", seed, *extra, "--out", path)
        out[name] = path
    return out
