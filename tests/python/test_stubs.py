"""The committed stub python/boxplus/_core.pyi is what pybind11-stubgen makes of
the installed extension: mypy checks the package against that file, so a binding
changed without `make stubs` would leave the type check reading a stale API."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

COMMITTED = Path(__file__).resolve().parents[2] / "python" / "boxplus" / "_core.pyi"


def test_committed_stub_matches_the_built_extension(tmp_path):
    run = subprocess.run([sys.executable, "-m", "pybind11_stubgen", "boxplus._core", "-o", str(tmp_path)],
                         capture_output=True, text=True)
    assert run.returncode == 0, f"pybind11-stubgen failed:\n{run.stderr}"
    generated = (tmp_path / "boxplus" / "_core.pyi").read_text(encoding="utf-8")
    committed = COMMITTED.read_text(encoding="utf-8")
    assert generated == committed, (
        f"{COMMITTED} differs from what pybind11-stubgen makes of the installed boxplus._core; "
        "regenerate it with `make stubs` and commit it")
