"""Graph SLAM: g2o/TORO pose graphs on boxplus.

>>> import boxplus.slam as slam
>>> graph = slam.load_g2o("parking-garage.g2o")      # read and built in C++
>>> before = graph.positions()
>>> summary = graph.solve(method="lm")
>>> graph.save_g2o("parking-garage-opt.g2o")          # ids and order kept
>>> slam.plot_trajectory(graph, "trajectory.png", before=before)

Poses: SE2 ambient ``[x, y, θ]``; SE3 ambient ``[px, py, pz, qx, qy, qz, qw]``
with tangent ``[δp, δθ]`` (translation first, ⊞ the compound R³ × SO(3)).
Relative-pose errors (see ``cpp/include/boxplus/factors/pose/relative_pose.h``),
with ``Δ = z⁻¹ (xᵢ⁻¹ xⱼ)``:

* ``convention="g2o"`` (default): ``e = [t(Δ), vec(q(Δ))]`` with ``w ≥ 0``,
  g2o's ``EdgeSE3``; 2D ``e = [t(Δ), θ(Δ)]`` (g2o and GTSAM alike);
* ``convention="log"``: ``e = [u, ω]`` from ``(ω, u) = Pose3::Logmap(Δ)``,
  GTSAM's ``BetweenFactor<Pose3>``;
* ``convention="compound"``: ``e = (xᵢ⁻¹ xⱼ) ⊟ z`` with the ⊟ of the compound
  manifold Rᵈ × SO(d), ``[t_ij − t_z, log(R_zᵀ R_ij)]`` (what
  ``Problem.add_relative_pose`` uses);
* ``convention="sesync"`` (alias ``"chordal"``): SE-Sync's objective (Rosen et
  al., IJRR 2019), residual ``[√τ (tⱼ − tᵢ − Rᵢt̃ᵢⱼ), √κ vec(Rⱼ − RᵢR̃ᵢⱼ)]``
  with isotropic precisions τ, κ from Ω as SE-Sync's ``read_g2o_file``
  computes them (``factors/pose/chordal_relative_pose.h``); its chi2 is SE-Sync's
  ``f`` (``chi2_sesync``). Its own residual kind, not an error of Δ: each edge
  registers the noise model ``W = diag(√τ I, √κ I)`` of that residual, so
  errors are the chordal differences in the poses' units.

The objective is ``chi2 = Σ eᵀΩe`` with the file's information matrices Ω
(twice Ceres' cost, twice GTSAM's ``graph.error``); ``Σ‖r‖²`` in the sesync
convention.
"""

from .plot import plot_trajectory
from .pose_graph import IMPLAUSIBLE_CHI2_PER_DOF, SOLVER_DEFAULTS, PoseGraph, load_g2o, save_g2o

__all__ = ["IMPLAUSIBLE_CHI2_PER_DOF", "SOLVER_DEFAULTS", "PoseGraph", "load_g2o", "save_g2o", "plot_trajectory"]
