"""The joint tools on any problem: random restarts, cross-validation folds, and the
synthetic robot of examples/joint_calibration_robot.py."""

import importlib.util
from pathlib import Path

import boxplus as bp
import numpy as np
import pytest
from boxplus.joint import kfold, solve_with_restarts

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "joint_calibration_robot.py"


def _example():
    spec = importlib.util.spec_from_file_location("joint_calibration_robot", EXAMPLE)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


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
