"""Mono and stereo calibration on OpenCV's stereo sample reach OpenCV's RMS
(within 0.005 px) and parameters (within boxplus' σ) for the same model."""

from pathlib import Path

import numpy as np
import pytest
from boxplus.calib import calibrate_mono, calibrate_stereo, intrinsics_vector

cv2 = pytest.importorskip("cv2")

DATA = Path(__file__).resolve().parents[2] / "data" / "calib" / "opencv_stereo_corners.npz"
FLAGS = {"opencv5": 0, "radial2": None, "radial1": None}


def _load():
    d = np.load(DATA)
    return (d["object_points"], list(d["image_points_left"]), list(d["image_points_right"]),
            tuple(int(s) for s in d["image_size"]))


def _cv_flags(model):
    return {
        "opencv5": 0,
        "radial2": cv2.CALIB_ZERO_TANGENT_DIST | cv2.CALIB_FIX_K3,
        "radial1": cv2.CALIB_ZERO_TANGENT_DIST | cv2.CALIB_FIX_K3 | cv2.CALIB_FIX_K2,
    }[model]


def _cv_mono(obj, pts, size, model):
    rms, K, dist, _, _ = cv2.calibrateCamera([obj.astype(np.float32)] * len(pts),
                                             [p.astype(np.float32) for p in pts], size, None, None,
                                             flags=_cv_flags(model))
    return rms, intrinsics_vector(K, model, dist.ravel())


@pytest.mark.parametrize("camera,model", [("left", "opencv5"), ("right", "opencv5"),
                                          ("left", "radial2"), ("right", "radial1")])
def test_mono_matches_opencv(camera, model):
    obj, L, R, size = _load()
    pts = L if camera == "left" else R
    cal = calibrate_mono(pts, obj, size, model, name=camera)
    rms_cv, k_cv = _cv_mono(obj, pts, size, model)
    assert abs(cal.rms() - rms_cv) < 0.005
    rep = cal.report()
    k = cal.problem[cal.ids[camera]].vec
    assert np.all(np.abs(k - k_cv) < rep.std(camera)), (k - k_cv) / rep.std(camera)
    assert not rep.undetermined


@pytest.mark.parametrize("fixed", [True, False])
def test_stereo_matches_opencv(fixed):
    obj, L, R, size = _load()
    o32 = [obj.astype(np.float32)] * len(L)
    l32, r32 = [p.astype(np.float32) for p in L], [p.astype(np.float32) for p in R]
    _, Kl, dl, _, _ = cv2.calibrateCamera(o32, l32, size, None, None)
    _, Kr, dr, _, _ = cv2.calibrateCamera(o32, r32, size, None, None)
    flags = cv2.CALIB_FIX_INTRINSIC if fixed else cv2.CALIB_USE_INTRINSIC_GUESS
    crit = (cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 200, 1e-10)
    rms_cv, Kl2, dl2, Kr2, dr2, Rcv, tcv, _, _ = cv2.stereoCalibrate(
        o32, l32, r32, Kl, dl, Kr, dr, size, flags=flags, criteria=crit)
    fixed_k = (intrinsics_vector(Kl, "opencv5", dl.ravel()), intrinsics_vector(Kr, "opencv5", dr.ravel()))
    cal = calibrate_stereo(L, R, obj, size, "opencv5", fixed_intrinsics=fixed_k if fixed else None)
    assert abs(cal.rms() - rms_cv) < 0.005
    rep = cal.report()
    right_from_left = cal.problem[cal.ids["right_from_left"]]
    s = rep.std("right_from_left")
    assert np.all(np.abs(right_from_left.pos - tcv.ravel()) < s[:3])
    dtheta = (cal.problem[cal.ids["right_from_left"]].rot.inverse() * __import__("boxplus").SO3(Rcv)).log()
    assert np.all(np.abs(dtheta) < s[3:])
    if not fixed:
        for name, K, d in [("left", Kl2, dl2), ("right", Kr2, dr2)]:
            k = cal.problem[cal.ids[name]].vec
            assert np.all(np.abs(k - intrinsics_vector(K, "opencv5", d.ravel())) < rep.std(name))


def test_bad_input_raises_clear_errors():
    obj, L, R, size = _load()
    with pytest.raises(ValueError, match="at least 3 are needed"):
        calibrate_mono(L[:2], obj, size)
    with pytest.raises(ValueError, match="view 1: the board was not detected"):
        calibrate_mono([L[0], None, L[2], L[3]], obj, size)
    with pytest.raises(ValueError, match="outside the 320×240 image"):
        calibrate_mono(L, obj, (320, 240))
    with pytest.raises(ValueError, match="54 board points"):
        calibrate_mono([L[0][:50]] + L[1:], obj, size)
    with pytest.raises(ValueError, match="not positive definite"):
        calibrate_mono(L, obj, size, covariance=np.array([[1.0, 2.0], [2.0, 1.0]]))
    with pytest.raises(ValueError, match="13 left and 12 right"):
        calibrate_stereo(L, R[:12], obj, size)


def test_results_convert_to_plain_json():
    import json

    obj, L, _, size = _load()
    cal = calibrate_mono(L, obj, size, "opencv5", name="left")
    d = json.loads(json.dumps(cal.todict()))
    assert d["cameras"]["left"]["model"] == "opencv5"
    assert np.allclose(d["cameras"]["left"]["K"], cal.camera("left")[0])
    assert np.allclose(d["variables"]["left"], cal.problem[cal.ids["left"]].vec)
    assert d["rms_px"] == cal.rms() and d["summary"]["termination"] == cal.result.termination
    rep = cal.report()
    r = json.loads(json.dumps(rep.todict()))
    assert np.allclose([p["std"] for p in r["parameters"] if p["variable"] == "left"], rep.std("left"))
    assert np.array(r["covariance"]).shape == rep.covariance.shape
    assert r["warnings"] == rep.warnings
