"""boxplus-g2o as a drop-in for g2o's command line: g2o's flag spellings
(g2o_cli's g2o.cpp) give the same runs as boxplus' own, '-' is standard input,
--summary / --stats files, refusals that name the flag."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest
from harness import boxplus_g2o

DATA = Path(__file__).resolve().parents[1] / "data"
GRID = DATA / "tinyGrid3D.g2o"
TAGS = DATA / "g2o_tags"


def run(*args: str, stdin: str | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([boxplus_g2o(), *args], capture_output=True, text=True, input=stdin,
                          timeout=120)


def solver_of(stderr: str) -> str:
    m = re.search(r"# initial chi2 .* solver (\w+)\)", stderr)
    assert m, stderr
    return m.group(1)


def final_chi2(stderr: str) -> float:
    m = re.search(r"# final chi2 g2o convention (\S+),", stderr)
    assert m, stderr
    return float(m.group(1))


@pytest.mark.parametrize(
    "name, method",
    [("gn_var", "gn"), ("gn_var_cholmod", "gn"), ("gn_fix6_3_csparse", "gn"), ("lm_var", "lm"),
     ("lm_fix6_3", "lm"), ("lm_fix3_2_eigen", "lm"), ("dl_var", "dogleg"), ("lm", "lm")],
)
def test_g2o_solver_names_map_to_boxplus_methods(name, method):
    r = run("-solver", name, "-i", "2", "-q", str(GRID))
    assert r.returncode == 0, r.stderr
    assert solver_of(r.stderr) == method


def test_unknown_solver_name_is_refused_by_name():
    r = run("-solver", "gn_magic", str(GRID))
    assert r.returncode == 2
    assert "gn_magic" in r.stderr


def test_g2o_spellings_give_the_same_run_as_boxplus_spellings(tmp_path):
    a, b = tmp_path / "a.g2o", tmp_path / "b.g2o"
    ra = run("-i", "5", "-q", "-robustKernel", "Huber", "-robustKernelWidth", "2", "-guess",
             "-o", str(a), str(GRID))
    rb = run("-i", "5", "-q", "--robust", "huber", "--robust-width", "2", "--init",
             "spanning-tree", "-o", str(b), str(GRID))
    assert ra.returncode == 0 and rb.returncode == 0, ra.stderr + rb.stderr
    assert a.read_text() == b.read_text()
    assert final_chi2(ra.stderr) == final_chi2(rb.stderr)


@pytest.mark.parametrize("kernel, loss", [("Cauchy", "cauchy"), ("Tukey", "tukey"),
                                          ("PseudoHuber", "soft_l1"), ("DCS", "dcs"),
                                          ("GemanMcClure", "geman_mcclure")])
def test_g2o_kernels_are_boxplus_losses(kernel, loss, tmp_path):
    ra = run("-i", "3", "-q", "-robustKernel", kernel, str(GRID))
    rb = run("-i", "3", "-q", "--robust", loss, str(GRID))
    assert ra.returncode == 0, ra.stderr
    assert final_chi2(ra.stderr) == final_chi2(rb.stderr)


@pytest.mark.parametrize("kernel", ["DCS", "GemanMcClure"])
def test_g2o_kernel_widths_on_chi2_become_widths_on_its_root(kernel, tmp_path):
    # g2o's DCS Φ and Geman-McClure width act on e'Ωe; boxplus' widths on √(e'Ωe)
    a, b = tmp_path / "a.g2o", tmp_path / "b.g2o"
    ra = run("-i", "3", "-q", "-robustKernel", kernel, "-robustKernelWidth", "4", "-o", str(a),
             str(GRID))
    loss = "dcs" if kernel == "DCS" else "geman_mcclure"
    rb = run("-i", "3", "-q", "--robust", loss, "--robust-width", "2", "-o", str(b), str(GRID))
    assert ra.returncode == 0 and rb.returncode == 0, ra.stderr + rb.stderr
    assert a.read_text() == b.read_text()
    r = run("-robustKernel", kernel, "-robustKernelWidth", "-3", str(GRID))
    assert r.returncode == 2 and "must be positive" in r.stderr


@pytest.mark.parametrize("kernel", ["Fair", "Saturated", "Welsch"])
def test_g2o_kernels_boxplus_lacks_are_refused_by_name(kernel):
    r = run("-robustKernel", kernel, str(GRID))
    assert r.returncode == 2
    assert f"g2o's kernel {kernel} has no boxplus equivalent" in r.stderr


@pytest.mark.parametrize(
    "flag",
    ["-guessOdometry", "-inc", "-update", "-marginalize", "-computeMarginals", "-solverProperties",
     "-printSolverProperties", "-renameTypes", "-solverlib", "-typeslib", "-gain", "-ig",
     "-nonSequential"],
)
def test_g2o_flags_without_a_boxplus_meaning_are_refused_by_name(flag):
    r = run(flag, str(GRID))
    assert r.returncode == 2
    assert f"g2o's {flag} (" in r.stderr and "is not supported" in r.stderr


def test_stdin_is_read_as_the_file(tmp_path):
    a, b = tmp_path / "a.g2o", tmp_path / "b.g2o"
    ra = run("-i", "5", "-q", "-o", str(a), "-", stdin=GRID.read_text())
    rb = run("-i", "5", "-q", "-o", str(b), str(GRID))
    assert ra.returncode == 0 and rb.returncode == 0, ra.stderr + rb.stderr
    assert a.read_text() == b.read_text()
    assert "# <stdin>:" in ra.stderr


def test_stdin_errors_name_stdin_and_the_line():
    r = run("-", stdin="VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 0 0\n")
    assert r.returncode == 2
    assert "<stdin>:2:" in r.stderr


def test_stdin_to_stdout_keeps_stdout_for_the_graph():
    r = run("-i", "3", "-o", "-", "-", stdin=GRID.read_text())
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert lines and all(ln.split()[0] in ("VERTEX_SE3:QUAT", "EDGE_SE3:QUAT", "FIX")
                         for ln in lines)
    assert "# final chi2" in r.stderr and "iter" in r.stderr


def test_summary_appends_one_line_per_run_and_stats_has_the_iterations(tmp_path):
    summary, stats = tmp_path / "summary.txt", tmp_path / "stats.txt"
    for _ in range(2):
        r = run("-i", "4", "-q", "-summary", str(summary), "-stats", str(stats), str(GRID))
        assert r.returncode == 0, r.stderr
    rows = summary.read_text().splitlines()
    assert len(rows) == 2
    fields = dict(kv.split("=", 1) for kv in rows[1].split())
    assert fields["file"] == str(GRID) and fields["status"] == "ok"
    assert float(fields["chi2_final"]) == pytest.approx(final_chi2(r.stderr), rel=1e-9)
    assert int(fields["iterations"]) >= 1
    st = stats.read_text().splitlines()
    assert st[0].split()[:2] == ["iter", "chi2"]
    assert len(st) >= 2 and st[1].split()[0] == "0"


def test_gauge_id_and_gauge_list_fix_those_vertices():
    r = run("-gaugeId", "3", "-i", "2", "-q", str(GRID))
    assert r.returncode == 0, r.stderr
    assert "gauge vertex 3" in r.stderr
    r = run("-gaugeList", "2,5", "-i", "2", "-q", str(GRID))
    assert r.returncode == 0, r.stderr
    assert "gauge vertex 2" in r.stderr
    r = run("-gaugeId", "12345", str(GRID))
    assert r.returncode == 2 and "12345" in r.stderr
    r = run("-gaugeList", "1,x", str(GRID))
    assert r.returncode == 2 and "--gauge: not a list of vertex ids: '1,x'" in r.stderr


def test_lists_print_and_exit_zero():
    r = run("-listSolvers")
    assert r.returncode == 0 and "gn_var" in r.stdout and "dogleg" in r.stdout
    r = run("-listRobustKernels")
    assert r.returncode == 0 and "PseudoHuber" in r.stdout and "huber" in r.stdout
    r = run("-listTypes")
    assert r.returncode == 0
    for tag in ("EDGE_SE3_OFFSET", "EDGE_PRIOR_SE2", "PARAMS_SE2OFFSET", "EQUIV"):
        assert tag in r.stdout


def test_verbose_flag_is_accepted_and_prints_iterations():
    r = run("-v", "-i", "2", str(GRID))
    assert r.returncode == 0, r.stderr
    assert r.stdout.splitlines()[0].split()[:2] == ["iter", "chi2"]


def test_a_file_with_new_tags_solves_from_the_command_line(tmp_path):
    out = tmp_path / "out.g2o"
    r = run("-solver", "lm_var", "-i", "20", "-q", "-o", str(out), str(TAGS / "se3_offset.g2o"))
    assert r.returncode == 0, r.stderr
    assert "EDGE_SE3_OFFSET 1 2 1 0 " in out.read_text()


def test_default_threads_give_the_one_thread_result_and_zero_is_refused(tmp_path):
    # Without -t the BLAS (CHOLMOD's supernodal factorisation, which a 3D
    # sphere of 500 poses takes) runs on every core; the optimum is the same.
    from boxplus.synthetic import pose_graphs as generate

    path = tmp_path / "sphere.g2o"
    generate.generate("sphere", 3, 500, noise="medium", seed=2).write(path)
    default = run("-q", str(path))
    one = run("-q", "-t", "1", str(path))
    assert default.returncode == 0 and one.returncode == 0, default.stderr + one.stderr
    assert final_chi2(default.stderr) == pytest.approx(final_chi2(one.stderr), rel=1e-9)
    zero = run("-t", "0", str(path))
    assert zero.returncode == 2 and "--threads must be >= 1" in zero.stderr


def test_gnu_style_options_parse_as_in_any_tool(tmp_path):
    # --opt=value, combined short flags with an attached value, a repeated option's
    # last value, and '--' before a file whose name starts with '-'
    a, b = tmp_path / "a.g2o", tmp_path / "b.g2o"
    ra = run("--iterations=3", "--quiet", "--output=" + str(a), str(GRID))
    rb = run("-i", "9", "-qi3", "-o", str(b), str(GRID))
    assert ra.returncode == 0 and rb.returncode == 0, ra.stderr + rb.stderr
    assert a.read_text() == b.read_text()
    dashed = tmp_path / "-graph.g2o"
    dashed.write_text(GRID.read_text())
    r = subprocess.run([boxplus_g2o(), "-qi2", "--", dashed.name], capture_output=True, text=True,
                       cwd=tmp_path, timeout=120)
    assert r.returncode == 0, r.stderr
    assert "-graph.g2o: " in r.stderr


@pytest.mark.parametrize("args, message", [
    (["--bogus", "g.g2o"], "unknown option --bogus"),
    (["g.g2o", "--bogus=3"], "unknown option --bogus=3"),
    (["a.g2o", "b.g2o"], "more than one input file ('a.g2o', 'b.g2o')"),
    (["-i", "x", "g.g2o"], "--iterations: not a non-negative integer: 'x'"),
    (["-i", "-2", "g.g2o"], "--iterations: not a non-negative integer: '-2'"),
    (["-w", "wide", "g.g2o"], "--robust-width"),
    (["-o"], "-o"),
    ([], "no input file"),
])
def test_usage_errors_name_the_option(args, message):
    r = run(*args)
    assert r.returncode == 2
    assert message in r.stderr and "(try boxplus-g2o --help)" in r.stderr, r.stderr


def test_help_and_version():
    r = run("--help")
    assert r.returncode == 0 and r.stdout.startswith("usage: boxplus-g2o [options] input.g2o")
    for option in ("-i,--iterations N", "-s,--solver NAME", "--outliers FILE", "--gauge ID[,ID...]",
                   "g2o's spellings are accepted too", "Exit codes:"):
        assert option in r.stdout
    v = run("--version")
    assert v.returncode == 0 and v.stdout.startswith("boxplus-g2o ")
