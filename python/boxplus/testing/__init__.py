"""Test oracles and harnesses, not API: an independent numpy reader and
objectives for g2o pose graphs (:mod:`boxplus.testing.g2o_reference`) and the
seeded fuzzer of the loader and the CLI (:mod:`boxplus.testing.fuzz`)."""

import os
import shutil
import sys
from pathlib import Path


def boxplus_g2o() -> str:
    """Path of the ``boxplus-g2o`` installed with this package (not another one
    on PATH): beside the package for ``pip install --target DIR`` (DIR/bin, how
    ``make sanitize`` installs the instrumented build), else next to the
    interpreter (a virtual environment's bin/)."""
    for d in (Path(__file__).resolve().parents[2] / "bin", Path(sys.executable).parent):
        exe = shutil.which("boxplus-g2o", path=os.fspath(d))
        if exe is not None:
            return exe
    raise FileNotFoundError("boxplus-g2o is not installed with the boxplus package")
