"""Test oracles and harnesses of the repository (not in the wheel): an
independent numpy reader and objectives for g2o pose graphs
(``harness.g2o_reference``), the seeded fuzzer of the loader and the CLI
(``harness.fuzz``) and the locator of the installed ``boxplus-g2o``. Importable
from the tests (pytest's ``pythonpath``) and the benchmarks (``tests/`` on
``sys.path``)."""

import os
import shutil
import sys
from pathlib import Path


def boxplus_g2o() -> str:
    """Path of the ``boxplus-g2o`` installed with the imported boxplus package
    (not another one on PATH): beside the package for ``pip install --target
    DIR`` (DIR/bin, how ``make sanitize`` installs the instrumented build), else
    next to the interpreter (a virtual environment's bin/)."""
    import boxplus

    package = Path(boxplus.__file__).resolve().parent
    for d in (package.parent / "bin", Path(sys.executable).parent):
        exe = shutil.which("boxplus-g2o", path=os.fspath(d))
        if exe is not None:
            return exe
    raise FileNotFoundError("boxplus-g2o is not installed with the boxplus package")
