"""Hypothesis over the Python API: random shapes, types, NaN/inf, Σ, ids, failing
user functions and manifolds. The only allowed outcomes are success or a
ValueError / TypeError / IndexError (BoxplusError, EvaluationError and
ParseError are subclasses) with a message; never another exception, a crash
or an abort. Cases that reach Ceres through user manifolds run in a subprocess."""

import subprocess
import sys
import textwrap

import boxplus as bp
import numpy as np
import pytest
from boxplus.noise import noise_model, noise_models
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

ALLOWED = (ValueError, TypeError, IndexError)
# Overflow in the fuzzed arithmetic is expected; what matters is the outcome.
pytestmark = pytest.mark.filterwarnings("ignore::RuntimeWarning")
FUZZ = settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])

special = st.sampled_from([0.0, -1.0, 1e-300, 1e300, np.nan, np.inf, -np.inf, 1.0, 2.5])
numbers = st.one_of(st.floats(allow_nan=True, allow_infinity=True), special,
                    st.integers(-5, 5))
shapes = st.lists(st.integers(0, 4), min_size=0, max_size=3).map(tuple)
arrays = st.tuples(shapes, st.lists(numbers, min_size=0, max_size=64)).map(
    lambda t: np.resize(np.asarray(t[1] or [0.0], float), t[0]))
junk = st.one_of(st.none(), st.text(max_size=3), st.dictionaries(st.text(max_size=2), st.integers(), max_size=2),
                 st.just(1j), st.just([1j, 2]), st.just(object()), st.booleans(),
                 st.integers(-(2**70), 2**70), st.lists(st.integers(-3, 3), max_size=4))
anything = st.one_of(arrays, numbers, junk)


def allowed(call):
    """Runs call(); success or an allowed exception with a non-empty message."""
    try:
        return call()
    except ALLOWED as e:
        assert str(e), f"{type(e).__name__} without a message"
        assert "C++ type '?'" not in str(e), str(e)
        return None


@FUZZ
@given(dim=st.integers(-2, 5), kind=st.sampled_from(["sigma", "covariance", "information", "noise"]),
       value=anything)
def test_noise_model_refuses_bad_noise_clearly(dim, kind, value):
    nm = allowed(lambda: noise_model(dim, **{kind: value}, what="fuzz"))
    if nm is not None:
        W = nm.sqrt_information_matrix
        assert W.shape == (dim, dim) and np.all(np.isfinite(W))
        assert np.allclose(nm.unwhiten(nm.whiten(np.ones(dim))), 1.0)
    allowed(lambda: noise_models(3, dim, **{kind: value}, what="fuzz"))


def model_square(v):
    return v.vec**2


VALUES = [bp.Rn([1.0, 2.0]), bp.Rn([0.5]), bp.SO3(), bp.SE2([1.0, 0.0], 0.3), bp.S2([0, 0, 1])]


@FUZZ
@given(z=anything, ids=st.one_of(st.lists(st.integers(-2, 6), max_size=3), st.integers(-2, 6), junk),
       noise_kw=st.sampled_from(["sigma", "covariance", "information"]), noise=anything,
       f_kind=st.sampled_from(["ok", "raise", "nan", "dict", "str", "wrong", "complex", "none"]),
       loss=st.one_of(st.none(), st.sampled_from(["huber", "cauchy", "nope", ("huber", -1.0),
                                                  ("tukey", 2.0), 3])),
       method=st.sampled_from(["lm", "gn_ls", "dogleg", "gn"]))
def test_optimization_problem_add_and_solve(z, ids, noise_kw, noise, f_kind, loss, method):
    p = bp.OptimizationProblem()
    for v in VALUES:
        p.add_random_var(v)
    calls = []

    def f(*values):
        calls.append(1)
        base = np.atleast_1d(np.asarray(getattr(values[0], "ambient", 0.0), float))[:2]
        if f_kind == "ok" or len(calls) < 3:
            return base
        return {"raise": lambda: (_ for _ in ()).throw(ZeroDivisionError("user")),
                "nan": lambda: base * np.nan, "dict": lambda: {"a": base},
                "str": lambda: "no", "wrong": lambda: np.zeros(7),
                "complex": lambda: base * 1j, "none": lambda: None}[f_kind]()

    def add():
        return p.add_measurement(z, f, ids, **{noise_kw: noise}, loss=loss, name="fuzzed")

    try:
        mid = allowed(add)
    except ZeroDivisionError:
        return  # the user's own exception, raised at add time with a note
    if mid is None:
        return
    try:
        s = allowed(lambda: p.solve(method=method, max_iterations=20))
    except ZeroDivisionError:
        return  # the user's exception from inside the solve
    if s is not None:
        assert s.termination in ("convergence", "no_convergence", "interrupted", "failure")
        assert isinstance(s.final_cost, float)
        for k in range(p.num_variables):
            allowed(lambda k=k: p.std(k))
        allowed(p.rms)


@FUZZ
@pytest.mark.filterwarnings("ignore::boxplus.UndeterminedWarning")
@given(Z=anything, ids=st.one_of(arrays, junk, st.lists(st.lists(st.integers(-1, 5), max_size=2), max_size=3)),
       cov=st.one_of(st.none(), arrays), constants=st.lists(anything, max_size=2))
def test_add_measurements_batches(Z, ids, cov, constants):
    p = bp.OptimizationProblem()
    for v in VALUES:
        p.add_random_var(v)

    def g(*batches):
        return np.asarray(batches[0].vec if hasattr(batches[0], "vec") else np.zeros((1, 1)))

    allowed(lambda: p.add_measurements(Z, g, ids, constants=tuple(constants), covariance=cov))
    allowed(lambda: p.solve(max_iterations=5))


@FUZZ
@given(call=st.sampled_from(["add_variable", "set_value", "add_prior", "value", "covariance",
                             "residual", "error", "solve", "values", "joint"]),
       a=anything, b=anything)
def test_low_level_problem(call, a, b):
    q = bp.Problem()
    x = q.add_variable(bp.SO3.manifold(), bp.SO3().ambient, "x")
    q.add_factor(bp._core.prior_factor(q, x, bp.SO3().ambient, bp.NoiseModel.unit(3)))
    calls = {
        "add_variable": lambda: q.add_variable(bp.make_manifold("Rn", 2), a, "v"),
        "set_value": lambda: q.set_value(b if isinstance(b, int) else x, a),
        "add_prior": lambda: q.add_factor(bp._core.prior_factor(q, x, a, bp.NoiseModel.unit(3))),
        "value": lambda: q.value(a),
        "covariance": lambda: q.covariance(a),
        "residual": lambda: q.residual(a),
        "error": lambda: q.error(a),
        "solve": lambda: q.solve(method=a) if isinstance(a, str) else q.solve(max_iterations=a),
        "values": lambda: q.values(a),
        "joint": lambda: q.joint_covariance(a),
    }
    allowed(calls[call])


MANIFOLD_FUZZ = """
import numpy as np, random, boxplus as bp
ALLOWED = (ValueError, TypeError, IndexError)
faults = ["ok", "raise", "nan", "array", "short", "none", "inf"]
rng = random.Random(17)

class Fuzzy(bp.ManifoldValue):
    dof = 2
    n = 0
    def __init__(self, a):
        self.a = np.asarray(a, float).reshape(3)
    def boxplus(self, d):
        Fuzzy.n += 1
        if Fuzzy.n > Fuzzy.after:
            f = Fuzzy.fault
            if f == "raise": raise RuntimeError("fuzzed boxplus")
            if f == "nan": return Fuzzy([np.nan, 0, 0])
            if f == "inf": return Fuzzy([np.inf, 0, 0])
            if f == "array": return self.a
            if f == "short": return Short()
            if f == "none": return None
        return Fuzzy(self.a + np.r_[d, 0.0])
    def boxminus(self, o):
        return (self.a - o.a)[:2]
    def to_ambient(self):
        return self.a
    @classmethod
    def from_ambient(cls, a):
        return cls(a)

class Short:
    def to_ambient(self):
        return np.zeros(1)

outcomes = {}
for case in range(300):
    Fuzzy.n, Fuzzy.fault, Fuzzy.after = 0, rng.choice(faults), rng.randrange(0, 60)
    p = bp.OptimizationProblem()
    try:
        x = p.add_random_var(Fuzzy([1.0, 2.0, 3.0]))
        y = p.add_random_var(bp.Rn([0.5]))
        p.add_measurement([0.0, 1.0], lambda v: v.a[:2] ** 2, [x], sigma=0.3)
        p.add_measurement([1.0], lambda v, w: w.vec * v.a[0], [x, y])
        s = p.solve(method=rng.choice(["lm", "gn_ls", "dogleg"]), max_iterations=30)
        p.std(y)
        key = "solved"
    except (RuntimeError,) + ALLOWED as e:
        assert str(e), repr(e)
        key = type(e).__name__
    outcomes[key] = outcomes.get(key, 0) + 1
print(outcomes)
print("alive")
"""


def test_fuzzed_user_manifolds_in_a_subprocess():
    r = subprocess.run([sys.executable, "-c", textwrap.dedent(MANIFOLD_FUZZ)], capture_output=True,
                       text=True, timeout=600)
    assert r.returncode == 0, f"exit {r.returncode}\n{r.stdout}\n{r.stderr[-3000:]}"
    assert r.stdout.strip().endswith("alive")
    assert "solved" in r.stdout and "RuntimeError" in r.stdout


@pytest.mark.parametrize("bad", ["lm", 3, None, "nope"])
def test_options_fuzz_small(bad):
    allowed(lambda: bp.SolverOptions(method=bad))
    allowed(lambda: bp.SolverOptions(damping=bad))
