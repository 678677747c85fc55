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

import numpy as np
from boxplus.calib.camera_imu import calibrate_camera_imu
from boxplus.calib.plot import plot_camera_imu
from boxplus.synthetic.camera_imu import simulate_camera_imu

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
    # The gyroscope against the fitted trajectory's angular velocity (plus the bias,
    # CameraImuCalibration.angular_velocity), and every corner's reprojection error.
    fig = plot_camera_imu(cal, data, seconds=2.0)
    fig.savefig(path, dpi=90)


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
