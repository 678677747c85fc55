"""Tutorial: calibrating a camera and an IMU in motion.

    python docs/tutorials/camera_imu.py [--out DIR]

Simulates a camera and an IMU waved in front of a target for 8 s (known truth:
imu_from_cam, the clocks' offset, the biases), calibrates them with
:func:`boxplus.calib.camera_imu.calibrate_camera_imu`, prints every estimate
with its σ beside the truth and writes the tutorial's picture (camera_imu.png)
into DIR (default: this folder).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from boxplus.calib.camera_imu import calibrate_camera_imu, simulate_camera_imu

HERE = Path(__file__).resolve().parent


def calibrate(seed: int = 0):
    # A recording with known truth: a 20 Hz camera and a 200 Hz IMU whose clocks
    # are 7 ms apart; corners with 0.3 px noise, gyro 0.005 rad/s, accel 0.05 m/s².
    data, truth, K = simulate_camera_imu(np.random.default_rng(seed), time_offset=0.007)
    # The camera's intrinsics come from an earlier calibration (boxplus-calib);
    # the noise σ per sample from the IMU's data sheet or Kalibr's imu.yaml
    # (σ = noise density · √rate).
    cal = calibrate_camera_imu(data, K, "pinhole", pixel_sigma=0.3,
                               gyro_sigma=0.005, accel_sigma=0.05)
    return data, truth, cal


def print_table(truth, cal) -> None:
    ic = truth["imu_from_cam"]
    rot_err = (ic.rot.inverse() * cal.imu_from_cam.rot).log()
    s = cal.std("imu_from_cam")  # tangent order [translation (m), rotation (rad)]
    print(f"imu_from_cam translation: {np.round(cal.imu_from_cam.pos * 1e3, 2)} mm "
          f"(truth {np.round(ic.pos * 1e3, 2)}, σ {np.round(s[:3] * 1e3, 2)})")
    print(f"imu_from_cam rotation error: {np.round(np.degrees(rot_err), 3)} ° "
          f"(σ {np.round(np.degrees(s[3:]), 3)})")
    print(f"time offset d: {cal.time_offset * 1e3:.3f} ms (truth {truth['time_offset'] * 1e3:.3f}, "
          f"σ {cal.std('time_offset')[0] * 1e3:.3f}; start {cal.initial['time_offset'] * 1e3:.1f})")
    print(f"gyro bias: {np.round(cal.gyro_bias, 4)} rad/s (truth {truth['gyro_bias']})")
    print(f"accel bias: {np.round(cal.accel_bias, 3)} m/s² (truth {truth['accel_bias']})")
    print("RMS per group:", {g: round(float(r), 4) for g, r in cal.problem.rms().items()})


def picture(data, cal, path: Path) -> None:
    fig, (a, b) = plt.subplots(1, 2, figsize=(12, 4.5))
    # the gyroscope against the fitted trajectory's body rate (+ bias), 2 s of it
    window = (data.imu_times > 2.0) & (data.imu_times < 4.0)
    t = data.imu_times[window]
    fitted = np.array([cal.angular_velocity(ti) for ti in t]) + cal.gyro_bias
    for j, axis in enumerate("xyz"):
        a.plot(t, data.gyro[window, j], ".", ms=2, color=f"C{j}", label=f"gyro {axis}")
        a.plot(t, fitted[:, j], "-", lw=1, color=f"C{j}")
    a.set(xlabel="IMU time [s]", ylabel="angular velocity [rad/s]",
          title="gyroscope samples (dots) and the fitted spline (lines)")
    a.legend(fontsize=8, ncol=3)
    # the corners' reprojection errors, in pixels
    e = cal.problem.errors()["reprojection"]
    b.plot(e[:, 0], e[:, 1], ".", ms=1.5, alpha=0.5)
    b.set(xlabel="error u [px]", ylabel="error v [px]", aspect="equal",
          title=f"reprojection errors of {len(e)} corners, RMS {np.sqrt(np.mean(e ** 2)):.3f} px")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=HERE)
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    data, truth, cal = calibrate()
    print_table(truth, cal)
    picture(data, cal, args.out / "camera_imu.png")


if __name__ == "__main__":
    main()
