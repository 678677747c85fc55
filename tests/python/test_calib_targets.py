"""Chessboard, ChArUco and AprilTag-grid targets: rendered, seen through a
homography, detected at the projected points (within 0.3 px), partial views
kept, and the target descriptions parsed or refused."""

import numpy as np
import pytest
from boxplus.calib.targets import Target, parse_target

cv2 = pytest.importorskip("cv2")

PPU = 2000.0  # pixels per board unit in the rendered target (whole pixels per square)
MARGIN = 30


def _view(target, H_cam):
    """The target rendered, then warped by H_cam into a 640×480 image; returns the
    image and the map from board points to its pixels."""
    img = target.image(PPU, MARGIN)
    o = target.image_origin(PPU, MARGIN)
    A = np.array([[PPU, 0, o[0]], [0, PPU, o[1]], [0, 0, 1.0]])
    warped = cv2.warpPerspective(img, H_cam, (640, 480), flags=cv2.INTER_AREA, borderValue=255)

    def to_pixels(p):
        q = (H_cam @ A @ np.column_stack([p[:, :2], np.ones(len(p))]).T).T
        return q[:, :2] / q[:, 2:]

    return warped, to_pixels


def _H(scale, tilt, shift):
    H = np.array([[scale, 0.02, shift[0]], [-0.03, scale * 0.95, shift[1]], [tilt, -tilt / 2, 1.0]])
    return H


@pytest.mark.parametrize("spec", ["chessboard:9x6:0.02", "charuco:7x5:0.03:0.022",
                                  "aprilgrid:5x4:0.025:0.3"])
def test_detection_at_the_projected_points(spec):
    t = parse_target(spec)
    img, to_pixels = _view(t, _H(0.95, 2e-4, (60, 40)))
    det = t.detect(img)
    assert det is not None
    z, obj = det
    assert len(z) == len(t.points()) and obj.shape == (len(z), 3)
    err = np.linalg.norm(z - to_pixels(obj), axis=1)
    # AprilTag corners are refined less tightly than chessboard saddles
    assert err.max() < (0.5 if t.kind == "aprilgrid" else 0.3), err.max()
    assert err.mean() < 0.3, err.mean()
    assert np.abs((z - to_pixels(obj)).mean(axis=0)).max() < 0.1  # no bias
    # every detected point is a point of the target
    P = t.points()
    assert all(np.min(np.linalg.norm(P - o, axis=1)) < 1e-12 for o in obj)


@pytest.mark.parametrize("spec", ["charuco:7x5:0.03:0.022", "aprilgrid:5x4:0.025:0.3"])
def test_partial_views_are_kept(spec):
    t = parse_target(spec)
    img, to_pixels = _view(t, _H(0.95, 2e-4, (60, 40)))
    img[:, 330:] = 255  # the right part of the target is hidden
    z, obj = t.detect(img)
    assert 4 <= len(z) < len(t.points())
    assert np.linalg.norm(z - to_pixels(obj), axis=1).max() < 0.5


def test_chessboard_order_is_black_first():
    """Seen upside down, the chessboard's corners still come first from the end
    whose outer square is black (a rig's cameras agree on the order)."""
    t = parse_target("chessboard:9x6:0.02")
    H = _H(0.95, 2e-4, (60, 40))
    flip = np.array([[-1, 0, 639.0], [0, -1, 479.0], [0, 0, 1]])  # a 180° turn of the image
    for M in (H, flip @ H):
        img, to_pixels = _view(t, M)
        z, obj = t.detect(img)
        assert np.linalg.norm(z - to_pixels(obj), axis=1).max() < 0.3


def test_no_target_and_bad_descriptions():
    blank = np.full((480, 640), 255, np.uint8)
    for spec in ["chessboard:9x6:1", "charuco:5x5:1:0.7", "aprilgrid:4x4:1:0.3"]:
        assert parse_target(spec).detect(blank) is None
    with pytest.raises(ValueError, match="expected chessboard:COLSxROWS:SQUARE"):
        parse_target("chessboard:9x6")
    with pytest.raises(ValueError, match="COLSxROWS must be two integers"):
        parse_target("chessboard:9by6:1")
    with pytest.raises(ValueError, match="marker size must be in"):
        parse_target("charuco:5x5:1:2")
    with pytest.raises(ValueError, match="unknown ArUco dictionary 'DICT_NOPE'"):
        parse_target("charuco:5x5:1:0.5:DICT_NOPE").points()
    assert Target("chessboard", 9, 6, 0.5).points().shape == (54, 3)


@pytest.mark.parametrize("spec", ["charuco:9x7:0.03:0.022", "aprilgrid:6x5:0.03:0.25"])
def test_calibration_from_rendered_views(spec):
    """A pinhole camera (K known) looks at the rendered target from 10 poses, some
    with part of the board outside the image; detection and calibrate_rig find K."""
    from boxplus.calib import calibrate_rig
    from boxplus.synthetic.cameras import random_views

    t = parse_target(spec)
    K = np.array([[520.0, 0, 318.0], [0, 515.0, 243.0], [0, 0, 1]])
    o = t.image_origin(PPU, MARGIN)
    A = np.array([[PPU, 0, o[0]], [0, PPU, o[1]], [0, 0, 1.0]])
    rng = np.random.default_rng(5)
    P = t.points()
    dets, partial = [], 0
    for world_from_cam in random_views(10, rng, P.mean(axis=0), distance=0.33, spread=0.45):
        cam_from_board = world_from_cam.inverse()
        R, tr = cam_from_board.rot.R, cam_from_board.pos
        H = K @ np.column_stack([R[:, 0], R[:, 1], tr]) @ np.linalg.inv(A)
        img, _ = _view(t, H / H[2, 2])
        det = t.detect(img)
        assert det is not None
        partial += len(det[0]) < len(P)
        dets.append(det)
    assert partial >= 1
    cal = calibrate_rig({"cam": dets}, (640, 480), "pinhole")
    k = cal.problem[cal.ids["cam"]].vec
    assert np.all(np.abs(k - [520.0, 515.0, 318.0, 243.0]) < [3.0, 3.0, 2.0, 2.0]), k
    # AprilTag corners come from the marker edges, less precise than saddle points
    assert cal.rms() < (0.5 if t.kind == "aprilgrid" else 0.3), cal.rms()
