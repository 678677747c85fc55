"""Horn's closed-form absolute orientation (boxplus.joint.horn)."""

import boxplus as bp
import numpy as np
import pytest
from boxplus.joint import horn
from scipy.spatial.transform import Rotation


def _transform(seed):
    rng = np.random.default_rng(seed)
    return bp.SE3(bp.SO3.from_scipy(Rotation.random(random_state=seed)), rng.normal(0, 2, 3))


@pytest.mark.parametrize("seed", range(20))
def test_recovers_a_known_transform_exactly_from_noise_free_points(seed):
    T = _transform(seed)
    a = np.random.default_rng(100 + seed).normal(0, 1, (3 + seed, 3))
    b = a @ T.R.T + T.pos
    est = horn(a, b)
    assert np.linalg.norm(est - T) < 1e-12 * 100


def test_is_unbiased_under_noise():
    T = _transform(7)
    rng = np.random.default_rng(8)
    a = rng.normal(0, 1, (30, 3))
    b = a @ T.R.T + T.pos
    errs = np.array([horn(a, b + rng.normal(0, 0.05, b.shape)) - T for _ in range(2000)])
    mean, sem = errs.mean(axis=0), errs.std(axis=0) / np.sqrt(len(errs))
    assert np.all(np.abs(mean) < 4 * sem), (mean, sem)
    assert np.all(errs.std(axis=0) < 0.05)  # and it does use the data


def test_weights_select_points():
    T = _transform(3)
    a = np.random.default_rng(4).normal(0, 1, (6, 3))
    b = a @ T.R.T + T.pos
    b[5] += 10.0  # an outlier with zero weight is ignored
    assert np.linalg.norm(horn(a, b, weights=[1, 1, 1, 1, 1, 0]) - T) < 1e-10


def test_bad_input_names_the_problem():
    with pytest.raises(ValueError, match="at least 3"):
        horn(np.zeros((2, 3)), np.zeros((2, 3)))
    with pytest.raises(ValueError, match="one line"):
        line = np.outer(np.arange(5.0), [1.0, 2.0, 3.0])
        horn(line, line)
    with pytest.raises(ValueError, match=r"\(N, 3\)"):
        horn(np.zeros((4, 2)), np.zeros((4, 2)))
