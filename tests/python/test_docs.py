"""The documentation: its tutorials run and make their pictures, and the
Sphinx site builds with every warning an error (when Sphinx is installed)."""

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"


@pytest.mark.parametrize(("script", "pictures"), [
    ("pose_graph.py", ["pose_graph_intel.png", "pose_graph_sphere.png"]),
    ("calibration.py", ["calibration_errors.png", "calibration_views.png"]),
    ("robust_pose_graph.py", ["robust_pose_graph.png"]),
    ("camera_imu.py", ["camera_imu.png"]),
    ("stereo.py", ["stereo_rectified.png"]),
    ("joint_rig.py", ["joint_rig.png"]),
])
def test_tutorial_scripts_make_their_pictures(tmp_path, script, pictures):
    pytest.importorskip("matplotlib")
    if script == "stereo.py":
        pytest.importorskip("cv2")
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
    elif script == "calibration.py":
        rms = float(r.stdout.split("RMS reprojection error ")[-1].split()[0])
        assert 0.05 < rms < 0.5  # OpenCV's sample: 0.18 px
    elif script == "robust_pose_graph.py":
        # the numbers the tutorial's page quotes (to their printed precision, with
        # room for another BLAS' rounding)
        ate = [float(x) for x in re.findall(r"ATE ([0-9.]+) m", r.stdout)]
        assert ate == pytest.approx([13.590, 0.087], abs=2e-3)
        assert "138 wrong;" in r.stdout and "precision 1.000, recall 1.000" in r.stdout
    elif script == "stereo.py":
        assert "ROS reads: f' = 516.75 px, baseline -Tx/f' = 3.3269 squares" in r.stdout
        rows = float(re.search(r"row difference .* RMS ([0-9.]+) px", r.stdout).group(1))
        assert rows < 0.25  # the page says 0.15 px
        assert (tmp_path / "stereo_calibration" / "left_camera_info.yaml").is_file()
    elif script == "joint_rig.py":
        rms = float(re.search(r"reprojection RMS ([0-9.]+) px", r.stdout).group(1))
        assert rms == pytest.approx(0.415, abs=2e-3)
        assert "(σ > 0.8 × the prior's): theta1, d1, d2, d3, d4" in r.stdout
    else:
        d, sigma = re.search(r"time offset d: ([0-9.]+) ms .*σ ([0-9.]+);", r.stdout).groups()
        assert float(d) == pytest.approx(7.007, abs=2e-3)
        assert float(sigma) == pytest.approx(0.027, abs=2e-3)


def test_every_public_module_has_an_api_page():
    # The site itself is built by `make docs` (sphinx -W, part of `make lint`);
    # this checks that no public module is left out of it: every module of the
    # installed package whose dotted name has no part starting with "_" has an
    # automodule directive, and every command-line module a page under docs/cli.
    import pkgutil

    import boxplus

    text = "\n".join(p.read_text() for p in (DOCS / "api").glob("*.rst"))
    documented = {line.split("::")[1].strip() for line in text.splitlines()
                  if line.startswith(".. automodule::")}
    public = {m.name for m in pkgutil.walk_packages(boxplus.__path__, "boxplus.")
              if not any(part.startswith("_") for part in m.name.split("."))}
    assert len(public) > 40  # the walk itself works
    commands = {"boxplus.calib.cli": "boxplus-calib",
                "boxplus.calib.camera_imu_cli": "boxplus-camera-imu"}
    for command in commands.values():
        assert (DOCS / "cli" / f"{command}.rst").is_file(), command
    assert public - set(commands) <= documented, sorted(public - set(commands) - documented)

    classes = {line.split("::")[1].strip() for line in text.splitlines()
               if line.startswith(".. autoclass::")}
    for name in ("SO2", "SO3", "SE2", "SE3", "S2", "Rn", "Problem", "SolverOptions",
                 "IterationInfo", "SolveSummary"):
        assert f"boxplus.{name}" in classes and hasattr(boxplus, name)
