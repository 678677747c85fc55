"""The bound solver vocabulary: SolverOptions, IterationInfo, SolveSummary, progress lines."""

import contextlib
import copy
import io
import pickle

import boxplus as bp
import numpy as np
import pytest
from boxplus import _core


def small_problem():
    p = bp.OptimizationProblem()
    # (from -1, a Gauss–Newton step lands on 0, where the Jacobian 3v² vanishes)
    x = p.add_random_var(bp.Rn([3.0, 1.5]), name="x")
    p.add_measurement([1.0, 2.0], lambda v: v.vec**3, [x], sigma=0.5, name="cubic")
    return p, x


def test_options_have_every_field_with_the_cpp_defaults():
    o = bp.SolverOptions()
    assert o.todict() == {
        "method": "lm", "max_iterations": 100, "function_tolerance": 1e-10,
        "gradient_tolerance": 1e-12, "parameter_tolerance": 1e-10, "num_threads": 1,
        "initial_trust_region_radius": 1e4, "damping": "marquardt", "jacobi_scaling": True,
        "use_nonmonotonic_steps": False, "max_consecutive_nonmonotonic_steps": 5,
        "verbose": False,
    }


def test_options_keyword_construction_repr_eq_copy_and_pickle():
    o = bp.SolverOptions(method="gauss_newton", damping="levenberg", max_iterations=7,
                         initial_trust_region_radius=1e16, jacobi_scaling=False)
    assert o.method == "gn" and o.damping == "levenberg" and o.max_iterations == 7
    assert "method='gn'" in repr(o) and "max_iterations=7" in repr(o)
    assert eval(repr(o), {"SolverOptions": bp.SolverOptions}) == o
    assert pickle.loads(pickle.dumps(o)) == o
    assert copy.deepcopy(o) == o and copy.deepcopy(o) is not o
    assert bp.SolverOptions(**o.todict()) == o
    assert o != bp.SolverOptions() and o != "lm"
    o.max_iterations = 9
    assert o.max_iterations == 9


@pytest.mark.parametrize("kw, error, match", [
    (dict(method="newton"), ValueError, "newton"),
    (dict(damping="strong"), ValueError, "strong"),
    (dict(max_iterations=1.5), TypeError, "max_iterations must be an int"),
    (dict(max_iterations=10**10), TypeError, "max_iterations"),
    (dict(function_tolerance="small"), TypeError, "function_tolerance must be a float"),
    (dict(jacobi_scaling=1), TypeError, "jacobi_scaling must be a bool"),
    (dict(num_threads=True), TypeError, "num_threads"),
    (dict(initial_trust_region_radius=0.0), ValueError, "initial_trust_region_radius"),
    (dict(initial_trust_region_radius=float("nan")), ValueError, "initial_trust_region_radius"),
    (dict(max_iterations=-1), ValueError, "max_iterations"),
    (dict(tolerance=1e-3), TypeError, "no field 'tolerance'"),
])
def test_options_refuse_bad_fields_naming_them(kw, error, match):
    with pytest.raises(error, match=match):
        bp.SolverOptions(**kw)
    o = bp.SolverOptions()
    name, value = next(iter(kw.items()))
    if name != "tolerance":
        with pytest.raises(error, match=match):
            setattr(o, name, value)
        assert o == bp.SolverOptions()  # a refused assignment leaves it unchanged


def test_method_and_damping_names_are_parsed_by_the_cpp_parsers():
    for name, canonical in [("lm", "lm"), ("LEVENBERG_MARQUARDT", "lm"), ("gn-ls", "gn_ls"),
                            ("dogleg", "dogleg")]:
        assert bp.SolverOptions(method=name).method == canonical


def test_iteration_info_is_read_only_with_chi2_and_step_length():
    p, _ = small_problem()
    seen = []
    s = p.solve(callback=seen.append)
    assert all(isinstance(i, bp.IterationInfo) for i in seen)
    first, last = seen[0], seen[-1]
    assert first.iteration == 0 and last.iteration == s.iterations
    assert last.chi2 == pytest.approx(2 * last.cost)
    assert last.step_length == 1.0 and last.trust_region_radius > 0
    d = last.todict()
    assert d["chi2"] == last.chi2 and d["step_length"] == 1.0
    assert "IterationInfo(iteration=" in repr(last)
    with pytest.raises(AttributeError):
        last.cost = 0.0
    ls = []
    small_problem()[0].solve(method="gn_ls", callback=ls.append)
    assert ls[-1].trust_region_radius == 0.0 and 0 < ls[-1].step_length <= 1


def test_solve_summary_attributes_chi2_repr_todict_pickle():
    p, x = small_problem()
    s = p.solve()
    assert isinstance(s, bp.SolveSummary)
    assert s.termination == "convergence" and s.usable
    assert s.initial_chi2 == pytest.approx(2 * s.initial_cost)
    assert s.final_chi2 == pytest.approx(2 * p.cost())
    assert np.allclose(p.X[x].vec, np.cbrt([1.0, 2.0]), atol=1e-6)
    assert pickle.loads(pickle.dumps(s)) == s
    assert s.todict()["final_chi2"] == s.final_chi2
    assert str(s) == _core.format_summary(s) and "chi2" in str(s)
    assert repr(s).startswith("SolveSummary(initial_chi2=") and "report=" not in repr(s)


def test_solve_takes_options_and_keyword_overrides():
    p, _ = small_problem()
    s = p.solve(bp.SolverOptions(max_iterations=1, function_tolerance=0, gradient_tolerance=0,
                                 parameter_tolerance=0))
    assert s.iterations == 1 and s.termination == "no_convergence"
    p, _ = small_problem()
    s = p.solve(bp.SolverOptions(max_iterations=1), max_iterations=50)
    assert s.termination == "convergence"
    for kw in [dict(initial_trust_region_radius=1e16, damping="levenberg", jacobi_scaling=False,
                    nonmonotonic_steps=3), dict(method="dogleg"), dict(method="gn_ls")]:
        p, _ = small_problem()
        assert p.solve(**kw).termination == "convergence", kw
    with pytest.raises(TypeError, match="no field 'max_iter'"):
        small_problem()[0].solve(max_iter=3)
    with pytest.raises(TypeError, match="options must be a boxplus.SolverOptions"):
        small_problem()[0].solve({"method": "lm"})
    with pytest.raises(ValueError, match="nonmonotonic_steps must be >= 0"):
        small_problem()[0].solve(nonmonotonic_steps=-1)


def test_verbose_prints_the_cpp_progress_format_through_python_print():
    p, _ = small_problem()
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        s = p.solve(verbose=True)
    lines = out.getvalue().splitlines()
    assert lines[0] == _core.progress_header() and "chi2" in lines[0]
    assert len(lines) == s.iterations + 3  # header, iterations 0..n, summary
    assert lines[-1] == _core.format_summary(s)
    assert float(lines[1].split()[1]) == pytest.approx(s.initial_chi2, rel=1e-6)


def test_low_level_solve_callback_must_return_none_or_a_bool():
    q = bp.Problem()
    x = q.add_variable(bp.SO3.manifold(), bp.SO3().ambient)
    q.add_factor(bp._core.prior_factor(q, x, bp.SO3.exp([2.0, 0.5, -0.3]).ambient, bp.NoiseModel.unit(3)))
    for bad in ["stop", [], 1]:
        with pytest.raises(TypeError, match="callback must return None, True or False"):
            q.solve(callback=lambda info, bad=bad: bad)
    assert q.solve(callback=lambda info: np.bool_(True)).termination == "convergence"
    with pytest.raises(TypeError, match="callback must be callable"):
        q.solve(callback=3)
