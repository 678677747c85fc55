"""``boxplus-camera-imu``: calibrate cameras and an IMU from a recording in motion.

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

A rig of several cameras and one IMU (a stereo pair, N cameras) is calibrated together
on one trajectory: ``--cam cam0 cam1`` (EuRoC) or ``--image-topic /cam0/image_raw
/cam1/image_raw`` (bags), the i-th camera with the i-th camera of ``--intrinsics`` (or
of ``--camera-name``); ``--common-clock`` when they are triggered together (one time
offset). More IMUs (``--imu-folder imu0 imu1``, ``--imu-topic /imu0 /imu1``) are placed
in the first one's frame (``imu-imucam.yaml``, Kalibr's ``T_i_b``) with their clocks'
offsets to the first one's (``time_offset``; ``--imus-common-clock`` when they share it).
``--imu-intrinsics`` estimates every IMU's scale and misalignment (Kalibr's
``scale-misalignment`` model, in ``imu-imucam.yaml`` too).
``--rolling-shutter`` estimates each camera's line delay (Kalibr's camchain has
no field for it: it is in ``camera_imu.yaml`` and the report). It

writes ``camchain-imucam.yaml`` (Kalibr's file: ``T_cam_imu``, ``timeshift_cam_imu``
per camera, ``T_cn_cnm1`` between consecutive ones),
``report.txt`` (every estimate with σ) and ``camera_imu.png`` (the gyroscope against
the fitted trajectory, the reprojection errors). Exit codes: 0 success, 1 the data
did not give a plausible answer (the message says what to check), 2 bad input, 130
interrupted while detecting (Ctrl-C during the solve keeps its best estimate).
"""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["main"]


def _parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(
        prog="boxplus-camera-imu",
        description="Calibrate a camera (or several) and an IMU (imu_from_cam, the clocks' time "
                    "offset, the biases) from a recording in motion: an EuRoC/ASL folder, a ROS 1/2 "
                    "bag or an MCAP file.",
        epilog="Example: boxplus-camera-imu recording/ --intrinsics calibration.yml "
               "--target target.yaml --imu imu.yaml --out result/")
    ap.add_argument("recording", nargs="?",
                    help="an EuRoC/ASL folder (FOLDER[/mav0]/cam0/data.csv, cam0/data/*.png, "
                         "imu0/data.csv; timestamps in ns), a ROS 1 bag (*.bag), a ROS 2 bag "
                         "folder or an MCAP file (it may also come last, after an option that "
                         "takes several values)")
    ap.add_argument("--intrinsics", required=True, metavar="FILE",
                    help="the camera's calibration: OpenCV YAML (boxplus-calib), Kalibr "
                         "camchain or ROS camera_info")
    ap.add_argument("--camera-name", nargs="+", default=None, metavar="NAME",
                    help="the cameras in --intrinsics, one per recorded camera (default: its "
                         "first cameras, in order)")
    ap.add_argument("--target", required=True,
                    help="Kalibr's target.yaml, or chessboard:COLSxROWS:SQUARE / "
                         "aprilgrid:COLSxROWS:TAG:SPACING (metres)")
    ap.add_argument("--imu", metavar="IMU_YAML", nargs="+",
                    help="Kalibr's imu.yaml (noise densities and rate), one for every IMU or one "
                         "per IMU; else --gyro-sigma and --accel-sigma")
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
    ap.add_argument("--knot-spacing", type=float, default=None,
                    help="the trajectory spline's knot spacing in s (default: from 0.05, halved "
                         "while the IMU residuals exceed 1.5x their noise)")
    ap.add_argument("--max-offset", type=float, default=0.1,
                    help="the largest time offset searched, in s (default 0.1)")
    ap.add_argument("--cam", nargs="+", default=["cam0"], metavar="FOLDER",
                    help="EuRoC: the cameras' subfolders (default cam0; e.g. cam0 cam1 for a "
                         "stereo pair)")
    ap.add_argument("--common-clock", action="store_true",
                    help="the cameras are triggered together: one time offset for all")
    ap.add_argument("--imu-intrinsics", action="store_true",
                    help="estimate every IMU's gyroscope and accelerometer scale and "
                         "misalignment too (Kalibr's scale-misalignment model)")
    ap.add_argument("--accel-size-effect", action="store_true",
                    help="with --imu-intrinsics: the first IMU's accelerometer's y and z sensing "
                         "elements' positions too (Kalibr's size effect)")
    ap.add_argument("--imus-common-clock", action="store_true",
                    help="the IMUs share the first one's clock: no time offset between IMUs "
                         "(default: each other IMU's offset is estimated)")
    ap.add_argument("--rolling-shutter", action="store_true",
                    help="the cameras read their rows one after the other: estimate each one's "
                         "line delay (row v seen at the frame's timestamp + delay·v)")
    ap.add_argument("--line-delay", type=float, default=0.0, metavar="SECONDS",
                    help="with --rolling-shutter: the line delay to start from, s per row "
                         "(default 0)")
    ap.add_argument("--imu-folder", nargs="+", default=["imu0"], metavar="FOLDER",
                    help="EuRoC: the IMUs' subfolders (default imu0; the first is the body whose "
                         "trajectory is estimated, the others are placed in its frame)")
    ap.add_argument("--image-topic", nargs="+", default=None, metavar="TOPIC",
                    help="bag: the cameras' topics (sensor_msgs/Image or CompressedImage; "
                         "default: the bag's only one)")
    ap.add_argument("--imu-topic", nargs="+", default=None, metavar="TOPIC",
                    help="bag: the IMUs' topics (sensor_msgs/Imu; default: the bag's only one)")
    ap.add_argument("--out", type=Path, default=Path("camera_imu"),
                    help="output folder (default ./camera_imu); files are written atomically")
    ap.add_argument("--no-plots", action="store_true", help="write no PNG")
    ap.add_argument("--quiet", action="store_true", help="no progress lines")
    return ap


def _fail(message: str, code: int = 2) -> SystemExit:
    print(f"boxplus-camera-imu: {message}", file=sys.stderr)
    return SystemExit(code)


def _cameras(args: Any, n: int) -> list[Any]:
    """The n recorded cameras' calibrations from --intrinsics: by --camera-name, else
    the file's first n."""
    from boxplus.calib import io

    try:
        cams = io.read_cameras(args.intrinsics)
    except (OSError, ValueError) as e:
        raise _fail(f"--intrinsics: {e}") from None
    if args.camera_name is None:
        if len(cams) < n:
            raise _fail(f"--intrinsics '{args.intrinsics}' has {len(cams)} camera(s) for {n} "
                        f"recorded cameras")
        return cams[:n]
    if len(args.camera_name) != n:
        raise _fail(f"--camera-name: {len(args.camera_name)} names for {n} recorded cameras")
    chosen = []
    for name in args.camera_name:
        found = [c for c in cams if c.name == name]
        if not found:
            raise _fail(f"--intrinsics '{args.intrinsics}': no camera '{name}' "
                        f"(it has {', '.join(c.name for c in cams)})")
        chosen.append(found[0])
    return chosen


def _target(spec: str) -> Any:
    from boxplus.calib.recordings import read_kalibr_target
    from boxplus.calib.targets import parse_target

    try:
        if Path(spec).suffix in (".yaml", ".yml") or Path(spec).is_file():
            return read_kalibr_target(spec)
        return parse_target(spec)
    except (OSError, ValueError) as e:
        raise _fail(f"--target: {e}") from None


def _noise(args: Any, n_imu: int) -> tuple[list[tuple[float, float]], float | None, float | None]:
    """((gyro σ, accel σ) per sample for each IMU, the gyro and accel random walks or
    None: the first IMU's)."""
    from boxplus.calib.recordings import read_kalibr_imu

    if args.imu:
        if len(args.imu) not in (1, n_imu):
            raise _fail(f"--imu: {len(args.imu)} files for {n_imu} IMUs: give one for all or one each")
        sigmas = []
        for path in args.imu:
            try:
                imu = read_kalibr_imu(path)
            except (OSError, ValueError) as e:
                raise _fail(f"--imu: {e}") from None
            sigmas.append((imu.gyro_sigma, imu.accel_sigma))
            if len(sigmas) == 1:
                gw: float | None = imu.gyro_random_walk
                aw: float | None = imu.accel_random_walk
        sigmas *= n_imu if len(sigmas) == 1 else 1
    else:
        if args.gyro_sigma is None or args.accel_sigma is None:
            raise _fail("give the IMU's noise: --imu imu.yaml, or --gyro-sigma and --accel-sigma")
        sigmas = [(args.gyro_sigma, args.accel_sigma)] * n_imu
        gw, aw = args.gyro_random_walk, args.accel_random_walk
    for name, v in (("--gyro-sigma", sigmas[0][0]), ("--accel-sigma", sigmas[0][1]),
                    ("--gyro-random-walk", gw), ("--accel-random-walk", aw)):
        if v is not None and not (np.isfinite(v) and v > 0):
            raise _fail(f"{name} must be positive, got {v}")
    if (gw is None) != (aw is None):
        raise _fail("give both random walks (--gyro-random-walk and --accel-random-walk) or neither")
    if args.constant_biases:
        gw = aw = None
    return sigmas, gw, aw


def _other_imus(args: Any, source: Path, bag: bool, first: Any) -> list[Any]:
    """The samples of every IMU after the first (--imu-folder / --imu-topic), their
    times re-based on the first IMU's origin (each reader counts from its own first
    stamp)."""
    from boxplus.calib.bags import read_bag
    from boxplus.calib.camera_imu import ImuSamples
    from boxplus.calib.recordings import read_euroc

    names = (args.imu_topic or [None])[1:] if bag else args.imu_folder[1:]
    out = []
    for name in names:
        try:
            rec = (read_bag(source, first.image_topic, name) if bag
                   else read_euroc(source, args.cam[0], name))
        except (OSError, ValueError, ImportError) as e:
            raise _fail(str(e)) from None
        shift = (rec.origin_ns - first.origin_ns) * 1e-9
        out.append(ImuSamples(rec.imu_times + shift, rec.gyro, rec.accel, str(name).strip("/")))
    return out


def _pose_lines(pose: Any, sigma: np.ndarray) -> list[str]:
    rot = np.degrees(pose.rot.log())
    return ["  translation (m): " + ", ".join(f"{a} {v:+.5f} ± {e:.5f}"
                                              for a, v, e in zip("xyz", pose.pos, sigma[:3])),
            "  rotation vector (deg): " + ", ".join(f"{a} {v:+.4f} ± {np.degrees(e):.4f}"
                                                    for a, v, e in zip("xyz", rot, sigma[3:]))]


def _report(cal: Any, cameras: list[Any], data: Any, gyro_sigma: float, accel_sigma: float) -> str:
    several = len(cameras) > 1
    lines = [
        f"boxplus-camera-imu: {len(data.imu_times)} IMU samples; "
        + "; ".join(f"camera '{c.name}' ({c.model}): {len(f.frame_times)} images "
                    f"({sum(x is not None for x in f.corners)} with the target)"
                    for c, f in zip(cameras, data.cameras)),
        f"noise: gyroscope σ {gyro_sigma:.4g} rad/s, accelerometer σ {accel_sigma:.4g} m/s² per "
        f"sample",
        f"trajectory: a spline with knots every {cal.knot_spacing * 1e3:.4g} ms ({cal.n_knots} knots)",
        f"solve: {cal.summary.termination}; RMS per group "
        + ", ".join(f"{g} {r:.4g}" for g, r in cal.problem.rms().items())]
    for c, cam in enumerate(cameras):
        lines.append(f"imu_from_cam{' of ' + repr(cam.name) if several else ''} (value ± σ):")
        lines += _pose_lines(cal.imu_from_cams[c], cal.std(f"imu_from_cam[{c}]"))
        d = cal.time_offsets[c]
        lines.append(f"time offset{' of ' + repr(cam.name) if several else ''}: t_imu = t_cam "
                     f"{'+' if d >= 0 else '−'} {abs(d) * 1e3:.4f} ms ± "
                     f"{cal.std(f'time_offset[{c}]')[0] * 1e3:.4f} ms")
        ell = cal.line_delays[c]
        if ell is not None:
            lines.append(f"line delay{' of ' + repr(cam.name) if several else ''}: {ell * 1e6:.4f} µs "
                         f"per row ± {cal.std(f'line_delay[{c}]')[0] * 1e6:.4f} (the "
                         f"{cam.image_size[1]} rows read out in {ell * cam.image_size[1] * 1e3:.3f} ms)")
    for c in range(1, len(cameras)):
        lines.append(f"{cameras[c].name}_from_{cameras[c - 1].name} (T_cn_cnm1; value ± σ):")
        lines += _pose_lines(cal.cam_from_cam(c, c - 1), cal.cam_from_cam_std(c, c - 1))
    for k in range(1, len(cal.imu_names)):
        name = cal.imu_names[k]
        lines.append(f"imu0_from_{name} (its lever arm and rotation in the first IMU's frame; "
                     f"value ± σ):")
        lines += _pose_lines(cal.imu0_from_imus[k], cal.std(f"imu0_from_imu[{k}]"))
        if f"imu_time_offset[{k}]" in cal.ids:
            d = cal.imu_time_offsets[k]
            lines.append(f"{name} time offset: t_imu0 = t_{name} {'+' if d >= 0 else '−'} "
                         f"{abs(d) * 1e3:.4f} ms ± {cal.std(f'imu_time_offset[{k}]')[0] * 1e3:.4f} ms")
        lines.append(f"{name} biases: gyroscope (rad/s) "
                     + " ".join(f"{v:+.5f}" for v in cal.imu_gyro_biases[k])
                     + ", accelerometer (m/s²) " + " ".join(f"{v:+.4f}" for v in cal.imu_accel_biases[k]))
        for kind, what in (("gyro_intrinsics", "gyroscope"), ("accel_intrinsics", "accelerometer")):
            if f"imu_{kind}[{k}]" in cal.ids:
                lines.append(_intrinsics_line(cal, f"imu_{kind}[{k}]",
                                              f"{name} {what} scale and misalignment (reading M x + b)"))
    lines += [
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
    for kind, what in (("gyro_intrinsics", "gyroscope scale and misalignment (reading M x + b)"),
                       ("accel_intrinsics", "accelerometer scale and misalignment (reading M x + b)"),
                       ("accel_size_effect", "accelerometer size effect (y, z elements from x, m)")):
        if kind in cal.ids:
            lines.append(_intrinsics_line(cal, kind, what))
    return "\n".join(lines)


def _intrinsics_line(cal: Any, name: str, what: str) -> str:
    """One report line: an IMU's own-model variable, each coordinate's label, value and σ."""
    values, std = cal.problem[cal.ids[name]].vec, cal.std(name)
    return f"{what}, value ± σ: " + ", ".join(f"{lab} {v:.5f} ± {s:.5f}" for lab, v, s in
                                               zip(cal.problem.labels(cal.ids[name]), values, std))


# every file a run writes into --out
_OUTPUTS = ("camchain-imucam.yaml", "camera_imu.yaml", "report.txt", "camera_imu.png", "imu-imucam.yaml")


def _kalibr_imus(cal: Any, data: Any, args: Any, bag: bool, sigmas: list[tuple[float, float]],
                 walks: tuple[float | None, float | None]) -> dict[str, Any]:
    """Kalibr's imu result YAML for a rig of several IMUs: per IMU ``T_i_b`` (the body
    (first IMU) into this IMU's frame, 4 × 4), the noise densities the fit assumed
    (σ per sample / √rate, Kalibr's discretisation undone) and the random walks,
    ``time_offset`` (s added to this IMU's stamps to reach the first IMU's clock, as
    Kalibr applies it), ``update_rate`` (from the samples' median spacing),
    ``rostopic`` and the IMU's own model (:func:`_kalibr_imu_model`)."""
    topics = (args.imu_topic or [None]) if bag else [None] * len(cal.imu_names)
    times = [np.asarray(data.imu_times), *(np.asarray(i.imu_times) for i in data.other_imus)]
    doc = {}
    for k, (name, pose) in enumerate(zip(cal.imu_names, cal.imu0_from_imus)):
        rate = float(1.0 / np.median(np.diff(times[k])))
        entry: dict[str, Any] = {"T_i_b": [[float(v) for v in row] for row in pose.inverse().matrix()],
                                 "accelerometer_noise_density": float(sigmas[k][1] / np.sqrt(rate)),
                                 "gyroscope_noise_density": float(sigmas[k][0] / np.sqrt(rate))}
        if walks[0] is not None and walks[1] is not None:
            entry.update(accelerometer_random_walk=float(walks[1]), gyroscope_random_walk=float(walks[0]))
        entry.update(time_offset=float(cal.imu_time_offsets[k]), update_rate=rate,
                     rostopic=topics[k] or f"/{name}")
        entry.update(_kalibr_imu_model(cal, k))
        doc[f"imu{k}"] = entry
    return doc


def _kalibr_imu_model(cal: Any, k: int) -> dict[str, Any]:
    """IMU k's own model as Kalibr's imu YAML holds it: ``model`` "calibrated" (none
    estimated), "scale-misalignment" with ``gyroscopes`` {M, A, C_gyro_i} and
    ``accelerometers`` {M} — Kalibr reads ω as M C_gyro_i ω_imu + A a + b and a as
    M a_imu + b with lower-triangular M, which is boxplus' model with C_gyro_i = I and
    A = 0 (neither estimated) — or "scale-misalignment-size-effect" with the
    accelerometer's ``rx_i`` (0: the x element is the origin), ``ry_i``, ``rz_i`` (m)."""
    if not cal.imu_gyro_intrinsics:
        return {"model": "calibrated"}

    def rows(M: Any) -> list[list[float]]:
        return [[float(v) for v in row] for row in np.asarray(M)]

    doc: dict[str, Any] = {
        "model": "scale-misalignment",
        "gyroscopes": {"M": rows(cal.imu_gyro_intrinsics[k]), "A": rows(np.zeros((3, 3))),
                       "C_gyro_i": rows(np.eye(3))},
        "accelerometers": {"M": rows(cal.imu_accel_intrinsics[k])}}
    if k == 0 and cal.accel_size_effect is not None:
        doc["model"] = "scale-misalignment-size-effect"
        r_y, r_z = (np.asarray(r, float) for r in cal.accel_size_effect)
        doc["accelerometers"].update(rx_i=[0.0, 0.0, 0.0], ry_i=[float(v) for v in r_y],
                                     rz_i=[float(v) for v in r_z])
    return doc


# the options that take several values: argparse gives them a recording written after them
_LISTS = ("camera_name", "imu", "cam", "imu_folder", "image_topic", "imu_topic")


def _parse(argv: list[str] | None) -> argparse.Namespace:
    """The arguments, with the recording taken back from a list option that swallowed it
    (``--cam cam0 cam1 recording/``): the last value of such an option that is a bag or a
    folder on disk, as the last word of the command line."""
    ap = _parser()
    args = ap.parse_args(argv)
    if args.accel_size_effect and not args.imu_intrinsics:
        ap.error("--accel-size-effect needs --imu-intrinsics (the size effect is part of the "
                 "accelerometer's own model)")
    if args.recording is not None:
        return args
    words = list(sys.argv[1:] if argv is None else argv)
    last = words[-1] if words else None
    for name in _LISTS:
        values = getattr(args, name)
        if (last is not None and isinstance(values, list) and len(values) > 1 and values[-1] == last
                and Path(last).exists() and not Path(last).suffix == ".yaml"):
            args.recording = values.pop()
            return args
    ap.error("the recording (an EuRoC folder, a bag or an MCAP file) is missing")
    raise AssertionError  # ap.error exits


def main(argv: list[str] | None = None) -> int:
    args = _parse(argv)
    from boxplus.calib import io
    from boxplus.calib.bags import is_bag, read_bag
    from boxplus.calib.camera_imu import calibrate_camera_imu
    from boxplus.calib.recordings import detect_recording, read_euroc

    source = Path(args.recording)
    bag = is_bag(source)
    n_cam = len(args.image_topic or [None]) if bag else len(args.cam)
    cameras = _cameras(args, n_cam)
    target = _target(args.target)
    n_imu = len(args.imu_topic or [None]) if bag else len(args.imu_folder)
    imu_sigmas, gyro_walk, accel_walk = _noise(args, n_imu)
    gyro_sigma, accel_sigma = imu_sigmas[0]
    imu_topic = (args.imu_topic or [None])[0]
    try:
        if bag:
            recordings: list[Any] = [read_bag(source, t, imu_topic)
                                     for t in (args.image_topic or [None])]
        else:
            recordings = [read_euroc(source, c, args.imu_folder[0]) for c in args.cam]
    except (OSError, ValueError, ImportError) as e:  # no rosbags: the message names the extra
        raise _fail(str(e)) from None
    other_imus = _other_imus(args, source, bag, recordings[0])
    inputs = [Path(p).resolve() for p in [args.intrinsics, args.target, *(args.imu or [])]]
    clash = [n for n in _OUTPUTS if (args.out / n).resolve() in inputs]
    if clash:
        raise _fail(f"--out {args.out}: writing {clash[0]} there would overwrite an input file; "
                    f"choose another folder")
    out = args.out
    if out.resolve() == source.resolve() or source.resolve() in out.resolve().parents:
        raise _fail(f"--out {out} is inside the recording {source}: choose another folder")

    def progress(done: int, total: int) -> None:
        if not args.quiet and (done == total or done % max(1, total // 10) == 0):
            print(f"detecting: {done}/{total} images", file=sys.stderr, flush=True)

    try:
        # Ctrl-C during a solve stops it at its best estimate (the summary says
        # 'interrupted' and so does the report); during detection nothing is estimated yet
        data = detect_recording(recordings, target, progress, [c.name for c in cameras])
        data.other_imus = other_imus
        several = len(cameras) > 1
        intrinsics = [c.intrinsics for c in cameras] if several else cameras[0].intrinsics
        models = [c.model for c in cameras] if several else cameras[0].model
        with warnings.catch_warnings(record=True) as caught:  # the report names them
            warnings.simplefilter("always", UserWarning)
            cal = calibrate_camera_imu(
                data, intrinsics, models, pixel_sigma=args.pixel_sigma, gyro_sigma=gyro_sigma,
                accel_sigma=accel_sigma, knot_spacing=args.knot_spacing, max_offset=args.max_offset,
                gyro_random_walk=gyro_walk, accel_random_walk=accel_walk,
                bias_spacing=args.bias_spacing, common_clock=args.common_clock,
                imu_time_offsets=not args.imus_common_clock, imu_intrinsics=args.imu_intrinsics,
                accel_size_effect=args.accel_size_effect,
                rolling_shutter=args.rolling_shutter, line_delay=args.line_delay,
                other_imu_sigmas=imu_sigmas[1:])
    except ValueError as e:
        raise _fail(str(e), code=1) from None
    except KeyboardInterrupt:
        raise _fail("interrupted before an estimate existed; nothing written", code=130) from None
    report = _report(cal, cameras, data, gyro_sigma, accel_sigma)
    notes = [str(w.message) for w in caught]
    for note in notes:
        print(f"boxplus-camera-imu: warning: {note}", file=sys.stderr)
    report += "".join(f"\nwarning: {note}" for note in notes)
    print(report)
    out.mkdir(parents=True, exist_ok=True)
    from boxplus.files import write_atomically

    written = []
    try:
        topics = [r.image_topic for r in recordings] if bag else None
        io.write_camchain_imucam(out / "camchain-imucam.yaml", cameras,
                                 [p.inverse() for p in cal.imu_from_cams], cal.time_offsets, topics)
        written.append("camchain-imucam.yaml")
    except ValueError as e:  # a lens Kalibr cannot describe: its reader would misread it
        print(f"not written: camchain-imucam.yaml: {e}", file=sys.stderr)
    # boxplus' own file: every estimate and σ, whatever the lens
    own: dict[str, Any] = {
        "camera": cameras[0].name, "model": cameras[0].model,
        "T_cam_imu": cal.imu_from_cam.inverse().matrix().tolist(),
        "timeshift_cam_imu": cal.time_offset}
    if len(cameras) > 1:
        own["cameras"] = [{"camera": c.name, "model": c.model,
                           "T_cam_imu": p.inverse().matrix().tolist(), "timeshift_cam_imu": d,
                           "line_delay": ell}
                          for c, p, d, ell in zip(cameras, cal.imu_from_cams, cal.time_offsets,
                                                  cal.line_delays)]
    io.write_yaml(out / "camera_imu.yaml", {**own, **cal.todict()})
    write_atomically(out / "report.txt", report + "\n")
    written += ["camera_imu.yaml", "report.txt"]
    if len(cal.imu_names) > 1 or cal.imu_gyro_intrinsics:  # Kalibr's file holds both
        io.write_yaml(out / "imu-imucam.yaml", _kalibr_imus(cal, data, args, bag, imu_sigmas,
                                                            (gyro_walk, accel_walk)))
        written.append("imu-imucam.yaml")
    if not args.no_plots:
        from boxplus.calib.plot import plot_camera_imu

        plot_camera_imu(cal, data, out / "camera_imu.png")
        written.append("camera_imu.png")
    print(f"wrote {', '.join(written)} to {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
