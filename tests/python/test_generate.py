"""The pose-graph generator: files the strict loader reads, seeded, statistically consistent."""

import numpy as np
import pytest
from boxplus import slam
from boxplus.synthetic import se_arrays as se
from boxplus.synthetic.pose_graphs import (
    LOOP_CLOSURE,
    NOISE_LEVELS,
    OUTLIER,
    benchmark_suite,
    generate,
    main,
    with_near_misses,
)
from boxplus.synthetic.trajectories import FAMILIES
from harness.g2o_reference import edge_errors, read_g2o_arrays

CASES = [(family, dim) for family in FAMILIES for dim in (2, 3)]


def _same_poses(a, b, dim, atol):
    """Poses equal up to atol, quaternions up to sign."""
    if dim == 2:
        return (np.allclose(a[:, :2], b[:, :2], atol=atol)
                and np.allclose(se.wrap_angle(a[:, 2] - b[:, 2]), 0.0, atol=atol))
    dot = np.abs(np.sum(a[:, 3:] * b[:, 3:], axis=1))
    return np.allclose(a[:, :3], b[:, :3], atol=atol) and np.allclose(dot, 1.0, atol=atol)


@pytest.mark.parametrize("family,dim", CASES)
def test_every_family_writes_files_the_strict_loader_reads(tmp_path, family, dim):
    g = generate(family, dim, 400, noise="medium", seed=5)
    g.write(tmp_path / "g.g2o")
    g.write_truth(tmp_path / "t.g2o")
    est = slam.load_g2o(tmp_path / "g.g2o", init="file")
    tru = slam.load_g2o(tmp_path / "t.g2o", init="file")
    for graph, poses in ((est, g.estimate), (tru, g.truth)):
        assert graph.dimension == dim
        assert graph.vertex_ids == list(range(400))
        assert graph.gauge_vertex == 0
        assert graph.num_edges == g.num_edges
        assert _same_poses(graph.poses(), poses, dim, 1e-12)  # 17 digits read back exactly
    # Odometry chain 0 → 1 → … plus the family's loop closures.
    odo = g.edges[g.kind == 0]
    assert np.array_equal(np.sort(odo[:, 0]), np.arange(399))
    assert np.all(odo[:, 1] == odo[:, 0] + 1)
    assert g.num_loop_closures > 0
    assert np.all(g.edges[:, 0] < g.edges[:, 1])
    keys = g.edges[:, 0] * 400 + g.edges[:, 1]
    assert len(np.unique(keys)) == len(keys)  # no edge twice
    # The initial estimate is the composed odometry: it starts at the truth and drifts.
    assert _same_poses(g.estimate[:1], g.truth[:1], dim, 1e-12)
    assert not _same_poses(g.estimate, g.truth, dim, 1e-3)


@pytest.mark.parametrize("family,dim", CASES)
def test_same_seed_same_bytes_other_seed_other_file(tmp_path, family, dim):
    paths = []
    for k, seed in enumerate((11, 11, 12)):
        paths.append(tmp_path / f"{k}.g2o")
        generate(family, dim, 200, noise="low", loop_closure_probability=0.7,
                 outlier_fraction=0.1, seed=seed).write(paths[-1])
    a, b, c = (p.read_bytes() for p in paths)
    assert a == b
    assert a != c


def _chi2_band(k, x=40.0):
    """[lo, hi] holding a χ²(k) draw except with probability 2 e⁻ˣ (Laurent & Massart,
    Ann. Statist. 2000, Lemma 1: P(χ² ≥ k + 2√(kx) + 2x) ≤ e⁻ˣ, P(χ² ≤ k − 2√(kx)) ≤ e⁻ˣ).
    x = 40: 8·10⁻¹⁸, a test that cannot fail by chance."""
    return k - 2.0 * np.sqrt(k * x), k + 2.0 * np.sqrt(k * x) + 2.0 * x


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("convention", ["g2o", "log"])
def test_noise_is_consistent_with_the_written_information(tmp_path, dim, convention):
    # At the true poses every edge's eᵀΩe is χ²(d): the sum over M edges is χ²(dM).
    g = generate("sphere", dim, 2500, noise="high", convention=convention, seed=7)
    g.write_truth(tmp_path / "t.g2o")
    d = 3 if dim == 2 else 6
    k = d * g.num_edges
    lo, hi = _chi2_band(k)
    chi2 = slam.load_g2o(tmp_path / "t.g2o", convention=convention, init="file").chi2()
    assert lo <= chi2 <= hi, (chi2 / g.num_edges, d)
    # Per component too: the whitened errors have unit variance (numpy reference errors).
    data = read_g2o_arrays(tmp_path / "t.g2o")
    if convention == "g2o":
        e = edge_errors(data, data["poses"], convention)
        L = np.linalg.cholesky(g.information)
        w2 = ((e @ L) ** 2).sum(axis=0)  # each a χ²(M)
        lo1, hi1 = _chi2_band(g.num_edges)
        assert np.all((lo1 <= w2) & (w2 <= hi1)), w2 / g.num_edges
    if dim == 3:
        # The band is narrow enough to see the factor 4 between the two 3D rotation
        # charts (vec(q) ≈ θ/2): the other convention's chi2 falls outside it.
        other = "log" if convention == "g2o" else "g2o"
        wrong = slam.load_g2o(tmp_path / "t.g2o", convention=other, init="file").chi2()
        assert not lo <= wrong <= hi


@pytest.mark.parametrize("family,dim", [("manhattan", 2), ("grid", 3), ("sphere", 3),
                                        ("torus", 2), ("random_walk", 2), ("random_walk", 3)])
def test_tiny_noise_solves_to_the_truth_up_to_the_gauge(tmp_path, family, dim):
    g = generate(family, dim, 300, noise="tiny", seed=3)
    g.write(tmp_path / "g.g2o")
    graph = slam.load_g2o(tmp_path / "g.g2o")
    summary = graph.solve(method="lm", max_iterations=50)
    assert summary.final_cost < summary.initial_cost
    # Gauge-free comparison: every pose relative to vertex 0.
    def rel(p):
        return se.between(np.repeat(p[:1], len(p), axis=0), p, dim)
    sol, tru, ini = rel(graph.poses()), rel(g.truth), rel(g.estimate)
    err = np.linalg.norm(sol[:, :dim] - tru[:, :dim], axis=1).max()
    err0 = np.linalg.norm(ini[:, :dim] - tru[:, :dim], axis=1).max()
    if dim == 2:
        rot = np.abs(se.wrap_angle(sol[:, 2] - tru[:, 2])).max()
    else:
        rot = 2 * np.arccos(np.minimum(1, np.abs(np.sum(sol[:, 3:] * tru[:, 3:], 1)))).max()
    # Loop closures hold the drift of the odometry (err0) to a few σ.
    sigma_t, sigma_r = NOISE_LEVELS["tiny"]
    assert err < 10 * sigma_t and err < err0 / 3, (err, err0)
    assert rot < 10 * sigma_r, rot
    # The optimum is no worse than the truth, a feasible point of a nearly convex problem.
    g.write_truth(tmp_path / "t.g2o")
    assert 2 * summary.final_cost <= slam.load_g2o(tmp_path / "t.g2o").chi2() * (1 + 1e-9)
    # With tiny noise the problem is linear about the truth: the minimum is χ² with
    # d·(M − (N − 1)) degrees of freedom (N − 1 free poses of d unknowns each).
    d = 3 if dim == 2 else 6
    lo, hi = _chi2_band(d * (g.num_edges - g.num_poses + 1))
    assert lo <= 2 * summary.final_cost <= hi


@pytest.mark.parametrize("dim", [2, 3])
def test_outliers_are_present_in_the_stated_fraction(tmp_path, dim):
    f = 0.1
    g = generate("manhattan", dim, 3000, noise="medium", outlier_fraction=f, seed=9)
    inliers = int(np.count_nonzero(g.kind == LOOP_CLOSURE))
    assert inliers > 300
    assert g.num_outliers == round(f * inliers / (1 - f))
    assert abs(g.num_outliers / g.num_loop_closures - f) < 1.0 / g.num_loop_closures
    # Every wrong closure is wrong at the truth, every other edge is not.
    g.write_truth(tmp_path / "t.g2o")
    data = read_g2o_arrays(tmp_path / "t.g2o")
    e = edge_errors(data, data["poses"], "g2o")
    chi2 = np.einsum("mi,ij,mj->m", e, g.information, e)
    threshold = 150.0  # P(χ²(6) > 150) < 10⁻²⁹: no inlier reaches it
    assert np.array_equal(chi2 > threshold, g.kind == OUTLIER)
    assert np.all(g.is_outlier == (g.kind == OUTLIER))


@pytest.mark.parametrize("dim", [2, 3])
def test_near_misses_are_wrong_closures_a_few_sigma_off(tmp_path, dim):
    g = generate("grid", dim, 500, noise="low", outlier_fraction=0.3, seed=2)
    near = with_near_misses(g, 0.5, (10.0, 20.0), seed=3)
    changed = np.any(near.measurements != g.measurements, axis=1)
    assert not np.any(changed & ~g.is_outlier)  # inliers and odometry untouched
    assert 0.35 < changed.sum() / g.num_outliers < 0.65
    assert np.array_equal(near.edges, g.edges) and np.array_equal(near.kind, g.kind)
    near.write_truth(tmp_path / "t.g2o")
    data = read_g2o_arrays(tmp_path / "t.g2o")
    chi2 = np.einsum("mi,ij,mj->m", e := edge_errors(data, data["poses"], "g2o"), g.information, e)
    d = 3 if dim == 2 else 6
    # eᵀΩe = k² χ²(d), k in [10, 20]: a χ²(d) draw is outside [0.01 (d/3), 30] with
    # probability < 3·10⁻⁴.
    assert np.all((chi2[changed] > 100 * 0.01 * d / 3) & (chi2[changed] < 400 * 30))
    assert np.all(chi2[g.is_outlier & ~changed] > 150)  # the others stay random poses
    with pytest.raises(ValueError, match="share"):
        with_near_misses(g, 1.5, (1.0, 2.0))
    with pytest.raises(ValueError, match="sigmas"):
        with_near_misses(g, 0.5, (0.0, 2.0))
    with pytest.raises(ValueError, match="sigmas"):
        with_near_misses(g, 0.5, (3.0, 2.0))


def test_no_closures_no_outliers_and_density_thins_closures():
    dense = generate("grid", 2, 900, loop_closure_probability=1.0, seed=1)
    sparse = generate("grid", 2, 900, loop_closure_probability=0.3, seed=1)
    none = generate("grid", 2, 900, loop_closure_probability=0.0, outlier_fraction=0.2, seed=1)
    assert none.num_loop_closures == 0 and none.num_edges == 899
    ratio = sparse.num_loop_closures / dense.num_loop_closures
    assert 0.2 < ratio < 0.4  # binomial(≈870, 0.3): 9 σ either side


def test_sphere_is_g2o_create_sphere():
    # create_sphere with 50 rings of 50 poses: 2500 poses, 2499 odometry edges and
    # 3 edges per pose of rings 1 … 49 but the last ring's n + 1: 49·150 − 50 = 7300.
    g = generate("sphere", 3, 2500, loop_closure_probability=1.0, seed=0)
    assert g.num_edges == 2499 + 7300
    r = np.linalg.norm(g.truth[:, :3], axis=1)
    assert np.allclose(r, 100.0)  # create_sphere's radius for 50 poses per ring


def test_bad_parameters_raise_clear_errors():
    with pytest.raises(ValueError, match="unknown family"):
        generate("moon", 2, 100)
    with pytest.raises(ValueError, match="dimension"):
        generate("grid", 4, 100)
    with pytest.raises(ValueError, match="num_poses"):
        generate("grid", 2, 2)
    with pytest.raises(ValueError, match="outlier_fraction"):
        generate("grid", 2, 100, outlier_fraction=1.0)
    with pytest.raises(ValueError, match="loop_closure_probability"):
        generate("grid", 2, 100, loop_closure_probability=-0.1)
    with pytest.raises(ValueError, match="exceeds"):
        generate("grid", 3, 100, noise=(0.1, 0.5))
    with pytest.raises(ValueError, match="unknown noise level"):
        generate("grid", 2, 100, noise="huge")
    with pytest.raises(ValueError, match="positive"):
        generate("grid", 2, 100, noise=(0.1, 0.0))
    with pytest.raises(TypeError, match="no option"):
        generate("grid", 2, 100, block=3)
    with pytest.raises(ValueError, match="integer"):
        generate("manhattan", 2, 100, block=2.5)
    with pytest.raises(ValueError, match="convention"):
        generate("grid", 2, 100, convention="sesync")


def test_benchmark_suite_spans_families_sizes_noise_and_outliers():
    suite = benchmark_suite(seed=1)
    assert len(suite) == 65
    assert len({s.name for s in suite}) == len(suite)
    assert {(s.family, s.dimension) for s in suite} == set(CASES)
    assert {s.noise for s in suite} == set(NOISE_LEVELS)
    assert {s.num_poses for s in suite} == {100, 1000, 10_000, 100_000}
    assert any(s.outlier_fraction > 0 for s in suite)
    assert any(s.outlier_fraction == 0 for s in suite)
    assert len({s.loop_closure_probability for s in suite}) >= 3
    assert benchmark_suite(seed=1) == suite
    other = benchmark_suite(seed=2)
    assert [s.name for s in other] == [s.name for s in suite]
    assert [s.seed for s in other] != [s.seed for s in suite]
    million = benchmark_suite(seed=1, include_million=True)
    assert million[: len(suite)] == suite
    assert {s.num_poses for s in million[len(suite):]} == {1_000_000}
    # Every family has wrong loop closures in 3D at 10³ poses too (appended last).
    assert {s.family for s in suite[60:]} == set(FAMILIES)
    assert all(s.dimension == 3 and s.num_poses == 1000 and s.outlier_fraction > 0
               for s in suite[60:])
    small = next(s for s in suite if s.num_poses == 100 and s.outlier_fraction == 0)
    g = small.generate()
    assert (g.family, g.dimension, g.num_poses, g.seed) == (small.family, small.dimension,
                                                            100, small.seed)


def test_command_line_writes_graph_and_truth(tmp_path, capsys):
    out = tmp_path / "out.g2o"
    assert main(["--family", "sphere", "--poses", "100", "--noise", "0.1,0.05", "--seed", "3",
                 "-o", str(out)]) == 0
    truth = tmp_path / "out_truth.g2o"
    g = slam.load_g2o(out, init="file")
    t = slam.load_g2o(truth, init="file")
    assert g.dimension == 3 and len(g.vertex_ids) == 100
    ref = generate("sphere", 3, 100, noise=(0.1, 0.05), seed=3)
    assert _same_poses(t.poses(), ref.truth, 3, 1e-12)
    assert "100 poses" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["--family", "grid", "--poses", "100", "--noise", "a,b", "-o", str(out)])


def test_prefix_compose_is_sequential_composition():
    rng = np.random.default_rng(0)
    for dim in (2, 3):
        n = 37
        if dim == 2:
            steps = rng.standard_normal((n, 3))
            first = np.array([1.0, -2.0, 0.5])
        else:
            steps = np.concatenate([rng.standard_normal((n, 3)),
                                    se.quat_from_rotation_vector(rng.standard_normal((n, 3)))],
                                   axis=1)
            first = np.array([1.0, -2.0, 0.5, 0.0, 0.6, 0.0, 0.8])
        out = se.prefix_compose(first, steps, dim)
        x = first[None]
        for k in range(n):
            x = se.compose(x, steps[k:k + 1], dim)
            assert _same_poses(out[k + 1:k + 2], x, dim, 1e-12)


def test_quaternion_from_matrix_in_every_branch():
    # Shepperd's four branches: w largest (small angles), x, y or z largest (≈ π about them).
    rng = np.random.default_rng(1)
    axes = np.concatenate([np.eye(3) * (np.pi - 1e-3), rng.standard_normal((20, 3)),
                           np.zeros((1, 3)), np.full((1, 3), 1e-9)])
    q = se.quat_from_rotation_vector(axes)
    q = np.where(q[:, 3:] < 0, -q, q)
    back = se.quat_from_matrix(se.matrix_from_quat(q))
    assert np.allclose(back, q, atol=1e-12)
