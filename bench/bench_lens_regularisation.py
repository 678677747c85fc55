"""Distortion regularisation scored against the truth (#32, #29).

Does a light prior on the distortion terms (:mod:`boxplus.calib.regularize`) give
a lens closer to the true one, and at what width s? Every row is a family of
simulated captures of a 9×6 chessboard (board poses that cover the image,
``boxplus.synthetic.images.board_views``), corner noise σ = 0.3 px, re-drawn
per seed, fitted by ``calibrate_mono`` without the prior (``regularize=False``) and with
s in ``--widths``, and by OpenCV's ``calibrateCamera`` (its default termination
criteria, as a user calls it) where OpenCV has the model.
The score is the user's quantity, the projection of the fitted lens against
the true one (:func:`boxplus.calib.lens_diff.projection_difference`, after the
best rotation between the camera frames):

* ``in field``: RMS / max pixel difference over the image pixels whose ray lies
  within the field the corners covered;
* ``image``: RMS over the whole image (extrapolation to the corners of the image);
* ``folds``: captures whose fit folds over inside the field (``fold_angle``);
* ``time``: median seconds per fit (one BLAS thread).

Each column is the median over the seeds, but ``max`` is the largest.

Families: the rational model fitted to rational lenses (mild and strong
distortion), to an opencv5 lens (a user who picks the richer model to be safe),
to a Kannala–Brandt fisheye seen up to 70° (the model mismatch a
user makes with OpenCV's rational model on a wide lens), and ``opencv5`` and
``kannala_brandt`` fitted to their own lenses (the prior must cost nothing
there).

Run: .venv/bin/python bench/bench_lens_regularisation.py [--seeds 20] [--widths 0.5 0.2 0.1 0.05]
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np
from boxplus import blas_threads
from boxplus.calib import calibrate_mono
from boxplus.calib.fold import fold_angle, observed_field
from boxplus.calib.lens_diff import projection_difference
from boxplus.calib.models import intrinsics_vector, project
from boxplus.calib.targets import Target
from boxplus.synthetic.images import board_views

SIZE = (640, 480)
PIXEL_SIGMA = 0.3

# name: (true model, true intrinsics, fitted model, views)
FAMILIES: dict[str, tuple[str, np.ndarray, str, int]] = {
    "rational mild": ("rational", np.array([500.0, 505.0, 320.0, 240.0, -0.25, 0.08, 0.001, -0.0015,
                                            -0.01, 0.02, 0.01, 0.005]), "rational", 20),
    "rational strong": ("rational", np.array([330.0, 331.0, 322.0, 238.0, 0.9, 0.25, 0.0005, -0.0008,
                                              0.01, 1.3, 0.55, 0.06]), "rational", 20),
    "fisheye → rational": ("kannala_brandt", np.array([230.0, 231.0, 320.0, 240.0, 0.02, -0.01, 0.004,
                                                       -0.001]), "rational", 20),
    "opencv5 → rational": ("opencv5", np.array([500.0, 505.0, 320.0, 240.0, -0.25, 0.08, 0.001, -0.0015,
                                                -0.01]), "rational", 20),
    "opencv5": ("opencv5", np.array([500.0, 505.0, 320.0, 240.0, -0.25, 0.08, 0.001, -0.0015, -0.01]),
                "opencv5", 20),
    "kannala_brandt": ("kannala_brandt", np.array([230.0, 231.0, 320.0, 240.0, 0.02, -0.01, 0.004,
                                                   -0.001]), "kannala_brandt", 20),
}


def _capture(true_model: str, k: np.ndarray, n: int, rng: np.random.Generator, target: Target):
    obj = target.points()
    poses = board_views(target, true_model, k, SIZE, n, rng, max_tilt_deg=45.0, fill=0.9)
    if true_model == "kannala_brandt":
        # a pinhole-family fit cannot reach 90°: keep corners within 70° of the axis
        keep = []
        for p in poses:
            pc = p.fromlocal(obj)
            if np.all(np.arctan2(np.hypot(pc[:, 0], pc[:, 1]), pc[:, 2]) < np.radians(70)):
                keep.append(p)
        poses = keep
    z = [project(k, p.fromlocal(obj), true_model) + rng.normal(0, PIXEL_SIGMA, (len(obj), 2))
         for p in poses]
    return obj, z


def _score(k_fit, model, k_true, true_model, field):
    d_field = projection_difference(k_fit, model, k_true, true_model, SIZE, theta_max=field)
    d_image = projection_difference(k_fit, model, k_true, true_model, SIZE)
    folds = fold_angle(np.asarray(k_fit, float), model, field) is not None
    return d_field.rms, d_field.max, d_image.rms, folds


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seeds", type=int, default=20)
    ap.add_argument("--views", type=int, help="views per capture (default: the family's 20)")
    ap.add_argument("--widths", type=float, nargs="+", default=[0.5, 0.2, 0.1, 0.05])
    ap.add_argument("--family", action="append", choices=list(FAMILIES))
    args = ap.parse_args()
    cv2 = None
    try:
        import cv2  # type: ignore[no-redef]
    except ImportError:
        pass
    target = Target("chessboard", 9, 6, 0.04)
    print(f"{'family':20s} {'fit':9s} {'in field RMS/max px':>20s} {'image RMS':>10s} {'folds':>6s} "
          f"{'time s':>6s}")
    for name in args.family or list(FAMILIES):
        true_model, k_true, model, n = FAMILIES[name]
        rows: dict[str, list] = {}
        for seed in range(args.seeds):
            rng = np.random.default_rng(1000 + seed)
            obj, z = _capture(true_model, k_true, args.views or n, rng, target)
            for width in [False, *args.widths]:
                label = "no prior" if width is False else f"s={width:g}"
                t0 = time.perf_counter()
                with warnings.catch_warnings(), blas_threads.limit(1):
                    warnings.simplefilter("ignore")
                    cal = calibrate_mono(z, obj, SIZE, model=model, sigma=PIXEL_SIGMA, regularize=width)
                dt = time.perf_counter() - t0
                field = observed_field(cal, "camera")
                k_fit = cal.problem[cal.ids["camera"]].vec
                rows.setdefault(label, []).append((*_score(k_fit, model, k_true, true_model, field), dt))
            if cv2 is not None and model in ("rational", "opencv5"):
                flags = cv2.CALIB_RATIONAL_MODEL if model == "rational" else 0
                t0 = time.perf_counter()
                _, K, d, _, _ = cv2.calibrateCamera([obj.astype(np.float32)] * len(z),
                                                    [p.astype(np.float32) for p in z], SIZE, None, None,
                                                    flags=flags)
                dt = time.perf_counter() - t0
                k_cv = intrinsics_vector(K, model, d.ravel())
                rows.setdefault("OpenCV", []).append((*_score(k_cv, model, k_true, true_model, field), dt))
        for label, r in rows.items():
            a = np.array(r, float)
            print(f"{name:20s} {label:9s} {np.median(a[:, 0]):9.3f} / {np.max(a[:, 1]):8.3f} "
                  f"{np.median(a[:, 2]):10.3f} {int(a[:, 3].sum()):3d}/{len(a):<2d} {np.median(a[:, 4]):6.2f}")
        print()


if __name__ == "__main__":
    main()
