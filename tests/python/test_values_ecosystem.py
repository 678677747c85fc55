"""Values that behave like numpy and Python expect: the constructors a user
tries first, == / hash / isclose by value, numpy.asarray, reprs of problems,
ids given as an int, and undetermined variables reported as such."""

import copy
import pickle
from pathlib import Path

import boxplus as bp
import numpy as np
import pytest
from boxplus import slam
from conftest import se2, se3, so3
from hypothesis import given, settings

DATA = Path(__file__).resolve().parents[1] / "data"


def rot_z(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


# ---- constructors ------------------------------------------------------------------------
def test_se2_constructors_agree():
    ref = bp.SE2([1.0, 2.0], 0.3)
    T = ref.transform()
    for x in (bp.SE2(1.0, 2.0, 0.3), bp.SE2(1, 2, 0.3), bp.SE2(x=1.0, y=2.0, theta=0.3),
              bp.SE2([1.0, 2.0, 0.3]), bp.SE2(np.array([1.0, 2.0, 0.3])), bp.SE2(T),
              bp.SE2(pos=[1.0, 2.0], rot=bp.SO2(0.3))):
        assert x == ref
        np.testing.assert_array_equal(x.ambient, [1.0, 2.0, 0.3])
    assert bp.SE2(0.0, 0.0, 4.0).phi == pytest.approx(4.0 - 2 * np.pi)  # wrapped like ⊞


def test_se2_constructor_errors_name_the_shape():
    with pytest.raises(TypeError, match=r"\[x, y, theta\].*shape \(4,\)"):
        bp.SE2([1.0, 2.0, 3.0, 4.0])
    with pytest.raises(ValueError, match="finite"):
        bp.SE2(np.nan, 0.0, 0.0)


def test_se3_constructors_agree():
    R, t = rot_z(0.4), np.array([1.0, -2.0, 3.0])
    ref = bp.SE3.from_matrix(np.block([[R, t[:, None]], [np.zeros((1, 3)), np.ones((1, 1))]]))
    q = ref.quat
    for x in (bp.SE3(R, t), bp.SE3(R=R, t=t), bp.SE3(R=bp.SO3(R), t=list(t)), bp.SE3(R=q, t=t),
              bp.SE3(ref.transform()), bp.SE3(np.r_[t, q])):
        assert x.isclose(ref, atol=1e-12)
        np.testing.assert_allclose(x.R, R, atol=1e-12)
        np.testing.assert_allclose(x.t, t)
    # Either part may be left out.
    np.testing.assert_array_equal(bp.SE3(t=t).quat, [0, 0, 0, 1])
    np.testing.assert_array_equal(bp.SE3(t=t).t, t)
    np.testing.assert_array_equal(bp.SE3(R=R).t, np.zeros(3))
    assert bp.SE3(R=R).rot.isclose(bp.SO3(R), atol=1e-12)


def test_se3_constructor_errors():
    with pytest.raises(TypeError, match=r"SE3\(R, t\).*3x3 matrix or a quaternion.*shape \(2, 2\)"):
        bp.SE3(R=np.eye(2))
    with pytest.raises(ValueError, match="not a rotation matrix"):
        bp.SE3(R=2 * np.eye(3), t=np.zeros(3))
    with pytest.raises(ValueError, match="SE3 t: expected a vector of 3 numbers"):
        bp.SE3(R=np.eye(3), t=[1.0, 2.0])
    with pytest.raises(ValueError, match=r"last row of a homogeneous matrix"):
        bp.SE3(np.ones((4, 4)))


def test_so3_and_so2_from_matrix_or_quaternion():
    R = rot_z(-1.1)
    a = bp.SO3(R)
    np.testing.assert_allclose(a.R, R, atol=1e-14)
    assert bp.SO3(a.quat) == a
    assert bp.SO3(R=a) == a
    assert bp.SO2(rot_z(0.7)[:2, :2]).phi == pytest.approx(0.7)
    with pytest.raises(TypeError, match=r"SO3\(R\).*shape \(3,\)"):
        bp.SO3([1.0, 2.0, 3.0])  # a rotation vector is SO3.exp's, not the constructor's
    with pytest.raises(ValueError, match="non-zero"):
        bp.SO3([0.0, 0.0, 0.0, 0.0])


# ---- ==, hash, isclose ----------------------------------------------------------------------
def test_equality_is_by_value_and_hash_agrees():
    a, b = bp.SO3.exp([0.1, 0.2, 0.3]), bp.SO3.exp([0.1, 0.2, 0.3])
    assert a is not b and a == b and not (a != b) and hash(a) == hash(b)
    assert a != bp.SO3.exp([0.1, 0.2, 0.3 + 1e-12])
    # q and -q are one rotation (both normalised alike: == is exact).
    pos, neg = bp.SO3.from_quat(a.quat), bp.SO3.from_quat(-a.quat)
    assert neg == pos and hash(neg) == hash(pos)
    p = bp.SE3(R=a.quat, t=[1, 2, 3])
    assert bp.SE3(R=-a.quat, t=[1, 2, 3]) == p
    assert hash(bp.SE3(R=-a.quat, t=[1, 2, 3])) == hash(p)
    assert len({p, copy.copy(p), pickle.loads(pickle.dumps(p))}) == 1
    # Rn by value; sizes and types must match.
    assert bp.Rn([1.0, 2.0]) == bp.Rn([1.0, 2.0]) and bp.Rn([1.0, 2.0]) != bp.Rn([1.0, 2.0, 0.0])
    assert bp.Rn([0.0]) != bp.SO2(0.0)
    assert bp.SO2(0.0) != 0.0 and bp.SE2() != bp.SE3()
    assert {bp.SE2(1, 2, 3): "x"}[bp.SE2([1, 2, 3])] == "x"


@settings(max_examples=50)
@given(so3)
def test_quaternion_sign_never_changes_equality(r):
    pos, neg = bp.SO3.from_quat(r.quat), bp.SO3.from_quat(-r.quat)
    assert neg == pos and hash(neg) == hash(pos)
    assert neg.isclose(r, atol=1e-15)
    assert (r + np.array([0, 0, 1e-3])) != r


@settings(max_examples=50)
@given(se3, se2)
def test_isclose_is_the_tangent_distance(x, y):
    for v, dof in ((x, 6), (y, 3)):
        for i in range(dof):
            d = np.zeros(dof)
            d[i] = 1e-7
            w = v + d
            assert v.isclose(w, atol=2e-7)
            assert not v.isclose(w, atol=5e-8)
        assert v.isclose(v, atol=0.0)


def test_isclose_errors_and_compounds():
    with pytest.raises(TypeError, match=r"SO3.isclose\(other\): other must be a SO3, got SE3"):
        bp.SO3().isclose(bp.SE3())
    with pytest.raises(ValueError, match="atol"):
        bp.SO3().isclose(bp.SO3(), atol=-1.0)
    C = bp.make_compound("C", r=bp.SO3(), v=bp.Rn(2))
    q = bp.SO3.exp([0, 0, 0.5]).quat
    a = C(r=bp.SO3.from_quat(q), v=[1.0, 2.0])
    b = C(r=bp.SO3.from_quat(-q), v=[1.0, 2.0])
    assert a == b and a.isclose(b, atol=1e-15)
    b.v = [1.0, 2.0 + 1e-6]
    assert a != b and a.isclose(b, atol=2e-6) and not a.isclose(b, atol=1e-7)
    with pytest.raises(TypeError, match="unhashable"):
        hash(a)


# ---- numpy ----------------------------------------------------------------------------------
def test_asarray_is_the_ambient_float_vector():
    cases = [bp.SO2(0.3), bp.SO3.exp([0.1, -0.2, 0.3]), bp.SE2(1, 2, 0.5),
             bp.SE3(R=rot_z(0.2), t=[1, 2, 3]), bp.S2([0, 0, 1]), bp.Rn([1.0, 2.0, 3.0])]
    for v in cases:
        a = np.asarray(v)
        assert a.dtype == np.float64 and a.ndim == 1
        np.testing.assert_array_equal(a, v.ambient)
        assert np.asarray(v, dtype=np.float32).dtype == np.float32
    stacked = np.asarray([bp.SE3(t=[i, 0, 0]) for i in range(4)])
    assert stacked.shape == (4, 7) and stacked.dtype == np.float64
    np.testing.assert_array_equal(stacked[:, 0], [0, 1, 2, 3])
    # A copy: writing to it leaves the value alone.
    x = bp.SE2(1, 2, 0.5)
    a = np.array(x)
    a[0] = 99.0
    assert x.pos[0] == 1.0
    C = bp.make_compound("C2", r=bp.SO2(), v=bp.Rn(2))
    np.testing.assert_array_equal(np.asarray(C(r=bp.SO2(0.1), v=[3.0, 4.0])), [0.1, 3.0, 4.0])


# ---- reprs ----------------------------------------------------------------------------------
def test_problem_reprs():
    p = bp.OptimizationProblem()
    assert repr(p) == "<OptimizationProblem: 0 variables, 0 measurements>"
    a = p.add_random_var(bp.SE3(), name="a")
    b = p.add_random_var(bp.SE3(), fixed=True)
    p.add_random_var(bp.Rn(2))
    p.add_prior(a, bp.SE3(), sigma=1.0)
    p.add_measurement(np.zeros(3), lambda x, y: y.pos - x.pos, [a, b])
    p.add_measurement(np.zeros(3), lambda x, y: y.pos - x.pos, [b, a])
    assert repr(p) == ("<OptimizationProblem: 3 variables (SE3 x2, Rn(2) x1; 1 fixed), "
                       "3 measurements (prior x1, <lambda> x2)>")
    assert repr(p._core) == ("<boxplus.Problem: 3 variables (1 fixed, 8 free tangent dimensions), "
                             "3 measurements (12 residuals)>")
    with pytest.warns(bp.UndeterminedWarning, match="'x2': all 2 directions"):
        s = p.solve()
    assert repr(s).startswith("SolveSummary(") and "termination='convergence'" in repr(s)


def test_pose_graph_repr():
    g = slam.load_g2o(DATA / "landmarks2d.g2o")
    n_poses, n_landmarks = len(g.poses()), len(g.landmarks())
    assert n_landmarks > 0
    assert repr(g) == (f"<PoseGraph 2D: {n_poses} poses, {n_landmarks} landmarks, "
                       f"{g.num_edges} edges, convention 'g2o'>")
    assert repr(g.problem).startswith(f"<boxplus.Problem: {n_poses + n_landmarks} variables (")


# ---- ids as an int, undetermined variables -------------------------------------------------
def test_ids_as_an_int_or_a_clear_type_error():
    p = bp.OptimizationProblem()
    x = p.add_random_var(bp.Rn(1))
    p.add_measurement([2.0], lambda v: v.vec, x, sigma=0.5)  # an int, not [x]
    p.add_measurement([2.0], lambda v: v.vec, np.int64(x), sigma=0.5)
    p.solve()
    assert p.value(x).vec[0] == pytest.approx(2.0)
    assert p.joint_covariance(x).shape == (1, 1)
    with pytest.raises(TypeError, match="ids must be a variable id or a sequence of them, got float"):
        p.add_measurement([2.0], lambda v: v.vec, 0.0)
    with pytest.raises(TypeError, match="got str"):
        p.add_measurement([2.0], lambda v: v.vec, "x")


def test_undetermined_variable_is_reported_not_sigma_zero():
    p = bp.OptimizationProblem()
    x = p.add_random_var(bp.Rn(2), name="seen")
    y = p.add_random_var(bp.SO3(), name="lonely")
    p.add_prior(x, bp.Rn([1.0, 2.0]), sigma=[0.5, 2.0])
    with pytest.warns(bp.UndeterminedWarning, match="'lonely': all 3 directions"):
        p.solve()
    np.testing.assert_allclose(p.std(x), [0.5, 2.0], rtol=1e-9)
    for f in (p.std, p.covariance):
        with pytest.raises(ValueError, match="variable 'lonely' is undetermined: no measurement"):
            f(y)
    with pytest.raises(ValueError, match="'lonely' is undetermined"):
        p.joint_covariance([x, y])
    # Fixed, it is a constant: no covariance either, and the message says why.
    p.fix(y)
    with pytest.raises(bp.BoxplusError, match="variable 'lonely' is fixed: it has no covariance"):
        p.std(y)
    np.testing.assert_allclose(p.std(x), [0.5, 2.0], rtol=1e-9)
