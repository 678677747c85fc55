"""Test oracles and harnesses, not API: an independent numpy reader and
objectives for g2o pose graphs (:mod:`boxplus.testing.g2o_reference`) and the
seeded fuzzer of the loader and the CLI (:mod:`boxplus.testing.fuzz`)."""

import os
import shutil
import sys


def boxplus_g2o() -> str:
    """Path of the ``boxplus-g2o`` installed next to this interpreter (the
    package's own command-line tool, not another one on PATH)."""
    exe = shutil.which("boxplus-g2o", path=os.path.dirname(sys.executable))
    if exe is None:
        raise FileNotFoundError("boxplus-g2o is not installed next to the Python interpreter")
    return exe
