"""Tutorial: a pose graph, from a g2o file to a picture.

    python docs/tutorials/pose_graph.py [--out DIR]

Optimises the Intel Research Lab pose graph that the repository ships
(data/slam/intel.g2o, 2D) and a generated 3D sphere, logs what boxplus does
through Python's logging, and writes the pictures of the tutorial
(pose_graph_intel.png, pose_graph_sphere.png) into DIR (default: this folder).
"""

from __future__ import annotations

import argparse
import logging
from pathlib import Path

import boxplus.log
import boxplus.slam as slam
import matplotlib.pyplot as plt
from boxplus.synthetic.pose_graphs import generate

HERE = Path(__file__).resolve().parent
INTEL = HERE.parents[1] / "data" / "slam" / "intel.g2o"


def intel(out: Path) -> dict:
    # Load: read, initialise and build in C++. init="best" starts from the
    # better of the file's estimate (raw odometry) and the chordal relaxation.
    graph = slam.load_g2o(INTEL, init="best")
    before = graph.positions()  # the start the solve begins from
    summary = graph.solve()  # the pose-graph default solver
    # The returned Figure: save it, or show it (plt.show(), a notebook).
    fig = graph.plot(before=before, title=f"Intel: chi2 {summary.final_chi2:.1f}")
    fig.savefig(out / "pose_graph_intel.png", dpi=90)
    plt.close(fig)
    return {"chi2": summary.final_chi2, "poses": len(before), "edges": graph.num_edges,
            "start": graph.report.start}


def sphere(out: Path) -> dict:
    # A 3D graph with known truth: a sphere of 400 poses, medium noise.
    generated = generate("sphere", 3, 400, noise="medium", seed=1)
    path = out / "sphere.g2o"
    generated.write(path)
    graph = slam.load_g2o(path, init="chordal")
    before = graph.positions()
    summary = graph.solve()
    # 3D graphs are drawn in 3D; two views side by side in one figure.
    fig = plt.figure(figsize=(11, 5.5))
    graph.plot(before=before, ax=fig.add_subplot(1, 2, 1, projection="3d"), title="3D view")
    graph.plot(ax=fig.add_subplot(1, 2, 2), title="top view (x-y)")
    fig.tight_layout()
    fig.savefig(out / "pose_graph_sphere.png", dpi=90)
    plt.close(fig)
    path.unlink()
    return {"chi2": summary.final_chi2, "poses": len(before), "edges": graph.num_edges}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=HERE)
    args = ap.parse_args()
    # Show boxplus' INFO messages: the load reports and the solve summaries.
    logging.basicConfig(level=logging.WARNING, format="%(name)s %(levelname)s: %(message)s")
    boxplus.log.logger.setLevel(logging.INFO)
    args.out.mkdir(parents=True, exist_ok=True)
    print("intel:", intel(args.out))
    print("sphere:", sphere(args.out))


if __name__ == "__main__":
    main()
