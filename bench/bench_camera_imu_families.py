"""Camera–IMU calibration on a family of generated rigs and recordings, with the defaults
(#28): does it work on whatever a user brings, and is its σ right there?

Every draw is a new rig and recording from boxplus.synthetic.camera_imu.simulate_camera_imu
with ``motion="sines"`` (no spline: a hand-waved rig, 1–2.5 Hz): IMU rate 100–1000 Hz,
camera rate 10–60 Hz, noise of real MEMS parts (gyroscope density 1e-4–2e-3 rad/s/√Hz,
accelerometer 1e-3–2e-2 m/s²/√Hz, the per-sample σ their density × √rate), the
camera's time offset −50…+50 ms, 1–3 cameras (each further camera at its own place,
clock and frame phase, 5–15 cm beside the first and turned by up to ~10°, a fisheye
among them half the time), and a rolling shutter (30 µs per row) on
a third of the first cameras. Each is fitted with ``calibrate_camera_imu``'s defaults
(adaptive knot spacing; the noise σ given as simulated, the line delay estimated where
there is a rolling shutter). Per draw: imu_from_cam's translation (mm) and rotation
(deg) errors and the time offset's (ms) for every camera, and the largest |error|/σ
over those seven quantities per camera. The summary: draws solved, the median and
worst errors, and the fraction of normalised errors within 3σ and 4σ.

Run: .venv/bin/python bench/bench_camera_imu_families.py [--draws 24] [--duration 6]
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np
from boxplus import SE3, SO3
from boxplus.calib.camera_imu import calibrate_camera_imu
from boxplus.synthetic.camera_imu import SimulatedCamera, simulate_camera_imu

FISHEYE = np.array([300.0, 300.0, 320.0, 240.0, 0.02, -0.01, 0.004, -0.001])


def _pose(rng: np.random.Generator) -> SE3:
    return SE3(SO3.exp(rng.normal(0.0, 0.6, 3)), rng.uniform(-0.1, 0.1, 3))


def draw(seed: int, duration: float) -> dict:
    rng = np.random.default_rng(seed)
    imu_rate = float(rng.choice([100.0, 200.0, 400.0, 1000.0]))
    camera_rate = float(rng.choice([10.0, 20.0, 30.0, 60.0]))
    gyro_density = float(np.exp(rng.uniform(np.log(1e-4), np.log(2e-3))))
    accel_density = float(np.exp(rng.uniform(np.log(1e-3), np.log(2e-2))))
    gyro_sigma, accel_sigma = gyro_density * np.sqrt(imu_rate), accel_density * np.sqrt(imu_rate)
    offset = float(rng.uniform(-0.05, 0.05))
    rolling = bool(rng.uniform() < 1 / 3)
    n_cam = int(rng.integers(1, 4))
    imu_from_cam = _pose(rng)
    # the other cameras look the same way as the first (the target in view), 5–15 cm away
    # and turned by up to ~10°
    others = [SimulatedCamera(imu_from_cam * SE3(SO3.exp(rng.normal(0.0, 0.1, 3)),
                                                 rng.uniform(0.05, 0.15) * np.r_[1.0, 0.0, 0.0]
                                                 * rng.choice([-1.0, 1.0])),
                              float(rng.uniform(-0.05, 0.05)),
                              "kannala_brandt" if c == 0 and rng.uniform() < 0.5 else "pinhole",
                              None, float(rng.uniform(0, 1 / camera_rate)), f"cam{c + 1}")
              for c in range(n_cam - 1)]
    for cam in others:
        if cam.model == "kannala_brandt":
            cam.intrinsics = FISHEYE
    bandwidth = float(rng.uniform(1.0, 2.5))
    data, truth, K = simulate_camera_imu(rng, duration=duration, camera_rate=camera_rate, imu_rate=imu_rate,
                                         time_offset=offset, imu_from_cam=imu_from_cam, gyro_sigma=gyro_sigma,
                                         accel_sigma=accel_sigma, other_cameras=others,
                                         line_delay=30e-6 if rolling else 0.0, motion="sines",
                                         bandwidth=bandwidth)
    intrinsics = truth.get("intrinsics", [K])
    models = ["pinhole", *(c.model for c in others)]
    row = dict(seed=seed, imu_rate=imu_rate, camera_rate=camera_rate, cameras=n_cam, rolling=rolling,
               bandwidth=bandwidth, offset_ms=1e3 * offset)
    t = time.perf_counter()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            cal = calibrate_camera_imu(data, list(intrinsics) if n_cam > 1 else K,
                                       models if n_cam > 1 else "pinhole", pixel_sigma=0.3,
                                       gyro_sigma=gyro_sigma, accel_sigma=accel_sigma,
                                       rolling_shutter=[rolling] + [False] * (n_cam - 1) if n_cam > 1 else rolling)
    except ValueError as e:
        row.update(ok=False, error=str(e)[:120], seconds=time.perf_counter() - t)
        return row
    row["seconds"] = time.perf_counter() - t
    true_poses = truth.get("imu_from_cams", [truth["imu_from_cam"]])
    true_offsets = truth.get("time_offsets", [truth["time_offset"]])
    trans, rot, offs, z = [], [], [], []
    for c in range(n_cam):
        est, tru = cal.imu_from_cams[c], true_poses[c]
        e = np.r_[est.pos - tru.pos, (tru.rot.inverse() * est.rot).log()]
        d = cal.time_offsets[c] - true_offsets[c]
        trans.append(1e3 * np.linalg.norm(e[:3]))
        rot.append(np.degrees(np.linalg.norm(e[3:])))
        offs.append(1e3 * abs(d))
        z += list(np.abs(e) / cal.std(f"imu_from_cam[{c}]")) + [abs(d) / cal.std(f"time_offset[{c}]")[0]]
    row.update(ok=True, trans_mm=max(trans), rot_deg=max(rot), offset_err_ms=max(offs), z=z,
               spacing_ms=1e3 * cal.knot_spacing)
    return row


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--draws", type=int, default=24)
    ap.add_argument("--duration", type=float, default=6.0)
    args = ap.parse_args()
    print(f"{'seed':>4s} {'IMU Hz':>6s} {'cam Hz':>6s} {'cams':>4s} {'RS':>3s} {'Hz bw':>5s} {'d ms':>6s} "
          f"{'knots ms':>8s} {'t mm':>6s} {'R deg':>6s} {'d err ms':>8s} {'max|z|':>6s} {'s':>6s}")
    rows = []
    for seed in range(args.draws):
        r = draw(seed, args.duration)
        rows.append(r)
        if r["ok"]:
            print(f"{seed:4d} {r['imu_rate']:6.0f} {r['camera_rate']:6.0f} {r['cameras']:4d} "
                  f"{'y' if r['rolling'] else 'n':>3s} {r['bandwidth']:5.2f} {r['offset_ms']:+6.1f} "
                  f"{r['spacing_ms']:8.1f} {r['trans_mm']:6.2f} {r['rot_deg']:6.3f} {r['offset_err_ms']:8.3f} "
                  f"{max(r['z']):6.2f} {r['seconds']:6.1f}", flush=True)
        else:
            print(f"{seed:4d} {r['imu_rate']:6.0f} {r['camera_rate']:6.0f} {r['cameras']:4d} "
                  f"{'y' if r['rolling'] else 'n':>3s}  refused: {r['error']}", flush=True)
    ok = [r for r in rows if r["ok"]]
    z = np.concatenate([r["z"] for r in ok]) if ok else np.zeros(0)
    print(f"solved {len(ok)}/{len(rows)}; median (worst) translation {np.median([r['trans_mm'] for r in ok]):.2f} "
          f"({max(r['trans_mm'] for r in ok):.2f}) mm, rotation {np.median([r['rot_deg'] for r in ok]):.3f} "
          f"({max(r['rot_deg'] for r in ok):.3f}) deg, time offset {np.median([r['offset_err_ms'] for r in ok]):.3f} "
          f"({max(r['offset_err_ms'] for r in ok):.3f}) ms; normalised errors within 3σ "
          f"{np.mean(z <= 3):.1%}, within 4σ {np.mean(z <= 4):.1%} ({len(z)})")


if __name__ == "__main__":
    main()
