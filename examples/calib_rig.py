"""Three cameras with partial overlap (each sees some of the views, often only
part of the board), calibrated in one joint solve by ``calibrate_rig``; the
estimates compared with the truth in units of their σ, and the rig written
as OpenCV, Kalibr and ROS files.

The cameras' poses in the rig start from a camera graph: every pair of cameras
that saw the board in the same views gives a pairwise pose, a spanning tree of
the most shared views chains them to the reference camera (cam0).

Run: .venv/bin/python examples/calib_rig.py [--out DIR]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import boxplus as bp
import numpy as np
from boxplus.calib import calibrate_rig, write_camchain, write_camera_info, write_opencv_yaml
from boxplus.synthetic.cameras import TRUE_K, board_points, observe, random_views

CAM_FROM_REF = {
    "cam1": bp.SE3(bp.SO3.exp(np.array([0.0, -0.25, 0.02])), np.array([-0.12, 0.01, 0.02])),
    "cam2": bp.SE3(bp.SO3.exp(np.array([0.03, 0.3, -0.01])), np.array([0.15, -0.02, 0.03])),
}
# radial2 intrinsics [fx, fy, cx, cy, k1, k2]: Kalibr's radtan can hold them
K = {"cam0": TRUE_K[:6], "cam1": TRUE_K[:6] * [1.01, 1.01, 0.98, 1.02, 0.9, 1.1],
     "cam2": TRUE_K[:6] * [0.99, 0.99, 1.01, 0.99, 1.1, 0.8]}


def simulate(rng: np.random.Generator, n_views: int = 24, sigma: float = 0.3) -> dict:
    """{camera: per view (pixels, board points) or None}: cam1 misses every third view,
    cam2 the next one (occlusions), and corners near the image border are dropped."""
    obj = board_points(9, 6, 0.04)
    views = random_views(n_views, rng, obj.mean(axis=0), distance=0.45, spread=0.7)
    hidden = {"cam0": -1, "cam1": 0, "cam2": 1}
    det: dict[str, list] = {c: [] for c in K}
    for i, v in enumerate(views):
        for c in K:
            pose = v if c == "cam0" else v * CAM_FROM_REF[c].inverse()  # world_from_cam
            z, vis = observe(K[c], pose, obj, sigma, rng, model="radial2", image_size=None)
            vis &= np.all((z > 3) & (z < [636, 476]), axis=1)
            det[c].append((z[vis], obj[vis]) if vis.sum() >= 12 and i % 3 != hidden[c] else None)
    return det


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default=None, help="folder for the YAML files and PNGs")
    args = ap.parse_args()
    det = simulate(np.random.default_rng(21))
    for c, d in det.items():
        seen = [x for x in d if x is not None]
        print(f"{c}: {len(seen)} of {len(d)} views, {sum(len(x[0]) for x in seen)} corners")
    cal = calibrate_rig(det, (640, 480), "radial2", sigma=0.3)
    rep = cal.report()
    o = cal.problem
    assert cal.result is not None  # solved (solve=True)
    print(f"{cal.result.termination}, RMS {cal.rms():.4f} px")
    for c in K:
        err = (o[cal.ids[c]].vec - K[c]) / rep.std(c)
        print(f"  {c} intrinsics error / σ: {np.array2string(err, precision=2)}")
    for c, truth in CAM_FROM_REF.items():
        est = o[cal.ids[f"{c}_from_cam0"]]
        d = np.concatenate([est.pos - truth.pos, (truth.rot.inverse() * est.rot).log()])
        print(f"  {c}_from_cam0 error / σ: {np.array2string(d / rep.std(f'{c}_from_cam0'), precision=2)}")
    if args.out:
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        cams = cal.cameras()
        write_opencv_yaml(out / "rig.yml", cams)
        write_camchain(out / "camchain.yaml", cams)
        for cam in cams:
            write_camera_info(out / f"{cam.name}.yaml", cam)
        from boxplus.calib.plot import plot_coverage, plot_rms_per_image

        plot_rms_per_image(o, cal.view_ids, path=out / "rms_per_image.png")
        for c in K:
            plot_coverage(cal, c, path=out / f"coverage_{c}.png")
        print(f"wrote rig.yml, camchain.yaml, cam*.yaml and PNGs to {out}")


if __name__ == "__main__":
    main()
