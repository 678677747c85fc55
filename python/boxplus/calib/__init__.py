"""Multi-sensor calibration toolkit.

* :mod:`~boxplus.calib.init` — closed-form initial values (Zhang, PnP, stereo,
  gravity rotation, hand-eye);
* :mod:`~boxplus.calib.models` — every camera model (pinhole family,
  rational, Kannala–Brandt, double sphere) in numpy: projection, rays, OpenCV layout;
* :mod:`~boxplus.calib.rig` — cameras as variables, mono, stereo and N-camera
  rig calibration on the C++ board factor (with outlier rejection), corner
  detection (OpenCV, optional);
* :mod:`~boxplus.calib.io` — OpenCV, ROS camera_info and Kalibr camchain YAML;
* :mod:`~boxplus.calib.targets` — chessboard, ChArUco and AprilTag-grid targets (OpenCV);
* :mod:`~boxplus.calib.uncertainty` — projection σ over the image, coverage;
* :mod:`~boxplus.calib.cli` — the ``boxplus-calib`` command line;
* :mod:`~boxplus.calib.report` — RMS per group, σ of every parameter, and the
  parameters the data cannot determine;
* :mod:`~boxplus.calib.plot` — reprojection errors, coverage, projection
  uncertainty and the rig in 3-D (matplotlib Figures, PNG).

* :mod:`~boxplus.calib.factors` — the C++ sensor factors as functions of an
  :class:`boxplus.OptimizationProblem` (``add_projection(o, ...)``,
  ``add_board``, ``add_marker``, ``add_dh_marker``, ``add_gravity``,
  ``add_disparity``); the generic ones (``add_prior``, ``add_relative_pose``,
  ``add_point``) are methods of the problem.

Frames are named ``b_from_a`` (maps a-coordinates to b), points ``p_in_b``.
"""

from boxplus.calib.factors import (
    add_board,
    add_dh_marker,
    add_disparity,
    add_gravity,
    add_marker,
    add_projection,
)
from boxplus.calib.init import (
    CAMERA_LABELS,
    board_pose,
    camera_matrix,
    check_views,
    hand_eye_park,
    intrinsics_vector,
    marker_hand_eye,
    mean_pose,
    relative_pose_init,
    robot_world_hand_eye,
    rotation_between,
    triangulate,
)
from boxplus.calib.io import (
    CalibratedCamera,
    read_camchain,
    read_camera_info,
    read_opencv_yaml,
    to_opencv,
    write_camchain,
    write_camera_info,
    write_opencv_yaml,
)
from boxplus.calib.report import CalibrationReport, report
from boxplus.calib.rig import (
    Calibration,
    DroppedCorner,
    add_camera,
    calibrate_mono,
    calibrate_rig,
    calibrate_stereo,
    detect_corners,
)
from boxplus.calib.targets import Target, parse_target
from boxplus.calib.uncertainty import coverage, projection_sigma, projection_uncertainty
from boxplus.calib.zhang import (
    homography,
    init_camera,
    intrinsics_from_homographies,
    pose_from_homography,
)

__all__ = [
    "CAMERA_LABELS", "Calibration", "CalibrationReport", "add_camera", "board_pose",
    "calibrate_mono", "calibrate_stereo", "camera_matrix", "check_views", "detect_corners",
    "hand_eye_park", "homography", "init_camera", "intrinsics_from_homographies",
    "intrinsics_vector", "mean_pose", "pose_from_homography", "relative_pose_init", "report",
    "marker_hand_eye", "robot_world_hand_eye", "rotation_between", "triangulate",
    "CalibratedCamera", "DroppedCorner", "calibrate_rig", "read_camchain", "read_camera_info",
    "read_opencv_yaml", "to_opencv", "write_camchain", "write_camera_info", "write_opencv_yaml",
    "Target", "coverage", "parse_target", "projection_sigma", "projection_uncertainty",
    "add_board", "add_dh_marker", "add_disparity", "add_gravity", "add_marker", "add_projection",
]
