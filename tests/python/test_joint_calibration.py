"""JointCalibration: errors that name the culprit, random restarts, cross-validation,
and the synthetic robot of examples/joint_calibration_robot.py."""

import importlib.util
from pathlib import Path

import boxplus as bp
import numpy as np
import pytest
from boxplus.joint import (
    JointCalibration,
    Plane,
    RangeFinder,
    RobotArm,
    kfold,
    solve_with_restarts,
)

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "joint_calibration_robot.py"


def _example():
    spec = importlib.util.spec_from_file_location("joint_calibration_robot", EXAMPLE)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _arm(lengths=(0.19, 0.14, 0.08, 0.05), offsets=(0.0, 0.0, 0.0, 0.0)):
    return RobotArm("arm", list(lengths), list(offsets), base_height=0.2)


def test_bad_input_names_the_group_or_system():
    jc = JointCalibration()
    jc.add_system(_arm())
    jc.add_system(RangeFinder("lidar"))
    jc.add_system(RangeFinder("tof"))
    with pytest.raises(ValueError, match="plane group 'wall'.*2 points.*at least 3"):
        jc.add_coplanar("lidar", np.zeros((2, 3)), 0.001, name="wall")
    with pytest.raises(KeyError, match="unknown system 'radar'"):
        jc.add_distances("radar", np.zeros((1, 3)), np.zeros((1, 3)), [1.0], 0.001)
    with pytest.raises(ValueError, match="system 'arm' has no data"):
        jc.check()
    rng = np.random.default_rng(0)
    E = rng.uniform(-1, 1, (10, 5))
    jc.add_distances("arm", E[:5], E[5:], np.ones(5), 0.001)
    jc.add_correspondences("lidar", "arm", rng.normal(size=(10, 3)), E, 0.001)
    jc.add_coplanar("tof", rng.normal(size=(5, 3)), 0.001, name="floor")
    with pytest.raises(ValueError, match=r"\['tof'\] are not connected to 'arm'"):
        jc.solve()
    with pytest.raises(ValueError, match="'stereo'.*already"):
        jc2 = JointCalibration()
        jc2.add_system(RangeFinder("stereo"))
        jc2.add_system(RangeFinder("stereo"))


def test_plane_only_system_without_scale_is_refused():
    jc = JointCalibration()
    jc.add_system(_arm())
    jc.add_coplanar("arm", np.random.default_rng(1).uniform(-1, 1, (6, 5)), 0.001, name="table")
    with pytest.raises(ValueError, match="system 'arm': plane and line groups do not fix scale"):
        jc.solve()


def test_range_finder_and_arm_recover_the_truth_jointly():
    """A perfect range finder fixes the arm's kinematics and its own pose."""
    rng = np.random.default_rng(2)
    truth = _arm((0.2, 0.13, 0.09, 0.06), (0.02, -0.03, 0.01, 0.04))
    E = rng.uniform(-1.0, 1.0, (60, 5))
    lidar_from_arm = bp.SE3(bp.SO3.exp([0.1, -0.2, 0.3]), [0.5, 0.1, -0.2])
    P = truth.evaluate(E) @ lidar_from_arm.R.T + lidar_from_arm.pos
    jc = JointCalibration(root="arm")
    jc.add_system(_arm())
    jc.add_system(RangeFinder("lidar"))
    jc.add_correspondences("lidar", "arm", P, E, 1e-4)
    r = jc.solve()
    assert r.termination == "convergence"
    assert np.allclose(jc.values["arm.lengths"].vec, truth.parameters["lengths"].vec, atol=1e-7)
    assert np.allclose(jc.values["arm.offsets"].vec, truth.parameters["offsets"].vec, atol=1e-7)
    assert np.linalg.norm(jc.transform("arm", "lidar") - lidar_from_arm) < 1e-7


def test_coplanar_groups_estimate_the_plane():
    """A wall seen by a range finder: the plane variable converges to the wall."""
    rng = np.random.default_rng(3)
    n = np.array([0.2, 0.1, 1.0]) / np.linalg.norm([0.2, 0.1, 1.0])
    u = np.cross(n, [1.0, 0, 0])
    u /= np.linalg.norm(u)
    P = 1.5 * n + rng.uniform(-1, 1, (20, 1)) * u + rng.uniform(-1, 1, (20, 1)) * np.cross(n, u)
    jc = JointCalibration()
    jc.add_system(RangeFinder("lidar"))
    jc.add_coplanar("lidar", P, 1e-3, name="wall")
    jc.solve()
    plane = jc.group_values["wall"]
    assert isinstance(plane, Plane)
    s = np.sign(plane.normal.vec @ n)
    assert np.allclose(s * plane.normal.vec, n, atol=1e-9) and np.isclose(s * plane.distance.vec[0], 1.5)


def test_random_restarts_never_return_a_worse_cost_than_a_single_solve():
    """A multimodal problem: x ∈ R with residuals sin(3x) and 0.1 x."""
    for seed in range(10):
        def make(seed=seed):
            p = bp.OptimizationProblem()
            x = p.add_random_var(bp.Rn([2.0 + seed * 0.3]))
            p.add_measurement([0.0, 0.0], lambda v: np.r_[np.sin(3 * v.vec[0]), 0.1 * v.vec[0]], [x])
            return p

        single = make()
        single.solve()
        p = make()
        rr = solve_with_restarts(p, 5, seed=seed, perturbation=lambda v: np.full(len(v), 1.0))
        assert rr.best_cost <= single.cost() + 1e-15
        assert rr.costs[0] == pytest.approx(single.cost())
        assert p.cost() == pytest.approx(rr.best_cost)
        again = make()
        assert solve_with_restarts(again, 5, seed=seed,
                                   perturbation=lambda v: np.full(len(v), 1.0)).costs == rr.costs


def test_kfold_splits_every_kind_and_covers_all_items():
    splits = kfold({"boards": 10, "planes": 5}, 5, seed=1)
    assert len(splits) == 5
    for kind, n in (("boards", 10), ("planes", 5)):
        val = np.concatenate([va[kind] for _, va in splits])
        assert sorted(val) == list(range(n))
        for tr, va in splits:
            assert not set(tr[kind]) & set(va[kind]) and len(tr[kind]) + len(va[kind]) == n
    with pytest.raises(ValueError, match="'planes'"):
        kfold({"planes": 2}, 5)


def test_example_robot_ml_and_joint_beat_incremental():
    """The Le & Ng experiment of the example (now on the simulated Sec. VIII rig through
    JointRig), on 2 of its 5 folds: the maximum-likelihood fit reprojects held-out
    arm-predicted corners nearly as well as the true parameters and better than
    incremental calibration."""
    ex = _example()
    out = ex.main(["--folds", "2", "--methods", "incremental", "joint, sharing", "full ML"])
    px = {m: e[:, 1].mean() for m, e in out["rows"].items()}
    assert px["full ML"] < px["incremental"]
    assert px["joint, sharing"] < px["incremental"]
    assert px["full ML"] < 1.15 * px["(true parameters)"]
