"""Camera–IMU from the files users have (#28): an EuRoC/ASL folder of rendered images
and IMU samples, Kalibr's target.yaml and imu.yaml, boxplus-calib's intrinsics, and
boxplus-camera-imu writing Kalibr's camchain-imucam.yaml; bad files named."""

import csv
import math

import numpy as np
import pytest
from boxplus import SE3, SO3

cv2 = pytest.importorskip("cv2")
yaml = pytest.importorskip("yaml")

from boxplus.calib import io  # noqa: E402
from boxplus.calib.recordings import (  # noqa: E402
    read_euroc,
    read_kalibr_imu,
    read_kalibr_target,
)
from boxplus.calib.targets import parse_target  # noqa: E402
from boxplus.synthetic.camera_imu import simulate_camera_imu  # noqa: E402
from boxplus.synthetic.images import render_view  # noqa: E402

ORIGIN_NS = 1_403_636_579_758_555_392  # an EuRoC-sized timestamp: seconds would lose µs
IMU_FROM_CAM = SE3(SO3.exp(np.array([0.1, -0.05, 1.2])), np.array([0.05, 0.02, -0.03]))


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    """3 s at 12 Hz of a 7x6 chessboard (6 cm), rendered, and 200 Hz IMU samples."""
    root = tmp_path_factory.mktemp("rec") / "mav0"
    data, truth, K = simulate_camera_imu(np.random.default_rng(5), duration=3.0, camera_rate=12.0,
                                         time_offset=0.012, imu_from_cam=IMU_FROM_CAM)
    target = parse_target("chessboard:7x6:0.06")
    world_from_board = SE3(SO3(), np.array([-0.18, -0.15, 0.0]))
    (root / "cam0" / "data").mkdir(parents=True)
    (root / "imu0").mkdir()
    ns = lambda t: ORIGIN_NS + int(round(t * 1e9))  # noqa: E731
    with open(root / "cam0" / "data.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["#timestamp [ns]", "filename"])
        for t, pose in zip(data.frame_times, truth["world_from_cam"]):
            name = f"{ns(t)}.png"
            image = render_view(target, "pinhole", K, (640, 480), pose.inverse() * world_from_board,
                                supersample=1, noise_sigma=2.0, rng=np.random.default_rng(int(t * 1e3)))
            cv2.imwrite(str(root / "cam0" / "data" / name), image)
            w.writerow([ns(t), name])
    with open(root / "imu0" / "data.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["#timestamp [ns]", "w_RS_S_x [rad s^-1]", "w_RS_S_y [rad s^-1]",
                    "w_RS_S_z [rad s^-1]", "a_RS_S_x [m s^-2]", "a_RS_S_y [m s^-2]",
                    "a_RS_S_z [m s^-2]"])
        for t, g, a in zip(data.imu_times, data.gyro, data.accel):
            w.writerow([ns(t), *(f"{v:.17g}" for v in g), *(f"{v:.17g}" for v in a)])
    folder = root.parent
    (folder / "imu.yaml").write_text(
        f"accelerometer_noise_density: {0.05 / math.sqrt(200):.17g}\n"
        "accelerometer_random_walk: 0.0002\n"
        f"gyroscope_noise_density: {0.005 / math.sqrt(200):.17g}\n"
        "gyroscope_random_walk: 4.0e-06\nrostopic: /imu0\nupdate_rate: 200.0\n")
    (folder / "target.yaml").write_text(
        "target_type: 'checkerboard'\ntargetCols: 7\ntargetRows: 6\nrowSpacingMeters: 0.06\n"
        "colSpacingMeters: 0.06\n")
    io.write_opencv_yaml(folder / "calibration.yml",
                         [io.CalibratedCamera("cam0", "pinhole", K, (640, 480))])
    return folder, data, truth


def test_euroc_reader_keeps_nanoseconds(recording):
    folder, data, _ = recording
    rec = read_euroc(folder)  # FOLDER/mav0/... found
    assert rec.origin_ns == ORIGIN_NS + int(round(data.imu_times[0] * 1e9))
    np.testing.assert_allclose(rec.imu_times, data.imu_times - data.imu_times[0], atol=1e-9)
    np.testing.assert_allclose(rec.frame_times, data.frame_times - data.imu_times[0], atol=1e-9)
    np.testing.assert_allclose(rec.gyro, data.gyro, atol=1e-15)
    assert len(rec.images) == len(data.frame_times) and rec.images[0].is_file()


def test_kalibr_yaml_files_mean_what_kalibr_means(recording, tmp_path):
    folder, *_ = recording
    imu = read_kalibr_imu(folder / "imu.yaml")
    assert imu.gyro_sigma == pytest.approx(0.005) and imu.accel_sigma == pytest.approx(0.05)
    t = read_kalibr_target(folder / "target.yaml")
    assert (t.kind, t.cols, t.rows, t.square) == ("chessboard", 7, 6, 0.06)
    grid = tmp_path / "april.yaml"
    grid.write_text("target_type: 'aprilgrid'\ntagCols: 6\ntagRows: 6\ntagSize: 0.088\n"
                    "tagSpacing: 0.3\n")
    a = read_kalibr_target(grid)
    assert (a.kind, a.cols, a.rows, a.square, a.marker) == ("aprilgrid", 6, 6, 0.088, 0.3)
    bad = tmp_path / "bad.yaml"
    bad.write_text("target_type: 'checkerboard'\ntargetCols: 7\ntargetRows: 6\n"
                   "rowSpacingMeters: 0.06\ncolSpacingMeters: 0.05\n")
    with pytest.raises(ValueError, match="bad.yaml: rowSpacingMeters 0.06 and colSpacingMeters 0.05"):
        read_kalibr_target(bad)
    bad.write_text("gyroscope_noise_density: 1e-4\n")
    with pytest.raises(ValueError, match="bad.yaml: missing key 'gyroscope_random_walk'"):
        read_kalibr_imu(bad)


def test_bad_recordings_are_named_with_file_and_line(tmp_path):
    (tmp_path / "imu0").mkdir()
    (tmp_path / "cam0" / "data").mkdir(parents=True)
    (tmp_path / "imu0" / "data.csv").write_text("#t,wx,wy,wz,ax,ay,az\n10,0,0,0,0,0,9.8\n"
                                                 "5,0,0,0,0,0,9.8\n")
    with pytest.raises(ValueError, match=r"imu0/data.csv:3: timestamp 5 does not increase"):
        read_euroc(tmp_path)
    (tmp_path / "imu0" / "data.csv").write_text("#t\n10,0,0,0,0,0,9.8\n20,0,0,0,0,0\n")
    with pytest.raises(ValueError, match=r"imu0/data.csv:3: expected 7 comma-separated values"):
        read_euroc(tmp_path)
    (tmp_path / "imu0" / "data.csv").write_text("10,0,0,0,0,0,9.8\n20,0,0,0,0,0,9.8\n")
    (tmp_path / "cam0" / "data.csv").write_text("#t,f\n15,missing.png\n")
    with pytest.raises(FileNotFoundError, match=r"cam0/data.csv:2: image .*missing.png does not exist"):
        read_euroc(tmp_path)


def test_the_command_line_calibrates_the_rendered_recording(recording, tmp_path):
    from boxplus.calib.camera_imu_cli import main

    folder, data, truth = recording
    out = tmp_path / "out"
    assert main([str(folder), "--intrinsics", str(folder / "calibration.yml"), "--target",
                 str(folder / "target.yaml"), "--imu", str(folder / "imu.yaml"),
                 "--pixel-sigma", "0.3", "--out", str(out), "--quiet"]) == 0
    # Kalibr's file, read as Kalibr reads it: T_cam_imu maps IMU points into the camera,
    # t_imu = t_cam + timeshift_cam_imu
    doc = yaml.safe_load((out / "camchain-imucam.yaml").read_text())["cam0"]
    T = np.array(doc["T_cam_imu"])
    imu_from_cam = SE3(SO3(T[:3, :3].T), -T[:3, :3].T @ T[:3, 3])
    own = yaml.safe_load((out / "camera_imu.yaml").read_text())
    sigma = np.array(own["std"]["imu_from_cam"])  # tangent [translation, rotation]
    err = np.r_[imu_from_cam.pos - IMU_FROM_CAM.pos,
                (IMU_FROM_CAM.rot.inverse() * imu_from_cam.rot).log()]
    assert np.all(np.abs(err) < 4 * sigma) and np.linalg.norm(err[:3]) < 6e-3
    assert np.degrees(np.linalg.norm(err[3:])) < 0.2
    assert abs(doc["timeshift_cam_imu"] - 0.012) < 4 * own["std"]["time_offset"][0]
    assert doc["camera_model"] == "pinhole" and doc["distortion_model"] == "none"
    assert own["time_offset"] == doc["timeshift_cam_imu"]
    # imu.yaml's random walks make the biases drift: 0.1 s segments over the ~3 s
    assert len(own["gyro_biases"]) >= 25
    assert "time offset: t_imu = t_cam +" in (out / "report.txt").read_text()
    assert (out / "camera_imu.png").read_bytes()[:4] == b"\x89PNG"


def test_the_command_line_refuses_bad_input_by_name(recording, tmp_path, capsys):
    from boxplus.calib.camera_imu_cli import main

    folder, *_ = recording
    base = [str(folder), "--intrinsics", str(folder / "calibration.yml"), "--target",
            str(folder / "target.yaml"), "--out", str(tmp_path / "o"), "--quiet"]
    with pytest.raises(SystemExit) as e:
        main(base)
    assert e.value.code == 2
    assert "give the IMU's noise" in capsys.readouterr().err
    with pytest.raises(SystemExit) as e:
        main(base + ["--imu", str(folder / "nope.yaml")])
    assert e.value.code == 2 and "--imu:" in capsys.readouterr().err
    with pytest.raises(SystemExit) as e:
        main([*base[:-3], "--out", str(folder / "mav0" / "out"), "--gyro-sigma", "0.005",
              "--accel-sigma", "0.05", "--quiet"])
    assert e.value.code == 2 and "inside the recording" in capsys.readouterr().err
