"""Problems, values and results pickle: an OptimizationProblem is rebuilt from its
description (variables, measurements with their functions by reference, noise,
losses, constants) and its copy solves to the same answer bit for bit."""

import copy
import pickle

import boxplus as bp
import numpy as np
import pytest
from boxplus._journal import journalled
from boxplus.calib import add_board, add_gravity
from boxplus.synthetic.cameras import TRUE_K, board_points, observe, random_views


def _offset(x, c):
    return x.vec - c


def _batched_rotation(R, p):
    return R.apply(p) if hasattr(R, "apply") else np.einsum("nij,nj->ni", R.R, p)


def _rotate(R, p):
    return R.R @ p


def _every_kind():
    """One problem with every kind of measurement and variable state."""
    rng = np.random.default_rng(5)
    o = bp.OptimizationProblem()
    x = o.add_random_var(bp.Rn([1.0, 2.0, 3.0]), name="x", labels=["a", "b", "c"])
    R = o.add_random_var(bp.SO3.exp([0.1, 0.2, 0.3]), name="R")
    fixed = o.add_random_var(bp.Rn([5.0]), fixed=True, name="held")
    o.add_measurement([0.5, 1.0, 1.5], _offset, [x], constants=(np.ones(3),), sigma=[0.1, 0.2, 0.3],
                      loss=("huber", 2.0), name="offset")
    p = rng.normal(size=3)
    for _ in range(4):
        z = _rotate(bp.SO3.exp([0.4, 0.1, -0.2]), p) + rng.normal(0, 0.01, 3)
        o.add_measurement(z, _rotate, [R], constants=(p,), covariance=np.diag([0.01, 0.02, 0.03]))
    p *= 1.1  # the problem keeps its constants by reference, and so must its copy
    o.add_prior(x, bp.Rn([0.0, 0.0, 0.0]), information=np.eye(3), loss="cauchy", name="x0")
    o.add_prior(R, bp.SO3(), sigma=1.0)
    # C++ factors: a board seen by a camera, and gravity.
    k = o.add_random_var(bp.Rn(TRUE_K + 1.0), name="k")
    ident = o.add_random_var(bp.SE3(), fixed=True, name="identity")
    pts = board_points()
    z_buf = np.empty((len(pts), 2))
    for i, view in enumerate(random_views(3, rng, pts.mean(axis=0))):
        pose = o.add_random_var(view + rng.normal(0, 0.01, 6), name=f"world_from_cam_{i}")
        z, vis = observe(TRUE_K, view, pts, 0.5, rng)
        z_buf[: len(z)] = z  # one buffer refilled for every view: the journal copies it
        add_board(o, z_buf[: len(z)], k, pose, ident, pts[vis], sigma=0.5, group="cam")
        add_gravity(o, view.rot.R.T @ [0, 0, -9.81], pose, ident, None, sigma=0.05)
    o.fix(fixed)
    o.unfix(fixed)
    o.fix(fixed)
    o.set_value(x, bp.Rn([0.9, 1.9, 2.9]))
    return o


def _ambient(o):
    return [np.asarray(o._core.value(v)) for v in range(o.num_variables)]


def _same(a, b):
    return len(a) == len(b) and all(np.array_equal(u, v) for u, v in zip(a, b))


def test_problem_rebuilt_from_its_description_solves_bit_for_bit():
    o = _every_kind()
    blob = pickle.dumps(o)
    c = pickle.loads(blob)
    assert type(c) is bp.OptimizationProblem
    assert (c.num_variables, c.num_measurements) == (o.num_variables, o.num_measurements)
    assert _same(_ambient(c), _ambient(o))
    assert [c.is_fixed(v) for v in range(c.num_variables)] == [o.is_fixed(v) for v in range(o.num_variables)]
    assert [c.variable_name(v) for v in range(c.num_variables)] == [
        o.variable_name(v) for v in range(o.num_variables)]
    assert c.labels(0) == ["a", "b", "c"]
    assert c.cost() == o.cost()
    so, sc = o.solve(), c.solve()
    assert so.final_cost == sc.final_cost and so.iterations == sc.iterations
    assert _same(_ambient(c), _ambient(o))
    assert c.rms() == o.rms()


def test_a_solved_problem_pickles_with_its_current_values():
    o = _every_kind()
    o.solve(max_iterations=3)
    c = pickle.loads(pickle.dumps(o))
    assert _same(_ambient(c), _ambient(o))
    # ... and goes on from there exactly like the original
    assert o.solve().final_cost == c.solve().final_cost
    assert _same(_ambient(c), _ambient(o))
    c2 = pickle.loads(pickle.dumps(c))  # a copy of a copy
    assert _same(_ambient(c2), _ambient(o))
    assert _same(_ambient(copy.deepcopy(o)), _ambient(o))


def test_vectorised_measurements_pickle():
    rng = np.random.default_rng(1)
    o = bp.OptimizationProblem()
    Rs = [o.add_random_var(bp.SO3.exp(rng.normal(0, 0.3, 3))) for _ in range(3)]
    ids = np.repeat(Rs, 4)[:, None]
    p = rng.normal(size=(12, 3))
    o.add_measurements(p + 0.01, _batched_rotation, ids, constants=(p,), sigma=0.05)
    c = pickle.loads(pickle.dumps(o))
    assert o.solve().final_cost == c.solve().final_cost
    assert _same(_ambient(c), _ambient(o))


def test_local_functions_are_named_when_plain_pickle_refuses_them():
    o = bp.OptimizationProblem()
    x = o.add_random_var(bp.Rn([1.0]))
    o.add_measurement([0.0], lambda v: v.vec, [x])
    with pytest.raises((pickle.PicklingError, AttributeError), match="lambda"):
        pickle.dumps(o)


def test_cloudpickle_takes_local_functions_by_value():
    cloudpickle = pytest.importorskip("cloudpickle")
    o = bp.OptimizationProblem()
    x = o.add_random_var(bp.Rn([1.0, 2.0]))
    scale = 3.0
    o.add_measurement([0.0, 1.0], lambda v: scale * v.vec, [x], sigma=0.1)
    c = pickle.loads(cloudpickle.dumps(o))
    assert o.solve().final_cost == c.solve().final_cost
    assert _same(_ambient(c), _ambient(o))


def test_changes_made_around_the_public_calls_are_refused():
    o = bp.OptimizationProblem()
    x = o.add_random_var(bp.Rn([1.0]))
    o._core.add_factor(bp._core.prior_factor(o._core, x, np.array([0.0]), bp.NoiseModel.isotropic(1, 1.0)))
    with pytest.raises(pickle.PicklingError, match="added through _core directly"):
        pickle.dumps(o)


@journalled
def add_offset_prior(o, vid, z, sigma):
    """A user's own factor function: journalled by its decorator, nowhere else."""
    f = bp._core.prior_factor(o._core, vid, np.atleast_1d(np.asarray(z, float)),
                              bp.NoiseModel.isotropic(1, sigma))
    return o.add_factor(f, group="offset")


def test_a_journalled_factor_function_anywhere_pickles_and_copies():
    o = bp.OptimizationProblem()
    x = o.add_random_var(bp.Rn([1.0]))
    add_offset_prior(o, x, 3.0, 0.5)
    o.add_prior(x, bp.Rn([2.0]), sigma=1.0)
    for c in (pickle.loads(pickle.dumps(o)), o.copy(), copy.deepcopy(o)):
        assert c.num_measurements == 2 and c.groups() == o.groups()
        assert c.solve().final_cost == o.copy().solve().final_cost
    assert o._journal[1][0] is add_offset_prior  # the function itself, not a name in a list


def test_a_bare_cpp_factor_is_refused_with_advice():
    o = bp.OptimizationProblem()
    x = o.add_random_var(bp.Rn([1.0]))
    o.add_factor(bp._core.prior_factor(o._core, x, np.array([0.0]), bp.NoiseModel.unit(1)))
    with pytest.raises(pickle.PicklingError, match="journalled"):
        pickle.dumps(o)


def test_a_loss_object_is_refused_with_advice():
    o = bp.OptimizationProblem()
    x = o.add_random_var(bp.Rn([1.0]))
    o.add_prior(x, bp.Rn([0.0]), loss=bp.Loss("huber", 1.0 / 3.0))
    with pytest.raises(pickle.PicklingError, match=r"\(name, width\) pair"):
        pickle.dumps(o)


def test_a_failed_call_leaves_the_problem_picklable():
    o = bp.OptimizationProblem()
    x = o.add_random_var(bp.Rn([1.0]))
    with pytest.raises(IndexError):
        o.add_prior(7, bp.Rn([0.0]))
    with pytest.raises(ValueError):
        o.add_measurement([0.0], _offset, [x], constants=(np.ones(2),))
    o.add_prior(x, bp.Rn([0.0]))
    c = pickle.loads(pickle.dumps(o))
    assert c.num_measurements == 1 and c.cost() == o.cost()


def test_summary_options_and_values_pickle():
    o = _every_kind()
    s = o.solve()
    t = pickle.loads(pickle.dumps(s))
    assert isinstance(t, bp.SolveSummary)
    assert t == s and t.final_cost == s.final_cost and t.report == s.report
    opts = bp.SolverOptions(method="gn_ls", max_iterations=7, num_threads=2)
    assert pickle.loads(pickle.dumps(opts)) == opts
    for v in (bp.SE3(bp.SO3.exp([0.1, 0.2, 0.3]), [1, 2, 3]), bp.SO3.exp([1e-9, 0, 0]), bp.Rn([1.5]),
              bp.SE2([1, 2], 0.3), bp.S2([0, 0, 1])):
        w = pickle.loads(pickle.dumps(v))
        assert type(w) is type(v)
        assert np.array_equal(bp.codec_of(w).to_ambient(w), bp.codec_of(v).to_ambient(v))


def test_exact_values_keep_their_bits_and_refuse_other_vectors():
    from boxplus import _core

    q = bp.SO3.exp([0.3, -0.2, 0.1]).ambient * (1 + 1e-15)  # unit within rounding only
    v = _core.exact_value("SO3", q)
    assert type(v) is bp.SO3 and np.array_equal(v.ambient, q)
    pose = np.r_[1.0, 2.0, 3.0, q]
    assert np.array_equal(_core.exact_value("SE3", pose).ambient, pose)
    with pytest.raises(ValueError, match="not a normalised value"):
        _core.exact_value("SO3", 2 * q)
    with pytest.raises(ValueError, match="kind must be SO3, SE3 or S2"):
        _core.exact_value("SO2", np.array([0.1]))
    with pytest.raises(ValueError, match="ambient size 7"):
        _core.exact_value("SE3", q)
    o = bp.OptimizationProblem()
    x = o.add_random_var(bp.SO3())
    o._core.restore_value(x, q)
    assert np.array_equal(o._core.value(x), q)
    with pytest.raises(ValueError, match="wrong size"):
        o._core.restore_value(x, np.ones(3))


def test_unit_values_unpickle_their_exact_bits():
    # A stored SO3/SE3/S2 holds normalised numbers; normalising them again on loading
    # can move the last bit (then a copy sent to a worker solves differently).
    rng = np.random.default_rng(7)
    moved = 0
    for _ in range(300):
        for v in (bp.SO3.exp(rng.normal(size=3)), bp.SE3(bp.SO3.exp(rng.normal(size=3)), rng.normal(size=3)),
                  bp.S2(rng.normal(size=3))):
            back = pickle.loads(pickle.dumps(v))
            assert np.array_equal(back.ambient, v.ambient)
            moved += not np.array_equal(type(v).from_ambient(v.ambient).ambient, v.ambient)
    assert moved > 0  # from_ambient alone does move bits: the test would see a regression
