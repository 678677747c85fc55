"""Pose graphs with wrong loop closures: boxplus' default beside GTSAM's GNC and g2o's kernels.

Each graph comes from ``boxplus.synthetic.pose_graphs`` with its truth: a family
(2D/3D), a size, a fraction of wrong loop closures (0, 5, 20, 50, 80 %) and
an outlier model ('random': independent wrong closures between random poses;
'clustered': groups of ten that agree with each other, as perceptual aliasing
makes them). Every system runs as a user would run it on the file, from the
file's estimate (the odometry), one thread:

* ``boxplus default``: ``boxplus-g2o FILE --outliers LIST`` with no other
  option (auto: GNC-TLS when the least-squares solution is implausible);
* ``inliers only``: ``boxplus-g2o`` on the same file without its wrong
  closures: the answer an oracle front end would give, the reference;
* ``gtsam gnc-tls`` / ``gtsam gnc-gm``: ``GncLMOptimizer`` with the odometry as
  known inliers and the inlier thresholds at probability 0.99 (its default),
  linear μ schedule (GTSAM's default);
* ``g2o cauchy`` / ``g2o dcs``: g2o's Levenberg–Marquardt, 100 iterations,
  with the Cauchy kernel (width 1) or dynamic covariance scaling (Φ = 1) on
  the loop closures;
* ``boxplus KERNEL`` (``--kernels dcs cauchy geman_mcclure``): ``boxplus-g2o FILE
  -r KERNEL``, boxplus' own kernels on every edge from its default start, for
  comparison with the default's judging (a kernel makes no decisions).

``--set shared``: the standard files of the SLAM literature (``../shared/data/slam``,
or ``--shared DIR``) with wrong loop closures added (5, 20 and 50 % random, 20 %
clustered; measurements drawn as the generator draws them, about the reference
optimum; information copied from one of the file's own closures). Their truth is
unknown, so the reference is the file's own optimum (``boxplus-g2o`` on the
clean file) and the ATE column is the distance to it (m, after alignment).

``--set scaled``: generated graphs whose files state the information wrongly, as real
files do (parking-garage's is 2·10⁴× under-confident, intel's 50×): every edge's
information 30× or 3000× too small, and optionally each edge's off by its own
log-uniform factor in [1/10, 10]; 2D/3D, 5–50 % wrong closures.

``--set nearmiss``: information 3000× or 2·10⁴× too small and half the wrong closures
near misses (``boxplus.synthetic.pose_graphs.with_near_misses``): so many pass χ²
thresholds in the file's units that the inliers' capped χ²/dof gives way.

``--set sparse``: few loop closures (5–10 % of the candidates) and a noisy odometry,
2D random walk and Manhattan, 3D sphere at 10³ poses, 5–50 % wrong, two seeds each:
the path between a closure's ends drifts, and eᵀΩe at an estimate without the
closure charges it with that drift (MIT's graph is such a one).

Columns: ATE (m, RMS position error after alignment to the truth), ATE over
the inlier-only ATE, precision and recall of the edges judged wrong (boxplus:
the --outliers list; GTSAM: weight < ½; g2o gives no decision), time (s,
excluding reading the file; boxplus' includes its initialisation and the
building of the problem), and boxplus' time over GTSAM GNC-TLS's. A peer's
run stops at a cap (``--cap`` s, default 300) and is then a miss. Rows go to a
JSON as they come; ``--summarise JSON`` prints an earlier run's table.

usage: python bench/bench_outliers.py [--set quick|full|shared|scaled|nearmiss|sparse] [--only SUBSTR ...]
        [--max-poses N] [--cap S] [--no-peers] [--kernels K ...] [--json PATH]
        [--summarise JSON]
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from boxplus.slam.metrics import ate, outlier_scores  # noqa: E402
from boxplus.synthetic import pose_graphs as gen  # noqa: E402

FRACTIONS = (0.0, 0.05, 0.2, 0.5, 0.8)
PEERS = ("gtsam gnc-tls", "gtsam gnc-gm", "g2o cauchy", "g2o dcs")


def graph_set(name: str) -> list[dict]:
    """The generated graphs: (family, dim, poses, noise, density) × fractions × models."""
    if name == "scaled":
        # Information the file states wrongly: every edge's 30× or 3000× under-confident,
        # and besides each edge's off by a log-uniform factor in [1/10, 10] (real front
        # ends' covariances are rarely right edge by edge).
        rows = []
        for family, dim, n, noise in (("manhattan", 2, 1000, "medium"), ("sphere", 3, 1000, "low"),
                                      ("grid", 3, 1000, "low")):
            for f, model in ((0.05, "random"), (0.2, "random"), (0.2, "clustered"), (0.5, "random")):
                for factor in (1 / 30, 1 / 3000):
                    for spread in (1.0, 10.0):
                        rows.append(dict(family=family, dimension=dim, num_poses=n, noise=noise,
                                         outlier_fraction=f, outlier_model=model, seed=1,
                                         information_factor=factor, information_spread=spread))
        return rows
    if name == "nearmiss":
        # Information far too small and half the wrong closures near misses (their true
        # relative pose 0.18–0.55 √factor σ off: they pass χ² thresholds in the file's
        # units, the random half does not), as a front end that recognises a place a
        # little off writes them.
        rows = []
        for family, dim, n, noise in (("manhattan", 2, 1000, "medium"), ("sphere", 3, 1000, "low"),
                                      ("grid", 3, 1000, "low")):
            for f in (0.2, 0.5):
                for factor in (1 / 3000, 1 / 20000):
                    far = 0.55 / np.sqrt(factor)
                    rows.append(dict(family=family, dimension=dim, num_poses=n, noise=noise,
                                     outlier_fraction=f, outlier_model="random", seed=1,
                                     information_factor=factor, near_miss_share=0.5,
                                     near_miss_sigmas=(far / 3, far)))
        return rows
    if name == "sparse":
        # Few loop closures and a noisy odometry: the path between a closure's ends
        # drifts, and eᵀΩe at an estimate without the closure charges it with that drift.
        rows = []
        for family, dim, noise, density in (("random_walk", 2, "high", 0.05),
                                            ("manhattan", 2, "high", 0.1),
                                            ("sphere", 3, "medium", 0.05)):
            for f, model in ((0.05, "random"), (0.2, "random"), (0.5, "random"),
                             (0.2, "clustered")):
                for seed in (1, 2):
                    rows.append(dict(family=family, dimension=dim, num_poses=1000, noise=noise,
                                     loop_closure_probability=density, outlier_fraction=f,
                                     outlier_model=model, seed=seed))
        return rows
    if name == "quick":
        shapes = [("manhattan", 2, 1000, "medium", 1.0), ("sphere", 3, 1000, "low", 1.0)]
        fractions, models = (0.0, 0.2, 0.5), ("random", "clustered")
    else:
        shapes = [("manhattan", 2, 3000, "medium", 1.0), ("random_walk", 2, 2000, "medium", 1.0),
                  ("grid", 2, 10000, "low", 0.3), ("sphere", 3, 2500, "low", 1.0),
                  ("torus", 3, 1000, "medium", 1.0), ("grid", 3, 3000, "low", 0.5)]
        fractions, models = FRACTIONS, ("random", "clustered")
    rows = []
    for family, dim, n, noise, density in shapes:
        for f in fractions:
            for model in models if f > 0 else ("random",):
                rows.append(dict(family=family, dimension=dim, num_poses=n, noise=noise,
                                 loop_closure_probability=density, outlier_fraction=f,
                                 outlier_model=model, seed=1))
    return rows


SHARED_FILES = ("intel", "MIT", "CSAIL", "manhattan", "parking-garage", "sphere2500",
                "smallGrid3D", "torus3D")
SHARED_VARIANTS = ((0.05, "random"), (0.2, "random"), (0.5, "random"), (0.2, "clustered"))


def shared_set() -> list[dict]:
    return [dict(file=f, outlier_fraction=fr, outlier_model=m, seed=1)
            for f in SHARED_FILES for fr, m in SHARED_VARIANTS]


def label(spec: dict) -> str:
    if "file" in spec:
        return f"{spec['file']}-{round(100 * spec['outlier_fraction'])}%-{spec['outlier_model']}"
    text = (f"{spec['family']}-{spec['dimension']}d-{spec['num_poses']}-"
            f"{round(100 * spec['outlier_fraction'])}%-{spec['outlier_model']}")
    if spec.get("information_factor", 1.0) != 1.0:
        text += f"-under{round(1 / spec['information_factor'])}x"
    if spec.get("information_spread", 1.0) != 1.0:
        text += f"-spread{spec['information_spread']:g}"
    if spec.get("near_miss_share"):
        text += f"-nearmiss{round(100 * spec['near_miss_share'])}%"
    if spec.get("seed", 1) != 1:
        text += f"-seed{spec['seed']}"
    return text


def misstate_information(path: Path, dim: int, spread: float, rng: np.random.Generator) -> None:
    """Each edge's information times its own log-uniform factor in [1/spread, spread]."""
    tag = "EDGE_SE2" if dim == 2 else "EDGE_SE3:QUAT"
    head = 3 + (3 if dim == 2 else 7)  # tag, from, to, measurement
    lines = path.read_text().splitlines()
    for k, line in enumerate(lines):
        if line.startswith(tag):
            t = line.split()
            r = float(np.exp(rng.uniform(-np.log(spread), np.log(spread))))
            lines[k] = " ".join(t[:head] + [f"{float(v) * r:.9g}" for v in t[head:]])
    path.write_text("\n".join(lines) + "\n")


def boxplus_g2o() -> str:
    if os.environ.get("BOXPLUS_G2O"):
        return os.environ["BOXPLUS_G2O"]
    for c in (HERE.parent / "build" / "cpp" / "boxplus-g2o", Path(sys.prefix) / "bin" / "boxplus-g2o"):
        if c.exists():
            return str(c)
    return "boxplus-g2o"


def read_poses(path: Path, dim: int) -> np.ndarray:
    tag = "VERTEX_SE2" if dim == 2 else "VERTEX_SE3:QUAT"
    rows = [ln.split() for ln in path.read_text().splitlines() if ln.startswith(tag)]
    rows.sort(key=lambda t: int(t[1]))
    return np.array([[float(v) for v in t[2:]] for t in rows])


def run_boxplus(path: Path, dim: int, extra=()) -> dict:
    with tempfile.TemporaryDirectory() as d:
        out, listed = Path(d) / "out.g2o", Path(d) / "outliers.txt"
        p = subprocess.run([boxplus_g2o(), "-q", "-t", "1", str(path), "-o", str(out),
                            "--outliers", str(listed), *extra],
                           capture_output=True, text=True, env={**os.environ,
                                                                "OPENBLAS_NUM_THREADS": "1"})
        if p.returncode != 0:
            return {"failed": p.stderr[-400:]}
        load = re.search(r"init ([0-9.]+) s, build ([0-9.]+) s", p.stderr)
        solve = re.search(r"in \d+ iterations, ([0-9.]+) s", p.stderr)
        seconds = float(load.group(1)) + float(load.group(2)) + float(solve.group(1))
        pairs = [tuple(int(v) for v in ln.split()[1:3])
                 for ln in listed.read_text().splitlines() if not ln.startswith("#")]
        return {"poses": read_poses(out, dim), "time_s": seconds, "judged_pairs": pairs}


# -- peers (each in its own process, so that the cap can stop it) -------------
def _peer_main(name: str, path: str, dim: int, out: str) -> None:
    sys.path.insert(0, str(HERE))
    import slam_peers as sp

    text = Path(path).read_text().splitlines()
    tag = "VERTEX_SE2" if dim == 2 else "VERTEX_SE3:QUAT"
    ids = [int(ln.split()[1]) for ln in text if ln.startswith(tag)]
    init = read_poses(Path(path), dim)
    data = {"dim": dim, "ids": sorted(ids)}
    edges = [ln.split() for ln in text if ln.startswith("EDGE")]
    sequential = np.array([abs(int(e[1]) - int(e[2])) == 1 for e in edges])
    weights = None
    if name.startswith("gtsam"):
        import gtsam

        graph = sp.gtsam_graph(path, dim)
        values = sp.gtsam_values(data, init)
        noise = gtsam.noiseModel.Isotropic.Sigma(6 if dim == 3 else 3, 1e-6)
        first = data["ids"][0]
        graph.add(gtsam.PriorFactorPose3(first, values.atPose3(first), noise) if dim == 3
                  else gtsam.PriorFactorPose2(first, values.atPose2(first), noise))
        params = gtsam.GncLMParams()
        params.setLossType(gtsam.GncLossType.TLS if name.endswith("tls") else gtsam.GncLossType.GM)
        params.setKnownInliers([int(k) for k in np.nonzero(sequential)[0]] + [len(edges)])
        t0 = time.perf_counter()
        opt = gtsam.GncLMOptimizer(graph, values, params)
        res = opt.optimize()
        seconds = time.perf_counter() - t0
        weights = np.asarray(opt.getWeights())[:len(edges)]
        poses = np.array([[*res.atPose3(i).translation(), *sp._quat_from_rot(
            res.atPose3(i).rotation().matrix())] if dim == 3 else
            [res.atPose2(i).x(), res.atPose2(i).y(), res.atPose2(i).theta()] for i in data["ids"]])
    else:
        import g2opy as g2o

        opt = g2o.SparseOptimizer()
        solver = (g2o.BlockSolverSE3(g2o.LinearSolverEigenSE3()) if dim == 3
                  else g2o.BlockSolverSE2(g2o.LinearSolverEigenSE2()))
        opt.set_algorithm(g2o.OptimizationAlgorithmLevenberg(solver))
        opt.load(path)
        opt.vertex(data["ids"][0]).set_fixed(True)
        for e in opt.edges():
            a, b = (v.id() for v in e.vertices())
            if abs(a - b) != 1:
                e.set_robust_kernel(g2o.RobustKernelCauchy(1.0) if name.endswith("cauchy")
                                    else g2o.RobustKernelDCS(1.0))
        t0 = time.perf_counter()
        opt.initialize_optimization()
        opt.optimize(100)
        seconds = time.perf_counter() - t0
        rows = []
        for i in data["ids"]:
            est = opt.vertex(i).estimate()
            if dim == 3:
                T = np.asarray(est.matrix())
                rows.append([*T[:3, 3], *sp._quat_from_rot(T[:3, :3])])
            else:
                v = est.vector()
                rows.append([v[0], v[1], v[2]])
        poses = np.array(rows)
    np.savez(out, poses=poses, time_s=seconds,
             weights=np.array([]) if weights is None else weights)


def run_peer(name: str, path: Path, dim: int, cap: float) -> dict:
    with tempfile.TemporaryDirectory() as d:
        out = Path(d) / "peer.npz"
        try:
            p = subprocess.run([sys.executable, __file__, "--peer", name, str(path), str(dim),
                                str(out)], capture_output=True, text=True, timeout=cap,
                               env={**os.environ, "OPENBLAS_NUM_THREADS": "1",
                                    "OMP_NUM_THREADS": "1"})
        except subprocess.TimeoutExpired:
            return {"capped": True}
        if p.returncode != 0 or not out.exists():
            return {"failed": (p.stderr or "no output")[-300:]}
        z = np.load(out)
        return {"poses": z["poses"], "time_s": float(z["time_s"]), "weights": z["weights"]}


# -- one graph ------------------------------------------------------------------
def judged_edges(pairs, edges) -> np.ndarray | None:
    """One boolean per edge (file order): listed by boxplus' --outliers (by vertex pair,
    each listing taking the first not yet taken edge of that pair)."""
    if pairs is None:
        return None
    listed: dict[tuple[int, int], int] = {}
    for pair in pairs:
        listed[pair] = listed.get(pair, 0) + 1
    judged = np.zeros(len(edges), bool)
    for k, (a, b) in enumerate(edges):
        if listed.get((int(a), int(b)), 0) > 0:
            listed[(int(a), int(b))] -= 1
            judged[k] = True
    return judged


def bench_graph(spec: dict, work: Path, args) -> dict:
    options = {k: v for k, v in spec.items() if not k.startswith(("information_", "near_miss_"))}
    g = gen.generate(**options)
    if spec.get("near_miss_share"):
        g = gen.with_near_misses(g, spec["near_miss_share"], spec["near_miss_sigmas"],
                                 seed=spec["seed"])
    g = dataclasses.replace(g, information=g.information * spec.get("information_factor", 1.0))
    path = work / (label(spec) + ".g2o")
    g.write(path)
    if spec.get("information_spread", 1.0) != 1.0:
        misstate_information(path, g.dimension, spec["information_spread"],
                             np.random.default_rng(spec["seed"] + 1))
    wrong = g.is_outlier
    # The inliers' file: the same lines without the wrong closures' (the file's edges
    # are g.edges in order, after the vertices and the FIX line).
    lines = path.read_text().splitlines()
    first_edge = len(lines) - len(g.edges)
    inlier_path = work / (label(spec) + "-inliers.g2o")
    inlier_path.write_text("\n".join(lines[:first_edge] + [
        line for line, bad in zip(lines[first_edge:], wrong) if not bad]) + "\n")
    row = {"graph": label(spec), **spec, "outliers": int(wrong.sum()),
           "closures": g.num_loop_closures}
    ref = run_boxplus(inlier_path, g.dimension, ["--outlier-mode", "off"])
    row["inliers only"] = {"ate": ate(ref["poses"], g.truth), "time_s": ref["time_s"]}
    reference = row["inliers only"]["ate"]

    def score(result, judged=None):
        if "poses" not in result:
            return {k: v for k, v in result.items() if k != "poses"}
        a = ate(result["poses"], g.truth)
        entry = {"ate": a, "ate_ratio": a / reference, "time_s": result["time_s"]}
        if judged is not None:
            entry["precision"], entry["recall"] = outlier_scores(judged, wrong)
        return entry

    bp = run_boxplus(path, g.dimension)
    judged = judged_edges(bp.get("judged_pairs"), [tuple(e) for e in g.edges.tolist()])
    row["boxplus default"] = score(bp, judged)
    for kernel in args.kernels:  # boxplus' own kernels, for comparison (no decisions)
        row[f"boxplus {kernel}"] = score(run_boxplus(path, g.dimension, ["-r", kernel]))
    if not args.no_peers:
        for name in PEERS:
            r = run_peer(name, path, g.dimension, args.cap)
            w = r.get("weights")
            row[name] = score(r, None if w is None or len(w) == 0 else w < 0.5)
    return row


def contaminate(lines: list[str], dim: int, optimum: np.ndarray, ids: list[int], fraction: float,
                model: str, rng: np.random.Generator) -> tuple[list[str], list[tuple[int, int]]]:
    """Wrong loop closures for a file: ``fraction`` of its closures afterwards are wrong.

    'random': independent closures between random poses ≥ 2 apart, measurements
    random poses within 5 odometry steps (boxplus.synthetic.pose_graphs's model);
    'clustered': groups of ten consecutive pairs that agree with one wrong map
    (perceptual aliasing). Each takes the information of a random closure of the file."""
    tag = "EDGE_SE2" if dim == 2 else "EDGE_SE3:QUAT"
    edges = [ln.split() for ln in lines if ln.startswith(tag)]
    closures = [e for e in edges if abs(int(e[1]) - int(e[2])) != 1] or edges
    num_out = int(round(fraction * len(closures) / (1.0 - fraction)))
    index = {v: k for k, v in enumerate(ids)}
    steps = [np.linalg.norm(gen.se.between(optimum[index[int(e[1])]][None], optimum[index[int(e[2])]][None],
                                           dim)[0, :dim])
             for e in edges if abs(int(e[1]) - int(e[2])) == 1 and int(e[1]) in index]
    reach = 5.0 * float(np.median(steps))
    n = len(ids)
    pairs, z = [], []
    while len(pairs) < num_out:
        if model == "random":
            i, j = np.sort(rng.integers(0, n, 2))
            if j - i < 2:
                continue
            pairs.append((i, j))
            z.append(gen._random_poses(rng, 1, dim, reach)[0])
        else:
            i, j = np.sort(rng.integers(0, n - 10, 2))
            if j - i < 12:
                continue
            wrong_map = gen.se.compose(gen.se.compose(optimum[i][None], gen._random_poses(rng, 1, dim, reach),
                                                      dim), gen.se.inverse(optimum[j][None], dim), dim)
            for s in range(min(10, num_out - len(pairs))):
                aliased = gen.se.compose(wrong_map, optimum[j + s][None], dim)
                pairs.append((i + s, j + s))
                z.append(gen.se.between(optimum[i + s][None], aliased, dim)[0])
    out = []
    for (i, j), m in zip(pairs, gen._canonical(np.array(z), dim)):
        info = closures[rng.integers(len(closures))][3 + len(m):]  # tag, i, j, z, info
        out.append(" ".join([tag, str(ids[i]), str(ids[j]), *(f"{v:.9g}" for v in m), *info]))
    return out, [(ids[i], ids[j]) for i, j in pairs]


def bench_shared(spec: dict, work: Path, args) -> dict:
    source = args.shared / f"{spec['file']}.g2o"
    lines = source.read_text().splitlines()
    dim = 3 if any(ln.startswith(("VERTEX_SE3", "EDGE_SE3")) for ln in lines[:50]) else 2
    tag = "VERTEX_SE2" if dim == 2 else "VERTEX_SE3:QUAT"
    ids = sorted(int(ln.split()[1]) for ln in lines if ln.startswith(tag))
    if not ids:
        # A file of edges only (CSAIL, manhattan): the odometry composed, as a front end
        # would write it, so that every system starts from the same estimate.
        from boxplus.slam import load_g2o

        start = load_g2o(source, init="file")
        ids = sorted(start.vertex_ids)
        poses = start.poses()
        order = np.argsort(start.vertex_ids)
        lines = [" ".join([tag, str(ids[k]), *(f"{v:.9g}" for v in poses[order[k]])])
                 for k in range(len(ids))] + lines
    ref = run_boxplus(source, dim, ["--outlier-mode", "off"])
    optimum = ref["poses"]
    rng = np.random.default_rng(spec["seed"])
    extra, wrong_pairs = contaminate(lines, dim, optimum, ids, spec["outlier_fraction"],
                                     spec["outlier_model"], rng)
    path = work / (label(spec) + ".g2o")
    path.write_text("\n".join(lines + extra) + "\n")
    edge_tag = "EDGE_SE2" if dim == 2 else "EDGE_SE3:QUAT"
    all_edges = [tuple(int(v) for v in ln.split()[1:3]) for ln in lines + extra
                 if ln.startswith(edge_tag)]
    wrong = np.zeros(len(all_edges), bool)
    wrong[len(all_edges) - len(extra):] = True
    row = {"graph": label(spec), **spec, "dimension": dim, "outliers": len(extra),
           "closures": int(sum(abs(a - b) != 1 for a, b in all_edges)) - len(extra)}
    row["inliers only"] = {"ate": 0.0, "time_s": ref["time_s"]}

    def score(result, judged=None):
        if "poses" not in result:
            return {k: v for k, v in result.items() if k != "poses"}
        entry = {"ate": ate(result["poses"], optimum), "time_s": result["time_s"]}
        if judged is not None:
            entry["precision"], entry["recall"] = outlier_scores(judged, wrong)
        return entry

    bp = run_boxplus(path, dim)
    judged = judged_edges(bp.get("judged_pairs"), all_edges)
    row["boxplus default"] = score(bp, judged)
    for kernel in args.kernels:  # boxplus' own kernels, for comparison (no decisions)
        row[f"boxplus {kernel}"] = score(run_boxplus(path, dim, ["-r", kernel]))
    if not args.no_peers:
        for name in PEERS:
            r = run_peer(name, path, dim, args.cap)
            w = r.get("weights")
            row[name] = score(r, None if w is None or len(w) == 0 else w < 0.5)
    return row


# -- table ----------------------------------------------------------------------
def fmt(entry: dict | None, key: str, spec: str) -> str:
    if not entry:
        return "-"
    if entry.get("capped"):
        return "capped"
    if "failed" in entry:
        return "failed"
    v = entry.get(key)
    return "-" if v is None else format(v, spec)


def summarise(rows: list[dict]) -> None:
    kernels = sorted({k for r in rows for k in r if k.startswith("boxplus ") and k != "boxplus default"})
    systems = ["boxplus default"] + kernels + [p for p in PEERS if any(p in r for r in rows)]
    print(f"{'graph':34s} {'wrong':>6s} {'inl. ATE':>8s} | " + " | ".join(
        f"{s:>30s}" for s in systems) + " | bp/gnc-tls time")
    print(f"{'':34s} {'':6s} {'':8s} | " + " | ".join(
        f"{'ATE×  prec  rec   time':>30s}" for _ in systems))
    ratios = []
    for r in rows:
        cells = []
        # generated graphs: ATE over the inliers-only ATE; shared files: ATE to the
        # file's own optimum, in metres
        key = "ate" if "file" in r else "ate_ratio"
        for s in systems:
            e = r.get(s)
            cells.append(f"{fmt(e, key, '6.3f'):>7s} {fmt(e, 'precision', '.3f'):>5s} "
                         f"{fmt(e, 'recall', '.3f'):>5s} {fmt(e, 'time_s', '8.2f'):>8s}".rjust(30))
        t = r.get("boxplus default", {}).get("time_s")
        p = r.get("gtsam gnc-tls", {})
        ratio = t / p["time_s"] if t and p.get("time_s") else None
        if ratio:
            ratios.append(ratio)
        print(f"{r['graph']:34s} {r['outliers']:6d} {r['inliers only']['ate']:8.4f} | "
              + " | ".join(cells) + f" | {'-' if ratio is None else format(ratio, '.2f')}")
    if any("file" in r for r in rows):
        print("\nshared files: 'ATE×' is the ATE to the clean file's optimum (m); 'inl. ATE' 0 "
              "by definition")
    if ratios:
        print(f"\nboxplus time / GTSAM GNC-TLS time: median {statistics.median(ratios):.2f}, "
              f"worst {max(ratios):.2f} over {len(ratios)} graphs")


def main(argv=None) -> int:
    if argv is None and len(sys.argv) > 1 and sys.argv[1] == "--peer":
        _peer_main(sys.argv[2], sys.argv[3], int(sys.argv[4]), sys.argv[5])
        return 0
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--set", choices=("quick", "full", "shared", "scaled", "nearmiss", "sparse"),
                    default="full")
    ap.add_argument("--shared", type=Path, default=HERE.parents[1] / "shared" / "data" / "slam")
    ap.add_argument("--only", nargs="*", default=[])
    ap.add_argument("--max-poses", type=int, default=None)
    ap.add_argument("--cap", type=float, default=300.0)
    ap.add_argument("--no-peers", action="store_true")
    ap.add_argument("--kernels", nargs="*", default=[],
                    help="also run boxplus-g2o -r KERNEL (e.g. dcs cauchy geman_mcclure)")
    ap.add_argument("--json", type=Path, default=Path("bench_outliers.json"))
    ap.add_argument("--summarise", type=Path)
    args = ap.parse_args(argv)
    if args.summarise:
        summarise(json.loads(args.summarise.read_text()))
        return 0
    specs = [s for s in (shared_set() if args.set == "shared" else graph_set(args.set))
             if (not args.only or any(o in label(s) for o in args.only))
             and (args.max_poses is None or s.get("num_poses", 0) <= args.max_poses)]
    rows = []
    with tempfile.TemporaryDirectory() as d:
        try:
            for k, spec in enumerate(specs):
                t = time.perf_counter()
                run = bench_shared if "file" in spec else bench_graph
                rows.append(run(spec, Path(d), args))
                print(f"[{k + 1}/{len(specs)}] {label(spec)} in {time.perf_counter() - t:.1f} s",
                      file=sys.stderr, flush=True)
                args.json.write_text(json.dumps(rows, indent=1))
        except KeyboardInterrupt:
            print("interrupted: the graphs done so far", file=sys.stderr)
    summarise(rows)
    return 0


if __name__ == "__main__":
    sys.exit(main())
