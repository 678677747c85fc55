"""⊞/⊟ axioms, Jacobians and group identities of every manifold, from Python."""

import boxplus as bp
import numpy as np
import pytest
from conftest import POINTS, delta_for, rotation_vector
from hypothesis import given
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

KINDS = sorted(POINTS)


def same(a, b, tol=1e-9):
    """Same point of the manifold (q and -q are one rotation)."""
    return np.linalg.norm(a - b) < tol * max(1.0, np.linalg.norm(a.ambient[:3]))


@pytest.mark.parametrize("kind", KINDS)
def test_plus_zero_is_identity(kind):
    @given(POINTS[kind])
    def check(x):
        assert same(x + np.zeros(x.dof), x, 1e-12)

    check()


@pytest.mark.parametrize("kind", KINDS)
def test_minus_of_plus_recovers_delta(kind):
    @given(POINTS[kind], delta_for(kind))
    def check(x, d):
        back = (x + d) - x
        scale = max(1.0, np.linalg.norm(x.ambient[:3]) if kind.startswith("SE") else 1.0)
        assert np.allclose(back, d, atol=1e-8 * scale), (x, d, back)

    check()


@pytest.mark.parametrize("kind", KINDS)
def test_plus_of_minus_reaches_y(kind):
    @given(POINTS[kind], POINTS[kind])
    def check(x, y):
        assert same(x + (y - x), y, 1e-8)

    check()


@pytest.mark.parametrize("kind", KINDS)
def test_minus_is_non_expansive(kind):
    @given(POINTS[kind], delta_for(kind, np.pi / 2), delta_for(kind, np.pi / 2))
    def check(x, d1, d2):
        lhs = np.linalg.norm((x + d1) - (x + d2))
        assert lhs <= np.linalg.norm(d1 - d2) * (1 + 1e-9) + 1e-9

    check()


@pytest.mark.parametrize("kind", KINDS)
def test_jacobians_match_central_differences(kind):
    m = getattr(bp, kind).manifold()

    @given(POINTS[kind])
    def check(x):
        a = x.ambient
        h = 1e-6

        def diff(u, v):
            d = u - v
            if kind in ("SO2", "SE2"):  # the stored angle jumps by 2π at the seam
                d[-1] = (d[-1] + np.pi) % (2 * np.pi) - np.pi
            return d

        J = np.column_stack(
            [diff(m.plus(a, h * e), m.plus(a, -h * e)) / (2 * h) for e in np.eye(m.tangent_size)]
        )
        assert np.allclose(m.plus_jacobian(a), J, atol=1e-6)
        # d(y ⊟ x)/dy at y = x, by moving y in ambient space (no renormalisation)
        Jm = np.column_stack(
            [(m.minus(a + h * e, a) - m.minus(a - h * e, a)) / (2 * h) for e in np.eye(m.ambient_size)]
        )
        assert np.allclose(m.minus_jacobian(a), Jm, atol=1e-6)
        assert np.allclose(m.minus_jacobian(a) @ m.plus_jacobian(a), np.eye(m.tangent_size), atol=1e-12)

    check()


@given(rotation_vector(np.pi))
def test_so3_exp_log_and_scipy_agree(w):
    R = bp.SO3.exp(w)
    assert np.allclose(R.log(), w, atol=1e-9)
    ref = Rotation.from_rotvec(w)
    assert np.allclose(R.R, ref.as_matrix(), atol=1e-12)
    q = ref.as_quat()  # scipy: [x, y, z, w], like boxplus
    assert np.allclose(bp.SO3.from_quat(q).R, R.R, atol=1e-12)


@given(POINTS["SO3"], POINTS["SO3"])
def test_so3_group_identities(a, b):
    assert np.allclose((a * a.inverse()).R, np.eye(3), atol=1e-12)
    assert np.allclose((a * b).R, a.R @ b.R, atol=1e-12)
    assert np.allclose((a @ b).R, (a * b).R)
    p = np.array([0.3, -1.0, 2.0])
    assert np.allclose(a * p, a.R @ p)
    assert np.allclose(bp.SO3(a.R).R, a.R, atol=1e-12)
    # q and -q are the same rotation and give the same ⊟
    assert np.allclose(bp.SO3.from_quat(-a.quat) - b, a - b, atol=1e-9)


@given(POINTS["SE3"], POINTS["SE3"])
def test_se3_transform_and_local_coordinates(a, b):
    p = np.array([[0.3, -1.0, 2.0], [4.0, 5.0, -6.0]])
    assert np.allclose(a.tolocal(a.fromlocal(p)), p, atol=1e-9 * (1 + np.abs(a.pos).max()))
    assert np.allclose((a * b).transform(), a.transform() @ b.transform(), atol=1e-8 * (1 + np.abs(a.pos).max() + np.abs(b.pos).max()))
    assert np.allclose(bp.SE3.from_matrix(a.transform()).transform(), a.transform(), atol=1e-9 * (1 + np.abs(a.pos).max()))


def test_se3_tangent_order_is_translation_then_rotation():
    x = bp.SE3(bp.SO3.exp([0.1, 0.2, 0.3]), [1.0, 2.0, 3.0])
    y = x + np.array([0.5, -0.5, 1.0, 0.0, 0.0, 0.2])
    assert np.allclose(y.pos, [1.5, 1.5, 4.0])
    assert np.allclose(y.R, x.R @ bp.SO3.exp([0, 0, 0.2]).R)


def test_so2_wraps_the_difference():
    assert np.isclose((bp.SO2(-3.1) - bp.SO2(3.1))[0], 2 * np.pi - 6.2)
    assert -np.pi <= bp.SO2(3 * np.pi).phi < np.pi


def test_values_reject_bad_input():
    x = bp.SO3()
    with pytest.raises(ValueError, match="expected a vector of 3"):
        x + np.zeros(2)
    with pytest.raises(TypeError, match="must be a SO3"):
        x - bp.SE3()
    with pytest.raises(ValueError, match="not a rotation matrix"):
        bp.SO3(np.diag([1.0, 1.0, -1.0]))
    with pytest.raises(ValueError, match="non-zero"):
        bp.SO3.from_quat([0, 0, 0, 0])
    with pytest.raises(ValueError, match="non-zero"):
        bp.S2([0, 0, 0])
    with pytest.raises(ValueError):
        bp.make_manifold("SE4")


@given(st.lists(st.sampled_from(KINDS), min_size=1, max_size=4), st.data())
def test_product_manifold_is_memberwise(kinds, data):
    members = [getattr(bp, k).manifold() for k in kinds]
    m = bp.make_product_manifold(members)
    xs = [data.draw(POINTS[k]) for k in kinds]
    ds = [data.draw(delta_for(k, 1.0)) for k in kinds]
    x = np.concatenate([v.ambient for v in xs])
    d = np.concatenate(ds)
    out = m.plus(x, d)
    expected = np.concatenate([(v + dd).ambient for v, dd in zip(xs, ds)])
    assert np.allclose(out, expected)
    assert np.allclose(m.minus(out, x), d, atol=1e-7 * max(1.0, np.abs(x).max()))


# ---- codecs: what callers ask of a type instead of switching on it ------------------

def test_codec_labels_name_the_tangent_directions():
    from boxplus.manifolds import codec_of

    assert codec_of(bp.SE3()).labels() == ["p.x", "p.y", "p.z", "θ.x", "θ.y", "θ.z"]
    assert codec_of(bp.Rn(2)).labels() == ["[0]", "[1]"]
    assert codec_of(bp.SO3()).labels() == ["θ.x", "θ.y", "θ.z"]
    assert codec_of(bp.SE2()).labels() == ["p.x", "p.y", "θ"]
    assert codec_of(bp.SO2()).labels() == ["θ"]
    C = bp.make_compound("C_labels", f=bp.Rn(1), c=bp.Rn(2), pose=bp.SE3())
    assert codec_of(C()).labels() == ["f", "c[0]", "c[1]"] + [f"pose[{i}]" for i in range(6)]


def test_codec_tangent_scale_is_per_row_and_member_wise():
    from boxplus.manifolds import codec_of

    X = np.array([[0.5, -3.0], [10.0, 0.0]])
    np.testing.assert_array_equal(codec_of(bp.Rn(2)).tangent_scale(X), [[1.0, 3.0], [10.0, 1.0]])
    se3 = codec_of(bp.SE3())
    np.testing.assert_array_equal(se3.tangent_scale(np.tile(bp.SE3().ambient, (3, 1))), np.ones((3, 6)))
    C = bp.make_compound("C_scale", k=bp.Rn(1), q=bp.SO3(), v=bp.Rn(2))
    c = codec_of(C())
    A = np.stack([C(k=[5.0], v=[0.1, -7.0]).to_ambient(), C(k=[-0.2]).to_ambient()])
    np.testing.assert_array_equal(c.tangent_scale(A), [[5.0, 1, 1, 1, 1.0, 7.0], [1.0, 1, 1, 1, 1.0, 1.0]])


def test_codec_parts_plus_batch_views_and_display():
    from boxplus import batch
    from boxplus.manifolds import codec_of

    rn, se3 = codec_of(bp.Rn(3)), codec_of(bp.SE3())
    assert rn.is_euclidean and not se3.is_euclidean
    X, D = np.ones((2, 3)), np.arange(6.0).reshape(2, 3)
    np.testing.assert_array_equal(rn.plus_batch(X, D), X + D)
    T = bp.SE3(bp.SO3.exp([0.1, 0.2, 0.3]), [1.0, 2, 3])
    d = np.array([0.01, -0.02, 0.03, 0.1, 0.0, -0.1])
    np.testing.assert_allclose(se3.plus_batch(T.ambient[None], d[None])[0], (T + d).ambient, atol=1e-15)
    np.testing.assert_allclose(se3.display(T), np.r_[T.pos, T.rot.log()])
    C = bp.make_compound("C_parts", a=bp.Rn(2), T=bp.SE3())
    c = codec_of(C())
    assert [(p.name, p.ambient, p.tangent) for p in c.parts()] == [
        ("a", slice(0, 2), slice(0, 2)), ("T", slice(2, 9), slice(2, 8))]
    assert rn.parts() == ()
    v = C(a=[1.0, 2.0], T=T)
    np.testing.assert_allclose(c.display(v), np.r_[1.0, 2.0, T.pos, T.rot.log()])
    assert np.all(np.isnan(codec_of(bp.S2([0, 0, 1.0])).display(bp.S2([0, 0, 1.0]))))
    B = c.view(np.stack([v.to_ambient()] * 2))
    assert isinstance(B, batch.CompoundBatch) and isinstance(B.T, batch.SE3Batch)
    np.testing.assert_allclose(B.a.vec, [[1.0, 2.0]] * 2)
    # perturbed views equal ⊞ through the solver's manifold, where the kind has them
    base = se3.view(np.stack([T.ambient] * 2))
    for j in range(6):
        P = se3.perturbed_view(base, j, np.full(2, 1e-3))
        step = np.zeros((2, 6))
        step[:, j] = 1e-3
        np.testing.assert_allclose(P.ambient, se3.plus_batch(base.ambient, step), atol=1e-14)
    assert se3.perturbed_view(base, 4, np.array([1e-3, 2e-3])) is None
    s2 = codec_of(bp.S2([0, 0, 1.0]))
    assert s2.perturbed_view(s2.view(np.array([[0, 0, 1.0]])), 0, np.array([1e-3])) is None
