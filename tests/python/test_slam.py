"""Graph SLAM: g2o files, pose graphs, boxplus-g2o, against independent objectives.

The optimum checks score boxplus' solution with ``harness.g2o_reference``
(numpy, independent of the C++ factors) and compare with the final objectives
of the peers (g2opy 2.3.0 Gauss-Newton/LM and GTSAM 4.3.0 LM, run from the
same initial estimate and gauge, scored by the same numpy function). They do
not need the peers installed; the live cross-checks at the end do.
"""

import subprocess
from pathlib import Path

import boxplus as bp
import boxplus.slam as slam
import numpy as np
import pytest
from harness import boxplus_g2o
from harness import g2o_reference as g2o_ref

DATA = Path(__file__).resolve().parents[1] / "data"

# Best final objective any peer reached (numpy chi2, both conventions).
PEER_BEST = {
    "tinyGrid3D": {"g2o": 6.727881617021661, "log": 18.62781886709005},
    "smallGrid3D": {"g2o": 458.1537842986353, "log": 1035.8506647225781},
    "CSAIL": {"g2o": 40.555128847805435, "log": 40.55088334565262},
    # g2o's LM (526.33) and GTSAM's LM (770.239, log) from the file's estimate
    "MIT": {"g2o": 526.3310384, "log": 770.2389839},
}
TIGHT = dict(function_tolerance=1e-12, gradient_tolerance=1e-14, parameter_tolerance=1e-12)


@pytest.mark.parametrize("name", sorted(PEER_BEST))
@pytest.mark.parametrize("convention", ["g2o", "log"])
def test_reaches_the_best_peer_objective(name, convention):
    # boxplus-g2o's default strategy: the better start, then the default solver.
    g = slam.load_g2o(DATA / f"{name}.g2o", convention=convention, init="best")
    data = g2o_ref.read_g2o_arrays(DATA / f"{name}.g2o")
    order = [g.vertex_ids.index(i) for i in data["ids"]]
    s = g.solve(**TIGHT)
    assert s.usable
    poses = g.poses()[order]
    ref = g2o_ref.chi2_g2o(data, poses) if convention == "g2o" else g2o_ref.chi2_log(data, poses)
    assert ref == pytest.approx(g.chi2(), rel=1e-9)
    assert ref == pytest.approx(2 * s.final_cost, rel=1e-9)
    assert ref <= PEER_BEST[name][convention] * (1 + 1e-6)


@pytest.mark.parametrize("name", ["tinyGrid3D", "smallGrid3D", "CSAIL"])
@pytest.mark.parametrize("convention", ["g2o", "log"])
def test_line_search_gauss_newton_reaches_the_best_peer_objective(name, convention):
    g = slam.load_g2o(DATA / f"{name}.g2o", convention=convention)
    data = g2o_ref.read_g2o_arrays(DATA / f"{name}.g2o")
    s = g.solve(method="gn_ls", **TIGHT)
    assert s.usable and s.termination == "convergence", s.report
    poses = g.poses()[[g.vertex_ids.index(i) for i in data["ids"]]]
    ref = g2o_ref.chi2_g2o(data, poses) if convention == "g2o" else g2o_ref.chi2_log(data, poses)
    assert ref == pytest.approx(2 * s.final_cost, rel=1e-9)
    assert ref <= PEER_BEST[name][convention] * (1 + 1e-6)


def test_numpy_reference_matches_cpp_at_the_file_estimate():
    g = slam.load_g2o(DATA / "smallGrid3D.g2o", init="file")
    data = g2o_ref.read_g2o_arrays(DATA / "smallGrid3D.g2o")
    assert g2o_ref.chi2_g2o(data, data["poses"]) == pytest.approx(g.chi2("g2o"), rel=1e-12)
    assert g2o_ref.chi2_log(data, data["poses"]) == pytest.approx(g.chi2("log"), rel=1e-12)


def test_edge_chi2_names_the_edges_that_carry_the_error(tmp_path):
    g = slam.load_g2o(DATA / "smallGrid3D.g2o", init="file")
    per_edge, ends = g.edge_chi2(), g.edge_vertices()
    assert per_edge.shape == (g.num_edges,) and ends.shape == (g.num_edges, 2)
    assert per_edge.sum() == pytest.approx(g.chi2(), rel=1e-12) and np.all(per_edge >= 0)
    lines = [ln.split() for ln in (DATA / "smallGrid3D.g2o").read_text().splitlines()
             if ln.startswith("EDGE_SE3")]
    np.testing.assert_array_equal(ends, [[int(ln[1]), int(ln[2])] for ln in lines])
    # one measurement moved by a metre: at the same poses only its eᵀΩe changes
    before, wrong = per_edge, 17
    lines[wrong][3] = str(float(lines[wrong][3]) + 1.0)
    text = (DATA / "smallGrid3D.g2o").read_text().splitlines()
    path = tmp_path / "one_wrong.g2o"
    path.write_text("\n".join([ln for ln in text if not ln.startswith("EDGE_SE3")]
                              + [" ".join(ln) for ln in lines]) + "\n")
    g = slam.load_g2o(path, init="file")
    changed = np.flatnonzero(g.edge_chi2() != before)
    assert changed.tolist() == [wrong] and g.edge_chi2()[wrong] > before[wrong] + 1


def _sesync_objective_loop(data, poses):
    """SE-Sync's f edge by edge, written from its definition (rotation matrices by scipy)."""
    from scipy.spatial.transform import Rotation

    d = data["dim"]
    total = 0.0
    for (i, j), z, info in zip(data["edge_index"], data["z"], data["info"]):
        if d == 3:
            Ri, Rj, Rz = (Rotation.from_quat(q).as_matrix() for q in (poses[i, 3:], poses[j, 3:], z[3:]))
            tau = 3.0 / np.trace(np.linalg.inv(info[:3, :3]))
            kappa = 3.0 / (2.0 * np.trace(np.linalg.inv(info[3:, 3:])))
        else:
            Ri, Rj, Rz = (Rotation.from_euler("z", a).as_matrix()[:2, :2]
                          for a in (poses[i, 2], poses[j, 2], z[2]))
            tau = 2.0 / np.trace(np.linalg.inv(info[:2, :2]))
            kappa = info[2, 2]
        t = poses[j, :d] - poses[i, :d] - Ri @ z[:d]
        total += kappa * np.sum((Rj - Ri @ Rz) ** 2) + tau * t @ t
    return total


@pytest.mark.parametrize("name", ["tinyGrid3D", "smallGrid3D", "CSAIL", "MIT"])
def test_sesync_chi2_matches_the_references_at_the_initial_estimate(name):
    # The file's estimate, or the spanning tree for CSAIL (no vertices).
    g = slam.load_g2o(DATA / f"{name}.g2o", convention="sesync")
    data = g2o_ref.read_g2o_arrays(DATA / f"{name}.g2o")
    poses = g.poses()[[g.vertex_ids.index(i) for i in data["ids"]]]
    ref = g2o_ref.chi2_sesync(data, poses)
    assert ref == pytest.approx(_sesync_objective_loop(data, poses), rel=1e-12)
    assert g.chi2() == pytest.approx(ref, rel=1e-12)
    assert g.chi2("chordal") == pytest.approx(ref, rel=1e-12)
    assert g.convention == "sesync"


def test_sesync_convention_reaches_the_certified_optimum_of_csail():
    # SE-Sync (Rosen et al., IJRR 2019) certifies f* = 3.170e1 on CSAIL; f is
    # its tr(Q YᵀY), with no ½ (README, SLAM).
    g = slam.load_g2o(DATA / "CSAIL.g2o", convention="sesync", init="chordal")
    s = g.solve(**TIGHT)
    assert s.usable
    data = g2o_ref.read_g2o_arrays(DATA / "CSAIL.g2o")
    poses = g.poses()[[g.vertex_ids.index(i) for i in data["ids"]]]
    f = g2o_ref.chi2_sesync(data, poses)
    assert f == pytest.approx(2 * s.final_cost, rel=1e-9)
    assert f == pytest.approx(31.70, rel=1e-3)


def test_parse_errors_name_file_and_line(tmp_path):
    bad = tmp_path / "bad.g2o"
    bad.write_text("VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\nEDGE_SE2 0 1 1 0 x 1 0 0 1 0 1\n")
    with pytest.raises(bp.ParseError, match=r"bad\.g2o:3: field 6 \('x'\) is not a finite number"):
        slam.load_g2o(bad)
    assert issubclass(bp.ParseError, ValueError)
    with pytest.raises(bp.ParseError, match=r"bad_unknown_tag\.g2o:3: unknown tag 'EDGE_SE2_FOO'"):
        slam.load_g2o(DATA / "bad_unknown_tag.g2o")
    with pytest.raises(bp.ParseError, match=r":4: EDGE_SE2: information matrix is not positive"):
        slam.load_g2o(DATA / "bad_indefinite_info.g2o")


def test_explicit_skip_and_repair_warn_with_counts():
    with pytest.warns(UserWarning, match=r"skipped 1 line\(s\) with unknown tags"):
        g = slam.load_g2o(DATA / "bad_unknown_tag.g2o", skip_unknown=True)
    assert g.report.unknown_tags == {"EDGE_SE2_FOO": 1}
    with pytest.warns(UserWarning, match=r"replaced 1 information matrix"):
        g = slam.load_g2o(DATA / "bad_indefinite_info.g2o", repair_information=True)
    assert g.report.repaired_information == 1 and g.report.repaired_lines == [4]


def test_extend_fix_solve_save_plot(tmp_path):
    g = slam.load_g2o(DATA / "landmarks2d.g2o")
    assert g.gauge_vertex == 0 and g.problem.is_fixed(g.variable(0))
    before = g.positions()
    # Extend from Python: a new pose with an odometry edge, a prior, a fixed vertex.
    g.add_vertex(3, "SE2", [3.0, 0.3, 0.2])
    g.add_edge("SE2", 2, 3, [1.0, 0.0, 0.0], np.diag([100.0, 100.0, 400.0]))
    g.add_prior(3, [2.95, 0.35, 0.2], information=np.eye(3))
    g.fix(10)
    x10 = g.value(10).copy()
    s = g.solve()
    assert s.usable and s.termination == "convergence"
    np.testing.assert_array_equal(g.value(10), x10)
    out = tmp_path / "out.g2o"
    g.save_g2o(out)
    text = out.read_text().splitlines()
    assert text[0].startswith("VERTEX_SE2 0 ")
    assert any(line.startswith("EDGE_SE2 2 3 ") for line in text)
    assert "FIX 0" in text
    again = slam.load_g2o(out, init="file")
    np.testing.assert_allclose(again.value(3), g.value(3), rtol=0, atol=1e-15)
    png = tmp_path / "traj.png"
    g.plot(png, before=before)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_bad_edges_from_python_raise():
    g = slam.load_g2o(DATA / "landmarks2d.g2o")
    with pytest.raises(bp.BoxplusIndexError):
        g.add_edge("SE2", 0, 99, [1, 0, 0], np.eye(3))
    with pytest.raises(ValueError, match="not positive definite"):
        g.add_edge("SE2", 0, 1, [1, 0, 0], -np.eye(3))
    with pytest.raises(ValueError, match="unknown edge kind"):
        g.add_edge("SE9", 0, 1, [1, 0, 0], np.eye(3))


@pytest.mark.parametrize("init", ["spanning-tree", "chordal"])
def test_initialisations_start_lower_than_the_file(init):
    file_ = slam.load_g2o(DATA / "smallGrid3D.g2o", init="file")
    other = slam.load_g2o(DATA / "smallGrid3D.g2o", init=init)
    if init == "chordal":
        assert other.chi2() < 0.1 * file_.chi2()
    other.solve(**TIGHT)
    assert other.chi2() <= PEER_BEST["smallGrid3D"]["g2o"] * (1 + 1e-6)


_cli = boxplus_g2o


def test_cli_solves_and_writes(tmp_path):
    out = tmp_path / "o.g2o"
    r = subprocess.run([_cli(), "-i", "50", "-o", str(out), str(DATA / "tinyGrid3D.g2o")],
                       capture_output=True, text=True, check=True)
    # Per-iteration lines (boxplus/progress.h) on stdout, diagnostics on stderr.
    assert r.stdout.splitlines()[0].split()[:2] == ["iter", "chi2"]
    assert r.stdout.splitlines()[2].split()[0] == "1"
    assert "# convergence: chi2 " in r.stderr
    g = slam.load_g2o(out)
    assert g.chi2() <= PEER_BEST["tinyGrid3D"]["g2o"] * (1 + 1e-6)


def test_cli_help_and_errors(tmp_path):
    r = subprocess.run([_cli(), "--help"], capture_output=True, text=True)
    assert r.returncode == 0 and "--robust-width" in r.stdout
    r = subprocess.run([_cli(), str(DATA / "bad_unknown_tag.g2o")], capture_output=True, text=True)
    assert r.returncode == 2 and "bad_unknown_tag.g2o:3: unknown tag" in r.stderr
    r = subprocess.run([_cli(), "--solver", "magic", "x.g2o"], capture_output=True, text=True)
    assert r.returncode == 2
    r = subprocess.run([_cli(), "--skip-unknown", "-q", str(DATA / "bad_unknown_tag.g2o")],
                       capture_output=True, text=True)
    assert r.returncode == 0 and "skipped 1 line(s)" in r.stderr


def test_gtsam_agrees_at_our_solution():
    gtsam = pytest.importorskip("gtsam")
    path = DATA / "smallGrid3D.g2o"
    g = slam.load_g2o(path, convention="log")
    g.solve(**TIGHT)
    graph, _ = gtsam.readG2o(str(path), True)
    values = gtsam.Values()
    for vid, x in zip(g.vertex_ids, g.poses()):
        q = x[3:]
        values.insert(vid, gtsam.Pose3(gtsam.Rot3.Quaternion(q[3], q[0], q[1], q[2]), x[:3]))
    assert 2 * graph.error(values) == pytest.approx(g.chi2("log"), rel=1e-9)


def test_pose_graph_solver_defaults_start_like_gauss_newton():
    # The pose-graph default (Gauss–Newton with a line search, then LM from
    # λI damping, nonmonotonic steps) reaches the peers' optimum in far fewer
    # iterations than Ceres' own LM defaults, which stay available by keyword.
    assert slam.SOLVER_DEFAULTS == {"method": "gn_lm", "initial_trust_region_radius": 1e16,
                                    "damping": "levenberg", "jacobi_scaling": False,
                                    "nonmonotonic_steps": 5}
    its = {}
    for name, kw in (("default", {}),
                     ("ceres", dict(method="lm", initial_trust_region_radius=1e4, damping="marquardt",
                                    jacobi_scaling=True, nonmonotonic_steps=0))):
        g = slam.load_g2o(DATA / "CSAIL.g2o")
        s = g.solve(**kw)
        assert g.chi2() <= PEER_BEST["CSAIL"]["g2o"] * (1 + 1e-6)
        its[name] = s.iterations
    assert its["default"] <= 8 < its["ceres"]
    with pytest.raises(TypeError):
        g.solve(radius=1.0)
    with pytest.raises(ValueError):
        g.solve(damping="magic")
    with pytest.raises(ValueError):
        g.solve(initial_trust_region_radius=0.0)


def test_cli_trust_region_options():
    for extra in (["--damping", "marquardt", "--jacobi-scaling", "--initial-radius", "1e4",
                   "--nonmonotonic", "0"], ["-s", "gn"], ["--no-jacobi-scaling"]):
        r = subprocess.run([_cli(), "-q", *extra, str(DATA / "smallGrid3D.g2o")],
                           capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
        chi2 = float(r.stderr.split("final chi2 g2o convention ")[1].split(",")[0])
        assert chi2 <= PEER_BEST["smallGrid3D"]["g2o"] * (1 + 1e-6)
    r = subprocess.run([_cli(), "-s", "gn-ls", str(DATA / "smallGrid3D.g2o")],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    # The line search reports its step length α where LM reports its radius.
    assert "radius/α" in r.stdout and "solver gn_ls" in r.stderr
    chi2 = float(r.stderr.split("final chi2 g2o convention ")[1].split(",")[0])
    assert chi2 <= PEER_BEST["smallGrid3D"]["g2o"] * (1 + 1e-6)
    for bad in (["--damping", "magic"], ["--initial-radius", "0"], ["--nonmonotonic", "-1"]):
        r = subprocess.run([_cli(), *bad, str(DATA / "tinyGrid3D.g2o")], capture_output=True,
                           text=True)
        assert r.returncode == 2


def test_example_slam_pose_graph(tmp_path):
    import importlib.util

    path = Path(__file__).resolve().parents[2] / "examples" / "slam_pose_graph.py"
    spec = importlib.util.spec_from_file_location("slam_pose_graph", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    res = mod.main(["--out", str(tmp_path)])  # bundled data/slam/intel.g2o, the default start (chordal here)
    assert res["summary"].usable
    assert res["chi2"] <= 45.00469581 * (1 + 1e-6)  # g2o's (and GTSAM's) optimum on intel
    assert res["chi2_file"] > 500
    assert slam.load_g2o(res["g2o"]).chi2() == pytest.approx(res["chi2"], rel=1e-9)
    assert res["png"].stat().st_size > 10_000


def test_default_strategy_starts_from_the_better_start(tmp_path):
    assert bp.slam.SOLVER_DEFAULTS["method"] == "gn_lm"
    # MIT from its file estimate (chi2 4.4e9): LM and Gauss–Newton stop at 770.66.
    g = slam.load_g2o(DATA / "MIT.g2o", init="file")
    assert g.report.start == "file"
    g.solve(method="lm")
    assert g.chi2() == pytest.approx(770.6635019, rel=1e-6)
    # The best start is the chordal one there (its chi2 is lower than the
    # file's), and the default solver from it goes below the lowest optimum
    # any solver finds from the file (476.30, dogleg).
    g = slam.load_g2o(DATA / "MIT.g2o", init="best")
    assert g.report.start == "chordal"
    assert g.solve().usable
    assert g.chi2() <= 476.30 * (1 + 1e-5)
    # A file that holds an optimum keeps it: the file's start is better.
    g.save_g2o(tmp_path / "mit_opt.g2o")
    again = slam.load_g2o(tmp_path / "mit_opt.g2o", init="best")
    assert again.report.start == "file"
    assert again.chi2() == pytest.approx(g.chi2(), rel=1e-9)

