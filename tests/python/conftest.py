"""Shared hypothesis strategies for the manifold property tests."""

import os

import boxplus as bp
import numpy as np
from hypothesis import settings
from hypothesis import strategies as st

settings.register_profile("boxplus", max_examples=200, deadline=None)
# CI runs a fixed set of examples (reproducible); locally each run explores anew.
settings.register_profile("ci", max_examples=200, deadline=None, derandomize=True, database=None)
settings.load_profile("ci" if os.environ.get("CI") else "boxplus")

finite = st.floats(-1e3, 1e3, allow_nan=False, allow_infinity=False)


def unit_vector(n):
    """Unit vectors in Rⁿ, including axis-aligned ones."""
    return (
        st.lists(st.floats(-1, 1, allow_nan=False), min_size=n, max_size=n)
        .map(np.array)
        .filter(lambda v: np.linalg.norm(v) > 1e-3)
        .map(lambda v: v / np.linalg.norm(v))
    )


def rotation_vector(max_angle):
    """Rotation vectors with |w| < max_angle, with emphasis on tiny and near-limit angles."""
    angles = st.one_of(
        st.floats(0, max_angle * 0.999),
        st.sampled_from([0.0, 1e-10, 1e-8, 1e-6, max_angle * (1 - 1e-7)]),
    )
    return st.tuples(unit_vector(3), angles).map(lambda t: t[0] * t[1])


so3 = unit_vector(4).map(bp.SO3.from_quat)
so2 = st.floats(-np.pi, np.pi, allow_nan=False).map(bp.SO2)
se2 = st.tuples(finite, finite, st.floats(-np.pi, np.pi)).map(lambda t: bp.SE2([t[0], t[1]], t[2]))
se3 = st.tuples(so3, st.tuples(finite, finite, finite)).map(lambda t: bp.SE3(t[0], list(t[1])))
s2 = unit_vector(3).map(bp.S2)


def delta_for(kind, max_rot=np.pi):
    """Tangent vectors for a kind whose rotational part stays below max_rot."""
    if kind == "SO2":
        return st.floats(-max_rot * 0.999, max_rot * 0.999).map(lambda a: np.array([a]))
    if kind == "SO3":
        return rotation_vector(max_rot)
    if kind == "SE2":
        return st.tuples(finite, finite, st.floats(-max_rot * 0.999, max_rot * 0.999)).map(np.array)
    if kind == "SE3":
        return st.tuples(st.tuples(finite, finite, finite), rotation_vector(max_rot)).map(
            lambda t: np.concatenate([t[0], t[1]])
        )
    if kind == "S2":
        return st.tuples(unit_vector(2), st.floats(0, max_rot * 0.999)).map(lambda t: t[0] * t[1])
    raise ValueError(kind)


POINTS = {"SO2": so2, "SO3": so3, "SE2": se2, "SE3": se3, "S2": s2}
