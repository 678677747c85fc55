"""A fleet of stereo + IMU rigs calibrated on a local Ray and a local Dask cluster.

Every rig that leaves a production line gets its own calibration. Here each
simulated rig has its own true parameters (the design values perturbed as a
real assembly line would: focal lengths, principal points, the stereo
baseline and the IMU's mounting) and its own session of board views; one
task per rig builds the problem, solves it and returns the few numbers the
line keeps. The tasks go through :func:`boxplus.solve_many` to

* a local Ray cluster (``ray.init(num_cpus=...)`` with the
  :class:`boxplus.parallel.RayExecutor` adapter), and
* a local Dask cluster (``distributed.LocalCluster``, its ``Client`` used
  directly as the executor),

each with 1 and with 2 worker processes. The script prints the throughput
(rigs per second) of each, checks that every cluster returns the serial
answer to the last bit, writes the fleet's accuracy distribution (a PNG) and
names the rigs whose calibration failed or was degenerate; a few are broken
on purpose:

* ``*-nan``: a corrupted detection (a NaN corner) -> the task fails with the
  ValueError that names the measurement;
* ``*-oneview``: the right camera saw the board in one view only, which
  cannot determine its intrinsics and the stereo pose together -> degenerate.

Model (the frames of :mod:`boxplus.calib`; rig = the left camera):

    z_cam,ij = π(k_cam, cam_from_rig · world_from_rig_i⁻¹ · p_world_j)     px
    g_i      = s · R(imu_from_rig) R(world_from_rig_i)ᵀ g_world + b      m/s²

Run: .venv/bin/python examples/fleet_calibration.py [--rigs 200] [--out DIR]
     [--ray-address ADDR] [--dask-address ADDR]     (an existing cluster)
"""

from __future__ import annotations

import argparse
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import boxplus as bp
import numpy as np
from boxplus.calib import add_board, add_gravity, report
from boxplus.synthetic.cameras import TRUE_K, board_points, observe, random_views

G_WORLD = np.array([0.0, 0.0, -9.81])
MODEL = "opencv5"
# The design: both cameras like TRUE_K, 12 cm apart; the IMU behind the left camera.
DESIGN_RIGHT_FROM_LEFT = bp.SE3(bp.SO3(), [-0.12, 0.0, 0.0])
DESIGN_IMU_FROM_RIG = bp.SE3(bp.SO3.exp(np.array([0.0, np.pi / 2, 0.0])), [0.0, -0.03, -0.02])
PIXEL_SIGMA = 0.3  # px
ACCEL_SIGMA = 0.02  # m/s²


@dataclass
class Rig:
    """One simulated rig: its name, its true parameters and what its session recorded."""

    name: str
    truth: dict[str, Any]
    z: dict[str, list[np.ndarray]] = field(default_factory=dict)  # camera -> views (N, 2) px
    g: list[np.ndarray] = field(default_factory=list)  # accelerometer per view, m/s²
    # true world_from_rig per view, as ambient vectors: a pickled SE3 is normalised
    # again on load, which can move its last bit (and then a worker's answer)
    views: list[np.ndarray] = field(default_factory=list)


def simulate_rig(index: int, rng: np.random.Generator, fault: str = "", n_views: int = 8) -> Rig:
    """Rig ``index`` with its own perturbed truth and noisy session (``fault``: '', 'nan', 'oneview')."""
    k_left = TRUE_K + np.r_[rng.normal(0, 4, 2), rng.normal(0, 3, 2), rng.normal(0, 0.01, 2), 0, 0, 0]
    k_right = TRUE_K + np.r_[rng.normal(0, 4, 2), rng.normal(0, 3, 2), rng.normal(0, 0.01, 2), 0, 0, 0]
    right_from_left = DESIGN_RIGHT_FROM_LEFT + np.r_[rng.normal(0, 0.002, 3), rng.normal(0, 0.005, 3)]
    imu_from_rig = DESIGN_IMU_FROM_RIG + np.r_[rng.normal(0, 0.002, 3), rng.normal(0, 0.02, 3)]
    accel = np.r_[1 + rng.normal(0, 0.01), rng.normal(0, 0.05, 3)]
    truth = dict(k_left=k_left, k_right=k_right, right_from_left=right_from_left,
                 imu_from_rig=imu_from_rig, accel=accel)
    rig = Rig(f"rig-{index:04d}" + (f"-{fault}" if fault else ""), truth)
    p_in_world = board_points()
    center = p_in_world.mean(axis=0)
    views = random_views(n_views, rng, center)
    rig.views = [np.asarray(v.ambient) for v in views]
    rig.z = {"left": [], "right": []}
    R_ir, s, b = imu_from_rig.rot.R, accel[0], accel[1:]
    for world_from_rig in views:
        for cam, k, cam_from_rig in (("left", k_left, bp.SE3()), ("right", k_right, right_from_left)):
            world_from_cam = world_from_rig * cam_from_rig.inverse()
            uv, vis = observe(k, world_from_cam, p_in_world, PIXEL_SIGMA, rng, MODEL)
            z = np.full((len(p_in_world), 2), np.nan)
            z[vis] = uv
            rig.z[cam].append(z)
        rig.g.append(s * R_ir @ world_from_rig.rot.R.T @ G_WORLD + b + rng.normal(0, ACCEL_SIGMA, 3))
    if fault == "oneview":  # the right camera's board detections lost but in view 0
        for z in rig.z["right"][1:]:
            z[:] = np.nan
    if fault == "nan":  # one coordinate of one visible corner lost
        z = rig.z["right"][2]
        z[int(np.flatnonzero(~np.isnan(z[:, 0]))[0]), 0] = np.nan
    return rig


def build(rig: Rig, rng: np.random.Generator | None = None) -> bp.OptimizationProblem:
    """The calibration problem of ``rig``, started from the design values and from
    view poses as good as a PnP would give (the truth moved by ~1 cm, ~1°)."""
    start = rng if rng is not None else np.random.default_rng(0)
    p_in_world = board_points()
    o = bp.OptimizationProblem()
    k = {cam: o.add_random_var(bp.Rn(TRUE_K), name=f"k_{cam}") for cam in ("left", "right")}
    rig_id = o.add_random_var(bp.SE3(), fixed=True, name="left_from_rig")
    right = o.add_random_var(DESIGN_RIGHT_FROM_LEFT, name="right_from_left")
    imu = o.add_random_var(DESIGN_IMU_FROM_RIG, name="imu_from_rig")
    accel = o.add_random_var(bp.Rn([1.0, 0, 0, 0]), name="accel", labels=["scale", "bx", "by", "bz"])
    # The IMU's position does not enter the measurements: measured by hand (σ 5 mm).
    o.add_prior(imu, DESIGN_IMU_FROM_RIG, sigma=[0.005] * 3 + [10.0] * 3, name="imu_by_hand")
    for i, view in enumerate(rig.views):
        guess = bp.SE3.from_ambient(view) + np.r_[start.normal(0, 0.01, 3), start.normal(0, 0.017, 3)]
        pose = o.add_random_var(guess, name=f"world_from_rig_{i}")
        for cam, cam_from_rig in (("left", rig_id), ("right", right)):
            z = rig.z[cam][i]
            seen = ~np.isnan(z).all(axis=1)  # corners outside the image are NaN rows
            if not seen.any():
                continue
            add_board(o, z[seen], k[cam], pose, cam_from_rig, p_in_world[seen], sigma=PIXEL_SIGMA,
                        model=MODEL, group=f"board_{cam}", name=f"{cam}_{i}")
        add_gravity(o, rig.g[i], pose, imu, accel, G_WORLD, sigma=ACCEL_SIGMA, group="accelerometer")
    return o


SUMMARY_VARIABLES = ("k_left", "k_right", "right_from_left", "imu_from_rig", "accel")


def keep(o: bp.OptimizationProblem, summary: bp.SolveSummary) -> dict[str, Any]:
    """What a task sends back (solve_many's ``extract``, run on the worker): the
    estimates by name, their σ, the solve's outcome, and the parameters the data
    does not determine (rank-deficient) or determines badly (condition)."""
    rep = report(o)
    return dict(usable=bool(summary.usable), termination=summary.termination,
                final_cost=summary.final_cost,
                undetermined=[n for _, names in rep.undetermined + rep.ill_conditioned for n in names],
                # ambient vectors: exact bits (a pickled SE3 is normalised again on load)
                values={o.variable_name(v): np.asarray(o._core.value(v)) for v in range(o.num_variables)},
                std={name: rep.std(name) for name in SUMMARY_VARIABLES})


def errors(rig: Rig, values: dict[str, np.ndarray]) -> dict[str, float]:
    """The estimate's errors (``values``: ambient vectors by name) against the rig's own
    truth, in the units of their names."""
    t = rig.truth
    imu = bp.SE3.from_ambient(values["imu_from_rig"])
    d_imu = (t["imu_from_rig"].rot.inverse() * imu.rot).log()
    return {
        "focal_left_px": float(np.max(np.abs(values["k_left"][:2] - t["k_left"][:2]))),
        "focal_right_px": float(np.max(np.abs(values["k_right"][:2] - t["k_right"][:2]))),
        "baseline_mm": 1e3 * float(np.linalg.norm(values["right_from_left"][:3]
                                                  - t["right_from_left"].pos)),
        "imu_rotation_deg": float(np.degrees(np.linalg.norm(d_imu))),
    }


def fleet(n: int, seed: int = 0, faults: dict[int, str] | None = None) -> list[Rig]:
    """``n`` rigs; ``faults`` {index: 'nan' | 'oneview'} breaks some on purpose."""
    faults = {3: "nan", 7: "oneview", 120: "oneview", 150: "nan"} if faults is None else faults
    return [simulate_rig(i, np.random.default_rng([seed, i]), faults.get(i, "")) for i in range(n)]


def run_fleet(rigs: list[Rig], executor: Any = None, seed: int = 1) -> list[bp.TaskResult]:
    """Calibrates every rig on ``executor`` (None: serially); task i's start drawn from
    ``default_rng([seed, i])``, so every executor gives the same answer."""
    return bp.solve_many(build, rigs, executor=executor, seed=seed, extract=keep,
                         max_iterations=100)


# The line's acceptance: the largest σ each kept parameter may have (directions of
# its tangent, limit, unit). A rig above it is degenerate even when its Jacobian
# has full rank: its data determine the parameter too weakly to ship.
ACCEPT_STD = {
    "k_left": (slice(0, 2), 10.0, "px"),
    "k_right": (slice(0, 2), 10.0, "px"),
    "right_from_left": (slice(0, 3), 0.01, "m"),
    "imu_from_rig": (slice(3, 6), np.radians(1.0), "rad"),
}


def verdicts(results: list[bp.TaskResult], rigs: list[Rig]) -> dict[str, str]:
    """{rig name: why it is not calibrated} for the failed and degenerate rigs."""
    out = {}
    for r, rig in zip(results, rigs):
        if not r.ok:
            last = (r.error or "").strip().splitlines()[-1]
            out[rig.name] = f"failed: {last}"
            continue
        weak = [f"{name} σ {float(np.max(r.value['std'][name][part])):.3g} {unit} > {limit:.3g}"
                for name, (part, limit, unit) in ACCEPT_STD.items()
                if not np.max(r.value["std"][name][part]) <= limit]  # inf and NaN too
        if r.value["undetermined"]:
            names = sorted({n.split(".")[0] for n in r.value["undetermined"]})
            out[rig.name] = "degenerate: not determined by the data: " + ", ".join(names)
        elif weak:
            out[rig.name] = "degenerate: too weakly determined: " + "; ".join(weak)
        elif not r.value["usable"] or r.value["termination"] != "convergence":
            out[rig.name] = f"solve did not converge ({r.value['termination']})"
    return out


def same_bits(a: list[bp.TaskResult], b: list[bp.TaskResult]) -> bool:
    """Whether two runs of the fleet gave the same estimates to the last bit."""
    if len(a) != len(b):
        return False
    for x, y in zip(a, b):
        if x.ok != y.ok:
            return False
        if x.ok and not all(np.array_equal(x.value["values"][k], v)
                            for k, v in y.value["values"].items()):
            return False
    return True


def accuracy(results: list[bp.TaskResult], rigs: list[Rig]) -> list[dict[str, float]]:
    """The errors of every calibrated rig (failed and degenerate ones left out)."""
    bad = verdicts(results, rigs)
    return [errors(rig, r.value["values"]) for r, rig in zip(results, rigs) if rig.name not in bad]


def plot_accuracy(good: list[dict[str, float]], path: Path) -> None:
    """Histograms of the fleet's errors (one panel per parameter, units on the axes)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    panels = [("focal_left_px", "focal length error, left (px)"),
              ("focal_right_px", "focal length error, right (px)"),
              ("baseline_mm", "stereo baseline error (mm)"),
              ("imu_rotation_deg", "camera→IMU rotation error (deg)")]
    fig, axes = plt.subplots(1, 4, figsize=(16, 3.6))
    for ax, (key, label) in zip(axes, panels):
        v = np.array([e[key] for e in good])
        ax.hist(v, bins=25, color="tab:blue")
        ax.axvline(np.percentile(v, 95), color="tab:red", ls="--", label="95th percentile")
        ax.set_xlabel(label)
        ax.set_ylabel("rigs")
        ax.legend(fontsize=8)
    fig.suptitle(f"Calibration accuracy over a fleet of {len(good)} rigs (errors against each "
                 f"rig's own truth)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _ray_executor(workers: int, address: str | None):
    import ray

    ray.shutdown()
    if address:
        ray.init(address=address, log_to_driver=False)
    else:
        # Loopback only: a local cluster has no business on the machine's
        # network interfaces.
        ray.init(num_cpus=workers, include_dashboard=False, log_to_driver=False,
                 _node_ip_address="127.0.0.1")
    return bp.parallel.RayExecutor(num_cpus=1), ray.shutdown


def _dask_executor(workers: int, address: str | None):
    from distributed import Client, LocalCluster

    if address:
        client = Client(address)
        return client, client.close
    # Any free port for the scheduler's HTTP server: with None it takes 8787,
    # and a second cluster on the machine (another run, another test suite)
    # then fails to start.
    cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                           host="127.0.0.1", dashboard_address="127.0.0.1:0")
    client = Client(cluster)

    def close() -> None:
        client.close()
        cluster.close()

    return client, close


CLUSTERS = {"ray": _ray_executor, "dask": _dask_executor}


def on_cluster(kind: str, workers: int, rigs: list[Rig], address: str | None = None):
    """(results, seconds) of the fleet on a local cluster of ``kind`` with ``workers`` processes."""
    executor, close = CLUSTERS[kind](workers, address)
    try:
        run_fleet(rigs[: 2 * workers], executor)  # warm the workers (imports) before timing
        t0 = time.perf_counter()
        results = run_fleet(rigs, executor)
        return results, time.perf_counter() - t0
    finally:
        close()


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rigs", type=int, default=200, help="fleet size (default 200)")
    ap.add_argument("--workers", type=int, nargs="+", default=[1, 2], help="worker counts to time")
    ap.add_argument("--clusters", nargs="+", default=["ray", "dask"], choices=sorted(CLUSTERS))
    ap.add_argument("--ray-address", default=None, help="an existing Ray cluster (ray://… or auto)")
    ap.add_argument("--dask-address", default=None, help="an existing Dask scheduler (tcp://…)")
    ap.add_argument("--out", default=".", help="directory of fleet_accuracy.png")
    args = ap.parse_args(argv)

    rigs = fleet(args.rigs)
    t0 = time.perf_counter()
    serial = run_fleet(rigs)
    t_serial = time.perf_counter() - t0
    print(f"serial, this process: {len(rigs)} rigs in {t_serial:.1f} s = {len(rigs) / t_serial:.1f} rigs/s")
    all_same = True
    for kind in args.clusters:
        address = args.ray_address if kind == "ray" else args.dask_address
        for workers in args.workers:
            results, seconds = on_cluster(kind, workers, rigs, address)
            same = same_bits(results, serial)
            all_same &= same
            print(f"{kind:4s} {workers} worker(s): {len(rigs)} rigs in {seconds:.1f} s = "
                  f"{len(rigs) / seconds:.1f} rigs/s; same bits as serial: {same}; "
                  f"worker retries: {sum(r.attempts - 1 for r in results)}")
            if address:
                break  # an existing cluster has its own size
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    good = accuracy(serial, rigs)
    plot_accuracy(good, out / "fleet_accuracy.png")
    for key in good[0]:
        v = np.array([e[key] for e in good])
        print(f"{key:18s} median {np.median(v):.4f}  95% {np.percentile(v, 95):.4f}  max {v.max():.4f}")
    print(f"accuracy distribution: {out / 'fleet_accuracy.png'}")
    bad = verdicts(serial, rigs)
    print(f"{len(bad)} rig(s) not calibrated:")
    for name, why in bad.items():
        print(f"  {name}: {why}")
    return 0 if all_same else 1


if __name__ == "__main__":
    sys.exit(main())
