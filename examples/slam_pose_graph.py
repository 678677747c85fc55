"""Pose-graph SLAM with boxplus: load a g2o file, initialise, solve, save, plot.

    python examples/slam_pose_graph.py [FILE.g2o] [--init best|chordal|spanning-tree|file]
                                       [--convention g2o|log] [--out DIR]

By default it optimises the bundled Intel Research Lab data set
(data/slam/intel.g2o, 1728 poses, 2512 edges) as ``boxplus-g2o FILE`` does:
from the better start of the file's estimate and the chordal relaxation
(rotations by the relaxation, translations by linear least squares), then the
pose-graph default solver (boxplus.slam.SOLVER_DEFAULTS: Gauss–Newton with a
line search, Levenberg–Marquardt if its steps must be shortened), printing χ²
per iteration in boxplus' one progress format. It writes the optimised graph (ids
and order of the input kept, so g2o's viewer and GTSAM read it) and a PNG of the
trajectory before (the file's own estimate: raw odometry) and after.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import boxplus.slam as slam

HERE = Path(__file__).resolve().parent
DEFAULT_FILE = HERE.parent / "data" / "slam" / "intel.g2o"


def run(path: Path, init: str = "best", convention: str = "g2o", out: Path = Path("."),
        verbose: bool = True) -> dict:
    """Solves ``path``; returns the chi2 values, the summary and the output paths."""
    start = slam.load_g2o(path, convention=convention, init="file")  # the file's estimate
    before = start.positions()
    graph = slam.load_g2o(path, convention=convention, init=init)
    if verbose:
        print(f"{path.name}: {len(graph.vertex_ids)} vertices, {graph.num_edges} edges, "
              f"{graph.dimension}D, gauge vertex {graph.gauge_vertex}, convention {convention}")
        print(f"  chi2 at the file's estimate {start.chi2():.6g}; start {graph.report.start} "
              f"(init {init}): chi2 {graph.chi2():.6g}")

    summary = graph.solve(verbose=verbose)
    out.mkdir(parents=True, exist_ok=True)
    g2o_out = out / f"{path.stem}_optimized.g2o"
    png_out = out / f"{path.stem}_before_after.png"
    graph.save_g2o(g2o_out)
    graph.plot(png_out, before=before,
               title=f"{path.stem}: chi2 {start.chi2():.4g} (file) -> {graph.chi2():.6g}")
    if verbose:
        print(f"  {summary.termination} after {summary.iterations} iterations, "
              f"{summary.time_s * 1e3:.1f} ms: chi2 {graph.chi2():.10g} "
              f"(g2o convention {graph.chi2('g2o'):.10g}, log {graph.chi2('log'):.10g})")
        print(f"  wrote {g2o_out} and {png_out}")
    return {"chi2_file": start.chi2(), "chi2": graph.chi2(), "summary": summary,
            "g2o": g2o_out, "png": png_out}


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("file", nargs="?", type=Path, default=DEFAULT_FILE)
    ap.add_argument("--init", default="best", choices=["best", "chordal", "spanning-tree", "file"])
    ap.add_argument("--convention", default="g2o", choices=["g2o", "log"])
    ap.add_argument("--out", type=Path, default=Path("slam_output"))
    args = ap.parse_args(argv)
    return run(args.file, args.init, args.convention, args.out)


if __name__ == "__main__":
    main()
