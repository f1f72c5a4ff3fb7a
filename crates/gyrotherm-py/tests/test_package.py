"""The package as a user meets it: type stubs that match the code, the GIL released during
long work."""

import ast
import inspect
import pathlib
import sys
import threading

import numpy as np
import pytest

import gyrotherm as gt
import gyrotherm._gyrotherm as native

PKG = pathlib.Path(gt.__file__).parent


def stub_defs(name):
    tree = ast.parse((PKG / name).read_text())
    funcs, names = {}, set()
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            funcs[node.name] = node
            names.add(node.name)
        elif isinstance(node, ast.ClassDef):
            names.add(node.name)
            for sub in node.body:
                if isinstance(sub, ast.FunctionDef):
                    funcs[f"{node.name}.{sub.name}"] = sub
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            names.add(node.target.id)
        elif isinstance(node, ast.Assign):
            names.update(t.id for t in node.targets if isinstance(t, ast.Name))
    return funcs, names


def params(fn: ast.FunctionDef):
    a = fn.args
    out = [p.arg for p in a.posonlyargs + a.args + a.kwonlyargs]
    return [p for p in out if p not in ("self", "cls")], a.kwarg is not None


def test_stubs_are_installed_and_typed():
    assert (PKG / "__init__.pyi").is_file() and (PKG / "_gyrotherm.pyi").is_file()
    assert (PKG / "py.typed").is_file()


def test_public_stub_covers_all_and_matches_signatures():
    funcs, names = stub_defs("__init__.pyi")
    missing = set(gt.__all__) - names - {"__version__"}
    assert not missing, f"not in __init__.pyi: {sorted(missing)}"
    for qual, fn in funcs.items():
        obj = gt
        for part in qual.split("."):
            obj = inspect.getattr_static(obj, part) if part != qual.split(".")[0] else getattr(obj, part)
        if isinstance(obj, (staticmethod, classmethod)):
            obj = obj.__func__
        if isinstance(obj, property) or qual.endswith("__init__"):
            continue
        sig = inspect.signature(obj)
        runtime = [p for p in sig.parameters.values() if p.name not in ("self", "cls")]
        runtime_named = [p.name for p in runtime if p.kind not in (p.VAR_KEYWORD, p.VAR_POSITIONAL)]
        runtime_kwargs = any(p.kind == p.VAR_KEYWORD for p in runtime)
        stub, stub_kwargs = params(fn)
        assert stub[: len(runtime_named)] == runtime_named, f"{qual}: stub {stub} vs code {runtime_named}"
        extra = stub[len(runtime_named):]
        assert not extra or runtime_kwargs, f"{qual}: stub names {extra} the code does not take"
        assert stub_kwargs or not runtime_kwargs or extra, f"{qual}: code takes **kwargs, stub does not"


def test_native_stub_matches_the_module():
    funcs, names = stub_defs("_gyrotherm.pyi")
    public = {n for n in dir(native) if not n.startswith("_")} | {"__version__"}
    names = {n for n in names if not n.startswith("_")} | {"__version__"}
    assert public == names, f"stub only: {sorted(names - public)}; module only: {sorted(public - names)}"
    for qual, fn in funcs.items():
        if "." in qual:
            continue
        sig = inspect.signature(getattr(native, qual))
        assert params(fn)[0] == list(sig.parameters), qual


def test_long_work_releases_the_gil():
    """With a 10 s switch interval the main thread gets the GIL back only when the worker
    gives it up: while oadev runs in Rust (detached), not after it returns."""
    y = np.zeros(20_000_000)
    started, done = threading.Event(), threading.Event()

    def work():
        started.set()
        gt.oadev(y, data_type="freq", taus="octave")
        done.set()

    old = sys.getswitchinterval()
    sys.setswitchinterval(10.0)
    try:
        t = threading.Thread(target=work)
        t.start()
        started.wait()
        ran_during = not done.is_set()
        t.join()
    finally:
        sys.setswitchinterval(old)
    assert ran_during, "the main thread could not run while oadev worked: the GIL was held"


def test_the_native_layer_refuses_bad_arguments_with_exceptions():
    """What reaches Rust unchecked by the Python layer is refused, not a crash."""
    with pytest.raises(gt.AllanError, match="out of range"):
        native.dev_freq(np.ones(10), "oadev", [0])
    with pytest.raises(gt.AllanError, match="out of range"):
        native.dev_freq(np.ones(10), "oadev", [50])
    with pytest.raises(gt.AllanError, match="contiguous"):
        native.dev_phase(np.ones(20)[::2], "oadev", [1])
    with pytest.raises(TypeError):
        native.dev_phase(np.ones(20, dtype=np.float32), "oadev", [1])
    assert np.isnan(native.dev_phase(np.ones(20), "oadev", [15])[0][0])
