"""Reliability of the SLAM wing (issue 17): bad input raises naming the file and
line, a failed call changes nothing, and no input is silently rewritten."""

from __future__ import annotations

import math
import signal
import subprocess
from pathlib import Path

import boxplus as bp
import boxplus.slam as slam
import numpy as np
import pytest
from harness import boxplus_g2o

DATA = Path(__file__).resolve().parents[1] / "data"
SHARED = Path("/work/shared/data/slam")

GRAPH_2D = """VERTEX_SE2 0 0 0 0
VERTEX_SE2 1 1 0 0.1
VERTEX_XY 10 1 1
EDGE_SE2 0 1 1 0 0.1 100 0 0 100 0 1000
EDGE_SE2_XY 0 10 1 1 10 0 10
"""
SE3_EDGE_INFO = np.eye(6)


_cli = boxplus_g2o


def _write(tmp_path, text, name="g.g2o"):
    p = tmp_path / name
    p.write_bytes(text if isinstance(text, bytes) else text.encode())
    return p


def _state(g):
    return (g.vertex_ids, g.num_edges, g.problem.num_variables, g.problem.num_measurements,
            g.chi2(), g.to_string())


# -- item 3: a failed add_vertex / add_edge leaves the graph unchanged ---------


def test_failed_add_vertex_and_add_edge_change_nothing(tmp_path):
    g = slam.load_g2o(_write(tmp_path, GRAPH_2D))
    before = _state(g)
    bad_vertices = [
        (5, "SE2", [0, np.nan, 0]),          # NaN estimate
        (5, "SE3", [0, 0, 0, 0, 0, 0, 1]),   # a 3D pose in a 2D graph
        (5, "SE2", [0, 0]),                  # wrong size
        (1, "SE2", [0, 0, 0]),               # existing id
        (5, "SE3", [0, 0, 0, 0, 0, 0, 0]),   # zero quaternion
    ]
    for vid, kind, est in bad_vertices:
        with pytest.raises((ValueError, IndexError, bp.BoxplusError)):
            g.add_vertex(vid, kind, est)
        assert _state(g) == before, (vid, kind, est)
    bad_edges = [
        ("SE3", 0, 1, [1, 0, 0, 0, 0, 0, 1], SE3_EDGE_INFO),     # SE3 edge on a 2D graph
        ("SE2", 0, 99, [1, 0, 0], np.eye(3)),                     # unknown id
        ("SE2", 0, 1, [1, 0], np.eye(3)),                         # wrong measurement size
        ("SE2", 0, 1, [1, 0, 0], np.eye(2)),                      # wrong information size
        ("SE2", 0, 1, [1, 0, 0], -np.eye(3)),                     # not positive definite
        ("SE2", 0, 1, [1, np.inf, 0], np.eye(3)),                 # not finite
        ("SE2_XY", 0, 1, [1, 1], np.eye(2)),                      # wrong vertex kinds
        ("SE2_BEARING_RANGE", 0, 10, [0.1, -1], np.eye(2)),       # negative range
    ]
    for kind, a, b, z, info in bad_edges:
        with pytest.raises((ValueError, IndexError, bp.BoxplusError)):
            g.add_edge(kind, a, b, z, info)
        assert _state(g) == before, (kind, a, b, z)
    # The graph still solves, saves and reloads.
    g.solve(max_iterations=5)
    out = tmp_path / "out.g2o"
    g.save_g2o(out)
    assert slam.load_g2o(out).chi2() == pytest.approx(g.chi2(), rel=1e-9, abs=1e-12)


def test_add_vertex_normalises_huge_quaternions_and_wraps_angles(tmp_path):
    g = slam.load_g2o(DATA / "tinyGrid3D.g2o")
    g.add_vertex(1000, "SE3", [0, 0, 0, 0, 0, 0, 1e200])
    np.testing.assert_allclose(g.value(1000)[3:], [0, 0, 0, 1])
    g2 = slam.load_g2o(_write(tmp_path, GRAPH_2D))
    g2.add_vertex(7, "SE2", [0, 0, 1e16])
    assert -math.pi <= g2.value(7)[2] < math.pi


def test_add_prior_with_non_pd_information_names_the_vertex(tmp_path):
    g = slam.load_g2o(_write(tmp_path, GRAPH_2D))
    with pytest.raises(ValueError, match="vertex 1"):
        g.add_prior(1, [0, 0, 0], information=-np.eye(3))


# -- item 7: quaternions with huge components ----------------------------------


def test_huge_quaternion_components_load_as_the_rotation_they_mean(tmp_path):
    p = _write(tmp_path, "VERTEX_SE3:QUAT 0 0 0 0 0 0 0 1\nVERTEX_SE3:QUAT 1 0 0 0 1e200 0 0 0\n"
               "EDGE_SE3:QUAT 0 1 0 0 0 0 0 0 1e200 " + " ".join(
                   str(v) for r in range(6) for v in np.eye(6)[r, r:]) + "\n")
    g = slam.load_g2o(p, init="file")
    np.testing.assert_allclose(g.value(1)[3:], [1, 0, 0, 0])
    assert g.chi2() > 0  # the edge says identity, the vertex is a half turn
    out = tmp_path / "o.g2o"
    g.save_g2o(out)
    np.testing.assert_allclose(slam.load_g2o(out, init="file").value(1)[3:], [1, 0, 0, 0])
    zero = _write(tmp_path, "VERTEX_SE3:QUAT 0 0 0 0 0 0 0 1\nVERTEX_SE3:QUAT 1 0 0 0 0 0 0 0\n",
                  "zero.g2o")
    with pytest.raises(bp.ParseError, match=r"zero\.g2o:2: VERTEX_SE3:QUAT: quaternion has zero"):
        slam.load_g2o(zero)


# -- item 8: TORO Euler angles at the gimbal lock ------------------------------


def _quat_angle(a, b):
    return 2 * math.acos(min(1.0, abs(float(np.dot(a, b)))))


@pytest.mark.parametrize("pitch", [math.pi / 2, -math.pi / 2, math.pi / 2 - 1e-9, 1.4])
def test_toro_euler_angles_round_trip_through_the_cli(tmp_path, pitch):
    info = " ".join(str(v) for r in range(6) for v in np.eye(6)[r, r:])
    text = (f"VERTEX3 0 0 0 0 0 0 0\nVERTEX3 1 1 2 3 0.3 {pitch!r} 0.5\n"
            f"EDGE3 0 1 1 2 3 -0.7 {pitch!r} 1.1 {info}\n")
    p = _write(tmp_path, text, "toro.graph")
    out = tmp_path / "out.graph"
    r = subprocess.run([_cli(), "-i", "0", "--init", "file", "-q", "-o", str(out), str(p)],
                       capture_output=True,
                       text=True)
    assert r.returncode == 0, r.stderr
    a, b = slam.load_g2o(p), slam.load_g2o(out)
    for vid in (0, 1):
        assert _quat_angle(a.value(vid)[3:], b.value(vid)[3:]) < 1e-7
    assert b.chi2() == pytest.approx(a.chi2(), rel=1e-7, abs=1e-12)


# -- items 9, 10, 14: errors name the file (and line), bytes escaped -----------


def test_non_utf8_bytes_give_a_parse_error_with_the_bytes_escaped(tmp_path):
    p = _write(tmp_path, b"VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 \xff\xfe 0 0\n", "bin.g2o")
    with pytest.raises(bp.ParseError, match=r"bin\.g2o:2: .*\\xff\\xfe"):
        slam.load_g2o(p)
    with pytest.raises(bp.ParseError, match=r"bin\.g2o:2:"):
        slam.load_g2o(p, skip_unknown=True)
    q = _write(tmp_path, b"VERTEX_SE2 0 0 0 0\nJUNK\xc3( 1 2\n", "tag.g2o")
    with pytest.raises(bp.ParseError, match=r"tag\.g2o:2: unknown tag 'JUNK\\xc3\('"):
        slam.load_g2o(q)
    with pytest.warns(UserWarning, match="skipped 1 line"):
        g = slam.load_g2o(q, skip_unknown=True)
    assert g.report.unknown_tags == {"JUNK\\xc3(": 1}


@pytest.mark.parametrize("text", ["", "\n\n", "# only a comment\n"])
def test_empty_or_comment_only_files_name_the_file(tmp_path, text):
    p = _write(tmp_path, text, "empty.g2o")
    with pytest.raises(bp.BoxplusError, match=r"empty\.g2o"):
        slam.load_g2o(p)


def test_errors_without_a_line_name_the_file(tmp_path):
    with pytest.raises(bp.BoxplusError, match=str(tmp_path) + ": is a directory"):
        slam.load_g2o(tmp_path)
    zero = _write(tmp_path, "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 0 0 0\n"
                  "EDGE_SE2 0 1 1 0 0 0 0 0 0 0 0\n", "zero.g2o")
    with pytest.raises(bp.ParseError, match=r"zero\.g2o:3: .*cannot be repaired"):
        slam.load_g2o(zero, repair_information=True)
    neg = _write(tmp_path, GRAPH_2D + "EDGE_SE2_BEARING_RANGE 1 10 0.5 -2 10 0 10\n", "neg.g2o")
    with pytest.raises(bp.ParseError, match=r"neg\.g2o:6: .*negative range"):
        slam.load_g2o(neg)
    apart = _write(tmp_path, "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 0 0 0\nVERTEX_SE2 2 0 0 0\n"
                   "EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\n", "apart.g2o")
    for init in ("spanning-tree", "chordal"):
        with pytest.raises(bp.BoxplusError, match=r"apart\.g2o:3: .*vertex 2 is not connected"):
            slam.load_g2o(apart, init=init)


# Chordal initialisation factorises positive definite systems (the graph is checked
# connected first); only weights from the information matrices that underflow or
# overflow make them singular — named by file, edge and line.
SINGULAR_CHORDAL = {
    # κ = Ω_θθ = 1e-320 (subnormal): the rotation system's pivots vanish
    "rotation": ("VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\nVERTEX_SE2 2 2 0 0\n"
                 "EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1e-320\nEDGE_SE2 1 2 1 0 0 1 0 0 1 0 1e-320\n",
                 r"line 4\) to .*line 4\)"),
    # τ = 2 / tr(Ω_xy⁻¹) = 0: Ω_xy = 1e-320 I inverts to inf
    "translation": ("VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\n"
                    "EDGE_SE2 0 1 1 0 0 1e-320 0 0 1e-320 0 1\n", r"0 \(edge 0 -> 1, line 3\) to 0"),
    # τ = 2 / tr(Ω_xy⁻¹) with Ω_xy = 1e308 I: the Laplacian's diagonal overflows
    "translation, overflow": ("VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\nVERTEX_SE2 2 1 0 0\n"
                              "EDGE_SE2 0 1 1 0 0 1e308 0 0 1e308 0 1\n"
                              "EDGE_SE2 1 2 1 0 0 1e308 0 0 1e308 0 1\n", r"line 4\)"),
}


@pytest.mark.parametrize("case", sorted(SINGULAR_CHORDAL))
def test_chordal_singular_system_names_the_file_and_the_edges(tmp_path, case):
    text, lines = SINGULAR_CHORDAL[case]
    p = _write(tmp_path, text, "singular.g2o")
    system = case.split(",")[0]
    with pytest.raises(bp.BoxplusError, match=str(tmp_path / "singular.g2o") +
                       f": chordal initialisation: singular {system} system: the edges' weights "
                       r"from their information matrices range from .*" + lines):
        slam.load_g2o(p, init="chordal")
    # the file itself is valid: the spanning tree composes its exact measurements
    g = slam.load_g2o(p, init="spanning-tree")
    np.testing.assert_allclose(g.poses()[:, 0], np.arange(len(g.poses())), atol=1e-12)


def test_se2_angle_1e16_loads_wrapped(tmp_path):
    g = slam.load_g2o(_write(tmp_path, "VERTEX_SE2 0 0 0 1e16\nVERTEX_SE2 1 0 0 -1e16\n"
                             "EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\n"), init="file")
    for vid, theta0 in ((0, 1e16), (1, -1e16)):
        theta = g.value(vid)[2]
        assert -math.pi <= theta < math.pi
        # The angle the file's number means, mod the true 2π (sin and cos reduce
        # exactly; remainder(θ, 2 * pi) would divide by a double that is not 2π).
        assert theta == pytest.approx(math.atan2(math.sin(theta0), math.cos(theta0)), abs=1e-15)


def test_se2_edge_angle_1e16_is_wrapped_as_exactly_as_a_vertex_angle(tmp_path):
    # The fuzzer found the loader's chi2 and the numpy oracle's disagreeing here:
    # the solver's wrap(θj − θi − θz) loses every digit of θz = 1e16.
    theta_z = math.atan2(math.sin(1e16), math.cos(1e16))
    g = slam.load_g2o(_write(tmp_path, "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\n"
                             "EDGE_SE2 0 1 1 0 1e16 1 0 0 1 0 1\n"), init="file")
    h = slam.load_g2o(_write(tmp_path, "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\n"
                             f"EDGE_SE2 0 1 1 0 {theta_z!r} 1 0 0 1 0 1\n", "h.g2o"), init="file")
    assert g.chi2() == pytest.approx(h.chi2(), rel=1e-15)
    assert g.chi2() == pytest.approx(theta_z**2, rel=1e-12)


def test_repairing_huge_information_entries_does_not_overflow(tmp_path):
    # Entries near the largest double: the eigen-decomposition is done at unit
    # scale, so the repair succeeds (or would name file:line).
    text = ("VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\n"
            "EDGE_SE2 0 1 1 0 0 1e300 1e300 0 1e300 0 -1e300\n")
    with pytest.warns(UserWarning, match="replaced 1 information"):
        g = slam.load_g2o(_write(tmp_path, text), repair_information=True)
    assert g.report.repaired_information == 1
    assert math.isfinite(g.chi2())


# -- item 11: FIX naming a landmark ----------------------------------------------


@pytest.mark.parametrize("init", ["spanning-tree", "chordal"])
def test_fix_of_a_landmark_roots_the_tree_at_a_pose(tmp_path, init):
    g = slam.load_g2o(_write(tmp_path, GRAPH_2D + "FIX 10\n"), init=init)
    np.testing.assert_allclose(g.value(0), [0, 0, 0])
    np.testing.assert_allclose(g.value(1), [1, 0, 0.1], atol=1e-12)
    assert math.isfinite(g.chi2())


# -- Ctrl-C: the CLI writes the best estimate so far and exits non-zero --------


def test_cli_writes_the_last_accepted_estimate_on_sigint(tmp_path):
    src = SHARED / "sphere2500.g2o"
    if not src.exists():
        src = DATA / "smallGrid3D.g2o"
    out = tmp_path / "out.g2o"
    # Tight tolerances and many iterations keep the solver busy until the signal.
    p = subprocess.Popen([_cli(), "-i", "100000", "-s", "lm", "--function-tolerance", "0",
                          "--gradient-tolerance", "0", "--parameter-tolerance", "0",
                          "--init", "chordal", "-o", str(out), str(src)],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    for line in p.stdout:
        if line.split() and line.split()[0] == "1":  # the first iteration line
            break
    p.send_signal(signal.SIGINT)
    _, err = p.communicate(timeout=120)
    assert p.returncode != 0 and p.returncode == 130, err
    assert "interrupted" in err
    initial = float(err.split("# initial chi2 ")[1].split()[0])
    g = slam.load_g2o(out)
    assert g.chi2() <= initial
