"""boxplus beside OpenCV 5's ``calibrateMultiview`` on OpenCV's own real
multi-camera sets, in one run: RMS, the relative poses against the reference
poses of OpenCV's tests (their tolerance: 1° and 10 mm of camera centre), time.

The sets are OpenCV's test data (opencv_extra, ``testdata/cv/cameracalibration/
multiview``): three cameras seeing an asymmetric circle grid (8 × 11, 40 mm), each
camera's corners in ``cam_N.json`` (OpenCV FileStorage JSON, ``frame_i`` a 176 × 1
matrix, missing where the camera did not see the grid):

- ``3cams-hetero``: a fisheye on the floor (cam_4, 2048 × 2048) between two
  pinholes on tripods (cam_7, cam_8, 1920 × 1080); reference poses from OpenCV's
  ``registerCameras`` tests (cam_4 from cam_7, cam_8 from cam_4);
- ``3cams-one-line``, ``3cams-to-floor``: three pinholes; reference poses from the
  ``MultiViewTest`` tests (each camera from cam_0).

The data are not in this repository: point ``--data`` (or ``$BOXPLUS_MULTIVIEW_DATA``)
at that folder or at one set in it. Without either, the script runs ``--seeds`` sets
simulated like 3cams-hetero (:func:`simulate_hetero`: the same cameras at the
reference poses, known lenses, 0.3 px noise, the same file format), where the
reference poses are the truth and the intrinsics are scored against it too, and
prints the medians over the sets.

Rows, for each set:
- OpenCV 5 ``calibrateMultiview`` (rational model for pinholes, fisheye with
  CALIB_RECOMPUTE_EXTRINSIC | CALIB_FIX_SKEW as OpenCV's tests do): each camera's
  intrinsics from its own calibration, then the poses. Run in this interpreter when
  its cv2 has ``calibrateMultiview``, else with ``--opencv5-python PY``.
- boxplus ``calibrate_rig``, every intrinsic free (one joint ML solve; Kannala–Brandt
  for the fisheye, rational with the default light distortion prior for pinholes);
- boxplus with each camera's intrinsics fixed at OpenCV's (the same problem as
  OpenCV's: RMS and poses should agree);
- and the free rig's relative poses against the fixed ones in units of the free
  rig's own σ, with the RigConsistencyWarning a user would see.

Run: .venv/bin/python bench/bench_multiview_real.py --data DIR [--opencv5-python PY]
(OpenCV 5 beside the 4.x of the venv: ``python3 -m venv /tmp/cv5 && /tmp/cv5/bin/pip
install numpy "opencv-python-headless>=5"``, then ``--opencv5-python /tmp/cv5/bin/python``.)
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np

SIZE = {"1080p": (1920, 1080), "720p": (1280, 720), "2k": (2048, 2048)}

# name: (cameras as (file, image size, boxplus model, OpenCV model), frames,
#        reference poses as {(a, b): (R, T) of b_from_a, x_b = R x_a + T})
SETS: dict[str, Any] = {
    "3cams-hetero": (
        [("cam_7", SIZE["1080p"], "rational", "pinhole"),
         ("cam_4", SIZE["2k"], "kannala_brandt", "fisheye"),
         ("cam_8", SIZE["1080p"], "rational", "pinhole")],
        127,
        {("cam_7", "cam_4"): ([[0.9923998627583629, 0.1102270543935739, 0.05470382872247866],
                               [-0.05295473891691575, -0.01873572048960163, 0.9984211377990636],
                               [0.1110779367085268, -0.9937298270945939, -0.01275628155556733]],
                              [0.5132123397314717, -0.345554256449513, 0.7851208074917889]),
         ("cam_4", "cam_8"): ([[0.9987381520324473, -0.03742623778583679, 0.0334870183804049],
                               [0.03272769253311544, -0.02072052049800844, -0.9992494974588425],
                               [0.03809201775004091, 0.999084549352801, -0.01946949994840527]],
                              [0.4660746974363485, 0.7703195273112146, 0.3243138654899712])}),
    "3cams-one-line": (
        [("cam_0", SIZE["1080p"], "rational", "pinhole"),
         ("cam_1", SIZE["1080p"], "rational", "pinhole"),
         ("cam_3", SIZE["1080p"], "rational", "pinhole")],
        96,
        {("cam_0", "cam_1"): ([[0.9996914489704484, -0.01160060078752197, -0.02196435559568884],
                               [0.012283315339906, 0.9994374509454836, 0.03120739995344806],
                               [0.02158997497973892, -0.03146756598408248, 0.9992715673286274]],
                              [0.5078811293323259, 0.002753469433719865, 0.02413521839310227]),
         ("cam_0", "cam_3"): ([[0.9988848194142131, -0.0255827884561986, -0.03968171466355882],
                               [0.0261796234191418, 0.999550713317242, 0.0145944792515729],
                               [0.03929051872229011, -0.0156170561181697, 0.9991057815350362]],
                              [1.007213763725429, 0.01645068247976361, 0.05394643957910365])}),
    "3cams-to-floor": (
        [("cam_0", SIZE["1080p"], "rational", "pinhole"),
         ("cam_1", SIZE["1080p"], "rational", "pinhole"),
         ("cam_2", SIZE["720p"], "rational", "pinhole")],
        125,
        {("cam_0", "cam_1"): ([[-0.05217184989559624, 0.6470741242690249, -0.7606399777686852],
                               [-0.526982982144755, 0.6291523784496631, 0.5713634755748329],
                               [0.8482729717539585, 0.4306534133065782, 0.3081730082260634]],
                              [1.064278166833888, -0.7727142268275895, 1.140555926119704]),
         ("cam_0", "cam_2"): ([[0.001580678474783847, -0.62542080411436, 0.7802860496231537],
                               [0.4843796328138114, 0.683118871472744, 0.5465573883435866],
                               [-0.8748564869569847, 0.3770907387072139, 0.304020890746888]],
                              [-0.9391478506021244, -1.048084838193036, 1.3973875466639])}),
}


def grid_points(cols: int = 8, rows: int = 11, spacing: float = 0.04) -> np.ndarray:
    """OpenCV's asymmetric circle grid in the order its detector returns the centres."""
    return np.array([((2 * j + i % 2) * spacing, i * spacing, 0.0)
                     for i in range(rows) for j in range(cols)])


def load_set(folder: Path, cameras: list[tuple], frames: int) -> dict[str, list[np.ndarray | None]]:
    """{camera: per frame (N, 2) pixels or None} from OpenCV's FileStorage JSON files."""
    out: dict[str, list[np.ndarray | None]] = {}
    for name, *_ in cameras:
        path = folder / f"{name}.json"
        doc = json.loads(path.read_text())
        pts: list[np.ndarray | None] = []
        for i in range(frames):
            node = doc.get(f"frame_{i}")
            if node is None:
                pts.append(None)
                continue
            data = np.asarray(node["data"], dtype=float)
            if data.size != node["rows"] * node["cols"] or data.size % 2:
                raise ValueError(f"{path}: frame_{i} has {data.size} numbers for a "
                                 f"{node['rows']} × {node['cols']} matrix")
            pts.append(data.reshape(-1, 2))
        out[name] = pts
    return out


def pose_error(R: np.ndarray, T: np.ndarray, R_ref: Any, T_ref: Any) -> tuple[float, float]:
    """OpenCV's test metric: rotation angle (deg) and camera-centre distance (mm)."""
    R_ref, T_ref = np.asarray(R_ref), np.asarray(T_ref)
    c = np.clip((np.trace(R_ref.T @ R) - 1) / 2, -1, 1)
    return float(np.degrees(np.arccos(c))), float(np.linalg.norm(R_ref.T @ T_ref - R.T @ T) * 1e3)


# ---- OpenCV 5 -----------------------------------------------------------------------

def run_opencv(folder: Path, set_name: str) -> dict[str, Any]:
    """calibrateMultiview on one set (needs OpenCV 5): RMS, time, K, distortion and
    cam_from_first (R, T) per camera, as plain lists."""
    import cv2

    cv2.setNumThreads(1)
    cameras, frames, _ = SETS[set_name]
    pts = load_set(folder, cameras, frames)
    obj = grid_points().astype(np.float32)
    image_points, mask = [], np.zeros((len(cameras), frames), np.uint8)
    for c, (name, *_) in enumerate(cameras):
        per = []
        for i, p in enumerate(pts[name]):
            mask[c, i] = p is not None
            per.append(np.zeros((0, 1, 2), np.float32) if p is None else p.astype(np.float32).reshape(-1, 1, 2))
        image_points.append(per)
    fisheye = [cam[3] == "fisheye" for cam in cameras]
    models = np.array([cv2.CALIB_MODEL_FISHEYE if f else cv2.CALIB_MODEL_PINHOLE for f in fisheye], np.uint8)
    flags = np.array([cv2.CALIB_RECOMPUTE_EXTRINSIC | cv2.CALIB_FIX_SKEW if f else cv2.CALIB_RATIONAL_MODEL
                      for f in fisheye], np.int32)
    Ks = [np.eye(3) for _ in cameras]
    dists = [np.zeros(4 if f else 8) for f in fisheye]
    t0 = time.perf_counter()
    rms, Ks, dists, Rs, Ts = cv2.calibrateMultiview([obj] * frames, image_points, [c[1] for c in cameras],
                                                    mask, models, Ks, dists, None, None, flags)
    t = time.perf_counter() - t0
    Rm = [cv2.Rodrigues(np.asarray(R, float).reshape(3, 1))[0] if np.size(R) == 3 else np.asarray(R, float)
          for R in Rs]
    return {"rms": float(rms), "time": t, "K": [np.asarray(K, float).tolist() for K in Ks],
            "dist": [np.asarray(d, float).ravel().tolist() for d in dists],
            "R": [R.tolist() for R in Rm], "T": [np.asarray(T, float).ravel().tolist() for T in Ts]}


def opencv_result(folder: Path, set_name: str, python: str | None) -> dict[str, Any] | str:
    import cv2

    if hasattr(cv2, "calibrateMultiview"):
        return run_opencv(folder, set_name)
    if not python:
        return f"OpenCV {cv2.__version__} has no calibrateMultiview (give --opencv5-python)"
    done = subprocess.run([python, __file__, "--opencv-only", set_name, "--data", str(folder)],
                          capture_output=True, text=True, check=False)
    if done.returncode != 0:
        return f"OpenCV 5 run failed: {done.stderr.strip().splitlines()[-1:]}"
    return json.loads(done.stdout)


# ---- boxplus ------------------------------------------------------------------------

def run_boxplus(pts: dict[str, list[np.ndarray | None]], cameras: list[tuple],
                known: dict[str, np.ndarray] | None = None):
    from boxplus.calib import calibrate_rig

    obj = grid_points()
    det = {name: [None if p is None else (p, obj) for p in pts[name]] for name, *_ in cameras}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        t0 = time.perf_counter()
        cal = calibrate_rig(det, {c[0]: c[1] for c in cameras}, model={c[0]: c[2] for c in cameras},
                            known_intrinsics=known)
        t = time.perf_counter() - t0
    return cal, t, [str(w.message) for w in caught]


def rig_pose(cal, cam: str):
    """(R, T) of cam_from_reference in the solved rig."""
    from boxplus import SE3

    p = SE3() if cam == cal.reference else cal.problem[cal.ids[f"{cam}_from_{cal.reference}"]]
    M = p.matrix()
    return M[:3, :3], M[:3, 3]


def _between(a: tuple[np.ndarray, np.ndarray], b: tuple[np.ndarray, np.ndarray]):
    """(R, T) of b_from_a from a_from_ref and b_from_ref."""
    R = b[0] @ a[0].T
    return R, b[1] - R @ a[1]


def relative(cal, a: str, b: str):
    """b_from_a from the rig's cam_from_reference."""
    return _between(rig_pose(cal, a), rig_pose(cal, b))


def opencv_relative(cv: dict[str, Any], names: list[str], a: str, b: str):
    """b_from_a from OpenCV's cam_from_first (R, T) per camera."""
    def pose(c: str) -> tuple[np.ndarray, np.ndarray]:
        return np.asarray(cv["R"][names.index(c)]), np.asarray(cv["T"][names.index(c)])

    return _between(pose(a), pose(b))


def shift_in_sigma(free, fixed, cam: str) -> tuple[float, float]:
    """The largest |Δ| / σ of the free rig's cam_from_reference (translation, rotation
    coordinates of the tangent) between the free and the fixed-intrinsics solve."""
    if cam == free.reference:
        return 0.0, 0.0
    name = f"{cam}_from_{free.reference}"
    d = fixed.problem[fixed.ids[name]] - free.problem[free.ids[name]]
    s = free.problem.std(free.ids[name])
    return float(np.max(np.abs(d[:3] / s[:3]))), float(np.max(np.abs(d[3:] / s[3:])))


def bench_set(folder: Path, set_name: str, python: str | None,
              truth: dict[str, np.ndarray] | None = None) -> dict[str, Any]:
    """One set's rows; ``truth`` {camera: true intrinsics} for a simulated set. Returns
    per method its time, RMS and pose errors against the reference (deg, mm)."""
    from boxplus.calib import intrinsics_vector

    cameras, frames, reference = SETS[set_name]
    names = [c[0] for c in cameras]
    pts = load_set(folder, cameras, frames)
    seen = {n: sum(p is not None for p in pts[n]) for n in names}
    kind = "simulated like " if truth is not None else ""
    print(f"\n== {kind}{set_name}: {', '.join(f'{n} ({c[2]}, {seen[n]} views)' for n, c in zip(names, cameras))}, "
          f"{frames} frames" + ("; the reference poses are the truth" if truth is not None else ""))
    cv = opencv_result(folder, set_name, python)
    free, t_free, warn_free = run_boxplus(pts, cameras)
    rows: list[tuple[str, float, float, Any]] = []
    if isinstance(cv, dict):
        rows.append(("OpenCV 5 calibrateMultiview", cv["rms"], cv["time"],
                     lambda a, b: opencv_relative(cv, names, a, b)))
    rows.append(("boxplus calibrate_rig, intrinsics free", free.rms(), t_free,
                 lambda a, b: relative(free, a, b)))
    fixed = None
    if isinstance(cv, dict):
        known = {n: intrinsics_vector(np.asarray(cv["K"][i]), c[2], cv["dist"][i])
                 for i, (n, c) in enumerate(zip(names, cameras))}
        fixed, t_fixed, _ = run_boxplus(pts, cameras, known)
        rows.append(("boxplus, OpenCV's intrinsics fixed", fixed.rms(), t_fixed,
                     lambda a, b: relative(fixed, a, b)))
    pairs = list(reference)
    head = " | ".join(f"{b} from {a}: Δ° / Δmm" for a, b in pairs)
    print(f"{'method':42s} {'RMS px':>8s} {'time s':>7s} | {head}")
    scores: dict[str, Any] = {}
    for label, rms, t, rel in rows:
        errs = []
        scores[label] = {"time": t, "rms": rms, "deg": [], "mm": []}
        for a, b in pairs:
            ang, pos = pose_error(*rel(a, b), *reference[(a, b)])
            scores[label]["deg"].append(ang)
            scores[label]["mm"].append(pos)
            ok = "" if ang <= 1.0 and pos <= 10.0 else " (outside 1°/10 mm)"
            errs.append(f"{ang:6.3f} / {pos:6.1f}{ok}")
        print(f"{label:42s} {rms:8.4f} {t:7.2f} | " + " | ".join(f"{e:>27s}" for e in errs))
    if not isinstance(cv, dict):
        print(f"  ({cv})")
    if isinstance(cv, dict):
        print(f"  boxplus time / OpenCV time: free {t_free / cv['time']:.2f}, "
              f"fixed {rows[2][2] / cv['time']:.2f}")
        for a, b in pairs:
            ang, pos = pose_error(*relative(fixed, a, b), *opencv_relative(cv, names, a, b))
            print(f"  {b} from {a}: boxplus with OpenCV's intrinsics vs OpenCV: {ang:.4f}° / {pos:.2f} mm")
        for n in names[1:]:
            st, sr = shift_in_sigma(free, fixed, n)
            print(f"  {n}_from_{free.reference}: free vs fixed intrinsics, largest |Δ|/σ: "
                  f"translation {st:.1f}, rotation {sr:.1f}")
    if truth is not None:
        for n in names:
            z = (free.problem[free.ids[n]].vec - truth[n]) / free.problem.std(free.ids[n])
            print(f"  {n} intrinsics, free rig vs the truth: largest |Δ|/σ {np.max(np.abs(z)):.1f}")
    for s in free.intrinsics_shift:
        print(f"  intrinsics, rig vs its own mono fit: {s.camera}: worst {s.worst} {s.worst_sigmas:.1f} σ")
    for w in warn_free:
        print(f"  warning (free rig): {w}")
    return scores


# the simulated set's lenses (models as SETS["3cams-hetero"]) and corner noise (px)
SIMULATED_LENSES = {
    "cam_7": np.array([1400.0, 1395.0, 955.0, 545.0, 0.1, -0.05, 0.0005, -0.0003, 0.01, 0.02, -0.01, 0.0]),
    "cam_4": np.array([600.0, 601.0, 1020.0, 1030.0, 0.02, -0.01, 0.003, -0.001]),
    "cam_8": np.array([1380.0, 1382.0, 965.0, 535.0, -0.08, 0.06, -0.0004, 0.0002, -0.02, 0.01, 0.0, 0.0])}
SIMULATED_NOISE = 0.3
# the largest angle from the optical axis at which a camera records the grid (rad): the
# fisheye's field is cut at 70°: with views out to 80°, 88° or the image's edge (~98°)
# OpenCV 5.1's calibrateMultiview stopped in its fisheye initialisation on seed 0 ("Too
# few image points can be undistorted to estimate the initial pose")
FIELD = {"rational": np.pi / 2, "kannala_brandt": np.radians(70.0)}


def simulate_hetero(folder: Path, seed: int = 0) -> dict[str, np.ndarray]:
    """A set like 3cams-hetero with known truth, written as OpenCV's JSON files: the
    cameras at the reference poses of OpenCV's tests, the lenses of
    :data:`SIMULATED_LENSES`, the grid held in front of each camera in turn (so that
    the fisheye shares views with each pinhole), corners with Gaussian noise; a camera
    records a frame only when every corner is in its image. Returns the true intrinsics."""
    from boxplus import SE3, SO3
    from boxplus.calib.models import project

    cameras, frames, reference = SETS["3cams-hetero"]
    rng = np.random.default_rng(seed)

    def pose(R: Any, T: Any) -> SE3:
        M = np.eye(4)
        M[:3, :3], M[:3, 3] = R, T
        return SE3.from_matrix(M)

    cam_from_7 = {"cam_7": SE3(), "cam_4": pose(*reference[("cam_7", "cam_4")])}
    cam_from_7["cam_8"] = pose(*reference[("cam_4", "cam_8")]) * cam_from_7["cam_4"]
    grid = grid_points()
    docs: dict[str, dict[str, Any]] = {c[0]: {} for c in cameras}
    for i in range(frames):
        facing = cameras[i % 3][0]
        world_from_board = (cam_from_7[facing].inverse()
                            * SE3(SO3.exp(rng.normal(0, 0.4, 3)), np.array([0.0, 0.0, 1.0]) + rng.normal(0, 0.2, 3))
                            * SE3(SO3(), -grid.mean(axis=0)))
        for name, size, model, _ in cameras:
            cam_from_board = cam_from_7[name] * world_from_board
            p = grid @ cam_from_board.rot.R.T + cam_from_board.pos
            if np.any(p[:, 2] < 0.2):
                continue
            uv = project(SIMULATED_LENSES[name], p, model)
            if not np.all(np.isfinite(uv)) or np.any(uv < 0) or np.any(uv >= size):
                continue
            if np.any(np.arccos(np.clip(p[:, 2] / np.linalg.norm(p, axis=1), -1, 1)) > FIELD[model]):
                continue
            uv = uv + rng.normal(0, SIMULATED_NOISE, uv.shape)
            docs[name][f"frame_{i}"] = {"type_id": "opencv-matrix", "rows": uv.size, "cols": 1, "dt": "f",
                                        "data": [float(v) for v in uv.ravel()]}
    folder.mkdir(parents=True, exist_ok=True)
    for name, doc in docs.items():
        (folder / f"{name}.json").write_text(json.dumps(doc))
    return dict(SIMULATED_LENSES)


def _summary(runs: list[dict[str, Any]]) -> None:
    """Medians over the simulated sets each method finished: pose error against the
    truth (the worst camera pair of each set), RMS and time; time also as a ratio to
    OpenCV's on the sets where OpenCV finished."""
    cv_label = "OpenCV 5 calibrateMultiview"
    methods = list(dict.fromkeys(m for r in runs for m in r))
    print(f"\n== over {len(runs)} simulated sets (medians over the sets a method finished; worst "
          f"camera pair of each set)")
    for m in methods:
        done = [r for r in runs if m in r]
        deg = np.median([max(r[m]["deg"]) for r in done])
        mm = np.median([max(r[m]["mm"]) for r in done])
        both = [r for r in done if cv_label in r]
        ratio = (f", {np.median([r[m]['time'] / r[cv_label]['time'] for r in both]):.2f}× OpenCV's time"
                 if both and m != cv_label else "")
        print(f"{m:42s} finished {len(done)}/{len(runs)}: pose error {deg:.3f}° / {mm:.2f} mm, RMS "
              f"{np.median([r[m]['rms'] for r in done]):.4f} px, time {np.median([r[m]['time'] for r in done]):.2f} s"
              + ratio)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--data", type=Path, default=os.environ.get("BOXPLUS_MULTIVIEW_DATA"),
                    help="opencv_extra's testdata/cv/cameracalibration/multiview, or one set in it "
                         "(default: $BOXPLUS_MULTIVIEW_DATA)")
    ap.add_argument("--opencv5-python", help="a Python whose cv2 is OpenCV 5 (for calibrateMultiview)")
    ap.add_argument("--seeds", type=int, default=5, help="simulated sets to run without --data")
    ap.add_argument("--opencv-only", help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.opencv_only:
        print(json.dumps(run_opencv(a.data, a.opencv_only)))
        return 0
    import tempfile

    import threadpoolctl

    if a.data is None:  # we do not ship OpenCV's data: sets like it with known truth
        print(f"bench_multiview_real: no data (--data DIR or $BOXPLUS_MULTIVIEW_DATA: opencv_extra's "
              f"testdata/cv/cameracalibration/multiview); running {a.seeds} simulated sets")
        runs = []
        with tempfile.TemporaryDirectory() as tmp, threadpoolctl.threadpool_limits(1):
            for seed in range(a.seeds):
                folder = Path(tmp) / str(seed) / "3cams-hetero"
                truth = simulate_hetero(folder, seed)
                runs.append(bench_set(folder, folder.name, a.opencv5_python, truth))
        _summary(runs)
        return 0
    a.data = Path(a.data)

    folders = [a.data] if a.data.name in SETS else [a.data / s for s in SETS if (a.data / s).is_dir()]
    if not folders:
        print(f"{a.data}: none of the sets {', '.join(SETS)} found", file=sys.stderr)
        return 2
    with threadpoolctl.threadpool_limits(1):
        for f in folders:
            bench_set(f, f.name, a.opencv5_python)
    return 0


if __name__ == "__main__":
    sys.exit(main())
