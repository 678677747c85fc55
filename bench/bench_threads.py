"""Threads and solves: BLAS oversubscription before/after, and two solves on two threads.

1. BLAS before/after, on a loaded machine: the same pose graph solved with
   ``num_threads=1`` while ``--load`` busy processes run, (a) as before this
   change: BLAS (CHOLMOD's supernodal kernels) left at one thread per core,
   and (b) as every solve now runs: BLAS capped at the solve's ``num_threads``
   (:mod:`boxplus.blas_threads`).
2. The GIL: ``--problems`` independent problems of C++ measurements solved
   serially, then on two threads (``ThreadPoolExecutor(2)``), results checked
   equal bit for bit; the speed-up is what releasing the GIL during a C++
   solve buys (at most the number of idle cores).

Run: .venv/bin/python bench/bench_threads.py [--poses 2000] [--load 2] [--repeat 3]
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager
from pathlib import Path

import boxplus as bp
import boxplus.slam as slam
import numpy as np
from boxplus import blas_threads
from boxplus.synthetic.pose_graphs import generate


@contextmanager
def busy_processes(n: int):
    """``n`` processes spinning on a core each: the other users of a shared machine."""
    procs = [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(n)]
    try:
        time.sleep(0.5)
        yield
    finally:
        for p in procs:
            p.kill()
            p.wait()


@contextmanager
def blas_as_before():
    """BLAS at one thread per core and the solve's cap switched off (the old behaviour)."""
    pools = blas_threads._pools()
    saved = [(p, p.get()) for p in pools]
    for p in pools:
        p.set(os.cpu_count() or 1)
    original = blas_threads.limit

    @contextmanager
    def no_limit(num_threads: int):
        yield

    blas_threads.limit = no_limit  # type: ignore[assignment]
    try:
        yield
    finally:
        blas_threads.limit = original  # type: ignore[assignment]
        for p, n in saved:
            p.set(n)


def graph_file(poses: int, directory: Path) -> Path:
    g = generate("sphere", 3, poses, noise="medium", seed=3)
    path = directory / f"sphere{poses}.g2o"
    g.write(path)
    return path


def time_solve(path: Path, repeat: int) -> tuple[float, float]:
    """(best seconds, final χ²) of ``repeat`` solves from the file's start."""
    best, chi2 = float("inf"), float("nan")
    for _ in range(repeat):
        graph = slam.load_g2o(path)
        t0 = time.perf_counter()
        s = graph.solve(num_threads=1, max_iterations=20)
        best = min(best, time.perf_counter() - t0)
        chi2 = s.final_chi2
    return best, chi2


def chain(seed: int, n: int = 400) -> bp.OptimizationProblem:
    rng = np.random.default_rng(seed)
    o = bp.OptimizationProblem()
    truth = [bp.SE3(bp.SO3.exp(rng.normal(0, 0.5, 3)), rng.normal(0, 2, 3)) for _ in range(n)]
    ids = [o.add_random_var(t + rng.normal(0, 0.3, 6)) for t in truth]
    o.add_prior(ids[0], truth[0], sigma=0.01)
    for i in range(n):
        for j in (i + 1, i + 5):
            if j < n:
                o.add_relative_pose(truth[i].inverse() * truth[j] + rng.normal(0, 0.01, 6), ids[i], ids[j],
                                    sigma=0.01)
    return o


def ambient(o: bp.OptimizationProblem) -> list[np.ndarray]:
    return [np.asarray(o._core.value(v)) for v in range(o.num_variables)]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--poses", type=int, default=2000, help="poses of the 3-D sphere graph")
    ap.add_argument("--load", type=int, default=os.cpu_count() or 2, help="busy processes during part 1")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--problems", type=int, default=8, help="problems of part 2")
    args = ap.parse_args()
    print(f"{os.cpu_count()} cores; BLAS thread control: {blas_threads.backend()}; "
          f"BLAS threads now: {blas_threads.current()}")

    with tempfile.TemporaryDirectory() as d:
        path = graph_file(args.poses, Path(d))
        with busy_processes(args.load):
            with blas_as_before():
                before, chi2_b = time_solve(path, args.repeat)
            after, chi2_a = time_solve(path, args.repeat)
    print(f"1. sphere {args.poses} poses, num_threads=1, {args.load} busy processes:")
    print(f"   before (BLAS at {os.cpu_count()} threads): {before:.3f} s  chi2 {chi2_b:.6g}")
    print(f"   after  (BLAS capped at 1):        {after:.3f} s  chi2 {chi2_a:.6g}")
    print(f"   before/after = {before / after:.2f}x")

    serial_problems = [chain(s) for s in range(args.problems)]
    t0 = time.perf_counter()
    for o in serial_problems:
        o.solve()
    t_serial = time.perf_counter() - t0
    threaded = [chain(s) for s in range(args.problems)]
    t0 = time.perf_counter()
    with ThreadPoolExecutor(2) as pool:
        list(pool.map(lambda o: o.solve(), threaded))
    t_threads = time.perf_counter() - t0
    same = all(
        all(np.array_equal(a, b) for a, b in zip(ambient(x), ambient(y)))
        for x, y in zip(serial_problems, threaded)
    )
    print(f"2. {args.problems} problems of 400 SE3 poses (C++ factors):")
    print(f"   serial {t_serial:.3f} s, two threads {t_threads:.3f} s: speed-up "
          f"{t_serial / t_threads:.2f}x; same bits: {same}")
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
