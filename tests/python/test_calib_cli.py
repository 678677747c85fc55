"""boxplus-calib on OpenCV's stereo sample (skipped only when the shared images
are absent): detection, the stereo solve, the report, the YAML files (read
back, and equal to the library's own calibration of the same corners) and
the PNGs; and its refusals."""

import os
import re
from pathlib import Path

import numpy as np
import pytest
from boxplus.calib import calibrate_stereo, read_camera_info, read_opencv_yaml
from boxplus.calib.cli import main

cv2 = pytest.importorskip("cv2")
pytest.importorskip("yaml")
pytest.importorskip("matplotlib")

ROOT = Path(__file__).resolve().parents[2]
# OpenCV's stereo sample images: the project's shared data folder beside the
# checkout, or BOXPLUS_CALIB_SAMPLE
SAMPLE = Path(os.environ.get("BOXPLUS_CALIB_SAMPLE",
                             ROOT.parent / "shared" / "data" / "calib" / "opencv_stereo"))
CORNERS = ROOT / "data" / "calib" / "opencv_stereo_corners.npz"


def test_console_script_is_declared():
    text = (ROOT / "pyproject.toml").read_text()
    section = re.search(r"\[project\.scripts\]\n(.*?)\n\n", text, re.S)
    assert section and 'boxplus-calib = "boxplus.calib.cli:main"' in section.group(1)


@pytest.mark.skipif(not SAMPLE.is_dir(), reason="the shared OpenCV stereo sample is absent")
def test_stereo_sample_end_to_end(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["--target", "chessboard:9x6:1", "--camera", f"left={SAMPLE}/left*.jpg",
                 "--camera", f"right={SAMPLE}/right*.jpg", "--out", str(out), "--robust"]) == 0
    printed = capsys.readouterr()
    assert "detecting left: 13/13 (13 with the target)" in printed.err
    assert "RMS reprojection error" in printed.out and "σ·σ̂" in printed.out
    for f in ["report.txt", "calibration.yml", "left_camera_info.yaml",
              "right_camera_info.yaml", "rms_per_image.png", "residuals_left.png", "coverage_right.png",
              "uncertainty_left.png", "rig.png"]:
        assert (out / f).stat().st_size > 100, f
    # Kalibr's radtan has no k3: the report says so instead of writing a wrong file
    assert "not written: camchain.yaml: camera 'left': Kalibr's radtan" in (out / "report.txt").read_text()
    rig = read_opencv_yaml(out / "calibration.yml")
    assert [c.name for c in rig] == ["left", "right"]
    left = read_camera_info(out / "left_camera_info.yaml")
    assert np.array_equal(left.intrinsics, rig[0].intrinsics)
    # the corners of the shared npz (detected like the command line does) through the
    # library: the same outliers dropped and the same calibration
    with np.load(CORNERS) as f:
        d = {k: f[k] for k in f.files}
    cal = calibrate_stereo(list(d["image_points_left"]), list(d["image_points_right"]),
                           d["object_points"], tuple(int(s) for s in d["image_size"]), robust=5.0,
                           sigma=1.0)
    text = (out / "report.txt").read_text()
    assert f"Dropped {len(cal.dropped)} corner(s)" in text
    for c in cal.dropped:
        assert f"{c.camera} {d['names_' + c.camera][c.view]} corner {c.corner} (" in text
    assert np.allclose(rig[0].intrinsics, cal.problem[cal.ids["left"]].vec, rtol=1e-6)
    assert np.allclose(rig[1].intrinsics, cal.problem[cal.ids["right"]].vec, rtol=1e-6)
    assert np.abs(rig[1].cam_from_ref.pos - cal.problem[cal.ids["right_from_left"]].pos).max() < 1e-6


def test_refusals(tmp_path):
    with pytest.raises(SystemExit, match="no images in"):
        main(["--target", "chessboard:9x6:1", str(tmp_path)])
    with pytest.raises(SystemExit, match="target 'board:9x6'"):
        main(["--target", "board:9x6", str(tmp_path)])
    with pytest.raises(SystemExit, match="unknown camera model 'fish'"):
        main(["--target", "chessboard:9x6:1", "--model", "fish", str(tmp_path)])
    (tmp_path / "a.png").write_bytes(b"not an image")
    with pytest.raises(SystemExit, match="cannot read the image"):
        main(["--target", "chessboard:9x6:1", "--quiet", str(tmp_path)])
    with pytest.raises(SystemExit, match="expected NAME=FOLDER_OR_GLOB"):
        main(["--target", "chessboard:9x6:1", "--camera", str(tmp_path)])
