"""Joint calibration of whole systems of sensors (Le & Ng, IROS 2009).

* :mod:`~boxplus.joint.systems`: 3D systems p = I(α, u) — :class:`StereoPair`,
  :class:`ActiveTriangulation`, :class:`RobotArm`, :class:`RangeFinder`; new
  kinds subclass :class:`ThreeDSystem`;
* :mod:`~boxplus.joint.constraints`: distance preservation, coplanarity and
  collinearity with :data:`Plane` and :data:`Line` estimated jointly;
* :class:`JointCalibration`: any graph of systems and links, one objective
  Σ Intr + γ Σ Extr, connectivity checks, Horn initialisation;
* :func:`horn`, :func:`solve_with_restarts`, :func:`cross_validate`,
  :func:`calibrate_incrementally`;
* :class:`JointRig` (:mod:`~boxplus.joint.rig`): the built-in systems as C++
  autodiff terms — :class:`DHArm` (standard/modified DH, unknown subsets with
  priors, encoder noise, known or unknown mount), :class:`Stereo` (reprojection
  in both images), :class:`LightSheet` and :class:`Beam` (laser triangulation),
  :class:`RangeSensor`, :class:`Camera` (reprojection of any system's points);
  links, distances, planes and lines across systems, each with its full Σ;
* :mod:`~boxplus.joint.synthetic`: a seeded rig like Le & Ng's Sec. VIII robot;
  :mod:`~boxplus.joint.geometry`: NumPy twins of the C++ terms.

SE(3) = R³ × SO(3), tangent [translation, rotation]; poses map local to
parent coordinates (``b_from_a.fromlocal(p_in_a) = p_in_b``).
"""

from boxplus.joint.calibrator import JointCalibration, JointResult
from boxplus.joint.camera import CameraIntrinsics, project, ray
from boxplus.joint.constraints import Line, Plane, fit_line, fit_plane
from boxplus.joint.crossval import CrossValidation, cross_validate, kfold
from boxplus.joint.horn import horn
from boxplus.joint.incremental import EXTRINSICS, calibrate_incrementally
from boxplus.joint.restarts import RestartResult, default_perturbation, solve_with_restarts
from boxplus.joint.rig import (
    Beam,
    Camera,
    DHArm,
    JointRig,
    LightSheet,
    PointRef,
    RangeSensor,
    RigResult,
    Stereo,
    SurfaceRef,
    dh_labels,
)
from boxplus.joint.systems import (
    ActiveTriangulation,
    RangeFinder,
    RobotArm,
    StereoPair,
    ThreeDSystem,
    camera,
)

__all__ = [
    "Beam", "Camera", "DHArm", "JointRig", "LightSheet", "PointRef", "RangeSensor", "RigResult", "Stereo",
    "SurfaceRef", "dh_labels",
    "EXTRINSICS", "ActiveTriangulation", "CameraIntrinsics", "CrossValidation", "JointCalibration",
    "JointResult", "Line", "Plane", "RangeFinder", "RestartResult", "RobotArm", "StereoPair",
    "ThreeDSystem", "calibrate_incrementally", "camera", "cross_validate", "default_perturbation",
    "fit_line", "fit_plane", "horn", "kfold", "project", "ray", "solve_with_restarts",
]
