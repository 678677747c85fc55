"""The pose-graph default strategy (boxplus-g2o FILE): the better start, then
Gauss–Newton with a line search falling back to Levenberg–Marquardt — checked
on generated families, not on one file."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import boxplus.slam as slam
import pytest
from boxplus.synthetic import pose_graphs as generate
from harness import boxplus_g2o

FAMILIES = [(f, d) for f in generate.FAMILIES for d in (2, 3)]


def _write(tmp_path, family, dim, n, **kw):
    path = tmp_path / f"{family}{dim}.g2o"
    generate.generate(family, dim, n, **kw).write(path)
    return path


def _solved(path, init, **solve):
    g = slam.load_g2o(path, init=init)
    s = g.solve(**solve)
    assert s.usable, s.message
    return g, s


@pytest.mark.parametrize(("family", "dim"), FAMILIES)
def test_default_reaches_the_lowest_objective_of_the_alternatives(tmp_path, family, dim):
    # At 'high' noise from odometry, solvers started from the file stop in
    # different local minima; the default must reach the lowest of them all.
    path = _write(tmp_path, family, dim, 150, noise="high", loop_closure_probability=0.5, seed=7)
    g, s = _solved(path, "best")
    assert s.termination == "convergence", s.message
    others = [_solved(path, init, method=m)[0].chi2()
              for init in ("file", "chordal") for m in ("lm", "dogleg", "gn_ls")]
    assert g.chi2() <= min(others) * (1 + 1e-6)


def test_best_start_keeps_a_file_that_is_already_optimal(tmp_path):
    path = _write(tmp_path, "sphere", 3, 200, noise="medium", seed=3)
    g, _ = _solved(path, "file")
    g.save_g2o(tmp_path / "opt.g2o")
    again = slam.load_g2o(tmp_path / "opt.g2o", init="best")
    assert again.report.start == "file" and not again.has_second_start
    s = again.solve()
    assert s.iterations <= 2
    assert again.chi2() == pytest.approx(g.chi2(), rel=1e-9)


@pytest.mark.parametrize(("family", "dim"), [("manhattan", 2), ("grid", 2), ("random_walk", 2),
                                             ("torus", 3)])
def test_implausible_solution_is_also_sought_from_other_starts(tmp_path, family, dim):
    # Wrong loop closures without a robust kernel: χ²/dof ≫ 1 and many minima.
    # The chordal start is pulled towards the wrong closures, odometry is not,
    # and a Huber solution bounds their pull; outliers="off" keeps the lowest
    # (the default judges the closures instead: test_outliers.py).
    path = _write(tmp_path, family, dim, 300, noise="medium", outlier_fraction=0.05, seed=11)
    g = slam.load_g2o(path, init="best", outliers="off")
    assert g.report.start == "chordal" and g.has_second_start and g.restart_when_implausible
    seen = []
    s = g.solve(callback=lambda i: seen.append((i.iteration, i.cumulative_time_s)))
    assert s.usable
    assert "from the file's estimate" in s.message and "from a Huber solution" in s.message
    assert g.chi2_per_dof() > slam.IMPLAUSIBLE_CHI2_PER_DOF
    assert not g.has_second_start and not g.restart_when_implausible  # only the first solve
    assert all(b[0] > a[0] and b[1] >= a[1] for a, b in zip(seen, seen[1:]))  # one run
    from_file = _solved(path, "file")[0].chi2()
    from_chordal = _solved(path, "chordal")[0].chi2()
    assert g.chi2() <= min(from_file, from_chordal) * (1 + 1e-6)
    assert g.chi2() == pytest.approx(2 * s.final_cost, rel=1e-9)


def test_plausible_solution_is_not_solved_twice(tmp_path):
    path = _write(tmp_path, "manhattan", 2, 300, noise="medium", seed=5)
    g = slam.load_g2o(path, init="best")
    s = g.solve()
    assert "kept the lowest" not in s.message
    assert g.chi2_per_dof() == pytest.approx(1.0, abs=0.3)  # the generator's noise is consistent


def test_line_search_hands_over_to_levenberg_marquardt_when_it_shortens_steps(tmp_path):
    # From odometry at bignoise the Gauss–Newton model is poor: the line search
    # shortens its steps and the solver switches; iterations keep counting and
    # the callback sees one sequence.
    path = _write(tmp_path, "torus", 2, 300, noise="bignoise", loop_closure_probability=0.5,
                  seed=0)
    g = slam.load_g2o(path, init="file")
    seen = []
    s = g.solve(callback=lambda info: seen.append((info.iteration, info.step_length)))
    assert s.usable
    assert "then Levenberg-Marquardt" in s.message
    assert [i for i, _ in seen] == list(range(len(seen)))
    assert sum(1 for _, a in seen[:4] if a < 1.0) >= 3
    assert g.chi2() <= _solved(path, "file", method="gn_ls")[0].chi2() * (1 + 1e-6)
    assert g.chi2() <= _solved(path, "file", method="lm")[0].chi2() * (1 + 1e-6)


def test_gn_lm_names_and_alias():
    from boxplus import SolverOptions

    for name in ("gn_lm", "gn-lm", "auto", "AUTO"):
        assert SolverOptions(method=name).method == "gn_lm"


def test_restarts_only_for_the_default_start_and_on_request(tmp_path):
    path = _write(tmp_path, "grid", 2, 300, noise="medium", outlier_fraction=0.05, seed=11)
    g = slam.load_g2o(path, init="file")
    assert not g.restart_when_implausible
    assert "kept the lowest" not in g.solve().message
    g = slam.load_g2o(path, init="file", outliers="off")
    g.restart_when_implausible = True  # no second start: the Huber one only
    s = g.solve()
    assert "from a Huber solution" in s.message and "file's estimate" not in s.message


def test_a_field_given_as_keyword_or_in_options_solves_the_same():
    """The pose graph's defaults are applied in C++ to every field not given, however
    the others are given: method='lm' as a keyword, in a SolverOptions, or on the
    command line (-s lm) solves with the same settings."""
    import pickle

    import boxplus as bp

    data = Path(__file__).resolve().parents[1] / "data" / "smallGrid3D.g2o"
    results = []
    for kw in ({"method": "lm"}, {"options": bp.SolverOptions(method="lm")},
               {"options": pickle.loads(pickle.dumps(bp.SolverOptions(method="lm")))}):
        g = slam.load_g2o(data, init="file")
        s = g.solve(**kw)
        results.append((s.iterations, s.final_chi2, g.poses().tobytes()))
    assert results[0] == results[1] == results[2]
    assert bp.SolverOptions(method="lm").given == ["method"]
    o = bp.SolverOptions()
    o.max_iterations = 3
    assert o.given == ["max_iterations"]
    cli = subprocess.run([boxplus_g2o(), "-s", "lm", "--init", "file", str(data)],
                         capture_output=True, text=True, timeout=120)
    m = re.search(r"# final chi2 g2o convention (\S+),", cli.stderr)
    assert m and float(m.group(1)) == pytest.approx(results[0][1], rel=1e-9)  # %.10g
