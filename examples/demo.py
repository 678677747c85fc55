"""boxplus demo on the bundled data.

1. Fuse twenty noisy observations z_i of one camera pose on SE(3) by minimising
   Σ ‖L⁻¹ (x ⊟ z_i)‖² with ⊞-steps; print the estimate and its error in units of
   the reported standard deviations (tangent space [translation, rotation]).
2. Calibrate a camera from OpenCV's chessboard sample (the MTKM paper's Listing 1,
   examples/camera_calibration.py) and compare with cv2.calibrateCamera.
3. Pose-graph SLAM on the bundled Intel Research Lab graph (data/slam/intel.g2o,
   examples/slam_pose_graph.py): the better start (file or chordal), then the default solver;
   chi2 per iteration, the optimised .g2o and a before/after PNG in slam_output/.
"""

import boxplus as bp
import numpy as np


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


if __name__ == "__main__":
    main()
    print()
    import camera_calibration

    camera_calibration.main()
    print()
    import slam_pose_graph

    print("pose-graph SLAM (examples/slam_pose_graph.py):")
    slam_pose_graph.main([])
