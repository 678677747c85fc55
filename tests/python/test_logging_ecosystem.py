"""Everything boxplus says goes through Python (logging, print, callbacks):
nothing reaches the process' stdout/stderr behind Python's back, Ceres' glog
included; progress bars are optional (tqdm)."""

import contextlib
import io
import logging
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import boxplus as bp
import boxplus.log as bplog
import numpy as np
import pytest
from boxplus import _core, slam

DATA = Path(__file__).resolve().parents[1] / "data"


@pytest.fixture
def caplog_boxplus(caplog):
    caplog.set_level(logging.DEBUG, logger="boxplus")
    return caplog


def _small_problem():
    p = bp.OptimizationProblem()
    x = p.add_random_var(bp.SE2(1, 2, 0.5))
    p.add_prior(x, bp.SE2(), sigma=0.1)
    p.add_measurement(np.zeros(2), lambda v: v.pos - np.array([0.3, 0.0]), x, sigma=0.2)
    return p


def test_library_adds_only_a_null_handler():
    assert any(isinstance(h, logging.NullHandler) for h in bplog.logger.handlers)
    assert bplog.logger.name == "boxplus" and bplog.ceres_logger.parent is bplog.logger


def test_pose_graph_load_and_solve_are_logged(caplog_boxplus):
    g = slam.load_g2o(DATA / "landmarks2d.g2o")
    s = g.solve()
    msgs = [(r.name, r.levelno, r.getMessage()) for r in caplog_boxplus.records]
    load = [m for n, lv, m in msgs if lv == logging.INFO and "landmarks2d.g2o" in m]
    assert len(load) == 1
    assert f"{len(g.poses())} 2D poses, {len(g.landmarks())} landmarks, {g.num_edges} edges" in load[0]
    summary = [m for n, lv, m in msgs if lv == logging.INFO and m.startswith("pose graph solve: ")]
    assert summary == [f"pose graph solve: {_core.format_summary(s)}"]
    # χ² everywhere: the summary's numbers are 2 × Ceres' cost.
    assert f"chi2 {2 * s.initial_cost:.10g} -> {2 * s.final_cost:.10g}" in summary[0]
    # Per iteration at DEBUG, in the one format, header first.
    debug = [m for n, lv, m in msgs if lv == logging.DEBUG and n == "boxplus"]
    assert debug[0] == _core.progress_header()
    assert len(debug) == s.iterations + 2  # header, iteration 0 … n
    assert debug[1].split()[:2] == ["0", f"{2 * s.initial_cost:.8e}"]


def test_optimization_problem_solve_is_logged(caplog_boxplus):
    s = _small_problem().solve()
    infos = [r.getMessage() for r in caplog_boxplus.records if r.levelno == logging.INFO]
    assert infos == [f"solve: {_core.format_summary(s)}"]


def test_low_level_verbose_solve_prints_through_python(capfd):
    p = _small_problem()
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        s = p._core.solve(verbose=True)
    lines = out.getvalue().splitlines()
    assert lines[0] == _core.progress_header()
    assert lines[-1] == _core.format_summary(s)
    assert len(lines) == s.iterations + 3  # header, iteration 0 … n, summary
    captured = capfd.readouterr()
    assert captured.err == "" and captured.out == ""


def test_load_warnings_are_logged_and_warned(caplog_boxplus):
    with pytest.warns(UserWarning, match=r"skipped 1 line\(s\) with unknown tags"):
        slam.load_g2o(DATA / "bad_unknown_tag.g2o", skip_unknown=True)
    warned = [r for r in caplog_boxplus.records if r.levelno == logging.WARNING]
    assert len(warned) == 1 and "skipped 1 line(s) with unknown tags" in warned[0].getMessage()


def test_verbose_goes_through_python_stdout_and_matches_callback():
    g = slam.load_g2o(DATA / "landmarks2d.g2o")
    seen = []
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        s = g.solve(verbose=True, callback=lambda info: seen.append(_core.format_progress(info)))
    lines = buf.getvalue().splitlines()
    assert lines[0] == _core.progress_header()
    assert lines[1:-1] == seen and len(seen) == s.iterations + 1
    assert lines[-1] == _core.format_summary(s)


def test_progress_callback_logs_and_chains(caplog_boxplus):
    p = _small_problem()
    infos = []
    with bplog.Progress(level=logging.INFO, callback=infos.append) as progress:
        s = p.solve(callback=progress)
    lines = [r.getMessage() for r in caplog_boxplus.records if r.levelno == logging.INFO]
    assert lines[0] == _core.progress_header()
    # The iterations, then OptimizationProblem.solve's own summary line.
    assert lines[1:-1] == [_core.format_progress(i) for i in infos]
    assert lines[-1] == f"solve: {_core.format_summary(s)}"
    assert progress.iterations == s.iterations
    assert progress.chi2 == pytest.approx(2 * s.final_cost)
    # The chained callback can stop the solve.
    p2 = _small_problem()
    s2 = p2.solve(callback=bplog.Progress(log=None, callback=lambda info: False))
    assert s2.iterations == 0 or s2.termination == "user"
    with pytest.raises(TypeError, match="callback must be callable"):
        bplog.Progress(callback=3)


def test_log_summary_format(caplog_boxplus):
    p = _small_problem()
    s = p.solve()
    bplog.log_summary(s, "calibration")
    assert caplog_boxplus.records[-1].getMessage() == f"calibration: {_core.format_summary(s)}"


def test_enable_writes_to_the_current_stderr():
    err = io.StringIO()
    h = bplog.enable(logging.INFO)
    try:
        with contextlib.redirect_stderr(err):
            slam.load_g2o(DATA / "landmarks2d.g2o")
    finally:
        bplog.logger.removeHandler(h)
        bplog.logger.setLevel(logging.NOTSET)
    assert err.getvalue().startswith("boxplus INFO: ") and "landmarks2d.g2o" in err.getvalue()


# ---- glog (Ceres) -------------------------------------------------------------------------
def test_glog_messages_reach_python_logging(caplog_boxplus):
    bplog.flush_native()
    _core._native_log_emit(1, "Manifold::PlusJacobian computation failed (test)")
    _core._native_log_emit(0, "an INFO of Ceres")
    # The pending call has run by now (the interpreter ran Python code since);
    # flushing again finds nothing.
    assert bplog.flush_native() == 0
    recs = [r for r in caplog_boxplus.records if r.name == "boxplus.ceres"]
    assert [(r.levelno, r.getMessage()) for r in recs] == [
        (logging.WARNING, "Manifold::PlusJacobian computation failed (test)"),
        (logging.DEBUG, "an INFO of Ceres"),
    ]
    assert recs[0].pathname == "native_log.cc" and recs[0].lineno > 0
    with pytest.raises(ValueError, match="severity"):
        _core._native_log_emit(3, "fatal would abort")


def test_glog_writes_nothing_to_the_process_stderr(tmp_path):
    # A child process: glog's own output would go to file descriptor 2, which
    # pytest's capture of sys.stderr does not see.
    code = textwrap.dedent("""
        import logging, boxplus, boxplus.log
        from boxplus import _core
        logging.basicConfig(level=logging.WARNING, format="%(name)s|%(levelname)s|%(message)s")
        _core._native_log_emit(1, "routed warning")
        _core._native_log_emit(2, "routed error")
        boxplus.log.flush_native()
        print("done")
    """)
    env = {**os.environ, "GLOG_log_dir": str(tmp_path)}
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                       timeout=120)
    assert r.returncode == 0, r.stderr
    assert r.stdout == "done\n"
    assert "InitGoogleLogging" not in r.stderr
    assert r.stderr.splitlines() == ["boxplus.ceres|WARNING|routed warning",
                                     "boxplus.ceres|ERROR|routed error"]
    assert list(tmp_path.iterdir()) == []  # no glog log files


# ---- progress bars (tqdm optional) --------------------------------------------------------
def test_bars_without_tqdm_are_silent(monkeypatch):
    monkeypatch.setitem(sys.modules, "tqdm", None)  # import tqdm → ImportError
    monkeypatch.setitem(sys.modules, "tqdm.auto", None)
    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        g = slam.load_g2o(DATA / "landmarks2d.g2o", progress=True)
        s = g.solve(progress=True)
    assert s.usable and err.getvalue() == ""
    assert not bplog.Progress(bar=True).has_bar


def test_bars_with_tqdm():
    pytest.importorskip("tqdm")
    err = io.StringIO()
    with bplog.Progress(log=None, bar=True, total=50, file=err) as progress:
        assert progress.has_bar
        s = _small_problem().solve(callback=progress)
        bar = progress._bar  # what tqdm shows: iterations done, χ² as postfix
        assert bar.n == s.iterations and bar.total == 50
        assert bar.postfix == f"chi2={2 * s.final_cost:.6g}"
    assert s.usable and "solve:" in err.getvalue() and not progress.has_bar
    # A load bar counts bytes; the read reports every 4096 lines.
    text = "".join(f"VERTEX_SE2 {i} {i} 0 0\n" for i in range(9000))
    text += "".join(f"EDGE_SE2 {i} {i + 1} 1 0 0 1 0 0 1 0 1\n" for i in range(8999))
    calls = []
    bar = bplog.LoadProgress("x.g2o", file=io.StringIO())
    path = Path(os.environ.get("TMPDIR", "/tmp")) / f"boxplus_load_{os.getpid()}.g2o"
    path.write_text(text)
    try:
        g = slam.load_g2o(path, progress=lambda *a: (calls.append(a), bar(*a)))
    finally:
        path.unlink()
        bar.close()
    assert g.num_edges == 8999
    assert [c[0] for c in calls] == [4096 * k for k in range(1, len(calls) + 1)]
    assert len(calls) == 17999 // 4096
    assert all(c[2] == len(text) and 0 < c[1] < c[2] for c in calls)
    assert bar.lines == calls[-1][0]


def test_load_progress_errors_stop_the_load(tmp_path):
    path = tmp_path / "g.g2o"
    path.write_text("".join(f"VERTEX_SE2 {i} {i} 0 0\n" for i in range(5000))
                    + "".join(f"EDGE_SE2 {i} {i + 1} 1 0 0 1 0 0 1 0 1\n" for i in range(4999)))

    def boom(lines, done, total):
        raise RuntimeError(f"stop at {lines}")

    with pytest.raises(RuntimeError, match="stop at 4096"):
        slam.load_g2o(path, progress=boom)
    with pytest.raises(TypeError, match="progress must be callable, got int"):
        slam.load_g2o(path, progress=3)
