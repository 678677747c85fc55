"""Calibration files: OpenCV ``FileStorage`` YAML, ROS ``camera_info`` YAML and
Kalibr camchain YAML, written and read, and OpenCV's layout for rectification.

A calibrated rig is a list of :class:`CalibratedCamera`: name, model, intrinsics vector
(:mod:`boxplus.calib.models`), image size and ``cam_from_ref``, the pose that
maps points of the reference camera (the first one) into this camera.

Formats (each file holds what the format can say; a model it cannot express
raises ValueError naming the camera):

* OpenCV YAML, written and read by ``cv2.FileStorage`` itself: ``camera_names``
  (a sequence), per camera ``<name>_model``, ``<name>_image_width``,
  ``<name>_image_height``, ``<name>_camera_matrix`` (3×3),
  ``<name>_distortion_coefficients`` (1×n, in OpenCV's order:
  :data:`~boxplus.calib.models.OPENCV_DISTORTION`) and, for every camera after
  the first, ``<name>_R`` (3×3) and ``<name>_T`` (3×1), the rotation and
  translation of ``cam_from_ref``. A stereo pair with its
  :class:`~boxplus.calib.rectify.StereoRectification` also gets the names of
  OpenCV's ``stereo_calib`` sample — ``M1 D1 M2 D2 R T R1 R2 P1 P2 Q`` — which
  ``cv2.initUndistortRectifyMap`` and ``cv2.StereoSGBM`` pipelines read as they
  are. OpenCV has no double-sphere model: such a camera is refused by name.
* ROS ``camera_info`` (camera_calibration_parsers): one camera per file;
  ``plumb_bob`` (pinhole family), ``rational_polynomial`` (rational) or
  ``equidistant`` (kannala_brandt). The rectification R and projection P are
  those of a stereo pair's rectification (``R1``/``P1`` for the left camera,
  ``R2``/``P2`` with Tx = −f′·B for the right: what ``stereo_image_proc``
  needs), else the identity and [K | 0] (a camera used alone).
* Kalibr camchain: ``cam0``, ``cam1``, …; ``pinhole`` with ``radtan`` (4
  coefficients: k3 must be 0) or ``equidistant``, and ``ds`` (double sphere,
  intrinsics [ξ, α, fu, fv, pu, pv]); ``T_cn_cnm1`` maps camera n−1 into camera
  n; ``cam_overlaps`` lists the cameras that saw the target together with it;
  ``rostopic`` carries the camera's name (``/<name>/image_raw``).

OpenCV's files go through ``cv2.FileStorage`` (a compatible text fallback when
OpenCV is absent), the other YAML files through ``yaml.safe_dump``/``safe_load``
(PyYAML, the ``yaml`` extra; writing falls back to plain text without it). Every
file is written atomically (:mod:`boxplus.files`): a failed write leaves the
previous file as it was.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from boxplus._optional import require
from boxplus.calib.models import camera_matrix, intrinsics_vector, model_labels
from boxplus.calib.rectify import StereoRectification, rectify_stereo
from boxplus.files import atomic_path, write_atomically
from boxplus.manifolds import SE3, SO3

__all__ = ["CalibratedCamera", "read_camchain", "read_camera_info", "read_cameras", "read_opencv_yaml",
           "to_opencv", "write_camchain", "write_camchain_imucam", "write_camera_info",
           "write_opencv_yaml", "write_stereo_camera_info", "write_yaml"]


@dataclass
class CalibratedCamera:
    """One calibrated camera of a rig.

    ``intrinsics`` in the model's order (:data:`boxplus.calib.models.CAMERA_LABELS`),
    ``image_size`` (width, height) in pixels, ``cam_from_ref`` maps points of the
    rig's reference camera into this one (the identity for the reference).
    """

    name: str
    model: str
    intrinsics: np.ndarray
    image_size: tuple[int, int]
    cam_from_ref: SE3 = field(default_factory=SE3)

    def __post_init__(self) -> None:
        k = np.asarray(self.intrinsics, dtype=float).reshape(-1)
        if k.size != len(model_labels(self.model)) or not np.all(np.isfinite(k)):
            raise ValueError(f"camera '{self.name}': model '{self.model}' needs "
                             f"{len(model_labels(self.model))} finite intrinsics, got {k}")
        self.intrinsics = k
        self.image_size = (int(self.image_size[0]), int(self.image_size[1]))

    @property
    def K(self) -> np.ndarray:
        return camera_matrix(self.intrinsics, self.model)[0]

    @property
    def dist(self) -> np.ndarray:
        """The distortion in OpenCV's order for the model."""
        return camera_matrix(self.intrinsics, self.model)[1]


def to_opencv(cameras: Sequence[CalibratedCamera]) -> dict[str, Any]:
    """OpenCV's layout of a rig: {name: {"K", "dist", "image_size", "R", "T"}} with R, T
    the rotation (3×3) and translation (3×1) of cam_from_ref; for two cameras also the
    top-level "K1", "D1", "K2", "D2", "R", "T", "image_size" that ``cv2.stereoRectify``
    (pinhole family) or ``cv2.fisheye.stereoRectify`` (kannala_brandt) take as they are."""
    out: dict[str, Any] = {}
    for c in cameras:
        out[c.name] = {"K": c.K, "dist": c.dist, "image_size": c.image_size, "model": c.model,
                       "R": c.cam_from_ref.rot.R, "T": c.cam_from_ref.pos.reshape(3, 1)}
    if len(cameras) == 2:
        a, b = cameras
        b_from_a = b.cam_from_ref * a.cam_from_ref.inverse()
        out.update(K1=a.K, D1=a.dist, K2=b.K, D2=b.dist, R=b_from_a.rot.R,
                   T=b_from_a.pos.reshape(3, 1), image_size=a.image_size)
    return out


# ---- writing ------------------------------------------------------------------------

def _num(x: float) -> str:
    return repr(float(x))  # shortest round-trip form: a reader gets the same double


def _opencv_matrix(name: str, M: np.ndarray) -> str:
    M = np.atleast_2d(np.asarray(M, dtype=float))
    data = ", ".join(_num(v) for v in M.reshape(-1))
    return (f"{name}: !!opencv-matrix\n   rows: {M.shape[0]}\n   cols: {M.shape[1]}\n"
            f"   dt: d\n   data: [ {data} ]\n")


def _check_name(name: str) -> None:
    if not name or not all(ch.isalnum() or ch == "_" for ch in name) or name[0].isdigit():
        raise ValueError(f"camera name '{name}' cannot be a YAML key prefix: use letters, digits "
                         f"and '_', not starting with a digit")


def write_opencv_yaml(path: str | Path, cameras: Sequence[CalibratedCamera],
                      rectification: StereoRectification | None = None) -> None:
    """Writes the rig as OpenCV FileStorage YAML (through ``cv2.FileStorage`` when OpenCV is
    installed); a stereo pair's ``rectification`` adds ``M1 D1 M2 D2 R T R1 R2 P1 P2 Q``."""
    if not cameras:
        raise ValueError(f"{path}: no cameras to write")
    entries: list[tuple[str, Any]] = [("camera_names", [c.name for c in cameras])]
    for i, c in enumerate(cameras):
        _check_name(c.name)
        if c.model == "double_sphere":
            raise ValueError(f"camera '{c.name}': OpenCV has no double-sphere model (its "
                             f"distortion_coefficients would mean k1, k2); write a Kalibr camchain")
        entries += [(f"{c.name}_model", c.model), (f"{c.name}_image_width", c.image_size[0]),
                    (f"{c.name}_image_height", c.image_size[1]),
                    (f"{c.name}_camera_matrix", c.K),
                    (f"{c.name}_distortion_coefficients", c.dist[None])]
        if i > 0:
            entries += [(f"{c.name}_R", c.cam_from_ref.rot.R),
                        (f"{c.name}_T", c.cam_from_ref.pos.reshape(3, 1))]
    if rectification is not None:
        if len(cameras) != 2:
            raise ValueError(f"{path}: a rectification belongs to a stereo pair, the rig has "
                             f"{len(cameras)} cameras")
        a, b = cameras
        b_from_a = b.cam_from_ref * a.cam_from_ref.inverse()
        r = rectification
        entries += [("M1", a.K), ("D1", a.dist[None]), ("M2", b.K), ("D2", b.dist[None]),
                    ("R", b_from_a.rot.R), ("T", b_from_a.pos.reshape(3, 1)), ("R1", r.R1),
                    ("R2", r.R2), ("P1", r.P1), ("P2", r.P2), ("Q", r.Q)]
    try:
        cv2 = require("cv2", "")
    except ImportError:
        write_atomically(path, _filestorage_text(entries))
        return
    with atomic_path(path) as tmp:
        fs = cv2.FileStorage(str(tmp), cv2.FILE_STORAGE_WRITE | cv2.FILE_STORAGE_FORMAT_YAML)
        for key, value in entries:
            if isinstance(value, list):
                fs.startWriteStruct(key, cv2.FileNode_SEQ)
                for v in value:
                    fs.write("", v)
                fs.endWriteStruct()
            elif isinstance(value, np.ndarray):
                fs.write(key, np.ascontiguousarray(value, dtype=float))
            else:
                fs.write(key, value)
        fs.release()


def _filestorage_text(entries: list[tuple[str, Any]]) -> str:
    """What ``cv2.FileStorage`` writes for these entries, for machines without OpenCV."""
    lines = ["%YAML:1.0\n---\n"]
    for key, value in entries:
        if isinstance(value, list):
            lines.append(f"{key}:\n" + "".join(f"   - {v}\n" for v in value))
        elif isinstance(value, np.ndarray):
            lines.append(_opencv_matrix(key, value))
        else:
            lines.append(f"{key}: {value}\n")
    return "".join(lines)


def _ros_model(c: CalibratedCamera) -> str:
    if c.model == "rational":
        return "rational_polynomial"
    if c.model == "kannala_brandt":
        return "equidistant"
    if c.model == "double_sphere":
        raise ValueError(f"camera '{c.name}': ROS camera_info has no double-sphere model "
                         "(write a Kalibr camchain or OpenCV YAML)")
    return "plumb_bob"


def write_camera_info(path: str | Path, camera: CalibratedCamera, R: np.ndarray | None = None,
                      P: np.ndarray | None = None) -> None:
    """Writes one camera as a ROS ``camera_info`` YAML; ``R`` (3×3) and ``P`` (3×4) are the
    rectification and projection (a stereo pair's ``R1``/``P1`` or ``R2``/``P2`` from
    :func:`boxplus.calib.rectify.rectify_stereo`; default: identity and [K | 0], a camera
    used alone)."""
    model = _ros_model(camera)
    K = camera.K
    R = np.eye(3) if R is None else np.asarray(R, float)
    P = np.column_stack([K, np.zeros(3)]) if P is None else np.asarray(P, float)
    if R.shape != (3, 3) or P.shape != (3, 4):
        raise ValueError(f"camera '{camera.name}': R must be 3×3 and P 3×4, got {R.shape}, {P.shape}")
    doc = {"image_width": int(camera.image_size[0]), "image_height": int(camera.image_size[1]),
           "camera_name": camera.name, "camera_matrix": _ros_mat(K), "distortion_model": model,
           "distortion_coefficients": _ros_mat(camera.dist[None]),
           "rectification_matrix": _ros_mat(R), "projection_matrix": _ros_mat(P)}
    write_yaml(path, doc)


def write_stereo_camera_info(left_path: str | Path, right_path: str | Path, left: CalibratedCamera,
                             right: CalibratedCamera, rectification: StereoRectification | None = None) -> None:
    """The two ``camera_info`` files of a stereo pair with its rectification (computed
    here unless given): what ``stereo_image_proc`` needs to see the baseline."""
    r = rectification if rectification is not None else rectify_stereo(left, right)
    write_camera_info(left_path, left, r.R1, r.P1)
    write_camera_info(right_path, right, r.R2, r.P2)


def _ros_mat(M: np.ndarray) -> dict[str, Any]:
    M = np.atleast_2d(np.asarray(M, dtype=float))
    return {"rows": int(M.shape[0]), "cols": int(M.shape[1]), "data": [float(v) for v in M.reshape(-1)]}


def write_yaml(path: str | Path, doc: dict[str, Any]) -> None:
    """Writes a mapping of plain values atomically: ``yaml.safe_dump`` (block style, keys
    in order) or, without PyYAML, the same mapping as text with the shortest
    round-trip numbers."""
    try:
        yaml = require("yaml", "")
        text = yaml.safe_dump(doc, sort_keys=False, default_flow_style=None, width=1000)
    except ImportError:
        text = _yaml_text(doc)
    write_atomically(path, text)


def _yaml_text(doc: Any, indent: str = "") -> str:
    out = []
    for k, v in doc.items():
        if isinstance(v, dict):
            out.append(f"{indent}{k}:\n" + _yaml_text(v, indent + "  "))
        elif isinstance(v, list) and v and isinstance(v[0], list):
            out.append(f"{indent}{k}:\n" + "".join(f"{indent}- {_flow(row)}\n" for row in v))
        elif isinstance(v, list):
            out.append(f"{indent}{k}: " + ("[" + ", ".join(_scalar(x) for x in v) + "]") + "\n")
        else:
            out.append(f"{indent}{k}: {_scalar(v)}\n")
    return "".join(out)


def _scalar(x: Any) -> str:
    return _num(x) if isinstance(x, float) else str(x)


def _kalibr_entry(c: CalibratedCamera) -> tuple[str, list[float], str, list[float]]:
    """(camera_model, intrinsics, distortion_model, distortion_coeffs) in Kalibr's terms."""
    K, d = c.K, c.dist
    pin = [K[0, 0], K[1, 1], K[0, 2], K[1, 2]]
    if c.model == "double_sphere":
        return "ds", [d[0], d[1], *pin], "none", []
    if c.model == "kannala_brandt":
        return "pinhole", pin, "equidistant", list(d)
    if c.model == "rational":
        raise ValueError(f"camera '{c.name}': Kalibr has no rational model (write OpenCV YAML "
                         "or ROS camera_info)")
    if d[4] != 0:
        raise ValueError(f"camera '{c.name}': Kalibr's radtan has k1 k2 p1 p2 only, k3 = {d[4]:g} "
                         "(calibrate with model 'radial2' or write OpenCV YAML)")
    if not np.any(d):
        return "pinhole", pin, "none", []
    return "pinhole", pin, "radtan", list(d[:4])


def _flow(v: Sequence[float]) -> str:
    return "[" + ", ".join(_num(x) for x in v) + "]"


def _rows(M: np.ndarray) -> list[list[float]]:
    """A matrix as YAML rows of plain floats."""
    return [[float(v) for v in row] for row in M]


def _camchain_entry(c: CalibratedCamera, topic: str | None) -> dict[str, Any]:
    """A camera's lens fields in a Kalibr camchain (camchain and camchain-imucam alike)."""
    cm, intr, dm, dc = _kalibr_entry(c)
    return {"camera_model": cm, "intrinsics": [float(v) for v in intr], "distortion_model": dm,
            "distortion_coeffs": [float(v) for v in dc],
            "resolution": [int(c.image_size[0]), int(c.image_size[1])],
            "rostopic": topic or f"/{c.name}/image_raw"}


def write_camchain(path: str | Path, cameras: Sequence[CalibratedCamera],
                   topics: Sequence[str] | None = None,
                   overlaps: Sequence[Sequence[int]] | None = None) -> None:
    """Writes the rig as a Kalibr camchain YAML (cam0 = the first camera); ``overlaps[i]``
    lists the cameras that saw the target together with camera i (``cam_overlaps``)."""
    doc: dict[str, Any] = {}
    for i, c in enumerate(cameras):
        entry: dict[str, Any] = {}
        if i > 0:
            entry["T_cn_cnm1"] = _rows((c.cam_from_ref * cameras[i - 1].cam_from_ref.inverse()).matrix())
        entry.update(_camchain_entry(c, topics[i] if topics else None))
        if overlaps is not None:
            entry["cam_overlaps"] = [int(j) for j in overlaps[i]]
        doc[f"cam{i}"] = entry
    write_yaml(path, doc)


def write_camchain_imucam(path: str | Path, camera: CalibratedCamera | Sequence[CalibratedCamera],
                          cam_from_imu: SE3 | Sequence[SE3], timeshift: float | Sequence[float],
                          topic: str | Sequence[str] | None = None) -> None:
    """Writes a camera–IMU calibration as Kalibr's ``camchain-imucam.yaml``: each
    camera's entry plus ``T_cam_imu`` (cam_from_imu: IMU coordinates into camera
    coordinates, 4 × 4) and ``timeshift_cam_imu`` (s; t_imu = t_cam + timeshift). Several
    cameras (lists, one entry each) also get ``T_cn_cnm1`` (camera n−1 into camera n,
    from their T_cam_imu), so that the file is a camchain Kalibr's tools read as the rig."""
    cams = [camera] if isinstance(camera, CalibratedCamera) else list(camera)
    poses = [cam_from_imu] if isinstance(cam_from_imu, SE3) else list(cam_from_imu)
    shifts = [float(t) for t in np.atleast_1d(np.asarray(timeshift, dtype=float))]
    topics = [None] * len(cams) if topic is None else [topic] if isinstance(topic, str) else list(topic)
    if not len(cams) == len(poses) == len(shifts) == len(topics):
        raise ValueError(f"write_camchain_imucam: {len(cams)} cameras, {len(poses)} T_cam_imu, "
                         f"{len(shifts)} time shifts and {len(topics)} topics: give one of each per camera")
    doc: dict[str, Any] = {}
    for i, (c, T, d, tp) in enumerate(zip(cams, poses, shifts, topics)):
        entry: dict[str, Any] = {"T_cam_imu": _rows(T.matrix())}
        if i > 0:
            entry["T_cn_cnm1"] = _rows((T * poses[i - 1].inverse()).matrix())
        entry.update(_camchain_entry(c, tp), timeshift_cam_imu=d)
        doc[f"cam{i}"] = entry
    write_yaml(path, doc)


# ---- reading ------------------------------------------------------------------------

def _yaml() -> Any:
    return require("yaml", "reading calibration files")


def _text(path: str | Path) -> str:
    try:
        text = Path(path).read_bytes().decode("utf-8")
    except UnicodeDecodeError as e:
        raise ValueError(f"{path}: not a YAML text file (byte {e.start} is not UTF-8)") from None
    if "\x00" in text:
        raise ValueError(f"{path}: not a YAML text file (it holds NUL bytes)")
    return text


def _load(path: str | Path, opencv: bool = False) -> dict:
    yaml = _yaml()
    text = _text(path)
    if opencv:
        # FileStorage's header and matrix tag are not YAML 1.1: drop the
        # directive, read the tag as a plain mapping.
        text = "\n".join(line for line in text.splitlines() if not line.startswith("%YAML"))
        text = text.replace("!!opencv-matrix", "")
    try:
        doc = yaml.safe_load(text)
    except yaml.YAMLError as e:
        raise ValueError(f"{path}: not valid YAML: {e}") from None
    if not isinstance(doc, dict):
        raise ValueError(f"{path}: expected a YAML mapping at the top")
    return doc


def _get(doc: dict, key: str, path: Any) -> Any:
    if key not in doc:
        raise ValueError(f"{path}: missing '{key}'")
    return doc[key]


def _matrix(doc: dict, key: str, path: Any, shape: tuple[int, ...] | None = None) -> np.ndarray:
    m = _get(doc, key, path)
    try:
        M = np.asarray(m["data"], dtype=float).reshape(int(m["rows"]), int(m["cols"]))
    except (TypeError, KeyError, ValueError):
        raise ValueError(f"{path}: '{key}' must have rows, cols and rows×cols data") from None
    if shape is not None and M.shape != shape:
        raise ValueError(f"{path}: '{key}' must be {shape[0]}×{shape[1]}, got {M.shape[0]}×{M.shape[1]}")
    if not np.all(np.isfinite(M)):
        raise ValueError(f"{path}: '{key}' has non-finite entries")
    return M


def _pose(R: np.ndarray, t: np.ndarray, what: str) -> SE3:
    if abs(np.linalg.det(R) - 1) > 1e-6 or np.abs(R.T @ R - np.eye(3)).max() > 1e-6:
        raise ValueError(f"{what}: not a rotation matrix")
    return SE3(SO3(R), np.asarray(t, float).reshape(3))


def _load_filestorage(path: str | Path) -> dict:
    """An OpenCV YAML file read by ``cv2.FileStorage`` into the mapping _load gives."""
    cv2 = require("cv2", "")
    _text(path)  # a clear error for binary junk before OpenCV parses it
    try:
        fs = cv2.FileStorage(str(path), cv2.FILE_STORAGE_READ | cv2.FILE_STORAGE_FORMAT_YAML)
    except (cv2.error, SystemError) as e:  # some builds wrap cv2.error in a SystemError
        raise ValueError(f"{path}: not an OpenCV FileStorage file: {str(e).strip()[-200:]}") from None
    if not fs.isOpened():
        raise ValueError(f"{path}: cannot be opened as an OpenCV FileStorage file")
    doc: dict[str, Any] = {}
    root = fs.root()
    for key in root.keys():
        node = root.getNode(key)
        if node.isSeq():
            doc[key] = [node.at(i).string() if node.at(i).isString() else node.at(i).real()
                        for i in range(node.size())]
        elif node.isMap():
            M = node.mat()
            doc[key] = None if M is None else {"rows": M.shape[0], "cols": M.shape[1] if M.ndim > 1 else 1,
                                               "data": M.reshape(-1).tolist()}
        elif node.isString():
            doc[key] = node.string()
        else:
            doc[key] = node.real()
    fs.release()
    return doc


def read_opencv_yaml(path: str | Path) -> list[CalibratedCamera]:
    """The rig of a file written by :func:`write_opencv_yaml` (or by hand in that layout),
    read by ``cv2.FileStorage`` (PyYAML when OpenCV is absent)."""
    try:
        doc = _load_filestorage(path)
    except ImportError:
        doc = _load(path, opencv=True)
    names = _get(doc, "camera_names", path)
    if isinstance(names, str):
        names = [names]
    out = []
    for i, n in enumerate(names):
        model = str(_get(doc, f"{n}_model", path))
        K = _matrix(doc, f"{n}_camera_matrix", path, (3, 3))
        d = _matrix(doc, f"{n}_distortion_coefficients", path).reshape(-1)
        try:
            k = intrinsics_vector(K, model, d)
        except ValueError as e:
            raise ValueError(f"{path}: camera '{n}': {e}") from None
        size = (int(_get(doc, f"{n}_image_width", path)), int(_get(doc, f"{n}_image_height", path)))
        pose = SE3()
        if i > 0:
            pose = _pose(_matrix(doc, f"{n}_R", path, (3, 3)), _matrix(doc, f"{n}_T", path, (3, 1)),
                         f"{path}: {n}_R")
        out.append(CalibratedCamera(str(n), model, k, size, pose))
    return out


_ROS_MODELS = {"plumb_bob": "opencv5", "rational_polynomial": "rational",
               "equidistant": "kannala_brandt"}


def read_camera_info(path: str | Path) -> CalibratedCamera:
    """One camera from a ROS ``camera_info`` YAML (plumb_bob, rational_polynomial or
    equidistant)."""
    doc = _load(path)
    dm = str(_get(doc, "distortion_model", path))
    if dm not in _ROS_MODELS:
        raise ValueError(f"{path}: distortion_model '{dm}' (expected one of {sorted(_ROS_MODELS)})")
    model = _ROS_MODELS[dm]
    K = _matrix(doc, "camera_matrix", path, (3, 3))
    d = _matrix(doc, "distortion_coefficients", path).reshape(-1)
    try:
        k = intrinsics_vector(K, model, d)
    except ValueError as e:
        raise ValueError(f"{path}: {e}") from None
    size = (int(_get(doc, "image_width", path)), int(_get(doc, "image_height", path)))
    return CalibratedCamera(str(doc.get("camera_name", "camera")), model, k, size)


def read_camchain(path: str | Path) -> list[CalibratedCamera]:
    """The rig of a Kalibr camchain YAML (pinhole with none / radtan / equidistant, and ds)."""
    doc = _load(path)
    out: list[CalibratedCamera] = []
    i = 0
    while f"cam{i}" in doc:
        c = doc[f"cam{i}"]
        what = f"{path}: cam{i}"
        cm, dm = str(_get(c, "camera_model", what)), str(c.get("distortion_model", "none"))
        intr = np.asarray(_get(c, "intrinsics", what), float)
        dc = np.asarray(c.get("distortion_coeffs", []) or [], float)
        res = _get(c, "resolution", what)
        if cm == "ds" and dm == "none" and intr.size == 6:
            K = np.array([[intr[2], 0, intr[4]], [0, intr[3], intr[5]], [0, 0, 1.0]])
            model, d = "double_sphere", intr[:2]
        elif cm == "pinhole" and intr.size == 4 and dm in ("none", "radtan", "equidistant"):
            K = np.array([[intr[0], 0, intr[2]], [0, intr[1], intr[3]], [0, 0, 1.0]])
            model = {"none": "pinhole", "radtan": "opencv5", "equidistant": "kannala_brandt"}[dm]
            d = dc
            if model == "pinhole" and dc.size:
                raise ValueError(f"{what}: distortion_model none with coefficients {dc}")
        else:
            raise ValueError(f"{what}: unsupported camera_model '{cm}' with distortion_model "
                             f"'{dm}' and {intr.size} intrinsics")
        try:
            k = intrinsics_vector(K, model, d)
        except ValueError as e:
            raise ValueError(f"{what}: {e}") from None
        pose = SE3()
        if i > 0:
            T = np.asarray(_get(c, "T_cn_cnm1", what), float)
            if T.shape != (4, 4):
                raise ValueError(f"{what}: T_cn_cnm1 must be 4×4, got {T.shape}")
            pose = _pose(T[:3, :3], T[:3, 3], f"{what}: T_cn_cnm1") * out[-1].cam_from_ref
        name = str(c.get("rostopic", f"cam{i}")).strip("/").split("/")[0] or f"cam{i}"
        out.append(CalibratedCamera(name, model, k, (int(res[0]), int(res[1])), pose))
        i += 1
    if not out:
        raise ValueError(f"{path}: no cam0 entry (not a Kalibr camchain)")
    return out


def read_cameras(path: str | Path) -> list[CalibratedCamera]:
    """The cameras of a calibration file in any of the formats boxplus writes: OpenCV
    YAML, a Kalibr camchain (also camchain-imucam) or a ROS camera_info; a ValueError
    naming the file when it is none of them."""
    errors = []
    for read in (read_opencv_yaml, read_camchain, lambda p: [read_camera_info(p)]):
        try:
            return read(path)
        except (ValueError, KeyError, TypeError) as e:
            errors.append(str(e))
    raise ValueError(f"{path}: not an OpenCV, Kalibr or ROS calibration file ({errors[0]})")

