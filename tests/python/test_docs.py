"""The documentation: its tutorials run and make their pictures, and the
Sphinx site builds with every warning an error (when Sphinx is installed)."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"


@pytest.mark.parametrize(("script", "pictures"), [
    ("pose_graph.py", ["pose_graph_intel.png", "pose_graph_sphere.png"]),
    ("calibration.py", ["calibration_errors.png", "calibration_views.png"]),
])
def test_tutorial_scripts_make_their_pictures(tmp_path, script, pictures):
    pytest.importorskip("matplotlib")
    r = subprocess.run([sys.executable, str(DOCS / "tutorials" / script), "--out", str(tmp_path)],
                       capture_output=True, text=True, timeout=300, cwd=tmp_path,
                       env={**os.environ, "MPLBACKEND": "Agg", "OPENBLAS_NUM_THREADS": "1"})
    assert r.returncode == 0, r.stderr
    for p in pictures:
        assert (tmp_path / p).read_bytes()[:4] == b"\x89PNG"
        assert (DOCS / "tutorials" / p).is_file(), f"{p} is not committed beside the tutorial"
    if script == "pose_graph.py":
        # The logging the tutorial shows: a load report and a solve summary per graph.
        assert r.stderr.count("boxplus INFO: pose graph solve: convergence: chi2") == 2
        assert "intel.g2o: 4" in r.stderr
    else:
        rms = float(r.stdout.split("RMS reprojection error ")[-1].split()[0])
        assert 0.05 < rms < 0.5  # OpenCV's sample: 0.18 px


def test_every_public_module_has_an_api_page():
    # The site itself is built by `make docs` (sphinx -W, part of `make lint`);
    # this checks that no public module is left out of it.
    text = "\n".join(p.read_text() for p in (DOCS / "api").glob("*.rst"))
    documented = {line.split("::")[1].strip() for line in text.splitlines()
                  if line.startswith(".. automodule::")}
    public = {"boxplus.manifolds", "boxplus.problem", "boxplus.noise", "boxplus.losses",
              "boxplus.solver", "boxplus.log", "boxplus.slam", "boxplus.slam.generate",
              "boxplus.calib", "boxplus.calib.rig", "boxplus.calib.init", "boxplus.calib.zhang",
              "boxplus.calib.report", "boxplus.calib.factors", "boxplus.joint", "boxplus.batch",
              "boxplus.measurements"}
    assert public <= documented, sorted(public - documented)
    import boxplus

    classes = {line.split("::")[1].strip() for line in text.splitlines()
               if line.startswith(".. autoclass::")}
    for name in ("SO2", "SO3", "SE2", "SE3", "S2", "Rn", "Problem", "SolverOptions",
                 "IterationInfo", "SolveSummary"):
        assert f"boxplus.{name}" in classes and hasattr(boxplus, name)
