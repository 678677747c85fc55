"""Camera–IMU recordings as users have them: EuRoC/ASL folders and Kalibr's YAML files.

* :func:`read_euroc` — a folder in the layout of the EuRoC MAV data sets (ETH's ASL
  format, which Kalibr's ``kalibr_bagcreater`` reads)::

      FOLDER[/mav0]/cam0/data.csv        #timestamp [ns],filename
      FOLDER[/mav0]/cam0/data/<ns>.png
      FOLDER[/mav0]/imu0/data.csv        #timestamp [ns],w_RS_S_x [rad s^-1],…,a_RS_S_z [m s^-2]

  Timestamps are integer nanoseconds; they are turned into seconds after the first
  IMU sample (``origin_ns``), in integer arithmetic first, so that 1.4e18 ns do not
  lose their microseconds to a float.
* :func:`read_kalibr_imu` — Kalibr's ``imu.yaml``: continuous-time noise densities
  and random walks and the rate; the per-sample σ is density · √rate (Kalibr's own
  discretisation).
* :func:`read_kalibr_target` — Kalibr's ``target.yaml`` (``checkerboard`` or
  ``aprilgrid``) as a :class:`boxplus.calib.targets.Target`.
* ROS 1/2 bags and MCAP files: :func:`boxplus.calib.bags.read_bag`.
* :func:`detect_recording` — the target's corners in every image, as the
  :class:`boxplus.calib.camera_imu.CameraImuData` that
  :func:`boxplus.calib.camera_imu.calibrate_camera_imu` takes.

Every error names the file (and line or key) that caused it.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Protocol

import numpy as np

from boxplus.calib.camera_imu import CameraFrames, CameraImuData
from boxplus.calib.targets import Target

__all__ = ["EurocRecording", "ImuNoise", "Recording", "detect_recording", "read_euroc", "read_kalibr_imu",
           "read_kalibr_target"]


@dataclass
class EurocRecording:
    """A camera's images and an IMU's samples; times in seconds after ``origin_ns``."""

    frame_times: np.ndarray   # (F,) s
    images: list[Path]        # (F,) image files
    imu_times: np.ndarray     # (N,) s
    gyro: np.ndarray          # (N, 3) rad/s
    accel: np.ndarray         # (N, 3) m/s²
    origin_ns: int            # the first IMU timestamp (ns): time 0

    def frames(self) -> Iterator[tuple[str, np.ndarray]]:
        """(the file's name, the grey image) of every frame, in time order."""
        from boxplus._optional import require

        cv2 = require("cv2", "reading camera images")
        for path in self.images:
            gray = cv2.imread(str(path), cv2.IMREAD_GRAYSCALE)
            if gray is None:
                raise ValueError(f"{path}: not an image OpenCV can read")
            yield str(path), gray


class Recording(Protocol):
    """What :func:`detect_recording` takes: an :class:`EurocRecording` or a
    :class:`boxplus.calib.bags.BagRecording`."""

    frame_times: np.ndarray
    imu_times: np.ndarray
    gyro: np.ndarray
    accel: np.ndarray

    def frames(self) -> Iterator[tuple[str, np.ndarray]]: ...


@dataclass
class ImuNoise:
    """Kalibr's imu.yaml: densities (continuous time) and the rate (Hz)."""

    gyro_noise_density: float     # rad/s/√Hz
    gyro_random_walk: float       # rad/s²/√Hz
    accel_noise_density: float    # m/s²/√Hz
    accel_random_walk: float      # m/s³/√Hz
    rate: float                   # Hz

    @property
    def gyro_sigma(self) -> float:
        """σ of one gyroscope sample (rad/s): density · √rate."""
        return self.gyro_noise_density * math.sqrt(self.rate)

    @property
    def accel_sigma(self) -> float:
        """σ of one accelerometer sample (m/s²): density · √rate."""
        return self.accel_noise_density * math.sqrt(self.rate)


def _csv_rows(path: Path, columns: int) -> list[tuple[int, list[str]]]:
    """(line number, fields) of the data rows of an EuRoC CSV; '#' lines are comments."""
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such file (expected the EuRoC/ASL layout, "
                                f"see boxplus.calib.recordings)")
    rows = []
    with open(path, newline="") as f:
        for line_no, fields in enumerate(csv.reader(f), start=1):
            if not fields or fields[0].lstrip().startswith("#"):
                continue
            if len(fields) < columns:
                raise ValueError(f"{path}:{line_no}: expected {columns} comma-separated values, "
                                 f"got {len(fields)}")
            rows.append((line_no, [v.strip() for v in fields]))
    if not rows:
        raise ValueError(f"{path}: no data rows")
    return rows


def _timestamp(path: Path, line_no: int, text: str) -> int:
    try:
        return int(text)
    except ValueError:
        raise ValueError(f"{path}:{line_no}: timestamp {text!r} is not an integer number of "
                         f"nanoseconds") from None


def _increasing(path: Path, lines: list[int], stamps: np.ndarray) -> None:
    bad = np.flatnonzero(np.diff(stamps) <= 0)
    if bad.size:
        raise ValueError(f"{path}:{lines[bad[0] + 1]}: timestamp {stamps[bad[0] + 1]} does not "
                         f"increase (previous {stamps[bad[0]]})")


def read_euroc(folder: str | Path, camera: str = "cam0", imu: str = "imu0") -> EurocRecording:
    """The images of ``camera`` and the samples of ``imu`` of an EuRoC/ASL folder
    (``FOLDER/mav0/...`` or ``FOLDER/...``; module docstring)."""
    root = Path(folder)
    if (root / "mav0").is_dir():
        root = root / "mav0"
    imu_csv = root / imu / "data.csv"
    rows = _csv_rows(imu_csv, 7)
    stamps = np.array([_timestamp(imu_csv, n, r[0]) for n, r in rows], dtype=np.int64)
    _increasing(imu_csv, [n for n, _ in rows], stamps)
    try:
        values = np.array([[float(v) for v in r[1:7]] for _, r in rows])
    except ValueError as e:
        raise ValueError(f"{imu_csv}: {e}") from None
    if not np.all(np.isfinite(values)):
        line = rows[int(np.flatnonzero(~np.all(np.isfinite(values), axis=1))[0])][0]
        raise ValueError(f"{imu_csv}:{line}: a non-finite gyroscope or accelerometer value")
    cam_csv = root / camera / "data.csv"
    crows = _csv_rows(cam_csv, 2)
    cstamps = np.array([_timestamp(cam_csv, n, r[0]) for n, r in crows], dtype=np.int64)
    _increasing(cam_csv, [n for n, _ in crows], cstamps)
    images = [root / camera / "data" / r[1] for _, r in crows]
    missing = [(n, p) for (n, _), p in zip(crows, images) if not p.is_file()]
    if missing:
        raise FileNotFoundError(f"{cam_csv}:{missing[0][0]}: image {missing[0][1]} does not exist "
                                f"({len(missing)} of {len(images)} missing)")
    origin = int(stamps[0])
    return EurocRecording((cstamps - origin) * 1e-9, images, (stamps - origin) * 1e-9,
                          values[:, :3], values[:, 3:], origin)


def _yaml_doc(path: str | Path) -> dict[str, Any]:
    from boxplus.calib.io import _load

    return _load(path)


def _number(doc: dict[str, Any], key: str, path: Any, positive: bool = True) -> float:
    if key not in doc:
        raise ValueError(f"{path}: missing key '{key}'")
    try:
        v = float(doc[key])
    except (TypeError, ValueError):
        raise ValueError(f"{path}: '{key}' must be a number, got {doc[key]!r}") from None
    if not math.isfinite(v) or (positive and v <= 0):
        raise ValueError(f"{path}: '{key}' must be {'positive and ' if positive else ''}finite, "
                         f"got {v}")
    return v


def read_kalibr_imu(path: str | Path) -> ImuNoise:
    """Kalibr's imu.yaml (``gyroscope_noise_density``, ``gyroscope_random_walk``,
    ``accelerometer_noise_density``, ``accelerometer_random_walk``, ``update_rate``)."""
    doc = _yaml_doc(path)
    return ImuNoise(_number(doc, "gyroscope_noise_density", path),
                    _number(doc, "gyroscope_random_walk", path),
                    _number(doc, "accelerometer_noise_density", path),
                    _number(doc, "accelerometer_random_walk", path),
                    _number(doc, "update_rate", path))


def read_kalibr_target(path: str | Path) -> Target:
    """Kalibr's target.yaml as a Target: ``checkerboard`` (``targetCols`` ×
    ``targetRows`` inner corners, square ``rowSpacingMeters`` = ``colSpacingMeters``)
    or ``aprilgrid`` (``tagCols`` × ``tagRows``, ``tagSize`` in metres, ``tagSpacing``
    the gap as a fraction of the tag size, Kalibr's 36h11 tags)."""
    doc = _yaml_doc(path)
    kind = str(doc.get("target_type", ""))
    if kind == "checkerboard":
        cols, rows = int(_number(doc, "targetCols", path)), int(_number(doc, "targetRows", path))
        dr, dc = _number(doc, "rowSpacingMeters", path), _number(doc, "colSpacingMeters", path)
        if not math.isclose(dr, dc, rel_tol=1e-9):
            raise ValueError(f"{path}: rowSpacingMeters {dr} and colSpacingMeters {dc} differ; "
                             f"boxplus' chessboard has square cells")
        return Target("chessboard", cols, rows, dc)
    if kind == "aprilgrid":
        return Target("aprilgrid", int(_number(doc, "tagCols", path)),
                      int(_number(doc, "tagRows", path)), _number(doc, "tagSize", path),
                      _number(doc, "tagSpacing", path, positive=False))
    raise ValueError(f"{path}: target_type '{kind}' (boxplus reads 'checkerboard' and "
                     f"'aprilgrid')")


def detect_recording(recording: Recording | Sequence[Recording], target: Target,
                     progress: Callable[[int, int], None] | None = None,
                     names: Sequence[str] | None = None) -> CameraImuData:
    """The target's corners in every image of ``recording`` (an EuRoC folder's or a
    bag's; frames without the target are kept, as None); ``progress(done, total)`` is
    called after each image. A list of recordings is a rig of several cameras with one
    IMU (the IMU samples are the first recording's; each camera named by ``names``,
    else cam0, cam1, …)."""
    recs: list[Recording] = list(recording) if isinstance(recording, (list, tuple)) else [recording]  # type: ignore[list-item]
    names = list(names) if names is not None else [f"cam{i}" for i in range(len(recs))]
    if len(names) != len(recs):
        raise ValueError(f"detect_recording: {len(names)} names for {len(recs)} cameras")
    total = sum(len(r.frame_times) for r in recs)
    done = 0
    cameras = []
    for rec, name in zip(recs, names):
        corners: list[Any] = []
        for _, gray in rec.frames():
            found = target.detect(gray)
            corners.append(None if found is None else (np.asarray(found[0], float),
                                                       np.asarray(found[1], float)))
            done += 1
            if progress is not None:
                progress(done, total)
        if len(corners) != len(rec.frame_times):
            raise ValueError(f"camera {name}: the recording gave {len(corners)} images for "
                             f"{len(rec.frame_times)} frame times")
        cameras.append(CameraFrames(rec.frame_times, corners, name))
    first = recs[0]
    return CameraImuData(first.frame_times, cameras[0].corners, first.imu_times, first.gyro,
                         first.accel, cameras[1:], names[0])
