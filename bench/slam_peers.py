"""Runs the peers of the SLAM benchmark (GTSAM, g2o) on one g2o file.

Each function starts from the given initial poses (rows aligned with
``data['ids']`` of ``harness.g2o_reference.read_g2o_arrays``), fixes the same gauge
(the first vertex) and returns the final poses in the same layout, the
iteration count, the solve time and a trace of (time, objective) per iteration
in the peer's own objective; ``setup_s`` is the time the peer spent building
its optimiser's state before the first iteration (g2o's
initialize_optimization, GTSAM's optimizer construction), which boxplus'
times include (its symbolic analysis is in iteration 0).

``max_seconds`` caps a run's wall time: the run stops after the iteration in
progress when the cap passes, and reports ``capped``. The suite needs it for
graphs where a peer's hundred iterations take an hour.
"""

from __future__ import annotations

import os
import select
import signal
import threading
import time
from pathlib import Path

import numpy as np


def _rot_from_quat(q):
    x, y, z, w = q / np.linalg.norm(q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def _quat_from_rot(R):
    from scipy.spatial.transform import Rotation

    return Rotation.from_matrix(R).as_quat()  # x y z w


def gtsam_values(data, poses):
    import gtsam

    v = gtsam.Values()
    for k, vid in enumerate(data["ids"]):
        x = poses[k]
        if data["dim"] == 3:
            v.insert(vid, gtsam.Pose3(gtsam.Rot3(_rot_from_quat(x[3:])), np.array(x[:3])))
        else:
            v.insert(vid, gtsam.Pose2(float(x[0]), float(x[1]), float(x[2])))
    return v


def gtsam_graph(path, dim):
    """GTSAM's reader on the file's VERTEX/EDGE lines. Its 2D parser stops at
    the first line it does not know (a FIX line ends the file for it: 0 factors
    from a generated 2D graph), its 3D parser skips them; every run here fixes
    the first vertex itself, so the FIX lines are left out."""
    import tempfile

    import gtsam

    text = Path(path).read_text()
    kept = [ln for ln in text.splitlines() if ln.startswith(("VERTEX", "EDGE"))]
    with tempfile.TemporaryDirectory() as d:
        clean = Path(d) / "graph.g2o"
        clean.write_text("\n".join(kept) + "\n")
        graph, _ = gtsam.readG2o(str(clean), dim == 3)
    n_edges = sum(1 for ln in kept if ln.startswith("EDGE"))
    if graph.size() != n_edges:
        raise RuntimeError(f"GTSAM read {graph.size()} factors of {n_edges} edges from {path}")
    return graph


def run_gtsam(path, data, init, method="lm", max_iterations=100, tol=1e-10, max_seconds=None):
    """GTSAM's own reader and optimiser (LM or GN); objective = 2·graph.error."""
    import gtsam

    graph = gtsam_graph(path, data["dim"])
    values = gtsam_values(data, init)
    g = gtsam.NonlinearFactorGraph(graph)
    first = data["ids"][0]
    if data["dim"] == 3:
        g.add(gtsam.PriorFactorPose3(first, values.atPose3(first),
                                     gtsam.noiseModel.Isotropic.Sigma(6, 1e-6)))
    else:
        g.add(gtsam.PriorFactorPose2(first, values.atPose2(first),
                                     gtsam.noiseModel.Isotropic.Sigma(3, 1e-6)))
    t_setup = time.perf_counter()
    if method == "lm":
        params = gtsam.LevenbergMarquardtParams()
    else:
        params = gtsam.GaussNewtonParams()
    params.setMaxIterations(max_iterations)
    params.setRelativeErrorTol(tol)
    params.setAbsoluteErrorTol(0.0)
    opt = (gtsam.LevenbergMarquardtOptimizer(g, values, params) if method == "lm"
           else gtsam.GaussNewtonOptimizer(g, values, params))
    trace = []
    t0 = time.perf_counter()
    setup_s = t0 - t_setup
    # Step by step to record the objective after each iteration.
    prev = 2 * graph.error(values)
    it = 0
    capped = False
    while it < max_iterations:
        if max_seconds is not None and time.perf_counter() - t_setup > max_seconds:
            capped = True
            break
        opt.iterate()
        it += 1
        cur = 2 * opt.error()
        trace.append((time.perf_counter() - t0, cur))
        if prev - cur <= tol * max(prev, 1e-300) and it > 1 or cur == 0.0:
            break
        prev = cur
    elapsed = time.perf_counter() - t0
    res = opt.values()
    poses = np.empty_like(init)
    for k, vid in enumerate(data["ids"]):
        if data["dim"] == 3:
            p = res.atPose3(vid)
            poses[k, :3] = p.translation()
            poses[k, 3:] = _quat_from_rot(p.rotation().matrix())
        else:
            p = res.atPose2(vid)
            poses[k] = [p.x(), p.y(), p.theta()]
    return {"poses": poses, "iterations": it, "time_s": elapsed, "trace": trace,
            "objective": 2 * graph.error(res), "setup_s": setup_s, "capped": capped}


class _StopWatch:
    """Sets g2o's force-stop flag after ``seconds`` (None: never) or at Ctrl-C."""

    def __init__(self, opt, seconds):
        self.opt, self.seconds, self.capped = opt, seconds, False
        self.done = threading.Event()
        self.wake = None

    def __enter__(self):
        try:  # only the main thread may set the wake-up fd
            r, w = os.pipe()
            os.set_blocking(w, False)
            self.previous = signal.set_wakeup_fd(w, warn_on_full_buffer=False)
            self.wake = (r, w)
        except ValueError:
            os.close(r)
            os.close(w)
        self.start = time.perf_counter()
        self.thread = threading.Thread(target=self._watch, daemon=True)
        self.thread.start()
        return self

    def _watch(self):
        while not self.done.is_set():
            if self.wake and select.select([self.wake[0]], [], [], 0.1)[0]:
                self.opt.set_force_stop_flag(True)  # Ctrl-C: Python raises once optimize() returns
                return
            if not self.wake:
                self.done.wait(0.1)
            if self.seconds is not None and time.perf_counter() - self.start > self.seconds:
                self.capped = True
                self.opt.set_force_stop_flag(True)
                return

    def __exit__(self, *exc):
        self.done.set()
        self.thread.join()
        if self.wake:
            signal.set_wakeup_fd(self.previous)
            os.close(self.wake[0])
            os.close(self.wake[1])
        self.opt.set_force_stop_flag(False)
        return False


def run_g2o(path, data, init, method="gn", max_iterations=100, max_seconds=None):
    """g2o (g2opy): its own reader, Eigen sparse Cholesky, GN or LM."""
    import g2opy as g2o

    opt = g2o.SparseOptimizer()
    if data["dim"] == 3:
        solver = g2o.BlockSolverSE3(g2o.LinearSolverEigenSE3())
    else:
        solver = g2o.BlockSolverSE2(g2o.LinearSolverEigenSE2())
    algo = (g2o.OptimizationAlgorithmGaussNewton(solver) if method == "gn"
            else g2o.OptimizationAlgorithmLevenberg(solver))
    opt.set_algorithm(algo)
    opt.load(str(path))
    for k, vid in enumerate(data["ids"]):
        x = init[k]
        v = opt.vertex(vid)
        if data["dim"] == 3:
            T = np.eye(4)
            T[:3, :3] = _rot_from_quat(x[3:])
            T[:3, 3] = x[:3]
            v.set_estimate(g2o.Isometry3d(T))
        else:
            v.set_estimate(g2o.SE2(float(x[0]), float(x[1]), float(x[2])))
        v.set_fixed(k == 0)
    t_setup = time.perf_counter()
    opt.initialize_optimization()
    setup_s = time.perf_counter() - t_setup
    opt.set_compute_batch_statistics(True)
    # g2o checks its force-stop flag before each iteration, and optimize()
    # releases the GIL, so a watching thread can stop it: at the cap, and at
    # Ctrl-C, which Python would otherwise act on only when optimize() returns
    # (the C-level handler writes to the wake-up pipe at once).
    with _StopWatch(opt, None if max_seconds is None else max_seconds - setup_s) as watch:
        t0 = time.perf_counter()
        iterations = opt.optimize(max_iterations)
        elapsed = time.perf_counter() - t0
    stopped = watch.capped
    opt.set_force_stop_flag(False)
    trace = []
    try:
        cum = 0.0
        # The statistics are sized for max_iterations; the entries of
        # iterations not run (LM's early stop, the cap) have iteration -1 and
        # chi2 0, which must not read as reaching the optimum.
        for s in opt.batch_statistics():
            if s.iteration < 0:
                break
            cum += s.time_iteration
            trace.append((cum, s.chi2))
    except Exception:  # noqa: BLE001 - statistics are optional in old bindings
        trace = []
    poses = np.empty_like(init)
    for k, vid in enumerate(data["ids"]):
        est = opt.vertex(vid).estimate()
        if data["dim"] == 3:
            T = np.asarray(est.matrix())
            poses[k, :3] = T[:3, 3]
            poses[k, 3:] = _quat_from_rot(T[:3, :3])
        else:
            poses[k] = [est.translation()[0], est.translation()[1], est.rotation().angle()]
    opt.compute_active_errors()
    return {"poses": poses, "iterations": iterations, "time_s": elapsed, "trace": trace,
            "objective": opt.chi2(), "setup_s": setup_s, "capped": bool(stopped)}
