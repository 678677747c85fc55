"""Camera–IMU from the files users have (#28): an EuRoC/ASL folder of rendered images
and IMU samples, Kalibr's target.yaml and imu.yaml, boxplus-calib's intrinsics, and
boxplus-camera-imu writing Kalibr's camchain-imucam.yaml; bad files named."""

import csv
import math
import re

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
from boxplus.synthetic.camera_imu import SimulatedCamera, SimulatedImu, simulate_camera_imu  # noqa: E402
from boxplus.synthetic.images import render_view  # noqa: E402

ORIGIN_NS = 1_403_636_579_758_555_392  # an EuRoC-sized timestamp: seconds would lose µs
IMU_FROM_CAM = SE3(SO3.exp(np.array([0.1, -0.05, 1.2])), np.array([0.05, 0.02, -0.03]))
# a second camera 11 cm beside the first, triggered with it (cam1: the stereo tests)
IMU_FROM_CAM1 = IMU_FROM_CAM * SE3(SO3.exp(np.array([0.01, 0.03, -0.02])), np.array([0.11, 0.0, 0.0]))
# a second IMU (imu1) 9 cm from the first, turned
IMU0_FROM_IMU1 = SE3(SO3.exp(np.array([0.2, 1.1, -0.4])), np.array([-0.09, 0.02, 0.03]))


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    """3 s at 12 Hz of a 7x6 chessboard (6 cm), rendered by two cameras (cam0, cam1),
    and 200 Hz IMU samples."""
    root = tmp_path_factory.mktemp("rec") / "mav0"
    data, truth, K = simulate_camera_imu(np.random.default_rng(5), duration=3.0, camera_rate=12.0,
                                         time_offset=0.012, imu_from_cam=IMU_FROM_CAM,
                                         other_cameras=[SimulatedCamera(IMU_FROM_CAM1, 0.012)],
                                         other_imus=[SimulatedImu(IMU0_FROM_IMU1, (0.01, 0.0, -0.02),
                                                                  (0.1, 0.05, 0.0), phase=0.0013)])
    folder = _write_recording(root, data, truth, K)
    io.write_opencv_yaml(folder / "calibration.yml",
                         [io.CalibratedCamera("cam0", "pinhole", K, (640, 480))])
    # the stereo pair as boxplus-calib would have written it for Kalibr (names from topics)
    rel = IMU_FROM_CAM1.inverse() * IMU_FROM_CAM
    io.write_camchain(folder / "stereo-camchain.yaml",
                      [io.CalibratedCamera("left", "pinhole", K, (640, 480)),
                       io.CalibratedCamera("right", "pinhole", K, (640, 480), rel)])
    return folder, data, truth


def _write_recording(root, data, truth, K, line_delay=0.0):
    """An EuRoC folder (root = FOLDER/mav0) of the simulated recording: every camera's
    rendered images (a rolling shutter's rows each at its own time when line_delay > 0,
    the first camera only), every IMU's samples, Kalibr's imu.yaml and target.yaml."""
    target = parse_target("chessboard:7x6:0.06")
    world_from_board = SE3(SO3(), np.array([-0.18, -0.15, 0.0]))
    (root / "imu0").mkdir(parents=True)
    ns = lambda t: ORIGIN_NS + int(round(t * 1e9))  # noqa: E731
    for c, cam in enumerate(data.cameras):
        (root / cam.name / "data").mkdir(parents=True)
        with open(root / cam.name / "data.csv", "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["#timestamp [ns]", "filename"])
            for t, pose in zip(cam.frame_times, truth["world_from_cams"][c]):
                name = f"{ns(t)}.png"
                if line_delay > 0 and c == 0:
                    # row v read ℓ·v after the timestamp (IMU time = camera time + offset)
                    at = truth["world_from_imu_at"]
                    view = [(at(t + truth["time_offset"] + line_delay * v) * truth["imu_from_cam"]).inverse()
                            * world_from_board for v in range(480)]
                else:
                    view = pose.inverse() * world_from_board
                image = render_view(target, "pinhole", K, (640, 480), view, supersample=1, noise_sigma=2.0,
                                    rng=np.random.default_rng(int(t * 1e3) + 7919 * c))
                cv2.imwrite(str(root / cam.name / "data" / name), image)
                w.writerow([ns(t), name])
    imus = [("imu0", data), *((f"imu{k + 1}", imu) for k, imu in enumerate(data.other_imus))]
    for folder_name, imu in imus:
        (root / folder_name).mkdir(exist_ok=True)
        with open(root / folder_name / "data.csv", "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["#timestamp [ns]", "w_RS_S_x [rad s^-1]", "w_RS_S_y [rad s^-1]",
                        "w_RS_S_z [rad s^-1]", "a_RS_S_x [m s^-2]", "a_RS_S_y [m s^-2]",
                        "a_RS_S_z [m s^-2]"])
            for t, g, a in zip(imu.imu_times, imu.gyro, imu.accel):
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
    return folder


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


def test_the_command_line_calibrates_a_stereo_pair_and_an_imu(recording, tmp_path):
    # EuRoC's layout with cam0 and cam1, the intrinsics from a Kalibr camchain of the pair;
    # the result is read as Kalibr reads camchain-imucam.yaml: T_cam_imu per camera and
    # T_cn_cnm1 the same rig (boxplus' own camchain reader takes it as the stereo pair)
    from boxplus.calib.camera_imu_cli import main

    folder, *_ = recording
    out = tmp_path / "out"
    assert main([str(folder), "--cam", "cam0", "cam1", "--intrinsics",
                 str(folder / "stereo-camchain.yaml"), "--target", str(folder / "target.yaml"),
                 "--imu", str(folder / "imu.yaml"), "--pixel-sigma", "0.3", "--common-clock",
                 "--out", str(out), "--quiet"]) == 0
    doc = yaml.safe_load((out / "camchain-imucam.yaml").read_text())
    own = yaml.safe_load((out / "camera_imu.yaml").read_text())
    assert [c["camera"] for c in own["cameras"]] == ["left", "right"]
    for c, (key, truth) in enumerate((("cam0", IMU_FROM_CAM), ("cam1", IMU_FROM_CAM1))):
        T = np.array(doc[key]["T_cam_imu"])
        ic = SE3(SO3(T[:3, :3].T), -T[:3, :3].T @ T[:3, 3])
        err = np.r_[ic.pos - truth.pos, (truth.rot.inverse() * ic.rot).log()]
        sigma = np.array(own["std"]["imu_from_cam" + (f"[{c}]" if c else "")])
        assert np.all(np.abs(err) < 4 * sigma) and np.linalg.norm(err[:3]) < 6e-3, key
        assert abs(doc[key]["timeshift_cam_imu"] - 0.012) < 4 * own["std"]["time_offset"][0]
    assert doc["cam0"]["timeshift_cam_imu"] == doc["cam1"]["timeshift_cam_imu"]  # one clock
    T_rel = np.array(doc["cam1"]["T_cn_cnm1"])
    np.testing.assert_allclose(T_rel, np.array(doc["cam1"]["T_cam_imu"])
                               @ np.linalg.inv(np.array(doc["cam0"]["T_cam_imu"])), atol=1e-12)
    rig = io.read_cameras(out / "camchain-imucam.yaml")
    true_rel = IMU_FROM_CAM1.inverse() * IMU_FROM_CAM
    assert np.linalg.norm(rig[1].cam_from_ref.pos - true_rel.pos) < 3e-3
    assert [c.name for c in rig] == ["left", "right"]
    report = (out / "report.txt").read_text()
    assert "right_from_left (T_cn_cnm1; value ± σ)" in report and "of 'right'" in report


def test_a_global_shutter_fitted_as_rolling_has_no_line_delay(recording, tmp_path):
    # --rolling-shutter on the rendered (global-shutter) recording: the line delay is
    # estimated at 0 within its σ, reported in µs per row and kept in boxplus' file
    from boxplus.calib.camera_imu_cli import main

    folder, *_ = recording
    out = tmp_path / "out"
    assert main([str(folder), "--intrinsics", str(folder / "calibration.yml"), "--target",
                 str(folder / "target.yaml"), "--imu", str(folder / "imu.yaml"), "--pixel-sigma",
                 "0.3", "--rolling-shutter", "--out", str(out), "--quiet", "--no-plots"]) == 0
    own = yaml.safe_load((out / "camera_imu.yaml").read_text())
    ell, sigma = own["line_delays"][0], own["std"]["line_delay[0]"][0]
    assert abs(ell) < 4 * sigma and sigma < 2e-6
    assert "line delay: " in (out / "report.txt").read_text()
    assert "line_delay" not in (out / "camchain-imucam.yaml").read_text()  # Kalibr has no field


def test_the_command_line_places_a_second_imu(recording, tmp_path, capsys):
    # EuRoC's imu0 and imu1 (imu1 sampled 1.3 ms after imu0, its own first stamp: the
    # reader re-bases it on imu0's clock); Kalibr's imu result file has T_i_b, the body
    # (imu0) into imu1, which must be the truth within the σ of boxplus' own file
    from boxplus.calib.camera_imu_cli import main

    folder, *_ = recording
    out = tmp_path / "out"
    assert main([str(folder), "--imu-folder", "imu0", "imu1", "--intrinsics",
                 str(folder / "calibration.yml"), "--target", str(folder / "target.yaml"),
                 "--imu", str(folder / "imu.yaml"), "--pixel-sigma", "0.3", "--out", str(out),
                 "--quiet", "--no-plots"]) == 0
    doc = yaml.safe_load((out / "imu-imucam.yaml").read_text())
    own = yaml.safe_load((out / "camera_imu.yaml").read_text())
    np.testing.assert_allclose(doc["imu0"]["T_i_b"], np.eye(4), atol=1e-15)
    T = np.array(doc["imu1"]["T_i_b"])  # imu1_from_imu0
    est = SE3(SO3(T[:3, :3].T), -T[:3, :3].T @ T[:3, 3])
    err = np.r_[est.pos - IMU0_FROM_IMU1.pos, (IMU0_FROM_IMU1.rot.inverse() * est.rot).log()]
    assert np.all(np.abs(err) < 4 * np.array(own["std"]["imu0_from_imu[1]"]))
    assert np.linalg.norm(err[:3]) < 5e-3
    assert doc["imu1"]["update_rate"] == pytest.approx(200.0) and doc["imu0"]["time_offset"] == 0.0
    assert doc["imu0"]["model"] == doc["imu1"]["model"] == "calibrated"  # no own model estimated
    # one clock in the simulation: the estimated offset is 0 within 4σ
    assert abs(doc["imu1"]["time_offset"]) < 4 * own["std"]["imu_time_offset[1]"][0]
    # the noise the fit assumed, as densities: imu.yaml's own values (its rate is the data's)
    given = yaml.safe_load((folder / "imu.yaml").read_text())
    for key in ("gyroscope_noise_density", "accelerometer_noise_density", "gyroscope_random_walk",
                "accelerometer_random_walk"):
        assert doc["imu1"][key] == pytest.approx(given[key], rel=1e-9), key
    assert "imu0_from_imu1 (its lever arm" in (out / "report.txt").read_text()
    # one --imu file per IMU or one for all: three for two is refused
    base = [str(folder), "--imu-folder", "imu0", "imu1", "--target", str(folder / "target.yaml"),
            "--quiet", "--no-plots"]
    with pytest.raises(SystemExit) as stop:
        main([*base, "--intrinsics", str(folder / "calibration.yml"), "--out", str(tmp_path / "o2"),
              "--imu", *[str(folder / "imu.yaml")] * 3])
    assert stop.value.code == 2
    # a run again from its own result (the camchain as intrinsics, the same --out) would
    # write over its input: refused before anything runs, the input kept
    before = (out / "camchain-imucam.yaml").read_bytes()
    with pytest.raises(SystemExit) as stop:
        main([*base, "--intrinsics", str(out / "camchain-imucam.yaml"), "--out", str(out),
              "--imu", str(folder / "imu.yaml")])
    assert stop.value.code == 2
    assert "writing camchain-imucam.yaml there would overwrite an input file" in capsys.readouterr().err
    assert (out / "camchain-imucam.yaml").read_bytes() == before


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


# ---- the same recording in ROS bags (boxplus.calib.bags), written by rosbags' writers


def _bag_writer(kind: str, path):
    """(writer, typestore, serialise) for a ROS 1 bag, a ROS 2 sqlite or MCAP bag."""
    from rosbags.rosbag1 import Writer as Writer1
    from rosbags.rosbag2 import StoragePlugin
    from rosbags.rosbag2 import Writer as Writer2
    from rosbags.typesys import Stores, get_typestore

    if kind == "ros1":
        ts = get_typestore(Stores.ROS1_NOETIC)
        return Writer1(path), ts, ts.serialize_ros1
    ts = get_typestore(Stores.ROS2_HUMBLE)
    plugin = StoragePlugin.MCAP if kind == "mcap" else StoragePlugin.SQLITE3
    return Writer2(path, version=9, storage_plugin=plugin), ts, ts.serialize_cdr


def _header(ts, kind, ns, seq=0):
    Header, Time = ts.types["std_msgs/msg/Header"], ts.types["builtin_interfaces/msg/Time"]
    stamp = Time(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)
    if kind == "ros1":
        return Header(seq=seq, stamp=stamp, frame_id="cam0")
    return Header(stamp=stamp, frame_id="cam0")


def _image_message(ts, kind, ns, gray, encoding):
    if encoding == "png":
        C = ts.types["sensor_msgs/msg/CompressedImage"]
        return C(header=_header(ts, kind, ns), format="mono8; png compressed",
                 data=np.frombuffer(cv2.imencode(".png", gray)[1].tobytes(), np.uint8))
    Image = ts.types["sensor_msgs/msg/Image"]
    h, w = gray.shape
    if encoding == "rgb8":
        pixels = np.repeat(gray[:, :, None], 3, axis=2)
    elif encoding == "mono16":  # a 12-bit sensor in 16 bits, big-endian, rows padded
        pixels = (gray.astype(np.uint16) * 16).astype(">u2").view(np.uint8).reshape(h, 2 * w)
        pixels = np.hstack([pixels, np.zeros((h, 6), np.uint8)])
        return Image(header=_header(ts, kind, ns), height=h, width=w, encoding="mono16",
                     is_bigendian=1, step=2 * w + 6, data=pixels.ravel())
    else:
        pixels = gray
    step = pixels.shape[1] * (pixels.shape[2] if pixels.ndim == 3 else 1)
    return Image(header=_header(ts, kind, ns), height=h, width=w, encoding=encoding,
                 is_bigendian=0, step=step, data=np.ascontiguousarray(pixels).ravel())


def write_bag(kind, path, folder, encoding="mono8", zero_imu_stamps=False, shuffle_imu=False):
    """The EuRoC folder's images and IMU samples as a bag: one camera topic, one IMU
    topic, a second camera topic of a few frames and a /tf-like topic to ignore."""
    rec = read_euroc(folder)
    writer, ts, ser = _bag_writer(kind, path)
    Imu, V3 = ts.types["sensor_msgs/msg/Imu"], ts.types["geometry_msgs/msg/Vector3"]
    Q, Str = ts.types["geometry_msgs/msg/Quaternion"], ts.types["std_msgs/msg/String"]
    image_type = ("sensor_msgs/msg/CompressedImage" if encoding == "png"
                  else "sensor_msgs/msg/Image")
    cam_ns = rec.origin_ns + np.round(rec.frame_times * 1e9).astype(np.int64)
    imu_ns = rec.origin_ns + np.round(rec.imu_times * 1e9).astype(np.int64)
    order = np.arange(len(imu_ns))
    if shuffle_imu:  # received out of stamp order, as over a busy USB link
        order = order.reshape(-1, 2)[:, ::-1].ravel() if len(order) % 2 == 0 else order
    with writer as w:
        cam = w.add_connection("/cam0/image_raw", image_type, typestore=ts)
        other = w.add_connection("/cam1/image_raw", "sensor_msgs/msg/Image", typestore=ts)
        imu = w.add_connection("/imu0", "sensor_msgs/msg/Imu", typestore=ts)
        note = w.add_connection("/note", "std_msgs/msg/String", typestore=ts)
        zero = np.zeros(9)
        # the j-th IMU message received carries sample order[j]'s stamp
        events = [(int(imu_ns[j]) + 1000, "imu", int(order[j])) for j in range(len(order))]
        events += [(int(t) + 2000, "cam", k) for k, t in enumerate(cam_ns)]
        for k, (received, what, i) in enumerate(sorted(events, key=lambda e: e[0])):
            if what == "imu":
                stamp = 0 if zero_imu_stamps else int(imu_ns[i])
                m = Imu(header=_header(ts, kind, stamp), orientation=Q(x=0.0, y=0.0, z=0.0, w=1.0),
                        orientation_covariance=zero,
                        angular_velocity=V3(x=rec.gyro[i, 0], y=rec.gyro[i, 1], z=rec.gyro[i, 2]),
                        angular_velocity_covariance=zero,
                        linear_acceleration=V3(x=rec.accel[i, 0], y=rec.accel[i, 1], z=rec.accel[i, 2]),
                        linear_acceleration_covariance=zero)
                w.write(imu, received, ser(m, "sensor_msgs/msg/Imu"))
            else:
                gray = cv2.imread(str(rec.images[i]), cv2.IMREAD_GRAYSCALE)
                m = _image_message(ts, kind, int(cam_ns[i]), gray, encoding)
                w.write(cam, received, ser(m, image_type))
                if i < 3:
                    w.write(other, received, ser(_image_message(ts, kind, int(cam_ns[i]), gray,
                                                                "mono8"), "sensor_msgs/msg/Image"))
            if k == 0:
                w.write(note, received, ser(Str(data="hello"), "std_msgs/msg/String"))
    return rec


def write_rig_bag(path, folder):
    """The whole rig of the EuRoC folder (cam0, cam1, imu0, imu1) as a ROS 1 bag."""
    writer, ts, ser = _bag_writer("ros1", path)
    Imu, V3 = ts.types["sensor_msgs/msg/Imu"], ts.types["geometry_msgs/msg/Vector3"]
    Q = ts.types["geometry_msgs/msg/Quaternion"]
    zero = np.zeros(9)
    events = []
    for imu in ("imu0", "imu1"):
        rec = read_euroc(folder, "cam0", imu)
        stamps = rec.origin_ns + np.round(rec.imu_times * 1e9).astype(np.int64)
        events += [(int(t), imu, (rec.gyro[i], rec.accel[i])) for i, t in enumerate(stamps)]
    for cam in ("cam0", "cam1"):
        rec = read_euroc(folder, cam)
        stamps = rec.origin_ns + np.round(rec.frame_times * 1e9).astype(np.int64)
        events += [(int(t), cam, rec.images[i]) for i, t in enumerate(stamps)]
    with writer as w:
        conns = {c: w.add_connection(f"/{c}/image_raw", "sensor_msgs/msg/Image", typestore=ts)
                 for c in ("cam0", "cam1")}
        conns.update({i: w.add_connection(f"/{i}", "sensor_msgs/msg/Imu", typestore=ts)
                      for i in ("imu0", "imu1")})
        for stamp, what, payload in sorted(events, key=lambda e: e[0]):
            if what.startswith("imu"):
                g, a = payload
                m = Imu(header=_header(ts, "ros1", stamp), orientation=Q(x=0.0, y=0.0, z=0.0, w=1.0),
                        orientation_covariance=zero, angular_velocity=V3(x=g[0], y=g[1], z=g[2]),
                        angular_velocity_covariance=zero,
                        linear_acceleration=V3(x=a[0], y=a[1], z=a[2]),
                        linear_acceleration_covariance=zero)
                w.write(conns[what], stamp + 1000, ser(m, "sensor_msgs/msg/Imu"))
            else:
                gray = cv2.imread(str(payload), cv2.IMREAD_GRAYSCALE)
                w.write(conns[what], stamp + 2000,
                        ser(_image_message(ts, "ros1", stamp, gray, "mono8"), "sensor_msgs/msg/Image"))


def test_the_command_line_calibrates_a_whole_rig_from_a_bag(recording, tmp_path):
    # two camera topics and two IMU topics of one bag, as a stereo pair and two IMUs:
    # Kalibr's files name the topics, and both cameras and the second IMU are the truth
    pytest.importorskip("rosbags")
    from boxplus.calib.camera_imu_cli import main

    folder, *_ = recording
    bag = tmp_path / "rig.bag"
    write_rig_bag(bag, folder)
    out = tmp_path / "out"
    assert main([str(bag), "--image-topic", "/cam0/image_raw", "/cam1/image_raw", "--imu-topic",
                 "/imu0", "/imu1", "--intrinsics", str(folder / "stereo-camchain.yaml"), "--target",
                 str(folder / "target.yaml"), "--imu", str(folder / "imu.yaml"), "--pixel-sigma", "0.3",
                 "--common-clock", "--out", str(out), "--quiet", "--no-plots"]) == 0
    doc = yaml.safe_load((out / "camchain-imucam.yaml").read_text())
    own = yaml.safe_load((out / "camera_imu.yaml").read_text())
    assert [doc[c]["rostopic"] for c in ("cam0", "cam1")] == ["/cam0/image_raw", "/cam1/image_raw"]
    for c, (key, truth) in enumerate((("cam0", IMU_FROM_CAM), ("cam1", IMU_FROM_CAM1))):
        T = np.array(doc[key]["T_cam_imu"])
        ic = SE3(SO3(T[:3, :3].T), -T[:3, :3].T @ T[:3, 3])
        err = np.r_[ic.pos - truth.pos, (truth.rot.inverse() * ic.rot).log()]
        assert np.all(np.abs(err) < 4 * np.array(own["std"]["imu_from_cam" + (f"[{c}]" if c else "")])), key
    imus = yaml.safe_load((out / "imu-imucam.yaml").read_text())
    assert [imus[i]["rostopic"] for i in ("imu0", "imu1")] == ["/imu0", "/imu1"]
    T = np.array(imus["imu1"]["T_i_b"])
    est = SE3(SO3(T[:3, :3].T), -T[:3, :3].T @ T[:3, 3])
    err = np.r_[est.pos - IMU0_FROM_IMU1.pos, (IMU0_FROM_IMU1.rot.inverse() * est.rot).log()]
    assert np.all(np.abs(err) < 4 * np.array(own["std"]["imu0_from_imu[1]"]))


@pytest.mark.parametrize("kind,encoding", [("ros1", "mono8"), ("sqlite", "rgb8"),
                                           ("mcap", "png"), ("ros1", "mono16")])
def test_bags_read_as_the_euroc_folder(recording, tmp_path, kind, encoding):
    pytest.importorskip("rosbags")
    from boxplus.calib.bags import is_bag, read_bag

    folder, *_ = recording
    path = tmp_path / ("rec.bag" if kind == "ros1" else "rec2")
    euroc = write_bag(kind, path, folder, encoding, shuffle_imu=kind == "sqlite")
    # a ROS 2 bag is a folder; its MCAP file alone is read too
    sources = [path] + (list(path.glob("*.mcap")) if kind == "mcap" else [])
    for source in sources:
        assert is_bag(source)
        rec = read_bag(source, image_topic="/cam0/image_raw")
        assert rec.imu_topic == "/imu0" and rec.origin_ns == euroc.origin_ns
        np.testing.assert_array_equal(rec.imu_times, euroc.imu_times)  # same integer ns
        np.testing.assert_array_equal(rec.frame_times, euroc.frame_times)
        np.testing.assert_array_equal(rec.gyro, euroc.gyro)
        np.testing.assert_array_equal(rec.accel, euroc.accel)
    frames = list(rec.frames())
    assert len(frames) == len(euroc.images)
    for (name, gray), image in zip(frames[::7], euroc.images[::7]):
        expected = cv2.imread(str(image), cv2.IMREAD_GRAYSCALE)
        if encoding == "mono16":  # stretched from 12 bits to the image's own maximum
            expected = np.round(expected * (255.0 / expected.max())).astype(np.uint8)
        np.testing.assert_array_equal(gray, expected, err_msg=name)


def test_bag_topics_and_stamps_are_checked(recording, tmp_path):
    pytest.importorskip("rosbags")
    from boxplus.calib.bags import read_bag

    folder, *_ = recording
    bag = tmp_path / "rec.bag"
    euroc = write_bag("ros1", bag, folder, zero_imu_stamps=True)
    with pytest.raises(ValueError, match=r"rec.bag: 2 topics of type sensor_msgs/msg/Image .*"
                                         r"\(/cam0/image_raw, /cam1/image_raw\); name one with "
                                         r"--image-topic"):
        read_bag(bag)
    with pytest.raises(ValueError, match=r"rec.bag: no topic '/imu1' \(topics: .*/imu0 "
                                         r"\(sensor_msgs/msg/Imu\)"):
        read_bag(bag, "/cam0/image_raw", "/imu1")
    with pytest.raises(ValueError, match="topic '/note' carries std_msgs/msg/String"):
        read_bag(bag, "/note")
    # the driver left the IMU's stamps unset: the receive times, and a warning saying so
    with pytest.warns(UserWarning, match="every header.stamp of '/imu0' is zero"):
        rec = read_bag(bag, "/cam0/image_raw")
    np.testing.assert_allclose(rec.imu_times, euroc.imu_times, atol=1e-9)
    np.testing.assert_allclose(rec.frame_times, euroc.frame_times - 1e-6, atol=1e-9)  # origin: a receive time
    with pytest.raises(FileNotFoundError, match="nothing.bag: no such bag"):
        read_bag(tmp_path / "nothing.bag")


def test_the_command_line_calibrates_from_a_bag(recording, tmp_path, capsys):
    pytest.importorskip("rosbags")
    from boxplus.calib.camera_imu_cli import main

    folder, *_ = recording
    bag = tmp_path / "rec.bag"
    write_bag("ros1", bag, folder)
    args = ["--intrinsics", str(folder / "calibration.yml"), "--target",
            str(folder / "target.yaml"), "--imu", str(folder / "imu.yaml"), "--pixel-sigma", "0.3",
            "--quiet", "--no-plots"]
    with pytest.raises(SystemExit) as stop:  # two camera topics: the user must choose
        main([str(bag), *args, "--out", str(tmp_path / "x")])
    assert stop.value.code == 2
    # both topics as a rig: the bag's second camera has 3 frames, and the message names it
    two = [str(bag), *args, "--image-topic", "/cam0/image_raw", "/cam1/image_raw", "--out",
           str(tmp_path / "y")]
    with pytest.raises(SystemExit) as stop:  # one camera in the intrinsics for two topics
        main(two)
    assert stop.value.code == 2
    two[two.index(str(folder / "calibration.yml"))] = str(folder / "stereo-camchain.yaml")
    with pytest.raises(SystemExit) as stop:
        main(two)
    assert stop.value.code == 1
    assert re.search(r"[0-3] frames with the target in camera right; need at least 10",
                     capsys.readouterr().err)
    out = tmp_path / "out"
    assert main([str(bag), *args, "--image-topic", "/cam0/image_raw", "--out", str(out)]) == 0
    doc = yaml.safe_load((out / "camchain-imucam.yaml").read_text())["cam0"]
    own = yaml.safe_load((out / "camera_imu.yaml").read_text())
    T = np.array(doc["T_cam_imu"])
    imu_from_cam = SE3(SO3(T[:3, :3].T), -T[:3, :3].T @ T[:3, 3])
    err = np.r_[imu_from_cam.pos - IMU_FROM_CAM.pos,
                (IMU_FROM_CAM.rot.inverse() * imu_from_cam.rot).log()]
    assert np.all(np.abs(err) < 4 * np.array(own["std"]["imu_from_cam"]))
    assert abs(doc["timeshift_cam_imu"] - 0.012) < 4 * own["std"]["time_offset"][0]


def test_damaged_bags_and_a_missing_rosbags_are_named(recording, tmp_path, monkeypatch):
    pytest.importorskip("rosbags")
    from boxplus.calib.bags import read_bag
    from boxplus.calib.camera_imu_cli import main

    folder, *_ = recording
    bag = tmp_path / "rec.bag"
    write_bag("ros1", bag, folder)
    cut = tmp_path / "cut.bag"  # a recording stopped by a full disk
    cut.write_bytes(bag.read_bytes()[:4000])
    with pytest.raises(ValueError, match=r"cut.bag: not a bag rosbags can read"):
        read_bag(cut)
    (tmp_path / "junk.mcap").write_bytes(b"not an mcap")
    with pytest.raises(ValueError, match=r"junk.mcap: not a bag rosbags can read"):
        read_bag(tmp_path / "junk.mcap")
    monkeypatch.setitem(__import__("sys").modules, "rosbags", None)
    with pytest.raises(ImportError, match=r"pip install 'boxplus\[ros\]'"):
        read_bag(bag)
    with pytest.raises(SystemExit) as stop:
        main([str(bag), "--intrinsics", str(folder / "calibration.yml"), "--target",
              str(folder / "target.yaml"), "--imu", str(folder / "imu.yaml"), "--quiet",
              "--out", str(tmp_path / "o")])
    assert stop.value.code == 2


def test_the_recording_may_follow_an_option_of_several_values(tmp_path, capsys):
    """``--cam cam0 cam1 recording/``: argparse gives the recording to --cam; the command
    takes it back (the last word, a folder or bag on disk), and says what is missing
    when there is none."""
    from boxplus.calib.camera_imu_cli import _parse

    rec = tmp_path / "rec"
    rec.mkdir()
    base = ["--intrinsics", "c.yml", "--target", "t.yaml"]
    args = _parse([*base, "--cam", "cam0", "cam1", str(rec)])
    assert args.recording == str(rec) and args.cam == ["cam0", "cam1"]
    args = _parse([*base, "--imu", "imu.yaml", str(rec)])
    assert args.recording == str(rec) and args.imu == ["imu.yaml"]
    args = _parse([str(rec), *base, "--cam", "cam0", "cam1"])  # the usual order is untouched
    assert args.recording == str(rec) and args.cam == ["cam0", "cam1"]
    with pytest.raises(SystemExit):
        _parse([*base, "--cam", "cam0", "cam1"])  # cam1 is no folder on disk
    assert "the recording (an EuRoC folder, a bag or an MCAP file) is missing" in capsys.readouterr().err



def test_the_size_effect_flag_needs_the_intrinsics_flag(capsys):
    from boxplus.calib.camera_imu_cli import _parse

    with pytest.raises(SystemExit):
        _parse(["rec", "--intrinsics", "c.yml", "--target", "t.yaml", "--accel-size-effect"])
    assert "--accel-size-effect needs --imu-intrinsics" in capsys.readouterr().err


def test_rendered_rolling_shutter_images_give_the_line_delay(tmp_path, capsys):
    # Images rendered row by row as the rig moves (30 µs per row: the 480 rows read out
    # over 14 ms), detected by OpenCV, fitted by the command line with --rolling-shutter:
    # the line delay within 4σ and 10 % of the truth, imu_from_cam within 4σ; fitted as a
    # global shutter the same images leave a larger reprojection RMS.
    from boxplus.calib.camera_imu_cli import main

    ell = 30e-6
    data, truth, K = simulate_camera_imu(np.random.default_rng(8), duration=3.0, camera_rate=12.0,
                                         time_offset=0.012, imu_from_cam=IMU_FROM_CAM, line_delay=ell)
    folder = _write_recording(tmp_path / "rec" / "mav0", data, truth, K, line_delay=ell)
    io.write_opencv_yaml(folder / "calibration.yml", [io.CalibratedCamera("cam0", "pinhole", K, (640, 480))])
    common = [str(folder), "--intrinsics", str(folder / "calibration.yml"), "--target",
              str(folder / "target.yaml"), "--imu", str(folder / "imu.yaml"), "--pixel-sigma", "0.3",
              "--quiet", "--no-plots"]
    # (with the IMU's own model too: one IMU, so Kalibr's imu file exists for it alone)
    assert main([*common, "--rolling-shutter", "--imu-intrinsics", "--out", str(tmp_path / "rs")]) == 0
    own = yaml.safe_load((tmp_path / "rs" / "camera_imu.yaml").read_text())
    imu = yaml.safe_load((tmp_path / "rs" / "imu-imucam.yaml").read_text())["imu0"]
    assert imu["model"] == "scale-misalignment" and imu["rostopic"] == "/imu0"
    for kind, key in (("gyro", "gyroscopes"), ("accel", "accelerometers")):
        M = np.array(imu[key]["M"])  # the simulated IMU reads x + b: M = I within 4σ
        est = np.r_[np.diag(M), M[1, 0], M[2, 0], M[2, 1]]
        assert np.all(np.abs(est - [1, 1, 1, 0, 0, 0]) < 4 * np.array(own["std"][f"{kind}_intrinsics"])), kind
    est, sigma = own["line_delays"][0], own["std"]["line_delay[0]"][0]
    assert abs(est - ell) < 4 * sigma and abs(est - ell) < 0.1 * ell, (est, sigma)
    doc = yaml.safe_load((tmp_path / "rs" / "camchain-imucam.yaml").read_text())["cam0"]
    T = np.array(doc["T_cam_imu"])
    ic = SE3(SO3(T[:3, :3].T), -T[:3, :3].T @ T[:3, 3])
    err = np.r_[ic.pos - IMU_FROM_CAM.pos, (IMU_FROM_CAM.rot.inverse() * ic.rot).log()]
    assert np.all(np.abs(err) < 4 * np.array(own["std"]["imu_from_cam"])), err
    capsys.readouterr()
    assert main([*common, "--out", str(tmp_path / "gs")]) == 0
    chi2 = {name: yaml.safe_load((tmp_path / name / "camera_imu.yaml").read_text())["summary"]["final_chi2"]
            for name in ("rs", "gs")}
    assert chi2["gs"] > 5 * chi2["rs"], chi2
    out = capsys.readouterr()
    assert "a rolling-shutter camera fitted as a global shutter" in out.out + out.err
