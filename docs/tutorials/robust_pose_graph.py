"""Tutorial: a pose graph with wrong loop closures.

    python docs/tutorials/robust_pose_graph.py [--out DIR]

Generates a 2D Manhattan-world graph of 1000 poses in which 20 % of the loop
closures are wrong (known truth), solves it twice — once as plain least squares
(``outliers='off'``) and once with the default, which judges the loop closures —
scores both against the truth, lists the closures judged wrong and writes the
tutorial's picture (robust_pose_graph.png) into DIR (default: this folder).
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import boxplus.slam as slam
import matplotlib.pyplot as plt
import numpy as np
from boxplus.slam.metrics import ate, outlier_scores
from boxplus.synthetic.pose_graphs import OUTLIER, generate

HERE = Path(__file__).resolve().parent


def make_graph(folder: Path) -> tuple[Path, object]:
    # Known truth: the generator keeps the true poses and marks
    # every edge as odometry, a true closure or a wrong one.
    generated = generate("manhattan", 2, 1000, noise="medium",
                         outlier_fraction=0.2, seed=3)
    path = folder / "manhattan_20pct_wrong.g2o"
    generated.write(path)
    return path, generated


def solve(path: Path, outliers: str) -> slam.PoseGraph:
    graph = slam.load_g2o(path, outliers=outliers)
    graph.solve()
    return graph


def judged_wrong(graph: slam.PoseGraph) -> np.ndarray:
    # One boolean per edge of the file: did the solve judge it a wrong closure?
    judged = np.zeros(graph.num_edges, bool)
    judged[[v.edge for v in graph.outliers]] = True
    return judged


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=HERE)
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        path, generated = make_graph(Path(tmp))
        plain = solve(path, outliers="off")
        robust = solve(path, outliers="auto")  # the default

    wrong = generated.kind == OUTLIER
    print(f"{path.name}: {robust.num_edges} edges, {wrong.sum()} wrong closures")
    print(f"least squares (outliers='off'): ATE {ate(plain.poses(), generated.truth):.3f} m")
    report = robust.outlier_report
    print(f"default: {report.method} judged {report.candidates} closures, "
          f"{len(robust.outliers)} wrong; ATE {ate(robust.poses(), generated.truth):.3f} m")
    precision, recall = outlier_scores(judged_wrong(robust), wrong)
    print(f"against the truth: precision {precision:.3f}, recall {recall:.3f}")
    for verdict in robust.outliers[:3]:
        print(f"  line {verdict.line}: {verdict.from_id} -> {verdict.to_id}, "
              f"chi2 {verdict.chi2:.3g} (threshold {report.threshold:.3g})")

    fig, (a, b) = plt.subplots(1, 2, figsize=(12, 5.5))
    plain.plot(ax=a, title="least squares: wrong closures pull the map together")
    robust.plot(ax=b, title=f"default: {len(robust.outliers)} closures judged wrong (red)")
    for ax in (a, b):
        t = generated.truth[:, :2]
        ax.plot(t[:, 0], t[:, 1], color="0.75", lw=0.6, zorder=0, label="truth")
        ax.legend(loc="lower right", fontsize=8)
    fig.tight_layout()
    fig.savefig(args.out / "robust_pose_graph.png", dpi=90)
    plt.close(fig)


if __name__ == "__main__":
    main()
