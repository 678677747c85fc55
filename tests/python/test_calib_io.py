"""Calibration files: OpenCV FileStorage YAML (read back by cv2.FileStorage),
ROS camera_info and Kalibr camchain round trips, refusals of what a format
cannot express, and the OpenCV layout for stereoRectify."""

from pathlib import Path

import numpy as np
import pytest
from boxplus import SE3, SO3
from boxplus.calib import (
    CalibratedCamera,
    calibrate_stereo,
    read_camchain,
    read_camera_info,
    read_opencv_yaml,
    to_opencv,
    write_camchain,
    write_camera_info,
    write_opencv_yaml,
)
from boxplus.calib.io import read_cameras

cv2 = pytest.importorskip("cv2")
pytest.importorskip("yaml")

DATA = Path(__file__).resolve().parents[2] / "data" / "calib" / "opencv_stereo_corners.npz"
POSE = SE3(SO3.exp(np.array([0.01, -0.02, 0.003])), np.array([-0.1, 0.002, 0.001]))
POSE2 = SE3(SO3.exp(np.array([0.0, 0.3, 0.01])), np.array([-0.2, 0.0, 0.05]))


def _rig(model):
    ks = {
        "opencv5": [520.1, 515.3, 322.2, 245.4, -0.28, 0.08, 0.001, -0.0005, 0.01],
        "radial2": [520.1, 515.3, 322.2, 245.4, -0.28, 0.08],
        "rational": [520.1, 515.3, 322.2, 245.4, -0.2, 0.05, 0.001, -0.0005, 0.01, 0.1, -0.02, 0.005],
        "kannala_brandt": [300.5, 302.25, 321.0, 242.0, 0.02, -0.01, 0.004, -0.001],
        "double_sphere": [250.0, 252.0, 320.0, 240.0, -0.15, 0.58],
        "pinhole": [520.1, 515.3, 322.2, 245.4],
    }
    k = np.array(ks[model]) + np.pi * 1e-7  # digits that need every bit
    return [CalibratedCamera("left", model, k, (640, 480)), CalibratedCamera("right", model, k * 1.001, (640, 480), POSE),
            CalibratedCamera("third", model, k * 0.999, (640, 480), POSE2)]


def _same(a, b, model=None):
    assert len(a) == len(b)
    for x, y in zip(a, b):
        assert x.name == y.name and x.image_size == y.image_size
        assert (model or x.model) == y.model
        assert np.array_equal(x.intrinsics, y.intrinsics)
        assert np.abs(x.cam_from_ref.matrix() - y.cam_from_ref.matrix()).max() < 1e-12


@pytest.mark.parametrize("model", ["opencv5", "rational", "kannala_brandt", "radial2"])
def test_opencv_yaml_round_trip_and_cv2_reads_it(model, tmp_path):
    rig = _rig(model)
    write_opencv_yaml(tmp_path / "c.yml", rig)
    _same(rig, read_opencv_yaml(tmp_path / "c.yml"))
    fs = cv2.FileStorage(str(tmp_path / "c.yml"), cv2.FILE_STORAGE_READ)
    assert fs.isOpened()
    assert np.array_equal(fs.getNode("left_camera_matrix").mat(), rig[0].K)
    assert np.array_equal(fs.getNode("right_distortion_coefficients").mat().ravel(), rig[1].dist)
    assert np.array_equal(fs.getNode("right_R").mat(), POSE.rot.R)
    assert np.array_equal(fs.getNode("right_T").mat().ravel(), POSE.pos)
    assert fs.getNode("third_model").string() == model
    assert int(fs.getNode("left_image_width").real()) == 640
    names = fs.getNode("camera_names")
    assert [names.at(i).string() for i in range(names.size())] == ["left", "right", "third"]


def test_opencv_yaml_refuses_a_double_sphere_camera(tmp_path):
    # its [ξ, α] in distortion_coefficients would read as OpenCV's k1, k2
    with pytest.raises(ValueError, match="camera 'left': OpenCV has no double-sphere model"):
        write_opencv_yaml(tmp_path / "c.yml", _rig("double_sphere"))
    assert not (tmp_path / "c.yml").exists()


@pytest.mark.parametrize("model", ["opencv5", "rational", "kannala_brandt"])
def test_ros_camera_info_round_trip(model, tmp_path):
    cam = _rig(model)[0]
    write_camera_info(tmp_path / "left.yaml", cam)
    back = read_camera_info(tmp_path / "left.yaml")
    _same([cam], [back])
    text = (tmp_path / "left.yaml").read_text()
    assert {"opencv5": "plumb_bob", "rational": "rational_polynomial",
            "kannala_brandt": "equidistant"}[model] in text


@pytest.mark.parametrize("model", ["pinhole", "kannala_brandt", "double_sphere"])
def test_kalibr_camchain_round_trip(model, tmp_path):
    rig = _rig(model)
    write_camchain(tmp_path / "camchain.yaml", rig)
    _same(rig, read_camchain(tmp_path / "camchain.yaml"))
    # read_cameras tries OpenCV's FileStorage first: a camchain is not its file (this
    # raised a SystemError out of cv2 before), so the camchain reader answers
    _same(rig, read_cameras(tmp_path / "camchain.yaml"))


def test_kalibr_radtan_round_trip_and_refusals(tmp_path):
    rig = _rig("opencv5")
    with pytest.raises(ValueError, match="camera 'left': Kalibr's radtan has k1 k2 p1 p2 only"):
        write_camchain(tmp_path / "x.yaml", rig)
    rig = [CalibratedCamera(c.name, c.model, np.r_[c.intrinsics[:8], 0.0], c.image_size, c.cam_from_ref)
           for c in rig]
    write_camchain(tmp_path / "c.yaml", rig)
    _same(rig, read_camchain(tmp_path / "c.yaml"))
    with pytest.raises(ValueError, match="no double-sphere model"):
        write_camera_info(tmp_path / "x.yaml", _rig("double_sphere")[0])
    with pytest.raises(ValueError, match="Kalibr has no rational model"):
        write_camchain(tmp_path / "x.yaml", _rig("rational"))


def test_bad_files_raise_naming_the_file(tmp_path):
    p = tmp_path / "bad.yml"
    p.write_text("%YAML:1.0\n---\ncamera_names: [ \"a\" ]\na_model: \"opencv5\"\n")
    with pytest.raises(ValueError, match=r"bad.yml: missing 'a_camera_matrix'"):
        read_opencv_yaml(p)
    p.write_text("image_width: 640\nimage_height: 480\ndistortion_model: fisheye62\n")
    with pytest.raises(ValueError, match="bad.yml: distortion_model 'fisheye62'"):
        read_camera_info(p)
    p.write_text("cam0:\n  camera_model: eucm\n  intrinsics: [1, 2, 3, 4, 5, 6]\n  resolution: [1, 1]\n")
    with pytest.raises(ValueError, match="cam0: unsupported camera_model 'eucm'"):
        read_camchain(p)
    p.write_text(": [\n")
    with pytest.raises(ValueError, match="not valid YAML"):
        read_camchain(p)
    with pytest.raises(ValueError, match="cannot be a YAML key prefix"):
        write_opencv_yaml(tmp_path / "x.yml", [CalibratedCamera("my cam", "pinhole", np.ones(4), (1, 1))])


def test_to_opencv_feeds_stereo_rectify_and_matches_opencv(tmp_path):
    with np.load(DATA) as f:
        d = {k: f[k] for k in f.files}
    obj, L, R = d["object_points"], list(d["image_points_left"]), list(d["image_points_right"])
    size = tuple(int(s) for s in d["image_size"])
    cal = calibrate_stereo(L, R, obj, size)
    cv = cal.to_opencv()
    assert set(cv) == {"left", "right", "K1", "D1", "K2", "D2", "R", "T", "image_size"}
    assert np.array_equal(cv["right"]["R"], to_opencv(cal.cameras())["R"])
    assert np.array_equal(cv["K1"], cal.camera("left")[0])
    R1, R2, P1, P2, Q, _, _ = cv2.stereoRectify(cv["K1"], cv["D1"], cv["K2"], cv["D2"], cv["image_size"],
                                                cv["R"], cv["T"])
    # rectified: a left-right pair of corners lands on one image row
    ul = cv2.undistortPoints(L[0].reshape(-1, 1, 2), cv["K1"], cv["D1"], R=R1, P=P1).reshape(-1, 2)
    ur = cv2.undistortPoints(R[0].reshape(-1, 1, 2), cv["K2"], cv["D2"], R=R2, P=P2).reshape(-1, 2)
    assert np.abs(ul[:, 1] - ur[:, 1]).max() < 0.5
    # R, T equal cv2.stereoCalibrate's with the same intrinsics fixed
    o32 = [obj.astype(np.float32)] * len(L)
    _, _, _, _, _, Rcv, Tcv, _, _ = cv2.stereoCalibrate(
        o32, [p.astype(np.float32) for p in L], [p.astype(np.float32) for p in R], cv["K1"], cv["D1"],
        cv["K2"], cv["D2"], size, flags=cv2.CALIB_FIX_INTRINSIC,
        criteria=(cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 200, 1e-12))
    assert np.abs(Tcv.ravel() - cv["T"].ravel()).max() < 1e-3 * np.linalg.norm(Tcv)
    assert np.abs(Rcv - cv["R"]).max() < 1e-4
    write_opencv_yaml(tmp_path / "stereo.yml", cal.cameras())
    back = read_opencv_yaml(tmp_path / "stereo.yml")
    assert np.abs(back[1].cam_from_ref.matrix() - cal.cameras()[1].cam_from_ref.matrix()).max() < 1e-12
