"""``boxplus-camera-imu``: calibrate a camera and an IMU from a recording in motion.

The recording is a folder in the EuRoC/ASL layout (``cam0/data.csv`` + images,
``imu0/data.csv``; :mod:`boxplus.calib.recordings`) or a bag — ROS 1 ``*.bag``, a
ROS 2 bag folder or an ``*.mcap`` file, read without ROS (:mod:`boxplus.calib.bags`,
``pip install 'boxplus[ros]'``; ``--image-topic``/``--imu-topic`` when the bag has
more than one camera or IMU topic). The camera's intrinsics come
from an earlier calibration (``boxplus-calib``'s OpenCV YAML, a Kalibr camchain or a
ROS camera_info), the target and the IMU's noise from Kalibr's ``target.yaml`` and
``imu.yaml`` (or boxplus' ``--target`` spelling and σ per sample)::

    boxplus-camera-imu recording/ --intrinsics calibration.yml \\
        --target target.yaml --imu imu.yaml --out result/
    boxplus-camera-imu recording.bag --image-topic /cam0/image_raw --imu-topic /imu0 ...

writes ``camchain-imucam.yaml`` (Kalibr's file: ``T_cam_imu``, ``timeshift_cam_imu``),
``report.txt`` (every estimate with σ) and ``camera_imu.png`` (the gyroscope against
the fitted trajectory, the reprojection errors). Exit codes: 0 success, 1 the data
did not give a plausible answer (the message says what to check), 2 bad input, 130
interrupted while detecting (Ctrl-C during the solve keeps its best estimate).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["main"]


def _parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(
        prog="boxplus-camera-imu",
        description="Calibrate a camera and an IMU (imu_from_cam, the clocks' time offset, "
                    "the biases) from a recording in motion: an EuRoC/ASL folder, a ROS 1/2 "
                    "bag or an MCAP file.",
        epilog="Example: boxplus-camera-imu recording/ --intrinsics calibration.yml "
               "--target target.yaml --imu imu.yaml --out result/")
    ap.add_argument("recording", help="an EuRoC/ASL folder (FOLDER[/mav0]/cam0/data.csv, "
                                      "cam0/data/*.png, imu0/data.csv; timestamps in ns), a ROS 1 "
                                      "bag (*.bag), a ROS 2 bag folder or an MCAP file")
    ap.add_argument("--intrinsics", required=True, metavar="FILE",
                    help="the camera's calibration: OpenCV YAML (boxplus-calib), Kalibr "
                         "camchain or ROS camera_info")
    ap.add_argument("--camera-name", default=None,
                    help="the camera in --intrinsics (default: its only or first camera)")
    ap.add_argument("--target", required=True,
                    help="Kalibr's target.yaml, or chessboard:COLSxROWS:SQUARE / "
                         "aprilgrid:COLSxROWS:TAG:SPACING (metres)")
    ap.add_argument("--imu", metavar="IMU_YAML",
                    help="Kalibr's imu.yaml (noise densities and rate); else --gyro-sigma and "
                         "--accel-sigma")
    ap.add_argument("--gyro-sigma", type=float, default=None,
                    help="σ of one gyroscope sample (rad/s)")
    ap.add_argument("--accel-sigma", type=float, default=None,
                    help="σ of one accelerometer sample (m/s²)")
    ap.add_argument("--gyro-random-walk", type=float, default=None,
                    help="the gyroscope bias' random walk (rad/s²/√Hz; imu.yaml gives it)")
    ap.add_argument("--accel-random-walk", type=float, default=None,
                    help="the accelerometer bias' random walk (m/s³/√Hz; imu.yaml gives it)")
    ap.add_argument("--bias-spacing", type=float, default=0.1,
                    help="seconds per bias segment when the biases drift (default 0.1)")
    ap.add_argument("--constant-biases", action="store_true",
                    help="hold the biases constant over the recording (ignore the random walks)")
    ap.add_argument("--pixel-sigma", type=float, default=0.5, help="corner σ in px (default 0.5)")
    ap.add_argument("--knot-spacing", type=float, default=0.05,
                    help="the trajectory spline's knot spacing in s (default 0.05)")
    ap.add_argument("--max-offset", type=float, default=0.1,
                    help="the largest time offset searched, in s (default 0.1)")
    ap.add_argument("--cam", default="cam0", help="EuRoC: the camera's subfolder (default cam0)")
    ap.add_argument("--imu-folder", default="imu0", help="EuRoC: the IMU's subfolder (default imu0)")
    ap.add_argument("--image-topic", default=None,
                    help="bag: the camera's topic (sensor_msgs/Image or CompressedImage; "
                         "default: the bag's only one)")
    ap.add_argument("--imu-topic", default=None,
                    help="bag: the IMU's topic (sensor_msgs/Imu; default: the bag's only one)")
    ap.add_argument("--out", type=Path, default=Path("camera_imu"),
                    help="output folder (default ./camera_imu); files are written atomically")
    ap.add_argument("--no-plots", action="store_true", help="write no PNG")
    ap.add_argument("--quiet", action="store_true", help="no progress lines")
    return ap


def _fail(message: str, code: int = 2) -> SystemExit:
    print(f"boxplus-camera-imu: {message}", file=sys.stderr)
    return SystemExit(code)


def _camera(args: Any) -> Any:
    from boxplus.calib import io

    try:
        cams = io.read_cameras(args.intrinsics)
    except (OSError, ValueError) as e:
        raise _fail(f"--intrinsics: {e}") from None
    if args.camera_name is None:
        return cams[0]
    found = [c for c in cams if c.name == args.camera_name]
    if not found:
        raise _fail(f"--intrinsics '{args.intrinsics}': no camera '{args.camera_name}' "
                    f"(it has {', '.join(c.name for c in cams)})")
    return found[0]


def _target(spec: str) -> Any:
    from boxplus.calib.recordings import read_kalibr_target
    from boxplus.calib.targets import parse_target

    try:
        if Path(spec).suffix in (".yaml", ".yml") or Path(spec).is_file():
            return read_kalibr_target(spec)
        return parse_target(spec)
    except (OSError, ValueError) as e:
        raise _fail(f"--target: {e}") from None


def _noise(args: Any) -> tuple[float, float, float | None, float | None]:
    """(gyro σ, accel σ per sample, gyro and accel random walks or None)."""
    from boxplus.calib.recordings import read_kalibr_imu

    if args.imu:
        try:
            imu = read_kalibr_imu(args.imu)
        except (OSError, ValueError) as e:
            raise _fail(f"--imu: {e}") from None
        gs, acs = imu.gyro_sigma, imu.accel_sigma
        gw: float | None = imu.gyro_random_walk
        aw: float | None = imu.accel_random_walk
    else:
        if args.gyro_sigma is None or args.accel_sigma is None:
            raise _fail("give the IMU's noise: --imu imu.yaml, or --gyro-sigma and --accel-sigma")
        gs, acs, gw, aw = (args.gyro_sigma, args.accel_sigma, args.gyro_random_walk,
                           args.accel_random_walk)
    for name, v in (("--gyro-sigma", gs), ("--accel-sigma", acs), ("--gyro-random-walk", gw),
                    ("--accel-random-walk", aw)):
        if v is not None and not (np.isfinite(v) and v > 0):
            raise _fail(f"{name} must be positive, got {v}")
    if (gw is None) != (aw is None):
        raise _fail("give both random walks (--gyro-random-walk and --accel-random-walk) or neither")
    if args.constant_biases:
        gw = aw = None
    return gs, acs, gw, aw


def _report(cal: Any, camera: Any, data: Any, gyro_sigma: float, accel_sigma: float) -> str:
    ic = cal.imu_from_cam
    s = cal.std("imu_from_cam")
    rot = np.degrees(ic.rot.log())
    found = sum(c is not None for c in data.corners)
    lines = [
        f"boxplus-camera-imu: camera '{camera.name}' ({camera.model}), {len(data.frame_times)} "
        f"images ({found} with the target), {len(data.imu_times)} IMU samples",
        f"noise: gyroscope σ {gyro_sigma:.4g} rad/s, accelerometer σ {accel_sigma:.4g} m/s² per "
        f"sample",
        f"solve: {cal.summary.termination}; RMS per group "
        + ", ".join(f"{g} {r:.4g}" for g, r in cal.problem.rms().items()),
        "imu_from_cam (value ± σ):",
        "  translation (m): " + ", ".join(f"{a} {v:+.5f} ± {e:.5f}"
                                          for a, v, e in zip("xyz", ic.pos, s[:3])),
        "  rotation vector (deg): " + ", ".join(f"{a} {v:+.4f} ± {np.degrees(e):.4f}"
                                                for a, v, e in zip("xyz", rot, s[3:])),
        f"time offset: t_imu = t_cam + {cal.time_offset * 1e3:+.4f} ms ± "
        f"{cal.std('time_offset')[0] * 1e3:.4f} ms",
        "gyroscope bias (rad/s): " + " ".join(f"{v:+.5f}" for v in cal.gyro_bias)
        + "  ± " + " ".join(f"{v:.5f}" for v in cal.std("gyro_bias")),
        "accelerometer bias (m/s²): " + " ".join(f"{v:+.4f}" for v in cal.accel_bias)
        + "  ± " + " ".join(f"{v:.4f}" for v in cal.std("accel_bias")),
        (f"biases: {len(cal.gyro_biases)} segments of {np.diff(cal.bias_times).mean():.3g} s "
         f"(random walk); the values above are their means, the first segment's σ; drift "
         f"over the recording: gyroscope {np.ptp(cal.gyro_biases, axis=0).max():.2g} rad/s, "
         f"accelerometer {np.ptp(cal.accel_biases, axis=0).max():.2g} m/s²"
         if len(cal.gyro_biases) > 1 else "biases: constant over the recording"),
        "gravity in the target frame (m/s²): " + " ".join(f"{v:+.4f}" for v in cal.gravity),
    ]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    from boxplus.calib import io
    from boxplus.calib.bags import is_bag, read_bag
    from boxplus.calib.camera_imu import calibrate_camera_imu
    from boxplus.calib.recordings import detect_recording, read_euroc

    camera = _camera(args)
    target = _target(args.target)
    gyro_sigma, accel_sigma, gyro_walk, accel_walk = _noise(args)
    source = Path(args.recording)
    try:
        if is_bag(source):
            recording: Any = read_bag(source, args.image_topic, args.imu_topic)
        else:
            recording = read_euroc(source, args.cam, args.imu_folder)
    except (OSError, ValueError, ImportError) as e:  # no rosbags: the message names the extra
        raise _fail(str(e)) from None
    out = args.out
    if out.resolve() == source.resolve() or source.resolve() in out.resolve().parents:
        raise _fail(f"--out {out} is inside the recording {source}: choose another folder")

    def progress(done: int, total: int) -> None:
        if not args.quiet and (done == total or done % max(1, total // 10) == 0):
            print(f"detecting: {done}/{total} images", file=sys.stderr, flush=True)

    try:
        # Ctrl-C during a solve stops it at its best estimate (the summary says
        # 'interrupted' and so does the report); during detection nothing is estimated yet
        data = detect_recording(recording, target, progress)
        cal = calibrate_camera_imu(data, camera.intrinsics, camera.model, pixel_sigma=args.pixel_sigma,
                                   gyro_sigma=gyro_sigma, accel_sigma=accel_sigma,
                                   knot_spacing=args.knot_spacing, max_offset=args.max_offset,
                                   gyro_random_walk=gyro_walk, accel_random_walk=accel_walk,
                                   bias_spacing=args.bias_spacing)
    except ValueError as e:
        raise _fail(str(e), code=1) from None
    except KeyboardInterrupt:
        raise _fail("interrupted before an estimate existed; nothing written", code=130) from None
    report = _report(cal, camera, data, gyro_sigma, accel_sigma)
    print(report)
    out.mkdir(parents=True, exist_ok=True)
    from boxplus.files import write_atomically

    written = []
    try:
        io.write_camchain_imucam(out / "camchain-imucam.yaml", camera, cal.imu_from_cam.inverse(),
                                 cal.time_offset)
        written.append("camchain-imucam.yaml")
    except ValueError as e:  # a lens Kalibr cannot describe: its reader would misread it
        print(f"not written: camchain-imucam.yaml: {e}", file=sys.stderr)
    # boxplus' own file: every estimate and σ, whatever the lens
    io.write_yaml(out / "camera_imu.yaml", {
        "camera": camera.name, "model": camera.model,
        "T_cam_imu": cal.imu_from_cam.inverse().matrix().tolist(),
        "timeshift_cam_imu": cal.time_offset, **cal.todict()})
    write_atomically(out / "report.txt", report + "\n")
    written += ["camera_imu.yaml", "report.txt"]
    if not args.no_plots:
        from boxplus.calib.plot import plot_camera_imu

        plot_camera_imu(cal, data, out / "camera_imu.png")
        written.append("camera_imu.png")
    print(f"wrote {', '.join(written)} to {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
