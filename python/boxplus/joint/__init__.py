"""Joint calibration of whole systems of sensors (Le & Ng, IROS 2009).

* :class:`JointRig` (:mod:`~boxplus.joint.rig`): systems as C++ autodiff terms —
  :class:`DHArm` (standard/modified DH, unknown subsets with priors, encoder
  noise, known or unknown mount), :class:`Stereo` (reprojection in both images),
  :class:`LightSheet` and :class:`Beam` (laser triangulation),
  :class:`RangeSensor`, :class:`Camera` (reprojection of any system's points);
  links, distances, planes and lines across systems, each with its full Σ; any
  other measurement goes on ``rig.problem`` (an :class:`~boxplus.OptimizationProblem`)
  beside them;
* :mod:`~boxplus.joint.constraints`: :data:`Plane` and :data:`Line` and their fits;
* :func:`horn`; :func:`solve_with_restarts`, :func:`cross_validate` and :func:`kfold`
  (tools of any problem, :mod:`boxplus.restarts` and :mod:`boxplus.crossval`);
* :mod:`~boxplus.synthetic.joint_rigs`: a seeded rig like Le & Ng's Sec. VIII robot;
  :mod:`~boxplus.joint.geometry`: NumPy twins of the C++ terms.

SE(3) = R³ × SO(3), tangent [translation, rotation]; poses map local to
parent coordinates (``b_from_a.fromlocal(p_in_a) = p_in_b``).
"""

from boxplus.crossval import CrossValidation, cross_validate, kfold
from boxplus.joint.constraints import Line, Plane, fit_line, fit_plane
from boxplus.joint.horn import horn
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
from boxplus.restarts import RestartResult, default_perturbation, solve_with_restarts

__all__ = [
    "Beam", "Camera", "CrossValidation", "DHArm", "JointRig", "LightSheet", "Line", "Plane", "PointRef",
    "RangeSensor", "RestartResult", "RigResult", "Stereo", "SurfaceRef", "cross_validate",
    "default_perturbation", "dh_labels", "fit_line", "fit_plane", "horn", "kfold", "solve_with_restarts",
]
