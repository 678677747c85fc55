"""Issue 17, the Python side: no bad input may abort, cross threads or lie.

Cases that would abort the interpreter if the guard failed run in a
subprocess, so that an abort fails the test instead of killing the run.
"""

import subprocess
import sys
import textwrap
import threading

import boxplus as bp
import numpy as np
import pytest
from boxplus import slam


def run_isolated(code: str) -> subprocess.CompletedProcess:
    r = subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True,
                       text=True, timeout=120)
    assert r.returncode == 0, f"exit {r.returncode}\nstdout:\n{r.stdout}\nstderr:\n{r.stderr}"
    return r


# ---- item 1: a broken ManifoldValue raises its own error, never aborts -------------------
BROKEN_MANIFOLD = """
import numpy as np, traceback, boxplus as bp

class Line(bp.ManifoldValue):
    dof = 1
    calls = 0
    fault = None
    def __init__(self, a):
        self.a = np.asarray(a, float).reshape(2)
    def boxplus(self, d):
        Line.calls += 1
        if Line.calls > Line.after:
            if Line.fault == "raise":
                raise KeyError("user bug in boxplus")
            if Line.fault == "nan":
                return Line([np.nan, 0.0])
            if Line.fault == "array":
                return self.a + d[0]
            if Line.fault == "size":  # a Line whose ambient vector has the wrong size
                wide = Line.__new__(Line)
                wide.a = np.zeros(5)
                return wide
        return Line(self.a + [d[0], 0.0])
    def boxminus(self, o):
        return np.array([self.a[0] - o.a[0]])
    def to_ambient(self):
        return self.a
    @classmethod
    def from_ambient(cls, a):
        return cls(a)

for fault, expected in [("raise", "KeyError"), ("nan", "non-finite"),
                        ("array", "Line.boxplus returned a ndarray, expected a Line"), ("size", "expected 2 numbers")]:
    for after in {after}:
        Line.calls, Line.fault, Line.after = 0, fault, after
        p = bp.OptimizationProblem()
        try:
            x = p.add_random_var(Line([3.0, 1.0]), name="line")
            p.add_measurement([1.0], lambda l: l.a[:1] ** 2, [x], name="square")
            p.add_prior  # C++ measurements on the variable too when the kind allows
            p.solve(method="{method}")
        except Exception as e:
            text = "".join(traceback.format_exception(e))
            assert expected in text, (fault, after, text)
            print("raised", fault, after, type(e).__name__)
        else:
            print("solved", fault, after)
print("alive")
"""


@pytest.mark.parametrize("method", ["lm", "gn_ls", "dogleg"])
def test_a_failing_user_manifold_never_aborts(method):
    r = run_isolated(BROKEN_MANIFOLD.format(method=method, after="(0, 2, 5, 9, 17, 40)"))
    assert r.stdout.strip().endswith("alive")
    assert "raised raise 0" in r.stdout  # refused when the variable is added
    assert r.stdout.count("raised") >= 8, r.stdout


def test_a_failing_manifold_at_solve_time_raises_the_users_exception_with_traceback():
    class Flaky(bp.ManifoldValue):
        dof = 1
        armed = False

        def __init__(self, a):
            self.a = float(np.asarray(a).reshape(-1)[0])

        def boxplus(self, d):
            if Flaky.armed:
                raise ZeroDivisionError("inside the user's boxplus")
            return Flaky(self.a + d[0])

        def boxminus(self, o):
            return np.array([self.a - o.a])

        def to_ambient(self):
            return np.array([self.a])

        @classmethod
        def from_ambient(cls, a):
            return cls(a)

    p = bp.OptimizationProblem()
    x = p.add_random_var(Flaky(2.0), name="flaky")
    p.add_measurement([1.0], lambda v: np.array([v.a]), [x])
    Flaky.armed = True
    with pytest.raises(ZeroDivisionError, match="inside the user's boxplus") as info:
        p.solve()
    assert "boxplus" in [f.name for f in info.traceback]


# ---- item 2: two threads, two problems, two error slots --------------------------------
def _solve_in_thread(problem, out, key):
    try:
        out[key] = problem.solve(max_iterations=200, function_tolerance=0, gradient_tolerance=0,
                                 parameter_tolerance=1e-14)
    except BaseException as e:  # noqa: BLE001 - the test inspects what arrived
        out[key] = e


def test_errors_of_one_threads_solve_never_reach_another():
    for attempt in range(25):
        calls = []

        def failing(v, calls=calls, attempt=attempt):
            calls.append(1)
            if len(calls) > 3 + attempt % 5:
                raise KeyError(f"failing thread, attempt {attempt}")
            return v.vec**3

        def healthy(v):
            return v.vec**3

        bad, good = bp.OptimizationProblem(), bp.OptimizationProblem()
        xb = bad.add_random_var(bp.Rn([3.0, 2.0]))
        xg = good.add_random_var(bp.Rn([3.0, 2.0]))
        bad.add_measurement([1.0, 8.0], failing, [xb])
        good.add_measurement([1.0, 8.0], healthy, [xg])
        out = {}
        threads = [threading.Thread(target=_solve_in_thread, args=(bad, out, "bad")),
                   threading.Thread(target=_solve_in_thread, args=(good, out, "good"))]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        assert isinstance(out["good"], bp.SolveSummary), out["good"]
        assert out["good"].usable
        assert np.allclose(good[xg].vec, [1.0, 2.0], atol=1e-6)
        assert isinstance(out["bad"], KeyError), out["bad"]
        assert f"attempt {attempt}" in str(out["bad"])


# ---- item 9: bytes that are not UTF-8 never become a UnicodeDecodeError ------------------
def test_a_message_with_invalid_utf8_becomes_a_parse_error_with_the_bytes_escaped(tmp_path):
    path = tmp_path / "junk.g2o"
    path.write_bytes(b"VERTEX_SE2 0 0 0 0\nVERTEX_\xff\xfe 1 2 3\n")
    with pytest.raises(bp.BoxplusError) as info:
        slam.load_g2o(path)
    assert not isinstance(info.value, UnicodeDecodeError)
    assert "junk.g2o" in str(info.value)
    if "VERTEX_" in str(info.value):
        assert "\\xff" in str(info.value)


def test_parse_errors_carry_file_and_line(tmp_path):
    path = tmp_path / "bad.g2o"
    path.write_bytes(b"VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 zero 0 0\n")
    with pytest.raises(bp.ParseError) as info:
        slam.load_g2o(path)
    assert info.value.line == 2 and info.value.file.endswith("bad.g2o")
    assert isinstance(info.value, ValueError)


# ---- item 14: clear errors naming the measurement or variable ---------------------------
def test_huge_rn_dimension_raises_a_clear_error():
    with pytest.raises((ValueError, TypeError, OverflowError, MemoryError)) as info:
        bp.Rn(10**10)
    assert "C++ type '?'" not in str(info.value)


def test_rn_size_check_is_exactly_what_a_measurement_can_use():
    """A measurement's n × n block of the normal equations must fit Ceres' int
    indexing (2³¹ − 1 entries): Rn(46340) can be measured, Rn(46341) never could
    and is refused at construction — Rn(2³¹ − 1) used to pass and allocate 16 GB."""
    assert 46340**2 <= 2**31 - 1 < 46341**2
    for n in (46341, 2**31 - 1, 10**10):
        with pytest.raises(ValueError, match=f"Rn: dimension {n} is too large: at most 46340"):
            bp.Rn(n)
    with pytest.raises(ValueError, match="Rn: dimension 46341 is too large"):
        bp.Rn(np.zeros(46341))
    p = bp.OptimizationProblem()
    x = p.add_random_var(bp.Rn(46340), name="largest")
    p.add_measurement([0.0], lambda v: v.vec[:1], [x], name="one coordinate")
    assert p._core.measurement_variables(0) == [x]


def test_bad_function_outputs_name_the_measurement():
    p = bp.OptimizationProblem()
    x = p.add_random_var(bp.Rn([1.0, 2.0]), name="x")
    with pytest.raises(ValueError, match="'as dict'.*dict"):
        p.add_measurement([0.0, 0.0], lambda v: {"a": 1}, [x], name="as dict")
    with pytest.raises(ValueError, match="'as str'.*str"):
        p.add_measurement([0.0, 0.0], lambda v: "ab", [x], name="as str")
    with pytest.raises(ValueError, match="'complex'.*complex"):
        p.add_measurement([0.0, 0.0], lambda v: v.vec * 1j, [x], name="complex")
    with pytest.raises(TypeError, match="'complex sigma'.*sigma"):
        p.add_measurement([0.0, 0.0], lambda v: v.vec, [x], sigma=1j, name="complex sigma")
    with pytest.raises(ValueError, match="'empty'.*ids is empty"):
        p.add_measurement([0.0, 0.0], lambda v: v.vec, [], name="empty")
    with pytest.raises(ValueError, match="measurements of .*ids"):
        p.add_measurements(np.zeros((0, 2)), lambda v: v.vec, np.zeros((0, 1), int))
    mid = p.add_measurement([0.0, 0.0], lambda v: v.vec, x, name="single id")
    assert p._core.measurement_variables(mid) == [x]
    with pytest.raises(TypeError, match="'id as str'.*ids"):
        p.add_measurement([0.0, 0.0], lambda v: v.vec, "0", name="id as str")
    with pytest.raises(IndexError, match="unknown variable id True"):
        p.add_measurement([0.0, 0.0], lambda v: v.vec, [True], name="bool id")


def test_wrong_output_size_mid_solve_names_the_measurement():
    calls = []

    def shrinking(v):
        calls.append(1)
        return v.vec if len(calls) < 4 else v.vec[:1]

    p = bp.OptimizationProblem()
    x = p.add_random_var(bp.Rn([1.0, 2.0]))
    p.add_measurement([0.0, 0.0], shrinking, [x], name="shrinks")
    with pytest.raises(bp.EvaluationError, match="'shrinks'.*returned 1 numbers"):
        p.solve()

    def vectorised(v):
        calls.append(1)
        return v.vec if len(calls) < 9 else v.vec[:, :1]

    q = bp.OptimizationProblem()
    ids = [[q.add_random_var(bp.Rn([1.0, 2.0]))] for _ in range(3)]
    q.add_measurements(np.zeros((3, 2)), vectorised, ids)
    with pytest.raises(bp.EvaluationError, match="'vectorised'.*shape"):
        q.solve()


# ---- item 5: a variable no measurement touches is undetermined, not known exactly --------
def test_untouched_variable_is_reported_undetermined():
    p = bp.OptimizationProblem()
    x = p.add_random_var(bp.Rn([1.0]), name="seen")
    y = p.add_random_var(bp.SO3(), name="unseen")
    p.add_measurement([2.0], lambda v: v.vec, [x], sigma=0.5)
    with pytest.warns(bp.UndeterminedWarning, match="do not determine 'unseen': all 3 directions"):
        p.solve()
    assert np.allclose(p.std(x), [0.5])
    for call in (lambda: p.std(y), lambda: p.covariance(y), lambda: p.joint_covariance([x, y])):
        with pytest.raises(ValueError, match="'unseen' is undetermined"):
            call()
    with pytest.raises(ValueError, match="listed twice"):
        p.joint_covariance([x, x])


# ---- calibration: view sets whose board planes are all parallel are refused ------------
def _parallel_view_sets(rng, n=5):
    """(geometry, world_from_cam per view) of sets whose board planes are parallel in
    the camera frame — Zhang's degenerate configuration."""
    from boxplus.synthetic.cameras import board_points, random_views

    c = board_points().mean(axis=0)
    base = random_views(1, rng, c)[0]
    yield "translation only", [bp.SE3(base.rot, base.pos + d) for d in rng.normal(0, 0.05, (n, 3))]
    # the camera orbits the board's normal: the board turns in its own plane
    turns = [bp.SO3.exp(np.array([0.0, 0.0, a])).R for a in rng.uniform(-2, 2, n)]
    yield "turns in the board plane", [bp.SE3(bp.SO3(T @ base.rot.R), T @ (base.pos - c) + c)
                                       for T in turns]


def _outcome(calibrate, args, views_message):
    """'refused' (ValueError naming every view as parallel), 'warned' (the focal
    length named as barely determined), 'not converged' or 'converged' — the last
    is the silent wrong answer the checks exist to stop."""
    import warnings

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            cal = calibrate(*args)
        except ValueError as e:
            assert "planes are parallel" in str(e) and views_message in str(e), str(e)
            return "refused"
    if any("barely determined by views 0, 1, 2, 3, 4" in str(w.message) for w in caught):
        return "warned"
    return "converged" if cal.result.termination == "convergence" else "not converged"


def _fronto_parallel_views(rng, n=5):
    """All boards facing the camera squarely: turns in their plane and small shifts."""
    from boxplus.geometry import look_at
    from boxplus.synthetic.cameras import board_points

    c = board_points().mean(axis=0)
    out = []
    for a, dx, dy in zip(rng.uniform(-2, 2, n), rng.uniform(-0.05, 0.05, n), rng.uniform(-0.05, 0.05, n)):
        eye = c + [dx, dy, -0.6]
        R = look_at(eye, c + [dx, dy, 0], up=np.array([0.0, 1.0, 0.0])).rot.R
        out.append(bp.SE3(bp.SO3(R @ bp.SO3.exp(np.array([0.0, 0.0, a])).R), eye))
    return out


def test_calibrate_mono_refuses_parallel_boards_naming_the_views():
    """Translation-only views, turns of the board in its plane, fronto-parallel sets,
    at two noise levels: never a silent converged answer. Mostly refused (the
    solved planes agree within 5°); where the degenerate solve wanders off, its
    poses cannot show the parallel planes, and the summary says it did not
    converge or a warning names the barely determined focal length."""
    from collections import Counter

    from boxplus.calib import calibrate_mono
    from boxplus.synthetic.cameras import TRUE_K, board_points, observe

    p = board_points()
    counts: Counter = Counter()
    for seed in range(4):
        rng = np.random.default_rng(seed)
        sets = [*_parallel_view_sets(rng), ("fronto-parallel", _fronto_parallel_views(rng))]
        for geometry, views in sets:
            for sigma in (0.3, 1.0):
                Z = [observe(TRUE_K, v, p, sigma, rng, image_size=None)[0] for v in views]
                outcome = _outcome(calibrate_mono, (Z, p, (640, 480)),
                                   "camera: the board has the same orientation in every view "
                                   "(0, 1, 2, 3, 4)")
                counts[geometry, outcome] += 1
                assert outcome != "converged", (geometry, seed, sigma)
    for geometry in ("translation only", "turns in the board plane", "fronto-parallel"):
        assert counts[geometry, "refused"] + counts[geometry, "warned"] == 8, dict(counts)
    for geometry in ("translation only", "turns in the board plane"):
        assert counts[geometry, "refused"] >= 7, dict(counts)


@pytest.mark.parametrize("seed", range(6))
def test_calibrate_mono_accepts_tilted_views(seed):
    from boxplus.calib import calibrate_mono
    from boxplus.synthetic.cameras import TRUE_K, board_points, observe, random_views

    rng = np.random.default_rng(100 + seed)
    p = board_points()
    Z = [observe(TRUE_K, v, p, 0.5, rng, image_size=None)[0] for v in random_views(5, rng, p.mean(axis=0))]
    cal = calibrate_mono(Z, p, (640, 480))
    assert cal.result.termination == "convergence"
    k, std = cal.problem[cal.ids["camera"]].vec, cal.report().std("camera")
    assert np.all(np.abs(k[:4] - TRUE_K[:4]) < 4 * std[:4]), (k[:4], std[:4])


def test_calibrate_stereo_refuses_parallel_boards():
    from collections import Counter

    from boxplus.calib import calibrate_stereo
    from boxplus.synthetic.cameras import TRUE_K, board_points, observe

    p = board_points()
    left_from_right = bp.SE3(bp.SO3.exp(np.array([0.0, 0.05, 0.0])), np.array([0.1, 0.0, 0.0]))
    counts: Counter = Counter()
    for seed in range(4):
        rng = np.random.default_rng(seed)
        for geometry, views in _parallel_view_sets(rng):
            L = [observe(TRUE_K, v, p, 0.5, rng, image_size=None)[0] for v in views]
            R = [observe(TRUE_K, v * left_from_right, p, 0.5, rng, image_size=None)[0] for v in views]
            outcome = _outcome(calibrate_stereo, (L, R, p, (640, 480)),
                               ": the board has the same orientation in every view (0, 1, 2, 3, 4)")
            counts[geometry, outcome] += 1
            assert outcome != "converged", (geometry, seed)
    assert counts["translation only", "refused"] + counts["turns in the board plane", "refused"] >= 6


def test_board_normals_of_parallel_planes_agree_for_any_intrinsics():
    """r1 × r2 of K⁻¹H is Kᵀ times the image of the plane's line at infinity: exact
    homographies of parallel boards give one normal whatever K is assumed (also the
    wrong K a degenerate set yields); tilted boards give their angle under the true K."""
    from boxplus.calib.zhang import board_normals, check_board_planes

    rng = np.random.default_rng(7)
    K = np.array([[520.0, 0, 322], [0, 515, 245], [0, 0, 1]])
    R = bp.SO3.exp(np.array([0.3, -0.2, 0.1])).R
    Hs = []
    for a in rng.uniform(-2, 2, 4):  # turns in the board plane and shifts
        Ra = R @ bp.SO3.exp(np.array([0.0, 0.0, a])).R
        t = np.array([0.0, 0.0, 0.6]) + rng.normal(0, 0.05, 3)
        Hs.append(K @ np.column_stack([Ra[:, 0], Ra[:, 1], t]))
    for K_assumed in (K, np.array([[3000.0, 0, 300], [0, 2900, 200], [0, 0, 1]])):
        N = board_normals(K_assumed, Hs)
        assert np.allclose(np.abs(N @ N[0]), 1.0, atol=1e-12)
        with pytest.raises(ValueError, match=r"cam: .* \(0, 1, 2, 3\)"):
            check_board_planes(N, "cam")
    tilt = bp.SO3.exp(np.array([0.2, 0.0, 0.0])).R  # 0.2 rad about the board's x axis
    R2 = R @ tilt
    Hs.append(K @ np.column_stack([R2[:, 0], R2[:, 1], [0.0, 0.0, 0.6]]))
    N = board_normals(K, Hs)
    assert np.isclose(np.arccos(abs(N[0] @ N[-1])), 0.2, atol=1e-9)
    check_board_planes(N, "cam")  # two orientations: accepted
