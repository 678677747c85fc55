"""Scale: a 10⁶-pose 2D and a 10⁵-pose 3D graph, boxplus beside g2o and GTSAM in one run.

The graphs are generated (``boxplus.synthetic.pose_graphs``, seeded, cached): a
Manhattan world of 10⁶ poses in 2D and a sphere of 10⁵ poses in 3D (g2o's
``create_sphere`` layout), medium noise, every loop closure kept. Each system
runs in its own process (so its peak memory is its own), reads the file with
its own reader, starts from the file's estimate, fixes the first pose and runs
``--iterations`` Gauss–Newton iterations, one thread (OPENBLAS_NUM_THREADS=1):

* boxplus: ``boxplus.slam.load_g2o`` and ``PoseGraph.solve(method='gn-ls')``;
  with ``--threads 2`` also the same solve on two threads (Jacobians on both,
  BLAS on both);
* g2o (g2opy): ``SparseOptimizer.load``, Gauss–Newton with its Eigen sparse
  Cholesky (the linear solver g2opy ships);
* GTSAM: ``readG2o`` and ``GaussNewtonOptimizer``.

Per system: the time to read the file (and per 10⁵ edges), the set-up (g2o's
``initialize_optimization``, GTSAM's optimizer construction, boxplus' problem
build and symbolic analysis, which boxplus counts in its first iteration), the
median time of an iteration, the objective after the iterations (each in its
own convention: g2o's χ², GTSAM's 2·error, the same numbers on these graphs up
to the rotation error's form) and the process' peak resident memory (a Python
interpreter with numpy is about 40 MB of it). Ratios are boxplus over each peer.
CPU seconds are reported beside wall seconds: on a shared machine they are the
steadier figure of a single-threaded run.

usage: python bench/bench_scale.py [--cache DIR] [--iterations 2] [--only 2d|3d]
        [--threads 2] [--systems boxplus g2o gtsam] [--timeout S] [--json PATH]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

GRAPHS = {
    "2d": dict(family="manhattan", dimension=2, num_poses=1_000_000),
    "3d": dict(family="sphere", dimension=3, num_poses=100_000),
}


def _graph(cache: Path, key: str) -> Path:
    from boxplus.synthetic.pose_graphs import generate

    spec = GRAPHS[key]
    path = cache / f"scale-{spec['family']}-{spec['dimension']}d-{spec['num_poses']}.g2o"
    if not path.exists():
        cache.mkdir(parents=True, exist_ok=True)
        g = generate(spec["family"], spec["dimension"], spec["num_poses"], noise="medium", seed=1)
        g.write(path)
    return path


def _clock() -> tuple[float, float]:
    t = os.times()
    return time.perf_counter(), t.user + t.system


def _since(start: tuple[float, float]) -> tuple[float, float]:
    w, c = _clock()
    return w - start[0], c - start[1]


def _peak_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def run_boxplus(path: str, iterations: int, threads: int) -> dict:
    import boxplus.slam as slam

    t = _clock()
    g = slam.load_g2o(path, init="file")
    read = _since(t)
    times: list[float] = []
    last = [time.perf_counter()]

    def on_iteration(info) -> None:
        now = time.perf_counter()
        if info.iteration > 0:
            times.append(now - last[0])
        last[0] = now

    t = _clock()
    s = g.solve(method="gn-ls", max_iterations=iterations, num_threads=threads, callback=on_iteration)
    solve = _since(t)
    edges = g.num_edges
    return {"read": read, "solve": solve, "iterations": s.iterations, "iteration_s": times,
            "chi2": g.chi2(), "edges": edges, "peak_mb": _peak_mb()}


def run_g2o(path: str, iterations: int, dimension: int) -> dict:
    import g2opy as g2o

    opt = g2o.SparseOptimizer()
    if dimension == 3:
        solver = g2o.BlockSolverSE3(g2o.LinearSolverEigenSE3())
    else:
        solver = g2o.BlockSolverSE2(g2o.LinearSolverEigenSE2())
    opt.set_algorithm(g2o.OptimizationAlgorithmGaussNewton(solver))
    t = _clock()
    opt.load(path)
    read = _since(t)
    first = min(opt.vertices())
    opt.vertex(first).set_fixed(True)
    t = _clock()
    opt.initialize_optimization()
    setup = _since(t)
    opt.set_compute_batch_statistics(True)
    t = _clock()
    opt.optimize(iterations)
    solve = _since(t)
    times = [s.time_iteration for s in opt.batch_statistics()]
    opt.compute_active_errors()
    return {"read": read, "setup": setup, "solve": solve, "iterations": len(times), "iteration_s": times,
            "chi2": opt.chi2(), "edges": len(opt.edges()), "peak_mb": _peak_mb()}


def run_gtsam(path: str, iterations: int, dimension: int) -> dict:
    import tempfile

    import gtsam

    # GTSAM's 2D reader stops at the first line it does not know (a FIX line
    # ends the file for it): it reads a copy with the VERTEX/EDGE lines only,
    # made before the clock starts; the first pose is fixed below, as for the others.
    clean = Path(tempfile.mkdtemp()) / "graph.g2o"
    with open(path) as src, open(clean, "w") as dst:
        dst.writelines(ln for ln in src if ln.startswith(("VERTEX", "EDGE")))
    t = _clock()
    graph, values = gtsam.readG2o(str(clean), dimension == 3)
    read = _since(t)
    clean.unlink()
    first = min(values.keys())
    g = gtsam.NonlinearFactorGraph(graph)
    if dimension == 3:
        g.add(gtsam.PriorFactorPose3(first, values.atPose3(first), gtsam.noiseModel.Isotropic.Sigma(6, 1e-6)))
    else:
        g.add(gtsam.PriorFactorPose2(first, values.atPose2(first), gtsam.noiseModel.Isotropic.Sigma(3, 1e-6)))
    params = gtsam.GaussNewtonParams()
    params.setMaxIterations(iterations)
    t = _clock()
    opt = gtsam.GaussNewtonOptimizer(g, values, params)
    setup = _since(t)
    times = []
    t = _clock()
    for _ in range(iterations):
        w = time.perf_counter()
        opt.iterate()
        times.append(time.perf_counter() - w)
    solve = _since(t)
    if graph.size() == 0:
        raise RuntimeError(f"GTSAM read no factor from {path}")
    return {"read": read, "setup": setup, "solve": solve, "iterations": iterations, "iteration_s": times,
            "chi2": 2 * graph.error(opt.values()), "edges": graph.size(), "peak_mb": _peak_mb()}


def _child(system: str, path: str, iterations: int, dimension: int, threads: int,
           timeout: float | None = None) -> dict:
    """Runs one system in a fresh process: its peak memory is its own; a run
    past ``timeout`` seconds is stopped and reported as such."""
    code = (f"import sys, json; sys.path.insert(0, {str(Path(__file__).parent)!r}); import bench_scale as b; "
            f"print(json.dumps(b._dispatch({system!r}, {path!r}, {iterations}, {dimension}, {threads})))")
    env = dict(os.environ, OPENBLAS_NUM_THREADS=str(threads), OMP_NUM_THREADS=str(threads))
    try:
        p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                           timeout=timeout)
    except subprocess.TimeoutExpired:
        return {"error": f"not finished after {timeout:.0f} s (stopped)"}
    if p.returncode != 0:
        return {"error": (p.stderr or p.stdout)[-400:]}
    return json.loads(p.stdout.strip().splitlines()[-1])


def _dispatch(system: str, path: str, iterations: int, dimension: int, threads: int) -> dict:
    if system.startswith("boxplus"):
        return run_boxplus(path, iterations, threads)
    if system == "g2o":
        return run_g2o(path, iterations, dimension)
    return run_gtsam(path, iterations, dimension)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cache", type=Path, default=Path("build/bench-scale"))
    ap.add_argument("--iterations", type=int, default=2)
    ap.add_argument("--only", choices=sorted(GRAPHS), nargs="*", default=sorted(GRAPHS))
    ap.add_argument("--threads", type=int, default=2, help="also run boxplus on this many threads (1: no)")
    ap.add_argument("--systems", nargs="*", default=["boxplus", "g2o", "gtsam"])
    ap.add_argument("--json", type=Path, default=None)
    ap.add_argument("--timeout", type=float, default=900.0, help="seconds a system may take")
    args = ap.parse_args(argv)
    results: dict = {}
    for key in args.only:
        path = _graph(args.cache, key)
        dim = GRAPHS[key]["dimension"]
        print(f"== {key}: {path.name} ({path.stat().st_size / 1e6:.0f} MB)", flush=True)
        runs = [(s, 1) for s in args.systems]
        if args.threads > 1 and "boxplus" in args.systems:
            runs.insert(1, ("boxplus", args.threads))
        results[key] = {}
        for system, threads in runs:
            name = system if threads == 1 else f"{system} ({threads} threads)"
            r = _child(system, str(path), args.iterations, dim, threads, args.timeout)
            results[key][name] = r
            if "error" in r:
                print(f"  {name:22s} failed: {r['error']}", flush=True)
                continue
            it = statistics.median(r["iteration_s"]) if r["iteration_s"] else float("nan")
            per = r["read"][0] / r["edges"] * 1e5
            print(f"  {name:22s} read {r['read'][0]:6.2f} s ({r['read'][1]:6.2f} CPU, {per:.3f} s/1e5 edges)  "
                  f"iteration {it:7.2f} s  {r['iterations']} it  chi2 {r['chi2']:.6e}  peak {r['peak_mb']:7.0f} MB",
                  flush=True)
        bp = results[key].get("boxplus")
        if bp and "error" not in bp:
            for peer in ("g2o", "gtsam"):
                q = results[key].get(peer)
                if not q or "error" in q:
                    continue
                ratio_read = bp["read"][0] / q["read"][0]
                ratio_it = statistics.median(bp["iteration_s"]) / statistics.median(q["iteration_s"])
                print(f"  boxplus / {peer:6s}: read {ratio_read:.2f}, iteration {ratio_it:.2f}, "
                      f"peak memory {bp['peak_mb'] / q['peak_mb']:.2f}", flush=True)
    if args.json:
        args.json.write_text(json.dumps(results, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
