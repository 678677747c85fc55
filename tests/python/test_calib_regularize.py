"""Distortion regularisation (boxplus.calib.regularize) and the lens difference it is
scored with (boxplus.calib.lens_diff): a prior on some coordinates of an Rn, the
projection difference's alignment, and a rational fit that folds over without the
prior and lands within half a pixel of the true lens with it."""

import warnings
from pathlib import Path

import numpy as np
import pytest
from boxplus import SO3, OptimizationProblem, Rn
from boxplus.calib import calibrate_mono, calibrate_rig
from boxplus.calib.cli import _parser
from boxplus.calib.fold import LensFoldWarning, observed_field
from boxplus.calib.lens_diff import projection_difference
from boxplus.calib.models import project
from boxplus.calib.regularize import DEFAULT_PRIOR_SIGMA, distortion_powers
from boxplus.calib.summary import summarise
from boxplus.calib.targets import Target
from boxplus.synthetic.images import board_views

SIZE = (640, 480)
DATA = Path(__file__).resolve().parents[2] / "data" / "calib" / "opencv_stereo_corners.npz"
RATIONAL = np.array([500.0, 505.0, 320.0, 240.0, -0.25, 0.08, 0.001, -0.0015, -0.01, 0.02, 0.01, 0.005])
OPENCV5 = np.array([500.0, 505.0, 320.0, 240.0, -0.25, 0.08, 0.001, -0.0015, -0.01])


def _capture(k, model, seed, n=20, sigma=0.3):
    """bench/bench_lens_regularisation.py's capture: n views of a 9×6 chessboard."""
    target = Target("chessboard", 9, 6, 0.04)
    rng = np.random.default_rng(seed)
    obj = target.points()
    poses = board_views(target, model, k, SIZE, n, rng, max_tilt_deg=45.0, fill=0.9)
    return obj, [project(k, p.fromlocal(obj), model) + rng.normal(0, sigma, (len(obj), 2)) for p in poses]


def test_prior_on_some_coordinates_is_the_closed_form():
    o = OptimizationProblem()
    v = o.add_random_var(Rn(np.array([1.0, 2.0, 3.0])), labels=["a", "b", "c"])
    o.add_prior(v, Rn(np.zeros(2)), sigma=[0.1, 1.0], coordinates=["c", "a"])
    o.add_prior(v, Rn(np.full(3, 5.0)), sigma=100.0)
    o.solve()
    # per coordinate the precision-weighted mean of the two priors; b has only the wide one
    a = 5.0 / 100.0**2 / (1 / 1.0 + 1 / 100.0**2)
    c = 5.0 / 100.0**2 / (1 / 0.1**2 + 1 / 100.0**2)
    std = np.array([1 / np.sqrt(1 + 1e-4), 100.0, 1 / np.sqrt(100 + 1e-4)])
    assert np.allclose(o.std(v), std, rtol=1e-9)
    assert np.all(np.abs(o[v].vec - [a, 5.0, c]) < 1e-6 * std)  # to the solver's tolerance
    with pytest.raises(ValueError, match="no coordinate 'd'"):
        o.add_prior(v, Rn(np.zeros(1)), sigma=1.0, coordinates=["d"])
    with pytest.raises(ValueError, match="given twice"):
        o.add_prior(v, Rn(np.zeros(2)), sigma=1.0, coordinates=[0, 0])
    w = o.add_random_var(SO3())
    with pytest.raises(TypeError, match="needs an Rn variable"):
        o.add_prior(w, Rn(np.zeros(1)), sigma=1.0, coordinates=[0])


def test_projection_difference_aligns_the_camera_frames():
    k = OPENCV5.copy()
    assert projection_difference(k, "opencv5", k, "opencv5", SIZE).max < 1e-6
    # a principal point moved by f·tan(0.01) is, near the axis, the pinhole turned by 0.01
    # rad about y (away from it the two differ by perspective, which no rotation removes)
    pin = np.array([500.0, 500.0, 320.0, 240.0])
    moved = pin.copy()
    moved[2] += 500.0 * np.tan(0.01)
    near = np.radians(10)
    unaligned = projection_difference(moved, "pinhole", pin, "pinhole", SIZE, theta_max=near, align=False)
    aligned = projection_difference(moved, "pinhole", pin, "pinhole", SIZE, theta_max=near)
    assert unaligned.rms == pytest.approx(5.0, rel=0.01)
    assert aligned.max < 0.2 and np.allclose(aligned.a_from_b.log(), [0, -0.01, 0], atol=2e-4)
    whole = projection_difference(moved, "pinhole", pin, "pinhole", SIZE)
    assert whole.rms < 0.2 * projection_difference(moved, "pinhole", pin, "pinhole", SIZE, align=False).rms
    # a different lens is not aligned away, and theta_max keeps the central pixels only
    other = k.copy()
    other[4] = -0.2
    d = projection_difference(other, "opencv5", k, "opencv5", SIZE)
    centre = projection_difference(other, "opencv5", k, "opencv5", SIZE, theta_max=np.radians(15))
    assert d.max > 5.0 and len(centre.pixels) < len(d.pixels) and np.all(centre.theta <= np.radians(15))
    with pytest.raises(ValueError, match="no pixel"):
        projection_difference(k, "opencv5", k, "opencv5", SIZE, theta_max=-1.0)


def test_a_rational_fit_that_folds_over_lands_on_the_lens_with_the_prior():
    # seed 1008 of the bench's "rational mild" family: without the prior the fit folds
    # over inside the field and is 20 px off the true lens there
    obj, z = _capture(RATIONAL, "rational", 1008)
    with pytest.warns(LensFoldWarning, match="regularize=True"):
        free = calibrate_mono(z, obj, SIZE, model="rational", sigma=0.3, regularize=False)
    with warnings.catch_warnings():
        warnings.simplefilter("error", LensFoldWarning)
        cal = calibrate_mono(z, obj, SIZE, model="rational", sigma=0.3)  # regularised by default
    assert free.priors == [] and len(cal.priors) == 1
    prior = cal.priors[0]
    assert prior.labels == list(distortion_powers("rational")) and prior.sigma == DEFAULT_PRIOR_SIGMA
    field = observed_field(cal, "camera")
    d_free = projection_difference(free.problem[free.ids["camera"]].vec, "rational", RATIONAL, "rational",
                                   SIZE, theta_max=field)
    d_reg = projection_difference(cal.problem[cal.ids["camera"]].vec, "rational", RATIONAL, "rational",
                                  SIZE, theta_max=field)
    assert d_free.max > 10.0
    assert d_reg.max < 0.6 and d_reg.rms < 0.25
    # the prior costs the corners almost nothing: the RMS rises by < 0.5 %
    assert free.rms() <= cal.rms() < 1.005 * free.rms()
    # it is reported, in the text and the JSON form
    assert "distortion regularised" in summarise(cal, cal.report())
    assert cal.todict()["distortion_priors"][0]["terms"] == prior.labels


def test_real_images_regularised_rational_is_the_opencv5_lens():
    """OpenCV's left sample images: the free rational fit wanders along its valley
    (k2 ≈ 20, k5 ≈ 18), the regularised one lands on the lens the 5-term model
    finds, at an RMS 0.7 % above the free fit's."""
    with np.load(DATA) as f:
        d = {k: f[k] for k in f.files}
    obj, pts = d["object_points"], list(d["image_points_left"])
    size = tuple(int(s) for s in d["image_size"])
    free = calibrate_mono(pts, obj, size, "rational", name="left", regularize=False)
    reg = calibrate_mono(pts, obj, size, "rational", name="left")
    five = calibrate_mono(pts, obj, size, "opencv5", name="left")
    assert np.abs(free.problem[free.ids["left"]].vec[4:]).max() > 10
    assert np.abs(reg.problem[reg.ids["left"]].vec[4:]).max() < 1
    field = observed_field(five, "left")
    k5 = five.problem[five.ids["left"]].vec
    d_reg = projection_difference(reg.problem[reg.ids["left"]].vec, "rational", k5, "opencv5", size, field)
    d_free = projection_difference(free.problem[free.ids["left"]].vec, "rational", k5, "opencv5", size, field)
    assert d_reg.max < 0.05 < d_free.max
    assert free.rms() < reg.rms() < 1.01 * free.rms()


def test_which_cameras_are_regularised():
    obj, z = _capture(OPENCV5, "opencv5", 3, n=12)
    assert calibrate_mono(z, obj, SIZE).priors == []  # opencv5: OpenCV's problem by default
    cal = calibrate_mono(z, obj, SIZE, regularize=0.2)
    assert [p.sigma for p in cal.priors] == [0.2] and cal.priors[0].labels == ["k1", "k2", "p1", "p2", "k3"]
    with warnings.catch_warnings():  # a double sphere on a narrow lens: fx, ξ barely determined
        warnings.simplefilter("ignore")
        ds = calibrate_mono(z, obj, SIZE, model="double_sphere", regularize=True)
    assert ds.priors == []
    # its parameters' σ is not to be trusted, the projection's is: the report says so
    text = summarise(ds, ds.report())
    assert "curved valley" in text and "cal.profile('camera', 'alpha')" in text
    rig = calibrate_rig({"a": [(p, obj) for p in z], "b": [(p, obj) for p in z]}, SIZE,
                        {"a": "rational", "b": "opencv5"}, known_intrinsics={"b": OPENCV5})
    assert [p.camera for p in rig.priors] == ["a"]  # b is held fixed, and opencv5
    with pytest.raises(ValueError, match="width s > 0"):
        calibrate_mono(z, obj, SIZE, regularize=-1.0)


def test_command_line_flags():
    ap = _parser()
    base = ["--target", "chessboard:9x6:0.04", "imgs"]
    assert ap.parse_args(base).regularize is None
    assert ap.parse_args([*base, "--regularize"]).regularize is True
    assert ap.parse_args([*base, "--regularize", "0.2"]).regularize == 0.2
    assert ap.parse_args([*base, "--no-regularize"]).regularize is False
