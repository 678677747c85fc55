"""``boxplus-calib``: calibrate one, two or N cameras from folders of images.

Examples
--------
One camera, every image of a folder::

    boxplus-calib --target chessboard:9x6:0.025 --out result images/

A stereo pair whose images share a folder (OpenCV's sample: left01.jpg,
right01.jpg, ...); images of one capture are matched by the number in their
file names::

    boxplus-calib --target chessboard:9x6:1 --camera 'left=data/left*.jpg' \\
        --camera 'right=data/right*.jpg' --out result

Three cameras, a fisheye among pinholes, the fisheye's intrinsics known from
an earlier run::

    boxplus-calib --target charuco:7x5:0.04:0.03 --model opencv5 --model fish=kannala_brandt \\
        --known-intrinsics fish=fisheye/calibration.yml cam0/ cam1/ fish/

Steps: detection (a progress bar on a terminal, a line per camera in a log),
the joint solve of :func:`boxplus.calib.calibrate_rig` (one camera: mono, two:
stereo, more: a rig with partial overlap; views a camera cannot use are skipped
and named), optionally dropping outlier corners (``--robust``), then into
``--out``: ``report.txt`` (also printed: RMS per camera and the worst images,
intrinsics and extrinsics with σ, the stereo baseline, what was skipped,
warnings), ``board_poses.csv`` (every view's board pose with σ),
``calibration.yml`` (OpenCV FileStorage; a stereo pair also with OpenCV's
rectification M1 D1 M2 D2 R T R1 R2 P1 P2 Q), ``camchain.yaml`` (Kalibr, with
``cam_overlaps``), one ROS ``camera_info`` YAML per camera (a stereo pair's with
its rectification R and P, Tx = −f′·B) and the PNGs — per-image RMS, the
residuals of each camera by size and by region of the image, its coverage, its
projection uncertainty, and the rig in 3-D.

σ convention: σ from the corner noise ``--sigma`` (px), with the σ rescaled by
the fit's residual beside it.
"""

from __future__ import annotations

import argparse
import functools
import glob
import re
import sys
import warnings
from pathlib import Path
from typing import Any, Callable

import numpy as np

from boxplus._optional import require
from boxplus.files import same_file, write_atomically

__all__ = ["main"]

IMAGE_SUFFIXES = {".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".pgm", ".ppm"}
# The list of files a run wrote into its --out folder: a later run that reads
# that folder as images skips them (its plots are PNGs too).
MANIFEST = ".boxplus-calib-outputs"


def _own_outputs(folder: Path) -> set[str]:
    try:
        return set((folder / MANIFEST).read_text(encoding="utf-8").split("\n")) - {""}
    except (OSError, UnicodeDecodeError):
        return set()


def _images(spec: str) -> list[Path]:
    p = Path(spec)
    if p.is_dir():
        files = sorted(f for f in p.iterdir() if f.suffix.lower() in IMAGE_SUFFIXES)
    else:
        files = sorted(Path(f) for f in glob.glob(spec))
    skip = {f for f in files if f.name in _own_outputs(f.parent)}
    files = [f for f in files if f not in skip]
    if not files:
        raise SystemExit(f"boxplus-calib: no images in '{spec}'"
                         + (f" (its {len(skip)} PNGs are a calibration's own plots)" if skip else ""))
    return files


def _camera_name(spec: str, index: int) -> str:
    """A camera's name from its folder or glob: 'data/left' and 'data/left*.jpg' → 'left'."""
    stem = Path(spec.rstrip("/")).name
    name = re.sub(r"[^A-Za-z0-9_]", "", re.split(r"[*?\[]", stem)[0].split(".")[0])
    return name if name and not name[0].isdigit() else f"cam{index}"


def _key(path: Path) -> str:
    """The capture a file belongs to: the numbers in its name (left01 ↔ right01)."""
    return "-".join(str(int(n)) for n in re.findall(r"\d+", path.stem))


def _match(cams: dict[str, list[Path]]) -> tuple[list[str], dict[str, list[Path | None]]]:
    """(view names, {camera: file per view or None}): by the numbers in the file names
    when they identify each camera's files, else by sorted order."""
    keys = {c: [_key(f) for f in fs] for c, fs in cams.items()}
    if len(cams) > 1 and all(len(set(k)) == len(k) and all(k) for k in keys.values()):
        views = sorted({k for ks in keys.values() for k in ks}, key=lambda s: [int(x) for x in s.split("-")])
        out = {c: [dict(zip(keys[c], fs)).get(v) for v in views] for c, fs in cams.items()}
        return views, out
    n = max(len(fs) for fs in cams.values())
    if len(cams) > 1 and len({len(fs) for fs in cams.values()}) > 1:
        raise SystemExit("boxplus-calib: the cameras have different numbers of images and their "
                         "file names carry no capture numbers to match them")
    first = next(iter(cams.values()))
    return [f.name for f in first] if len(cams) == 1 else [str(i) for i in range(n)], \
        {c: list(fs) for c, fs in cams.items()}


class _DetectionProgress:
    """Progress of the detection: a bar (tqdm) or a line rewritten with \\r on a terminal,
    one line per camera when done in a log file (no 900-character line of \\r updates)."""

    def __init__(self, camera: str, total: int, quiet: bool) -> None:
        self.camera, self.total, self.found, self.done = camera, total, 0, 0
        self.quiet = quiet
        self.tty = sys.stderr.isatty()
        self.bar = None
        if not quiet and self.tty:
            try:
                tqdm = require("tqdm.auto", "a progress bar").tqdm
                self.bar = tqdm(total=total, desc=f"detecting {camera}", unit="image", leave=True)
            except ImportError:
                pass

    def step(self, found: bool) -> None:
        self.done += 1
        self.found += found
        if self.quiet:
            return
        if self.bar is not None:
            self.bar.update(1)
            self.bar.set_postfix_str(f"{self.found} with the target")
        elif self.tty:
            print(f"\rdetecting {self.camera}: {self.done}/{self.total} ({self.found} with the "
                  f"target)", end="", file=sys.stderr, flush=True)

    def close(self) -> None:
        if self.quiet:
            return
        if self.bar is not None:
            self.bar.close()
        else:
            print(("\r" if self.tty else "") + f"detecting {self.camera}: {self.done}/{self.total} "
                  f"({self.found} with the target)", file=sys.stderr, flush=True)


def _detect(target: Any, cams: dict[str, list[Path | None]], quiet: bool) -> tuple[dict, dict]:
    try:
        cv2 = require("cv2", "reading images and finding the target")
    except ImportError as e:
        raise SystemExit(f"boxplus-calib: {e}") from None
    detections: dict[str, list[Any]] = {}
    sizes: dict[str, tuple[int, int]] = {}
    for c, files in cams.items():
        det: list[Any] = []
        progress = _DetectionProgress(c, len(files), quiet)
        for f in files:
            if f is None:
                det.append(None)
                progress.step(False)
                continue
            img = cv2.imread(str(f), cv2.IMREAD_GRAYSCALE)
            if img is None:
                raise SystemExit(f"boxplus-calib: cannot read the image '{f}'")
            size = (img.shape[1], img.shape[0])
            if sizes.setdefault(c, size) != size:
                raise SystemExit(f"boxplus-calib: '{f}' is {size[0]}×{size[1]}, camera {c}'s other "
                                 f"images are {sizes[c][0]}×{sizes[c][1]}")
            d = target.detect(img)
            det.append(d)
            progress.step(d is not None)
        progress.close()
        detections[c] = det
    return detections, sizes


def _parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(
        prog="boxplus-calib", description=__doc__.split("\n\n")[0] if __doc__ else None,
        formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("folders", nargs="*", help="one folder (or glob) of images per camera; the "
                    "camera is named after the folder")
    ap.add_argument("--camera", action="append", default=[], metavar="NAME=FOLDER_OR_GLOB",
                    help="a camera and its images (repeat for more cameras)")
    ap.add_argument("--target", required=True,
                    help="chessboard:COLSxROWS:SQUARE, charuco:COLSxROWS:SQUARE:MARKER[:DICT] or "
                    "aprilgrid:COLSxROWS:TAG:SPACING[:DICT] (sizes in your unit, e.g. metres)")
    ap.add_argument("--model", action="append", default=[], metavar="[CAMERA=]MODEL",
                    help="camera model: simple_radial, pinhole, radial1, radial2, opencv5, "
                    "rational, kannala_brandt or double_sphere (default opencv5); CAMERA=MODEL "
                    "for one camera (repeat), a bare MODEL for the others")
    ap.add_argument("--known-intrinsics", action="append", default=[], metavar="CAMERA=FILE",
                    help="hold a camera's intrinsics at those of an earlier calibration (an "
                    "OpenCV YAML, Kalibr camchain or ROS camera_info file; the camera of that "
                    "name in it, or its only camera); repeat for more cameras")
    ap.add_argument("--sigma", type=float, default=1.0, help="corner noise σ in px (default 1)")
    ap.add_argument("--robust", type=float, nargs="?", const=5.0, default=None, metavar="K",
                    help="drop corners whose error exceeds K σ̂ and re-solve (K default 5)")
    reg = ap.add_mutually_exclusive_group()
    reg.add_argument("--regularize", type=float, nargs="?", const=True, default=None, metavar="S",
                     help="pull every camera's distortion terms lightly towards 0 (a prior of "
                     "width S of their effect at the field's edge, default 0.1); without it only "
                     "rational cameras are regularised")
    reg.add_argument("--no-regularize", dest="regularize", action="store_false",
                     help="no distortion prior, not even for rational cameras (OpenCV's problem)")
    ap.add_argument("--distance", type=float, default=None,
                    help="distance for the projection uncertainty (target units; default the "
                    "median distance of the boards)")
    ap.add_argument("--out", default="calibration", help="output folder (default ./calibration); "
                    "every file is written atomically (a failed write keeps the previous file)")
    ap.add_argument("--write-into-input", action="store_true",
                    help="allow --out to be a folder the images are read from (its outputs are "
                    "then listed in .boxplus-calib-outputs and skipped by later runs)")
    ap.add_argument("--suggest", type=int, default=0, metavar="N",
                    help="rank N board poses to capture next per camera (the worst projection σ "
                         "they would leave): suggested_views.csv and suggestions_CAMERA.png")
    ap.add_argument("--profile", action="store_true",
                    help="also give every free intrinsic's profile-likelihood interval at 3σ "
                         "(held at each value, every other parameter re-adjusted: asymmetric "
                         "where σ is not enough, e.g. a double sphere's f, ξ and α; about 40 "
                         "solves per parameter)")
    ap.add_argument("--no-plots", action="store_true", help="write no PNGs")
    ap.add_argument("--quiet", action="store_true", help="no progress lines")
    return ap


def _models(specs: list[str], cams: list[str]) -> dict[str, str]:
    """{camera: model} from repeated --model MODEL / CAMERA=MODEL."""
    from boxplus.calib.models import model_labels

    default, named = "opencv5", {}
    for spec in specs:
        cam, sep, model = spec.rpartition("=")
        try:
            model_labels(model)
        except ValueError as e:
            raise SystemExit(f"boxplus-calib: --model '{spec}': {e}") from None
        if not sep:
            default = model
        elif cams and cam not in cams:
            raise SystemExit(f"boxplus-calib: --model '{spec}': no camera '{cam}' (cameras: "
                             f"{', '.join(cams)})")
        else:
            named[cam] = model
    return {c: named.get(c, default) for c in cams}


def _known_intrinsics(specs: list[str], models: dict[str, str]) -> dict[str, Any]:
    """{camera: intrinsics} from --known-intrinsics CAMERA=FILE (any of the three formats)."""
    from boxplus.calib import io

    out = {}
    for spec in specs:
        cam, sep, path = spec.partition("=")
        if not sep or cam not in models:
            raise SystemExit(f"boxplus-calib: --known-intrinsics '{spec}': expected CAMERA=FILE with "
                             f"CAMERA one of {', '.join(models)}")
        try:
            rig = io.read_cameras(path)
        except OSError as e:
            raise SystemExit(f"boxplus-calib: --known-intrinsics: {e}") from None
        except ValueError as e:
            raise SystemExit(f"boxplus-calib: --known-intrinsics '{path}': {e}") from None
        found = [c for c in rig if c.name == cam] or (rig if len(rig) == 1 else [])
        if not found:
            raise SystemExit(f"boxplus-calib: --known-intrinsics '{path}': no camera '{cam}' in it "
                             f"(it has {', '.join(c.name for c in rig)})")
        if found[0].model != models[cam]:
            raise SystemExit(f"boxplus-calib: --known-intrinsics '{path}': camera '{cam}' is a "
                             f"{found[0].model} there, --model says {models[cam]}")
        out[cam] = found[0].intrinsics
    return out


def main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    from boxplus.calib.targets import parse_target

    try:
        target = parse_target(args.target)
    except ValueError as e:
        raise SystemExit(f"boxplus-calib: {e}") from None
    _models(args.model, [])  # unknown model names fail before the images are read
    cams: dict[str, list[Path]] = {}
    for spec in args.camera:
        name, sep, where = spec.partition("=")
        if not sep or not name:
            raise SystemExit(f"boxplus-calib: --camera '{spec}': expected NAME=FOLDER_OR_GLOB")
        cams[name] = _images(where)
    for folder in args.folders:
        name = _camera_name(folder, len(cams))
        if name in cams:
            name = f"{name}{len(cams)}"
        cams[name] = _images(folder)
    if not cams:
        raise SystemExit("boxplus-calib: no images: give folders or --camera NAME=GLOB")
    for name in cams:
        if not name.isidentifier():
            raise SystemExit(f"boxplus-calib: camera name '{name}' must be letters, digits and "
                             f"'_', not starting with a digit (it names keys in the output files)")
    if args.suggest < 0:
        raise SystemExit(f"boxplus-calib: --suggest must be >= 0, got {args.suggest}")
    _check_output_folder(Path(args.out), cams, args.write_into_input)
    models = _models(args.model, list(cams))
    known = _known_intrinsics(args.known_intrinsics, models)
    view_names, files = _match(cams)
    detections, sizes = _detect(target, files, args.quiet)
    # views no camera saw the target in are left out
    keep = [i for i in range(len(view_names)) if any(d[i] is not None for d in detections.values())]
    from boxplus.calib.rig import RigConsistencyWarning, calibrate_rig

    try:
        for c in detections:
            if c not in sizes:
                raise ValueError(f"camera {c}: no readable image")
        with warnings.catch_warnings():  # the report names them
            warnings.simplefilter("ignore", RigConsistencyWarning)
            cal = calibrate_rig({c: [d[i] for i in keep] for c, d in detections.items()}, sizes,
                                models, sigma=args.sigma, robust=args.robust,
                                view_names=[view_names[i] for i in keep], known_intrinsics=known,
                                regularize=args.regularize)
    except ValueError as e:
        raise SystemExit(f"boxplus-calib: {e}") from None
    file_names = {c: [f.name if (f := files[c][i]) is not None else "" for i in keep] for c in files}
    _write(cal, file_names, args)
    return 0


def _check_output_folder(out: Path, cams: dict[str, list[Path]], allowed: bool) -> None:
    """--out must be a folder (or not exist yet) and, unless allowed, not hold images read."""
    if out.exists() and not out.is_dir():
        raise SystemExit(f"boxplus-calib: --out '{out}' is a file, not a folder")
    if allowed or not out.is_dir():
        return
    for name, files in cams.items():
        if any(same_file(f.parent, out) for f in files):
            raise SystemExit(f"boxplus-calib: --out '{out}' is the folder camera '{name}' reads "
                             f"its images from; choose another folder, or --write-into-input")


def _write(cal: Any, file_names: dict[str, list[str]], args: Any) -> None:
    try:
        _write_outputs(cal, file_names, args)
    except OSError as e:
        raise SystemExit(f"boxplus-calib: {e.strerror or e} ('{e.filename or args.out}'); "
                         f"files written before are complete, none is truncated") from None


def _write_outputs(cal: Any, file_names: dict[str, list[str]], args: Any) -> None:
    from boxplus.calib import io
    from boxplus.calib.summary import board_poses_csv, summarise
    from boxplus.calib.uncertainty import projection_uncertainty

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    _record_outputs(out, _planned_outputs(cal, args))
    rep = cal.report()
    cams = cal.cameras()
    notes: list[str] = []
    rect = None
    if len(cams) == 2:
        from boxplus.calib.rectify import rectify_stereo

        try:
            rect = rectify_stereo(*cams)
        except (ValueError, ImportError) as e:
            notes.append(f"no stereo rectification: {e}")
    distance = args.distance or _median_distance(cal)
    uncs, unc_lines = {}, []
    for c in cal.view_ids:
        try:
            # from the fitted noise (σ·σ̂): the given --sigma is a guess, often 10× too large
            uncs[c] = projection_uncertainty(cal, c, distance, rescale=True)
            unc_lines.append(str(uncs[c]))
        except ValueError as e:
            unc_lines.append(f"{c}: no projection uncertainty: {e}")
    written = []
    overlaps = _overlaps(cal)
    files: list[tuple[str, Callable[[], None]]] = [
        ("calibration.yml", lambda: io.write_opencv_yaml(out / "calibration.yml", cams, rect)),
             ("camchain.yaml", lambda: io.write_camchain(out / "camchain.yaml", cams,
                                                         overlaps=overlaps))]
    if rect is not None:
        a, b = cams
        files.append((f"{a.name}_camera_info.yaml and {b.name}_camera_info.yaml",
                      lambda: io.write_stereo_camera_info(out / f"{a.name}_camera_info.yaml",
                                                          out / f"{b.name}_camera_info.yaml", a, b,
                                                          rect)))
    else:
        for c in cams:
            files.append((f"{c.name}_camera_info.yaml",
                          functools.partial(io.write_camera_info, out / f"{c.name}_camera_info.yaml", c)))
    files.append(("board_poses.csv",
                  lambda: write_atomically(out / "board_poses.csv", board_poses_csv(cal, rep))))
    for what, fn in files:
        try:
            fn()
            written.append(what)
        except ValueError as e:
            notes.append(f"not written: {what}: {e}")
    if not args.no_plots:
        written += _plots(cal, out, uncs, file_names)
    suggest_lines = _suggest(cal, rep, distance, out, args, written) if args.suggest > 0 else []
    profile_lines = _profile(cal, args.quiet) if args.profile else []
    text = summarise(cal, rep, file_names, args.target, rect)
    text += "\n" + "\n".join(["Projection uncertainty:", *unc_lines, *suggest_lines, *profile_lines,
                              *notes])
    text += "\nwrote " + ", ".join(written + ["report.txt"]) + f" to {out}"
    full = text + "\n\nAll parameters but the board poses (those are in board_poses.csv):\n" + \
        "\n".join(line for line in str(rep).splitlines() if "world_from_" not in line)
    write_atomically(out / "report.txt", full + "\n")
    print(text)


def _suggest(cal: Any, rep: Any, distance: float, out: Path, args: Any, written: list[str]) -> list[str]:
    """--suggest N: the board poses to capture next per camera, as lines of the
    report, a CSV and a picture per camera (the fitted noise, as the uncertainty maps)."""
    from boxplus.calib.suggest import suggest_views, suggestions_csv

    lines, every = [f"Capture next (--suggest {args.suggest}):"], []
    for c in cal.view_ids:
        try:
            got = suggest_views(cal, c, args.suggest, distance=distance,
                                sigma_factor=rep.sigma_factor)
        except ValueError as e:
            lines.append(f"  {c}: no suggestion: {e}")
            continue
        every += got
        lines += [f"  {s}" for s in got]
        if not args.no_plots:
            from boxplus.calib import plot

            plot.plot_suggestions(cal, got, c, path=out / f"suggestions_{c}.png")
            written.append(f"suggestions_{c}.png")
    write_atomically(out / "suggested_views.csv", suggestions_csv(every))
    written.append("suggested_views.csv")
    return lines


def _profile(cal: Any, quiet: bool) -> list[str]:
    """--profile: each free intrinsic's profile-likelihood interval at 3σ, as report lines
    (the given corner noise, as the report's σ; boxplus/profile.py)."""
    lines = ["Profile-likelihood intervals at 3σ (each intrinsic held, every other parameter "
             "re-adjusted; from the given corner noise):"]
    for c in cal.view_ids:
        vid = cal.ids[c]
        if cal.problem.is_fixed(vid):
            lines.append(f"  {c}: held fixed (known intrinsics)")
            continue
        labels = cal.problem.labels(vid)
        if not quiet:
            print(f"profiling {c}: {len(labels)} intrinsics", file=sys.stderr, flush=True)
        for lab in labels:
            try:
                lines.append(f"  {cal.profile(c, lab, level=3.0)}")
            except ValueError as e:
                lines.append(f"  {c}.{lab}: no interval: {e}")
    return lines


def _overlaps(cal: Any) -> list[list[int]]:
    """For each camera, the cameras that saw the target in the same views (Kalibr's
    cam_overlaps)."""
    names = list(cal.view_ids)
    seen = {c: set(cal.view_index[c]) for c in names}
    return [[j for j, d in enumerate(names) if d != c and seen[c] & seen[d]] for c in names]


def _planned_outputs(cal: Any, args: Any) -> list[str]:
    """Every file a run may write into --out, listed before any is written."""
    names = ["report.txt", "calibration.yml", "camchain.yaml", "board_poses.csv"]
    names += [f"{c.name}_camera_info.yaml" for c in cal.cameras()]
    if not args.no_plots:
        names += ["rms_per_image.png", "rig.png"]
        for c in cal.view_ids:
            names += [f"residuals_{c}.png", f"coverage_{c}.png", f"uncertainty_{c}.png"]
    if args.suggest > 0:
        names.append("suggested_views.csv")
        if not args.no_plots:
            names += [f"suggestions_{c}.png" for c in cal.view_ids]
    return names


def _record_outputs(out: Path, names: list[str]) -> None:
    write_atomically(out / MANIFEST, "\n".join(sorted(_own_outputs(out) | set(names))) + "\n")


def _median_distance(cal: Any) -> float:
    o = cal.problem
    d = [np.linalg.norm(o[v].pos) for v in cal.world_from_ref if v is not None]
    return float(np.median(d))


def _plots(cal: Any, out: Path, uncs: dict, file_names: dict[str, list[str]]) -> list[str]:
    from boxplus.calib import plot

    o = cal.problem
    written = []
    names = {c: [file_names[c][i] for i in cal.view_index[c]] for c in cal.view_ids}
    plot.plot_rms_per_image(o, cal.view_ids, names, path=out / "rms_per_image.png",
                            title="RMS reprojection error per image (px)")
    written.append("rms_per_image.png")
    for c in cal.view_ids:
        plot.plot_residual_field(cal, c, path=out / f"residuals_{c}.png")
        plot.plot_coverage(cal, c, path=out / f"coverage_{c}.png")
        written += [f"residuals_{c}.png", f"coverage_{c}.png"]
        if c in uncs:
            plot.plot_projection_uncertainty(uncs[c], path=out / f"uncertainty_{c}.png")
            written.append(f"uncertainty_{c}.png")
    # the rig in the reference camera's frame: cameras and every board pose
    frames = {cam.name: cam.cam_from_ref.inverse() for cam in cal.cameras()}
    boards, bnames = [], []
    obj: dict[int, np.ndarray] = {}
    for ob in cal.observations:
        obj.setdefault(ob.view, ob.obj)
    for i, v in enumerate(cal.world_from_ref):
        if v is not None:
            boards.append((o[v].inverse(), obj[i]))
            bnames.append(cal.view_names[i])
    size = max(np.ptp(np.concatenate(list(obj.values())), axis=0).max(), 1e-9)
    plot.plot_rig(out / "rig.png", frames, boards, length=0.3 * size, title="rig and boards",
                  board_names=bnames)
    written.append("rig.png")
    return written


if __name__ == "__main__":
    sys.exit(main())
