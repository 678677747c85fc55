"""The calibration job end to end on images rendered through known lenses
(boxplus.synthetic.images): boxplus-calib in every documented form recovers the
truth within its σ, and the files it writes mean what their readers — OpenCV's
FileStorage and rectification, a ROS stereo pipeline, Kalibr — think they mean."""


import re

import numpy as np
import pytest
from boxplus import SE3, SO3
from boxplus.calib import io
from boxplus.calib.cli import main
from boxplus.calib.models import project
from boxplus.calib.rectify import rectify_stereo
from boxplus.calib.targets import parse_target
from boxplus.synthetic.images import RigCamera, board_views, write_rig_views, write_views

cv2 = pytest.importorskip("cv2")
yaml = pytest.importorskip("yaml")
pytest.importorskip("matplotlib")

TARGET = "chessboard:9x6:0.025"
PINHOLE = np.array([510.0, 505.0, 322.0, 238.0, -0.12, 0.04, 0.0005, -0.0003, 0.0])
FISHEYE = np.array([300.0, 301.0, 319.0, 241.0, 0.03, -0.012, 0.004, -0.0008])
RIGHT_FROM_LEFT = SE3(SO3.exp([0.01, -0.02, 0.005]), [-0.12, 0.002, 0.001])


def _sigma_check(values, truth, std, what, k=3.0):
    bad = np.abs(np.asarray(values) - truth) > k * np.asarray(std)
    assert not bad.any(), f"{what}: {np.asarray(values)[bad]} vs truth {np.asarray(truth)[bad]} " \
                          f"(σ {np.asarray(std)[bad]})"


def test_mono_pinhole_from_a_folder_recovers_the_truth(tmp_path, capsys):
    t = parse_target(TARGET)
    poses = board_views(t, "opencv5", PINHOLE, (640, 480), 10, np.random.default_rng(1))
    write_views(tmp_path / "cam", t, "opencv5", PINHOLE, (640, 480), poses, noise_sigma=1.0)
    out = tmp_path / "out"
    assert main(["--target", TARGET, "--quiet", "--no-plots", "--sigma", "0.1", "--out", str(out),
                 "--suggest", "2", "--profile", str(tmp_path / "cam")]) == 0
    text = capsys.readouterr().out
    assert "Capture next (--suggest 2):" in text and "  2. cam: board centre at" in text
    # --profile: a 3σ interval for each of the 9 intrinsics; this pinhole's problem is
    # nearly linear, so each side is close to 3 linear σ
    rows = [line for line in text.splitlines() if "(profile, 3σ; linear σ" in line]
    assert len(rows) == 9 and rows[0].startswith("  cam.fx = ")
    for row in rows:
        lo, hi, sigma = (float(v) for v in re.search(r" −(\S+) \+(\S+) .*linear σ (\S+)\)", row).groups())
        assert 2.4 * sigma < lo < 3.6 * sigma and 2.4 * sigma < hi < 3.6 * sigma, row
    rows = (out / "suggested_views.csv").read_text().splitlines()
    assert rows[0].startswith("camera,rank,center_u_px") and len(rows) == 3
    (cam,) = io.read_opencv_yaml(out / "calibration.yml")
    assert cam.name == "cam" and cam.model == "opencv5"
    rms = float(text.split("RMS reprojection error ")[1].split()[0])
    assert rms < 0.2  # rendering + detection noise of the chessboard's corners
    # the projection of the calibrated model equals the true one over the image
    uv = np.stack(np.meshgrid(np.linspace(20, 620, 13), np.linspace(20, 460, 10)), -1).reshape(-1, 2)
    from boxplus.calib.models import rays

    p = rays(PINHOLE, uv, "opencv5")
    assert np.abs(project(cam.intrinsics, p, "opencv5") - uv).max() < 0.5
    poses_csv = (out / "board_poses.csv").read_text().splitlines()
    assert len(poses_csv) == 11 and poses_csv[0].startswith("view,name,x,y,z,qx")


def test_stereo_pair_from_positional_globs_writes_files_a_stereo_pipeline_reads(tmp_path, capsys):
    """`boxplus-calib left*.png right*.png` (the form --help offers) with both cameras'
    images in one folder; the ROS camera_info pair carries the rectification (Tx = −f′B)."""
    t = parse_target(TARGET)
    cams = {"left": RigCamera("opencv5", PINHOLE, (640, 480), SE3()),
            "right": RigCamera("opencv5", PINHOLE * [1.01, 1.01, 0.99, 1.0, 1, 1, 1, 1, 1], (640, 480),
                               RIGHT_FROM_LEFT)}
    rng = np.random.default_rng(2)
    write_rig_views(tmp_path / "render", t, cams, 12, rng)
    shared = tmp_path / "images"
    shared.mkdir()
    for c in cams:  # both cameras' images in one folder: left03.png, right03.png, ...
        for f in (tmp_path / "render" / c).iterdir():
            f.rename(shared / f"{c}{f.name[4:]}")
    out = tmp_path / "out"
    assert main(["--target", TARGET, "--quiet", "--no-plots", "--out", str(out),
                 f"{shared}/left*.png", f"{shared}/right*.png"]) == 0
    text = capsys.readouterr().out
    assert "Stereo baseline" in text
    left = yaml.safe_load((out / "left_camera_info.yaml").read_text())
    right = yaml.safe_load((out / "right_camera_info.yaml").read_text())
    P2 = np.array(right["projection_matrix"]["data"]).reshape(3, 4)
    assert P2[0, 3] < 0
    assert abs(-P2[0, 3] / P2[0, 0] - 0.12) < 0.002  # the baseline, in metres
    _check_ros_stereo(left, right, cams, tol_px=0.5)  # a calibrated pair: its own errors


def _check_ros_stereo(left: dict, right: dict, cams: dict, tol_px: float = 1e-3) -> None:
    """What stereo_image_proc does with two camera_info messages: rectify each camera's
    pixels with (K, D, R, P), match along rows, depth Z = −Tx / d."""
    def msg(m):
        return (np.array(m["camera_matrix"]["data"]).reshape(3, 3),
                np.array(m["distortion_coefficients"]["data"]),
                np.array(m["rectification_matrix"]["data"]).reshape(3, 3),
                np.array(m["projection_matrix"]["data"]).reshape(3, 4), m["distortion_model"])

    rng = np.random.default_rng(7)
    X = np.column_stack([rng.uniform(-0.3, 0.3, 30), rng.uniform(-0.2, 0.2, 30),
                         rng.uniform(0.8, 3.0, 30)])  # points in the left camera
    rect = []
    for name, m in (("left", left), ("right", right)):
        K, D, R, P, dm = msg(m)
        cam = cams[name]
        uv = project(cam.k, cam.cam_from_ref.fromlocal(X), cam.model)  # true raw pixels
        if dm == "equidistant":
            r = cv2.fisheye.undistortPoints(uv.reshape(-1, 1, 2), K, D, R=R, P=P)
        else:
            r = cv2.undistortPoints(uv.reshape(-1, 1, 2), K, D, R=R, P=P)
        rect.append(r.reshape(-1, 2))
    assert np.abs(rect[0][:, 1] - rect[1][:, 1]).max() < tol_px  # rows are epipolar lines
    P1, P2, R1 = msg(left)[3], msg(right)[3], msg(left)[2]
    # the disparity of each point's true depth in the rectified left frame, Z = −Tx / d
    d_true = -P2[0, 3] / (X @ R1.T)[:, 2]
    assert np.abs((rect[0][:, 0] - rect[1][:, 0]) - d_true).max() < tol_px
    assert P1[0, 0] == P2[0, 0]


@pytest.mark.parametrize("model,k", [("opencv5", PINHOLE), ("kannala_brandt", FISHEYE)])
def test_opencv_files_rectify_as_opencv_reads_them(tmp_path, model, k):
    """The OpenCV YAML of a stereo pair read by cv2.FileStorage: M1 D1 M2 D2 R T R1 R2
    P1 P2 Q give rectified rows that agree and the right depth; the ROS pair too."""
    left = io.CalibratedCamera("left", model, k, (640, 480))
    right = io.CalibratedCamera("right", model, k * 1.002, (640, 480), RIGHT_FROM_LEFT)
    rect = rectify_stereo(left, right)
    io.write_opencv_yaml(tmp_path / "c.yml", [left, right], rect)
    fs = cv2.FileStorage(str(tmp_path / "c.yml"), cv2.FILE_STORAGE_READ)
    names = ["M1", "D1", "M2", "D2", "R", "T", "R1", "R2", "P1", "P2", "Q"]
    M = {n: fs.getNode(n).mat() for n in names}
    fs.release()
    assert np.allclose(M["T"].ravel(), RIGHT_FROM_LEFT.pos)
    # a disparity through Q gives the point back (cv2.perspectiveTransform of [u, v, d])
    X = np.array([[0.1, -0.05, 1.5], [-0.2, 0.1, 2.5]])
    uvl = project(left.intrinsics, X, model)
    uvr = project(right.intrinsics, RIGHT_FROM_LEFT.fromlocal(X), model)
    und = cv2.fisheye.undistortPoints if model == "kannala_brandt" else cv2.undistortPoints
    rl = und(uvl.reshape(-1, 1, 2), M["M1"], M["D1"], R=M["R1"], P=M["P1"]).reshape(-1, 2)
    rr = und(uvr.reshape(-1, 1, 2), M["M2"], M["D2"], R=M["R2"], P=M["P2"]).reshape(-1, 2)
    assert np.abs(rl[:, 1] - rr[:, 1]).max() < 1e-3
    pts = np.column_stack([rl, rl[:, 0] - rr[:, 0]]).reshape(-1, 1, 3)
    back = cv2.perspectiveTransform(pts, M["Q"]).reshape(-1, 3)
    assert np.allclose(back, X @ M["R1"].T, atol=1e-3)
    io.write_stereo_camera_info(tmp_path / "l.yaml", tmp_path / "r.yaml", left, right, rect)
    _check_ros_stereo(yaml.safe_load((tmp_path / "l.yaml").read_text()),
                      yaml.safe_load((tmp_path / "r.yaml").read_text()),
                      {"left": RigCamera(model, left.intrinsics, (640, 480), SE3()),
                       "right": RigCamera(model, right.intrinsics, (640, 480), RIGHT_FROM_LEFT)})


def test_three_cameras_with_a_fisheye_known_intrinsics_and_partial_overlap(tmp_path, capsys):
    """A fisheye between two pinholes, each with its own model on the command line, the
    fisheye's intrinsics known from its own earlier calibration (OpenCV's
    calibrateMultiview with fixed intrinsics); the rig's poses within σ of the truth."""
    t = parse_target(TARGET)
    radial2 = PINHOLE[:6]  # Kalibr's radtan without tangential terms: a camchain can hold it
    cams = {"cam0": RigCamera("radial2", radial2, (640, 480), SE3()),
            "fish": RigCamera("kannala_brandt", FISHEYE, (640, 480),
                              SE3(SO3.exp([0.0, 0.25, 0.0]), [-0.15, 0.0, 0.02])),
            "cam2": RigCamera("radial2", radial2 * [0.98, 0.98, 1, 1, 1, 1], (640, 480),
                              SE3(SO3.exp([0.0, 0.5, 0.0]), [-0.3, 0.0, 0.08]))}
    rng = np.random.default_rng(3)
    truth = write_rig_views(tmp_path / "img", t, cams, 30, rng)
    assert len(truth) == 30
    counts = {c: len(list((tmp_path / "img" / c).glob("*.png"))) for c in cams}
    assert 6 <= min(counts.values()) < 30, counts  # partial overlap
    # the fisheye alone first: its file gives the rig its intrinsics
    # (a board far out in the fisheye's field is detected with a bias of 0.5-2 px by
    # OpenCV's chessboard detector: --robust drops those corners)
    assert main(["--target", TARGET, "--quiet", "--no-plots", "--model", "kannala_brandt", "--robust",
                 "--out", str(tmp_path / "fish_alone"), str(tmp_path / "img" / "fish")]) == 0
    capsys.readouterr()
    out = tmp_path / "rig"
    assert main(["--target", TARGET, "--quiet", "--no-plots", "--sigma", "0.1", "--robust",
                 "--model", "radial2", "--model", "fish=kannala_brandt",
                 "--known-intrinsics", f"fish={tmp_path / 'fish_alone' / 'calibration.yml'}",
                 "--out", str(out), *(str(tmp_path / "img" / c) for c in cams)]) == 0
    text = capsys.readouterr().out
    assert "fish (held fixed: known intrinsics)" in text
    rig = {c.name: c for c in io.read_camchain(out / "camchain.yaml")}
    assert set(rig) == set(cams)
    for c in ("fish", "cam2"):
        err = (rig[c].cam_from_ref * cams[c].cam_from_ref.inverse()) - SE3()
        assert np.linalg.norm(err[:3]) < 0.003, (c, err)  # 3 mm
        assert np.degrees(np.linalg.norm(err[3:])) < 0.25, (c, err)  # the fisheye's own cx error
    chain = yaml.safe_load((out / "camchain.yaml").read_text())
    assert chain["cam1"]["rostopic"] == "/fish/image_raw" and "cam_overlaps" in chain["cam0"]


def test_a_rolling_shutter_render_reads_each_row_at_its_own_pose():
    # One pose per row: the same pose on every row is the global-shutter image; rows that
    # move sideways shift the board by the rows' own shift (a rolling shutter's skew).
    from boxplus.synthetic.images import render_view

    t = parse_target(TARGET)
    K = np.array([127.5, 126.25, 80.5, 59.5])  # a 160 × 120 pinhole
    pose = SE3(SO3(), [-0.12, -0.09, 0.3])
    still = render_view(t, "pinhole", K, (160, 120), pose, supersample=1)
    np.testing.assert_array_equal(render_view(t, "pinhole", K, (160, 120), [pose] * 120, supersample=1),
                                  still)
    # the board 0.2 mm further left per row: at 0.3 m, 0.085 px per row
    rows = [SE3(SO3(), [-0.12 - 2e-4 * v, -0.09, 0.3]) for v in range(120)]
    moving = render_view(t, "pinhole", K, (160, 120), rows, supersample=2)
    still2 = render_view(t, "pinhole", K, (160, 120), pose, supersample=2)

    def first_dark(img, v):  # sub-pixel column where a row first turns dark
        x = img[v].astype(float)
        j = int(np.argmax(x < 128))
        return j - 1 + (x[j - 1] - 128) / (x[j - 1] - x[j])

    shift = {v: first_dark(moving, v) - first_dark(still2, v) for v in (40, 80)}
    for v, s in shift.items():
        assert s == pytest.approx(-127.5 * 2e-4 * v / 0.3, abs=0.5), shift
    with pytest.raises(ValueError, match="119 row poses for an image of 120 rows"):
        render_view(t, "pinhole", K, (160, 120), rows[:-1])


def test_board_views_skip_pixels_outside_a_wide_lens_field():
    # a double sphere whose image corners lie beyond its field (no ray there): the board
    # centres drawn there are skipped instead of making a pose at NaN
    import warnings

    k = np.array([160.0, 160.0, 320.0, 240.0, -0.2, 0.6])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        poses = board_views(parse_target(TARGET), "double_sphere", k, (640, 480), 8,
                            np.random.default_rng(5), max_tilt_deg=45.0, fill=0.95)
    assert len(poses) == 8 and all(np.isfinite(q.t).all() for q in poses)
