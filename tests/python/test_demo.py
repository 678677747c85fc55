"""The README's first command runs examples/demo.py: every part of it works and
says what the README promises (in a scratch folder: it writes its outputs)."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def test_demo_runs_every_part(tmp_path):
    pytest.importorskip("cv2")
    pytest.importorskip("matplotlib")
    r = subprocess.run([sys.executable, str(ROOT / "examples" / "demo.py")], cwd=tmp_path,
                       capture_output=True, text=True, timeout=300,
                       env={**os.environ, "MPLBACKEND": "Agg", "OPENBLAS_NUM_THREADS": "1",
                            "PYTHONPATH": str(ROOT / "examples")})
    assert r.returncode == 0, r.stderr[-3000:]
    out = r.stdout
    assert "RMS difference boxplus − OpenCV" in out
    assert "certificate: globally optimal" in out
    assert "RMS reprojection error 0.2010 px over 1404 corners" in out  # 13 stereo pairs
    stereo = tmp_path / "demo_output" / "stereo"
    for name in ("calibration.yml", "left_camera_info.yaml", "right_camera_info.yaml", "rig.png"):
        assert (stereo / name).stat().st_size > 0, name
    assert "the default: ATE 0.087 m, 138 closures judged wrong (precision 1.00, recall 1.00)" in out
