"""The documented Python example runs as written: the ```python block of docs/python.md (the
README's Python section links there), executed in an empty folder with the `gyrotherm` CLI on
PATH (GYROTHERM_BIN's)."""

import os
import pathlib
import re

from conftest import REPO, _must_have


def documented_python_block() -> str:
    text = (REPO / "docs" / "python.md").read_text(encoding="utf-8")
    m = re.search(r"```python\n(.*?)```", text, re.S)
    assert m, "docs/python.md has no ```python block"
    return m.group(1)


def test_readme_python_example_runs(tmp_path, monkeypatch, capsys):
    exe = pathlib.Path(os.environ.get("GYROTHERM_BIN", REPO / "target" / "release" / "gyrotherm"))
    if not exe.is_file():
        _must_have(f"the gyrotherm CLI is not built at {exe} (set GYROTHERM_BIN)")
    if exe.name != "gyrotherm":
        # The example calls `gyrotherm` by name.
        link = tmp_path / "bin" / "gyrotherm"
        link.parent.mkdir()
        link.symlink_to(exe.resolve())
        exe = link
    monkeypatch.setenv("PATH", f"{exe.absolute().parent}{os.pathsep}{os.environ.get('PATH', '')}")
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    code = documented_python_block()
    exec(compile(code, "docs/python.md (Python example)", "exec"), {"__name__": "__readme__"})
    out = capsys.readouterr().out
    assert (work / "model.json").is_file()
    assert "gyrotherm model" in out and "epochs: 0" not in out, out
