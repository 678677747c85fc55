"""Tutorial: calibrate a camera from images of a chessboard.

    python docs/tutorials/calibration.py [IMAGE_DIR] [--pattern 9x6] [--out DIR]

IMAGE_DIR holds the images (``*.jpg``/``*.png``) of a chessboard with PATTERN
inner corners; corners are detected with OpenCV (opencv-python-headless).
Without IMAGE_DIR the tutorial uses the corners that the repository ships
(data/calib/opencv_stereo_corners.npz: the same detection run on OpenCV's
sample images left01…14.jpg). It writes the pictures of the tutorial
(calibration_errors.png, calibration_views.png) into DIR (default: this folder).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import boxplus.calib as calib
import matplotlib.pyplot as plt
import numpy as np

HERE = Path(__file__).resolve().parent
CORNERS = HERE.parents[1] / "data" / "calib" / "opencv_stereo_corners.npz"


def corners_from_images(folder: Path, pattern: tuple[int, int]):
    """(image points per view, board points, image size) from a folder of images."""
    import cv2

    files = sorted(p for p in folder.iterdir() if p.suffix.lower() in (".jpg", ".png"))
    images = [cv2.imread(str(p), cv2.IMREAD_GRAYSCALE) for p in files]
    found = calib.detect_corners(images, pattern)  # None where no board was seen
    views = [c for c in found if c is not None]
    print(f"{len(views)} of {len(files)} images show the board")
    cols, rows = pattern
    board = np.array([[i, j, 0.0] for j in range(rows) for i in range(cols)])  # unit: a square
    height, width = images[0].shape[:2]
    return views, board, (width, height)


def shipped_corners():
    d = np.load(CORNERS)
    views = [p for p, ok in zip(d["image_points_left"], d["found_left"]) if ok]
    return views, d["object_points"], tuple(int(s) for s in d["image_size"])


def calibrate(views, board, image_size, out: Path) -> dict:
    # Zhang's closed form for the start, then maximum likelihood over the
    # intrinsics (OpenCV's 5-coefficient model) and one board pose per view.
    cal = calib.calibrate_mono(views, board, image_size, model="opencv5", sigma=1.0)
    rep = cal.report(rescale=True)  # σ scaled by the residuals' own spread
    print(rep)
    errors = cal.problem.errors()["camera"]  # (corners, 2) in pixels
    per_view = np.sqrt(np.mean(np.sum(errors.reshape(len(views), -1, 2) ** 2, axis=2), axis=1))

    fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4.2))
    a.bar(np.arange(len(per_view)), per_view, color="C0")
    a.set_xlabel("view")
    a.set_ylabel("RMS reprojection error [px]")
    a.set_title("per view")
    b.scatter(errors[:, 0], errors[:, 1], s=4, color="C0")
    b.set_aspect("equal", adjustable="datalim")
    b.set_xlabel("u error [px]")
    b.set_ylabel("v error [px]")
    b.set_title("every corner")
    fig.tight_layout()
    fig.savefig(out / "calibration_errors.png", dpi=90)
    plt.close(fig)

    # The board poses seen from the camera: camera frame at the origin.
    fig = plt.figure(figsize=(6, 5))
    ax = fig.add_subplot(1, 1, 1, projection="3d")
    o = cal.problem
    for k in range(o.num_variables):
        if o.variable_name(k).startswith("world_from_camera_"):
            cam_from_world = o.value(k).inverse()
            p = cam_from_world * board  # board corners in the camera frame
            ax.plot(p[:, 0], p[:, 2], -p[:, 1], ".", ms=1.5)
    ax.plot([0], [0], [0], "k^", ms=8, label="camera")
    ax.set_xlabel("x [squares]")
    ax.set_ylabel("z (depth) [squares]")
    ax.set_zlabel("-y [squares]")
    ax.legend(loc="upper left")
    ax.set_title("board in each view, camera frame")
    fig.tight_layout()
    fig.savefig(out / "calibration_views.png", dpi=90)
    plt.close(fig)
    return {"rms_px": float(np.sqrt(np.mean(np.sum(errors**2, axis=1)))), "views": len(views),
            "report": rep}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("images", type=Path, nargs="?")
    ap.add_argument("--pattern", default="9x6", help="inner corners, COLSxROWS")
    ap.add_argument("--out", type=Path, default=HERE)
    args = ap.parse_args()
    if args.images is None:
        views, board, size = shipped_corners()
    else:
        cols, rows = (int(v) for v in args.pattern.split("x"))
        views, board, size = corners_from_images(args.images, (cols, rows))
    args.out.mkdir(parents=True, exist_ok=True)
    result = calibrate(views, board, size, args.out)
    print(f"RMS reprojection error {result['rms_px']:.4f} px over {result['views']} views")


if __name__ == "__main__":
    main()
