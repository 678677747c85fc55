"""Single camera calibration: the MTKM paper's Listing 1, in boxplus.

The camera model is the paper's: one focal length f, the principal point
(offset) and one radial distortion coefficient k1,

    u = f · x · (1 + k1 r²) + offset,    x = p_in_cam[:2] / p_in_cam[2],  r² = |x|²

and each image i has an unknown camera pose world_from_cam_i (camera → board
frame). Every detected corner is a measurement

    z_ij = project_point(intrinsic, world_from_cam_i, identity, p_world_j) + noise.

Run with ``--per-point`` for the paper's literal form (one Python call per
corner; slow), default is the vectorised form (one call per solver step for all
corners). Prints the RMS reprojection error beside OpenCV's calibrateCamera for
the same model, when OpenCV is installed.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import boxplus as bp
import numpy as np
from boxplus.calib import init_camera
from boxplus.calib.models import project_pinhole

DATA = Path(__file__).resolve().parents[1] / "data" / "calib" / "opencv_stereo_corners.npz"


def pinhole(focal_length, offset, distortion, p_in_cam):
    """Projects camera-frame points (..., 3) to pixels (..., 2)."""
    return project_pinhole(p_in_cam, focal_length, offset, k1=distortion)


def project_point(intrinsic, world_from_rig, cam_from_rig, p_in_world):
    """MTKM's measurement function: world → x (inverse of world_from_rig) → camera."""
    p_in_cam = cam_from_rig.fromlocal(world_from_rig.tolocal(p_in_world))
    return pinhole(intrinsic.focal_length.vec, intrinsic.offset.vec, intrinsic.distortion.vec, p_in_cam)


def project_points(intrinsic, world_from_cam, p_in_world):
    """The same for a whole batch: world_from_cam and intrinsic are batches, p_in_world (N, 3)."""
    return pinhole(
        intrinsic.focal_length.vec, intrinsic.offset.vec, intrinsic.distortion.vec,
        world_from_cam.tolocal(p_in_world),
    )


intrinsic_t = bp.make_compound(
    "intrinsic_t", focal_length=bp.Rn(1), offset=bp.Rn(2), distortion=bp.Rn(1)
)


def calibrate(image_points, object_points, image_size, per_point=False, verbose=False):
    """Returns (problem, intrinsic_id, pose_ids, result)."""
    K, cam_from_board = init_camera(object_points, image_points, image_size)
    intrinsic = intrinsic_t(
        focal_length=[(K[0, 0] + K[1, 1]) / 2], offset=K[:2, 2], distortion=[0.0]
    )
    o = bp.OptimizationProblem()
    intrinsic_id = o.add_random_var(intrinsic, name="intrinsic")
    pose_ids = []
    sigma = 1.0  # px; the reported standard deviations are rescaled by the residuals
    for i, (p_img, pose) in enumerate(zip(image_points, cam_from_board)):
        world_from_cam_id = o.add_random_var(pose.inverse(), name=f"world_from_cam_{i}")
        pose_ids.append(world_from_cam_id)
        if per_point:
            for j in range(len(p_img)):
                o.add_measurement(p_img[j], project_point, [intrinsic_id, world_from_cam_id],
                                  constants=(bp.SE3(), object_points[j]), sigma=sigma)
        else:
            n = len(p_img)
            ids = np.column_stack([np.full(n, intrinsic_id), np.full(n, world_from_cam_id)])
            o.add_measurements(p_img, project_points, ids, constants=(object_points,), sigma=sigma)
    result = o.solve(verbose=verbose)
    return o, intrinsic_id, pose_ids, result


def opencv_reference(image_points, object_points, image_size):
    """cv2.calibrateCamera with the same model (fx = fy, k1 only), or None."""
    try:
        import cv2
    except ImportError:
        return None
    flags = (cv2.CALIB_FIX_ASPECT_RATIO | cv2.CALIB_ZERO_TANGENT_DIST | cv2.CALIB_FIX_K2
             | cv2.CALIB_FIX_K3 | cv2.CALIB_USE_INTRINSIC_GUESS)
    K0 = np.array([[500.0, 0, image_size[0] / 2], [0, 500.0, image_size[1] / 2], [0, 0, 1]])
    t0 = time.perf_counter()
    rms, K, dist, _, _ = cv2.calibrateCamera(
        [object_points.astype(np.float32)] * len(image_points),
        [p.astype(np.float32) for p in image_points], tuple(int(s) for s in image_size),
        K0, np.zeros(5), flags=flags,
    )
    return rms, K, dist.ravel(), time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--per-point", action="store_true", help="one Python call per corner (MTKM's form)")
    ap.add_argument("--camera", choices=["left", "right"], default="left")
    ap.add_argument("--verbose", action="store_true")
    args = ap.parse_args()

    d = np.load(DATA)
    obj = d["object_points"]
    imgs = [p for p, ok in zip(d[f"image_points_{args.camera}"], d[f"found_{args.camera}"]) if ok]
    size = tuple(d["image_size"])

    t0 = time.perf_counter()
    o, iid, _, result = calibrate(imgs, obj, size, per_point=args.per_point, verbose=args.verbose)
    elapsed = time.perf_counter() - t0
    intr = o[iid]
    errors = np.concatenate(list(o.errors().values()))
    rms = np.sqrt(np.mean(np.sum(errors**2, axis=1)))
    dof = errors.size - (intr.dof + 6 * len(imgs))
    sigma_hat = np.sqrt(np.sum(errors**2) / dof)  # a-posteriori pixel noise
    std = o.std(iid) * sigma_hat

    print(f"boxplus single camera calibration ({args.camera}, {len(imgs)} images, "
          f"{'per-point' if args.per_point else 'vectorised'} measurement function)")
    print(f"  {result}")
    print(f"  RMS reprojection error {rms:.5f} px (per axis {np.sqrt(np.mean(errors**2, axis=0)).round(4)})")
    for name in intrinsic_t.members():
        s = intrinsic_t.slice_of(name)
        print(f"  {name:13s} {getattr(intr, name).vec.round(4)} ± {std[s].round(4)}")
    print(f"  time {elapsed:.3f} s (including initialisation)")
    ref = opencv_reference(imgs, obj, size)
    if ref is None:
        print("  (install opencv-python-headless to compare with cv2.calibrateCamera)")
    else:
        rms_cv, K, dist, t_cv = ref
        print(f"OpenCV calibrateCamera, same model: RMS {rms_cv:.5f} px, f {K[0, 0]:.4f}, "
              f"offset [{K[0, 2]:.4f} {K[1, 2]:.4f}], k1 {dist[0]:.5f}, time {t_cv:.3f} s")
        print(f"  RMS difference boxplus − OpenCV: {rms - rms_cv:+.2e} px")


if __name__ == "__main__":
    main()
