"""boxplus demo on the bundled data.

1. Fuse twenty noisy observations z_i of one camera pose on SE(3) by minimising
   Σ ‖L⁻¹ (x ⊟ z_i)‖² with ⊞-steps; print the estimate and its error in units of
   the reported standard deviations (tangent space [translation, rotation]).
2. Calibrate a camera from OpenCV's chessboard sample (the MTKM paper's Listing 1,
   examples/camera_calibration.py) and compare with cv2.calibrateCamera.
3. Pose-graph SLAM on the bundled Intel Research Lab graph (data/slam/intel.g2o,
   examples/slam_pose_graph.py): the better start (file or chordal), then the default solver;
   chi2 per iteration, the optimised .g2o and a before/after PNG in slam_output/; then the
   proof that this solution is the global optimum (SE-Sync's dual certificate).
4. A stereo pair calibrated from the bundled images (OpenCV's sample, data/calib/
   opencv_stereo) by the command line ``boxplus-calib``: report, OpenCV YAML, ROS
   camera_info files and pictures in demo_output/stereo/.
5. A generated pose graph in which 20 % of the loop closures are wrong: least squares
   against the default, which judges the closures, scored against the known truth.
"""

from pathlib import Path

import boxplus as bp
import numpy as np

DATA = Path(__file__).resolve().parents[1] / "data"


def main() -> None:
    rng = np.random.default_rng(0)
    truth = bp.SE3(bp.SO3.exp([0.3, -0.2, 2.9]), [1.0, 2.0, 0.5])
    sigma = np.array([0.05, 0.05, 0.05, 0.02, 0.02, 0.02])  # m, m, m, rad, rad, rad

    problem = bp.OptimizationProblem()
    pose = problem.add_random_var(bp.SE3(), name="world_from_cam")
    for i in range(20):
        z = truth + rng.normal(0.0, sigma)
        problem.add_prior(pose, z, sigma=sigma, name=f"obs{i}")

    summary = problem.solve()
    est = problem[pose]
    std = problem.std(pose)
    err = est - truth
    print(f"boxplus {bp.__version__} demo: fusing 20 noisy SE(3) observations")
    print(f"  solver: {summary.termination}, {summary.iterations} iterations, "
          f"cost {summary.initial_cost:.4g} -> {summary.final_cost:.4g}")
    print(f"  estimate: {est}")
    print(f"  truth:    {truth}")
    print("  error (est ⊟ truth) / reported σ:", np.array2string(err / std, precision=2))


def certify_intel() -> None:
    # The certificate is for SE-Sync's objective: solve in that convention.
    graph = bp.slam.load_g2o(DATA / "slam" / "intel.g2o", convention="sesync")
    graph.solve()
    result = graph.certify()
    verdict = "globally optimal" if result.certified else "not certified"
    print(f"  certificate: {verdict} (f − f* ≤ {result.suboptimality_bound:.2g} proven; "
          f"{result.verify_time_s:.2f} s)")


def stereo_from_images() -> None:
    from boxplus.calib import cli

    images = DATA / "calib" / "opencv_stereo"
    args = ["--target", "chessboard:9x6:1", "--camera", f"left={images}/left*.jpg",
            "--camera", f"right={images}/right*.jpg", "--out", "demo_output/stereo", "--quiet"]
    print("$ boxplus-calib " + " ".join(a if "*" not in a else repr(a) for a in args))
    cli.main(args)


def wrong_loop_closures() -> None:
    import tempfile

    from boxplus.slam.metrics import ate, outlier_scores
    from boxplus.synthetic.pose_graphs import OUTLIER, generate

    generated = generate("manhattan", 2, 1000, noise="medium", outlier_fraction=0.2, seed=3)
    wrong = generated.kind == OUTLIER
    print(f"  a 2D graph of 1000 poses, {wrong.sum()} of its loop closures wrong (known truth)")
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "graph.g2o"
        generated.write(path)
        for mode in ("off", "auto"):
            graph = bp.slam.load_g2o(path, outliers=mode)
            graph.solve()
            judged = np.zeros(graph.num_edges, bool)
            judged[[v.edge for v in graph.outliers]] = True
            precision, recall = outlier_scores(judged, wrong)
            name = "least squares (outliers='off')" if mode == "off" else "the default"
            print(f"  {name}: ATE {ate(graph.poses(), generated.truth):.3f} m, "
                  f"{judged.sum()} closures judged wrong (precision {precision:.2f}, "
                  f"recall {recall:.2f})")


if __name__ == "__main__":
    main()
    print()
    import camera_calibration

    camera_calibration.main()
    print()
    import slam_pose_graph

    print("pose-graph SLAM (examples/slam_pose_graph.py):")
    slam_pose_graph.main([])
    certify_intel()
    print()
    print("stereo calibration from images (boxplus-calib):")
    stereo_from_images()
    print()
    print("pose graph with wrong loop closures:")
    wrong_loop_closures()
