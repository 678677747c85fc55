"""What to capture next (#29): the information a suggested view adds is what the
calibration gains when that view is captured, and greedy suggestions lower the score."""

import warnings

import numpy as np
import pytest
from boxplus.calib import calibrate_mono
from boxplus.calib.suggest import (
    image_grid_jacobians,
    suggest_views,
    suggestions_csv,
    worst_projection_sigma,
)
from boxplus.synthetic.cameras import board_points, observe, random_views

K = np.array([500.0, 505.0, 320.0, 240.0, -0.25, 0.08, 0.001, -0.0015, -0.01])
SIGMA = 0.3


def _calibrate(z, p):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return calibrate_mono(z, p, (640, 480), sigma=SIGMA)


def test_a_suggested_view_delivers_the_predicted_sigma():
    rng = np.random.default_rng(0)
    p = board_points()
    views = random_views(5, rng, p.mean(axis=0))
    z = [observe(K, v, p, SIGMA, rng)[0] for v in views]
    cal = _calibrate(z, p)
    got = suggest_views(cal, n=3, distance=0.6)
    assert [s.rank for s in got] == [1, 2, 3]
    scores = [got[0].score_before] + [s.score_after for s in got]
    assert all(a > b for a, b in zip(scores, scores[1:]))  # each view helps
    # capture the first suggestion (noise-free corners keep the estimate, so the
    # linearisation the prediction used is the calibration's own)
    world_from_cam = got[0].cam_from_board.inverse()
    uv, vis = observe(cal.problem[cal.ids["camera"]].vec, world_from_cam, p, 0.0, rng)
    assert vis.all()
    after = _calibrate(z + [uv], p)
    G = image_grid_jacobians(cal.problem[cal.ids["camera"]].vec, "opencv5", (640, 480), 0.6, (16, 12))
    actual = worst_projection_sigma(G, np.asarray(after.problem.covariance(after.ids["camera"])))
    assert actual == pytest.approx(got[0].score_after, rel=0.05)
    # and the suggestion beats a random view by far
    rnd = random_views(1, rng, p.mean(axis=0))[0]
    after_random = _calibrate(z + [observe(K, rnd, p, SIGMA, rng)[0]], p)
    random_score = worst_projection_sigma(
        G, np.asarray(after_random.problem.covariance(after_random.ids["camera"])))
    assert got[0].score_after < 0.5 * random_score
    csv = suggestions_csv(got).splitlines()
    assert len(csv) == 4 and csv[1].startswith("camera,1,")


def test_suggestions_refuse_fixed_intrinsics_and_plot(tmp_path):
    pytest.importorskip("matplotlib")
    from boxplus.calib.plot import plot_suggestions

    rng = np.random.default_rng(1)
    p = board_points()
    z = [observe(K, v, p, SIGMA, rng)[0] for v in random_views(6, rng, p.mean(axis=0))]
    cal = _calibrate(z, p)
    got = suggest_views(cal, n=2)
    plot_suggestions(cal, got, "camera", path=tmp_path / "s.png")
    assert (tmp_path / "s.png").stat().st_size > 1000
    cal.problem.fix(cal.ids["camera"])
    with pytest.raises(ValueError, match="held fixed"):
        suggest_views(cal)
    with pytest.raises(ValueError, match="no camera 'nope'"):
        suggest_views(cal, "nope")


def test_hand_eye_robot_poses_ranked_by_the_sigma_they_leave():
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[2] / "examples" / "hand_eye_calibration.py"
    spec = importlib.util.spec_from_file_location("hand_eye_calibration", path)
    ex = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(ex)
    rng = np.random.default_rng(7)
    data = ex.simulate(rng, pixel_sigma=0.5, n=4)
    o, ids, _ = ex.calibrate(data)
    candidates = ex.robot_pose_candidates(o, ids, rng, n=20)
    ranked = ex.suggest_robot_poses(o, ids, data, candidates)
    assert sorted(i for i, _ in ranked) == list(range(20))
    assert ranked[0][1] < 0.8 * ranked[-1][1]

    def sigma_after(G):
        # the robot goes to G; the camera truly sees the board from Z⁻¹ G X
        board_from_cam = ex.TRUTH["base_from_board"].inverse() * G * ex.TRUTH["gripper_from_cam"]
        d = {**data, "z": data["z"] + [ex.observe(ex.TRUE_K, board_from_cam, data["p"], 0.5, rng)[0]],
             "G": data["G"] + [ex.perturb(G, 1e-4, 2e-4, rng)]}
        o2, ids2, _ = ex.calibrate(d)
        return float(np.max(o2.std(ids2["cam_from_gripper"])))

    best, worst = sigma_after(candidates[ranked[0][0]]), sigma_after(candidates[ranked[-1][0]])
    assert best == pytest.approx(ranked[0][1], rel=0.3)  # the prediction holds on the truth
    assert best < worst
