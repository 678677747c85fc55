"""Tutorial: a stereo pair, from images to rectified images.

    python docs/tutorials/stereo.py [--out DIR] [--calibration DIR]

Calibrates the stereo pair of OpenCV's sample images (bundled in
data/calib/opencv_stereo) with the command line ``boxplus-calib``, then uses the
files it wrote the way their consumers do: OpenCV reads calibration.yml, and the
ROS camera_info files rectify a pair as ROS' stereo_image_proc would. Writes the
calibration into --calibration (default: stereo_calibration in the current folder)
and the tutorial's picture (stereo_rectified.png) into --out (default: this folder).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import cv2
import matplotlib.pyplot as plt
import numpy as np
import yaml
from boxplus.calib import cli

HERE = Path(__file__).resolve().parent
IMAGES = HERE.parents[1] / "data" / "calib" / "opencv_stereo"


def calibrate(out: Path) -> None:
    # The same as typing, in a shell:
    #   boxplus-calib --target chessboard:9x6:1 --camera 'left=.../left*.jpg' \
    #                 --camera 'right=.../right*.jpg' --out OUT
    # The board's unit is one square: every translation comes out in squares.
    cli.main(["--target", "chessboard:9x6:1",
              "--camera", f"left={IMAGES}/left*.jpg",
              "--camera", f"right={IMAGES}/right*.jpg",
              "--out", str(out), "--quiet"])


def read_opencv(out: Path) -> dict:
    # OpenCV's own reader: stereo_calib's names M1 D1 M2 D2 R T (right_from_left).
    fs = cv2.FileStorage(str(out / "calibration.yml"), cv2.FILE_STORAGE_READ)
    m = {k: fs.getNode(k).mat() for k in ("M1", "D1", "M2", "D2", "R", "T")}
    fs.release()
    return m


def rectify_like_ros(out: Path, name: str, image: np.ndarray) -> np.ndarray:
    # What stereo_image_proc does with a camera_info: undistort with K and D,
    # rotate by R, project with P (whose Tx = -f'B on the right camera).
    info = yaml.safe_load((out / f"{name}_camera_info.yaml").read_text())
    K = np.reshape(info["camera_matrix"]["data"], (3, 3))
    D = np.asarray(info["distortion_coefficients"]["data"])
    R = np.reshape(info["rectification_matrix"]["data"], (3, 3))
    P = np.reshape(info["projection_matrix"]["data"], (3, 4))
    size = (info["image_width"], info["image_height"])
    map1, map2 = cv2.initUndistortRectifyMap(K, D, R, P[:, :3], size, cv2.CV_32FC1)
    return cv2.remap(image, map1, map2, cv2.INTER_LINEAR), P


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=HERE)
    ap.add_argument("--calibration", type=Path, default=Path("stereo_calibration"))
    args = ap.parse_args()
    out = args.calibration
    calibrate(out)

    m = read_opencv(out)
    print(f"OpenCV reads: baseline |T| = {np.linalg.norm(m['T']):.4f} squares, "
          f"fx left {m['M1'][0, 0]:.2f} px, right {m['M2'][0, 0]:.2f} px")

    left = cv2.imread(str(IMAGES / "left01.jpg"), cv2.IMREAD_GRAYSCALE)
    right = cv2.imread(str(IMAGES / "right01.jpg"), cv2.IMREAD_GRAYSCALE)
    left_r, P1 = rectify_like_ros(out, "left", left)
    right_r, P2 = rectify_like_ros(out, "right", right)
    print(f"ROS reads: f' = {P1[0, 0]:.2f} px, baseline -Tx/f' = {-P2[0, 3] / P2[0, 0]:.4f} squares")

    # After rectification a board corner lies on the same row in both images.
    pattern = (9, 6)
    stop = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 50, 1e-3)
    c_left, c_right = (cv2.cornerSubPix(im, cv2.findChessboardCorners(im, pattern)[1], (5, 5),
                                        (-1, -1), stop) for im in (left_r, right_r))
    dv = c_left[:, 0, 1] - c_right[:, 0, 1]
    print(f"row difference of the 54 corners after rectification: "
          f"mean {dv.mean():+.3f} px, RMS {np.sqrt(np.mean(dv ** 2)):.3f} px")

    fig, ax = plt.subplots(figsize=(12, 4.8))
    ax.imshow(np.hstack([left_r, right_r]), cmap="gray")
    for v in np.linspace(40, 440, 11):
        ax.axhline(v, color="tab:green", lw=0.6)
    ax.plot(c_left[:, 0, 0], c_left[:, 0, 1], "r+", ms=5, label="corners found")
    ax.plot(c_right[:, 0, 0] + left_r.shape[1], c_right[:, 0, 1], "r+", ms=5)
    ax.set(title=f"left01 and right01 rectified with the ROS camera_info files: rows agree to "
                 f"{np.sqrt(np.mean(dv ** 2)):.2f} px RMS", xlabel="u [px]", ylabel="v [px]")
    ax.legend(loc="lower right", fontsize=8)
    fig.tight_layout()
    fig.savefig(args.out / "stereo_rectified.png", dpi=90)
    plt.close(fig)


if __name__ == "__main__":
    main()
