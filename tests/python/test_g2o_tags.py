"""Every g2o / TORO tag of tests/data/g2o_tags/: the loaded problem's chi2
against an independent evaluation (numpy, homogeneous matrices, the formulas of
g2o's computeError), before and after solving, and the save → reload round trip.

The oracle below reads the files itself (it shares nothing with the C++ reader
but the file format) and evaluates each edge with 3×3 / 4×4 matrices, where the
library composes quaternions and angles.
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import boxplus as bp
import boxplus.slam as slam
import numpy as np
import pytest

TAGS = Path(__file__).resolve().parents[1] / "data" / "g2o_tags"
FILES = sorted(TAGS.glob("*.g2o"))


# ---- an independent reader and evaluator ------------------------------------------


def _wrap(a: float) -> float:
    return (a + math.pi) % (2 * math.pi) - math.pi


def _se2(x: float, y: float, th: float) -> np.ndarray:
    c, s = math.cos(th), math.sin(th)
    return np.array([[c, -s, x], [s, c, y], [0.0, 0.0, 1.0]])


def _rot(q) -> np.ndarray:
    x, y, z, w = np.asarray(q, float) / np.linalg.norm(q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def _se3(t, R) -> np.ndarray:
    M = np.eye(4)
    M[:3, :3] = R
    M[:3, 3] = t
    return M


def _euler(roll: float, pitch: float, yaw: float) -> np.ndarray:
    cr, sr, cp, sp, cy, sy = (f(a) for a in (roll, pitch, yaw) for f in (math.cos, math.sin))
    Rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    Ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    Rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return Rz @ Ry @ Rx


def _quat_of(R: np.ndarray) -> np.ndarray:
    """[x, y, z, w] of a rotation matrix, w ≥ 0 (largest-diagonal branch)."""
    tr = np.trace(R)
    cands = [tr, R[0, 0], R[1, 1], R[2, 2]]
    k = int(np.argmax(cands))
    if k == 0:
        w = math.sqrt(1 + tr) / 2
        q = [(R[2, 1] - R[1, 2]) / (4 * w), (R[0, 2] - R[2, 0]) / (4 * w),
             (R[1, 0] - R[0, 1]) / (4 * w), w]
    else:
        i, j, m = [(0, 1, 2), (1, 2, 0), (2, 0, 1)][k - 1]
        v = [0.0, 0.0, 0.0]
        v[i] = math.sqrt(1 + R[i, i] - R[j, j] - R[m, m]) / 2
        v[j] = (R[j, i] + R[i, j]) / (4 * v[i])
        v[m] = (R[m, i] + R[i, m]) / (4 * v[i])
        w = (R[m, j] - R[j, m]) / (4 * v[i])
        q = [*v, w]
    q = np.array(q)
    return -q if q[3] < 0 else q


def _err2(M: np.ndarray) -> np.ndarray:
    return np.array([M[0, 2], M[1, 2], _wrap(math.atan2(M[1, 0], M[0, 0]))])


def _err3(M: np.ndarray) -> np.ndarray:
    return np.concatenate([M[:3, 3], _quat_of(M[:3, :3])[:3]])


def _upper(vals, n: int) -> np.ndarray:
    it = iter(vals)
    m = np.zeros((n, n))
    for r in range(n):
        for c in range(r, n):
            m[r, c] = m[c, r] = next(it)
    return m


def oracle_chi2(path: Path) -> float:
    """Σ eᵀΩe of a file at its own vertex estimates."""
    poses: dict[int, np.ndarray] = {}
    lands: dict[int, np.ndarray] = {}
    params: dict[int, np.ndarray] = {}
    edges: list[tuple] = []
    for line in path.read_text().splitlines():
        t = line.split("#")[0].split()
        if not t:
            continue
        tag, v = t[0], [float(x) for x in t[1:]]
        if tag in ("VERTEX_SE2", "VERTEX2", "VERTEX"):
            poses[int(v[0])] = _se2(*v[1:4])
        elif tag == "VERTEX_SE3:QUAT":
            poses[int(v[0])] = _se3(v[1:4], _rot(v[4:8]))
        elif tag == "VERTEX3":
            poses[int(v[0])] = _se3(v[1:4], _euler(*v[4:7]))
        elif tag in ("VERTEX_XY", "VERTEX_TRACKXYZ"):
            lands[int(v[0])] = np.array(v[1:])
        elif tag == "PARAMS_SE2OFFSET":
            params[int(v[0])] = _se2(*v[1:4])
        elif tag == "PARAMS_SE3OFFSET":
            params[int(v[0])] = _se3(v[1:4], _rot(v[4:8]))
        else:
            edges.append((tag, v))
    dim = 3 if any(p.shape == (4, 4) for p in poses.values()) else 2
    inv = np.linalg.inv
    total = 0.0
    pose_edges = []
    for tag, v in edges:
        if tag in ("EDGE_SE2", "EDGE2", "EDGE", "EDGE_SE3:QUAT", "EDGE3"):
            i, j = int(v[0]), int(v[1])
            if tag in ("EDGE_SE2", "EDGE2", "EDGE"):
                Z = _se2(*v[2:5])
                if tag == "EDGE_SE2":
                    info = _upper(v[5:11], 3)
                else:  # TORO: I11 I12 I22 I33 I13 I23
                    a = v[5:11]
                    info = np.array([[a[0], a[1], a[4]], [a[1], a[2], a[5]], [a[4], a[5], a[3]]])
            elif tag == "EDGE_SE3:QUAT":
                Z, info = _se3(v[2:5], _rot(v[5:9])), _upper(v[9:30], 6)
            else:
                Z = _se3(v[2:5], _euler(*v[5:8]))
                info = _upper(v[8:29], 6) if len(v) > 8 else np.eye(6)
            pose_edges.append((i, j, Z))
            e = (_err2 if dim == 2 else _err3)(inv(Z) @ inv(poses[i]) @ poses[j])
        elif tag in ("EDGE_SE2_OFFSET", "EDGE_SE3_OFFSET"):
            i, j, pa, pb = (int(x) for x in v[:4])
            if tag == "EDGE_SE2_OFFSET":
                Z, info, err = _se2(*v[4:7]), _upper(v[7:13], 3), _err2
            else:
                Z, info, err = _se3(v[4:7], _rot(v[7:11])), _upper(v[11:32], 6), _err3
            e = err(inv(Z) @ inv(poses[i] @ params[pa]) @ poses[j] @ params[pb])
        elif tag == "EDGE_PRIOR_SE2":
            i = int(v[0])
            e, info = _err2(inv(_se2(*v[1:4])) @ poses[i]), _upper(v[4:10], 3)
        elif tag == "EDGE_SE3_PRIOR":
            i, p = int(v[0]), int(v[1])
            Z = _se3(v[2:5], _rot(v[5:9]))
            e, info = _err3(inv(Z) @ poses[i] @ params[p]), _upper(v[9:30], 6)
        elif tag == "EDGE_PRIOR_SE2_XY":
            i = int(v[0])
            e, info = poses[i][:2, 2] - v[1:3], _upper(v[3:6], 2)
        elif tag == "EDGE_SE3_XYZ_PRIOR":
            i = int(v[0])
            e, info = poses[i][:3, 3] - v[2:5], _upper(v[5:11], 3)
        elif tag in ("EDGE_PRIOR_XY", "EDGE_POINTXYZ_PRIOR"):
            d = 2 if tag == "EDGE_PRIOR_XY" else 3
            e, info = lands[int(v[0])] - v[1 : 1 + d], _upper(v[1 + d :], d)
        elif tag in ("EDGE_POINTXY", "EDGE_POINTXYZ"):
            d = 2 if tag == "EDGE_POINTXY" else 3
            i, j = int(v[0]), int(v[1])
            e, info = (lands[j] - lands[i]) - v[2 : 2 + d], _upper(v[2 + d :], d)
        elif tag in ("EDGE_SE2_XY", "EDGE_SE2_POINTXY_OFFSET", "EDGE_SE3_TRACKXYZ"):
            d = 3 if tag == "EDGE_SE3_TRACKXYZ" else 2
            i, j = int(v[0]), int(v[1])
            k = 2
            frame = poses[i]
            if tag != "EDGE_SE2_XY":
                frame = frame @ params.get(int(v[2]), np.eye(d + 1))
                k = 3
            local = inv(frame) @ np.append(lands[j], 1.0)
            e, info = local[:d] - v[k : k + d], _upper(v[k + d :], d)
        elif tag == "EDGE_BEARING_SE2_XY":
            i, j = int(v[0]), int(v[1])
            local = inv(poses[i]) @ np.append(lands[j], 1.0)
            e, info = np.array([_wrap(math.atan2(local[1], local[0]) - v[2])]), np.array([[v[3]]])
        elif tag == "EQUIV":
            i, j = int(v[0]), int(v[1])
            Z = np.eye(dim + 1)
            for a, b, M in pose_edges:
                if (a, b) == (i, j):
                    Z = M
                    break
                if (a, b) == (j, i):
                    Z = inv(M)
                    break
            e = (_err2 if dim == 2 else _err3)(inv(Z) @ inv(poses[i]) @ poses[j])
            info = 1e6 * np.eye(len(e))
        elif tag == "FIX":
            continue
        else:
            raise AssertionError(f"the oracle does not know {tag}")
        total += float(e @ info @ e)
    return total


def _load(path: Path) -> slam.PoseGraph:
    with warnings.catch_warnings():
        # EDGE3 without information warns (tested below); the others must not.
        warnings.simplefilter("error" if "edge3_no_information" not in path.name else "ignore")
        return slam.load_g2o(path, init="file")


# ---- the tests -----------------------------------------------------------------------


def test_every_file_has_a_tag_the_oracle_checks():
    assert len(FILES) >= 17


@pytest.mark.parametrize("path", FILES, ids=[p.stem for p in FILES])
def test_chi2_matches_the_independent_evaluation(path):
    g = _load(path)
    expected = oracle_chi2(path)
    assert expected > 0.1
    assert g.chi2() == pytest.approx(expected, rel=1e-10)


@pytest.mark.parametrize("path", FILES, ids=[p.stem for p in FILES])
def test_solve_lowers_chi2_and_the_saved_file_evaluates_to_it(path, tmp_path):
    g = _load(path)
    before = g.chi2()
    summary = g.solve(max_iterations=50)
    assert summary.usable
    after = g.chi2()
    assert after < before
    out = tmp_path / path.name
    g.save_g2o(out)
    # The saved file, read by the oracle, is the solution's chi2 (the factors
    # agree with g2o's formulas away from the file's values too) ...
    assert oracle_chi2(out) == pytest.approx(after, rel=1e-8, abs=1e-12)
    # ... and reloads to the same problem and the same text.
    again = _load(out)
    assert again.chi2() == pytest.approx(after, rel=1e-12, abs=1e-15)
    out2 = tmp_path / ("again_" + path.name)
    again.save_g2o(out2)
    # The same records; the numbers equal to rounding (quaternions are
    # normalised when read, TORO's Euler angles pass through a quaternion).
    a, b = (f.read_text().split() for f in (out, out2))
    assert [t for t in a if t[0].isalpha()] == [t for t in b if t[0].isalpha()]
    nums = [[float(t) for t in x if not t[0].isalpha()] for x in (a, b)]
    np.testing.assert_allclose(nums[1], nums[0], rtol=1e-13, atol=1e-15)


def test_tags_are_written_back_as_read(tmp_path):
    for path in FILES:
        g = _load(path)
        out = tmp_path / path.name
        g.save_g2o(out)
        tags_in = [ln.split()[0] for ln in path.read_text().splitlines() if ln and ln[0] != "#"]
        tags_out = [ln.split()[0] for ln in out.read_text().splitlines() if ln]
        # TORO's VERTEX / EDGE are written as VERTEX2 / EDGE2.
        alias = {"VERTEX": "VERTEX2", "EDGE": "EDGE2"}
        assert tags_out == [alias.get(t, t) for t in tags_in], path.name


def test_edge3_without_information_is_the_identity_with_one_warning(tmp_path):
    path = TAGS / "edge3_no_information.g2o"
    with pytest.warns(UserWarning, match=r"2 EDGE3 line\(s\) without an information matrix.*line 5"):
        g = slam.load_g2o(path)
    out = tmp_path / "out.g2o"
    g.save_g2o(out)
    # Written back as read: without the 21 numbers where the file had none.
    counts = [len(ln.split()) - 1 for ln in out.read_text().splitlines() if ln.startswith("EDGE3")]
    assert counts == [8, 29, 8]


def test_pose_priors_fix_the_gauge_and_position_priors_do_not():
    assert _load(TAGS / "prior_se2.g2o").gauge_vertex == -1
    assert _load(TAGS / "se3_prior.g2o").gauge_vertex == -1
    assert _load(TAGS / "prior_se2_xy.g2o").gauge_vertex == 0
    assert _load(TAGS / "se3_xyz_prior.g2o").gauge_vertex == 0


def test_poses_and_landmarks_have_their_own_id_ranges():
    g = _load(TAGS / "landmark_id_range.g2o")
    assert g.vertex_ids == [0, 1, 0, 1]
    assert g.poses().shape == (2, 3) and g.landmarks().shape == (2, 2)
    np.testing.assert_array_equal(g.landmarks(), [[2, 1], [0.5, -1]])


def test_equiv_is_a_tight_edge_that_solving_satisfies():
    g = _load(TAGS / "toro_equiv.g2o")
    assert g.num_edges == 7
    g.solve(max_iterations=100)
    p = dict(zip(g.vertex_ids, g.poses()))
    # 0 ≡ 4 (no edge between them: the same pose) to about σ = 1e-3.
    np.testing.assert_allclose(p[4], p[0], atol=5e-3)


@pytest.mark.parametrize(
    "text, message",
    [
        ("VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 0 0 0\nEDGE_SE2_OFFSET 0 1 0 0 1 0 0 1 0 0 1 0 1\n",
         "t.g2o:3: EDGE_SE2_OFFSET: offset parameter 0 has no PARAMS_SE2OFFSET line before it"),
        ("PARAMS_SE3OFFSET 0 0 0 0 0 0 0 1\nVERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 0 0 0\n"
         "EDGE_SE2_POINTXY_OFFSET 0 1 0 1 0 1 0 1\n",
         "t.g2o:4: EDGE_SE2_POINTXY_OFFSET: offset parameter 0 is not a PARAMS_SE2OFFSET"),
        ("PARAMS_SE2OFFSET 0 0 0 0\nPARAMS_SE2OFFSET 0 1 0 0\n",
         "t.g2o:2: PARAMS_SE2OFFSET: parameter id 0 is defined twice"),
        ("VERTEX_SE2 0 0 0 0\nVERTEX_SE2 0 1 0 0\n",
         "t.g2o:2: vertex id 0 appears twice (first at line 1), both poses"),
        ("VERTEX_SE2 0 0 0 0\nEDGE_PRIOR_XY 0 1 1 1 0 1\n",
         "t.g2o:2: edge to a missing vertex 0 (a landmark)"),
        ("VERTEX2 0 0 0 0\nEQUIV 0 0\n", "t.g2o:2: EQUIV: a vertex with itself"),
        ("EDGE_PRIOR_SE2 0 0 0 0 1 0 0 1 0 1\n", "t.g2o:1: this edge needs VERTEX lines"),
        ("VERTEX3 0 0 0 0 0 0 0\nVERTEX3 1 0 0 0 0 0 0\nEDGE3 0 1 1 0 0 0 0 0 1\n",
         "t.g2o:3: EDGE3: too few numbers (9, expected 29"),
    ],
)
def test_bad_lines_name_the_file_line_and_what(tmp_path, text, message):
    path = tmp_path / "t.g2o"
    path.write_text(text)
    with pytest.raises(bp.ParseError) as err:
        slam.load_g2o(path)
    assert message in str(err.value)


def test_gtsam_landmark2_lines_load_solve_and_write_back(tmp_path):
    # The layout of GTSAM's cityTrees_reduced_1k / victoriaPark_reduced_1k:
    # EDGE_SE2 odometry without vertices, LANDMARK2 pose landmark x y I11 I12 I22.
    src = Path(__file__).resolve().parents[1] / "data" / "landmark2_square.g2o"
    graph = slam.load_g2o(src)
    assert len(graph.poses()) == 12 and len(graph.landmarks()) == 4
    graph.solve()
    assert graph.chi2() < 1e-8  # exact measurements of a square loop
    assert np.allclose(graph.landmarks()[0], [1.5, -1.0], atol=1e-6)
    out = tmp_path / "out.g2o"
    graph.save_g2o(out)
    text = out.read_text()
    assert text.count("LANDMARK2 ") == src.read_text().count("LANDMARK2 ")
    again = slam.load_g2o(out)
    assert again.num_edges == graph.num_edges


def test_every_tag_of_the_readers_table_is_read_and_written_back(tmp_path):
    # The reader's one tag table (boxplus::io::RecordTags): each tag appears in a
    # test file here or in tests/data, and the writer writes every record under a
    # tag of that table, the one it was read under unless it was a TORO alias.
    from boxplus import _core

    table = {tag for tag, _, _ in _core.g2o_record_tags()}
    data = TAGS.parent
    seen = set()
    for path in [*FILES, *data.glob("*.g2o")]:
        for line in path.read_text(errors="replace").splitlines():
            fields = line.split()
            if fields and fields[0] in table:
                seen.add(fields[0])
    assert seen == table, f"tags without a test file: {sorted(table - seen)}"
    aliases = {"VERTEX": "VERTEX2", "EDGE": "EDGE2"}
    for path in FILES:
        read = {ln.split()[0] for ln in path.read_text().splitlines() if ln.split()}
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            g = slam.load_g2o(path, init="file")
        out = tmp_path / path.name
        g.save_g2o(out)
        written = {ln.split()[0] for ln in out.read_text().splitlines() if ln.split()}
        assert written <= table
        assert written == {aliases.get(t, t) for t in read & table}, path.name
