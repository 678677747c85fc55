// Bindings of the generic (pose-domain) factors, each a function returning a
// Factor for Problem.add_factor: a prior on any built-in manifold
// (factors/pose/prior.h), relative poses (compound ⊟ of R³ × SO(3),
// factors/pose/relative_pose.h) and a 3-D point seen by a sensor on a rig
// (factors/pose/observed_point.h). Frames as b_from_a (MTKM's a2b); tangent
// order [δp, δθ]. The noise is a boxplus.NoiseModel, registered with the
// measurement so that errors are un-whitened in C++.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "../bindings.h"
#include "../factor.h"
#include "boxplus/factors/pose/observed_point.h"
#include "boxplus/factors/pose/prior.h"
#include "boxplus/factors/pose/relative_pose.h"
#include "boxplus/noise.h"
#include "boxplus/problem.h"

namespace py = pybind11;

namespace boxplus::python {
namespace {

using Pose = Eigen::Matrix<double, 7, 1>;

void CheckDim(const NoiseModel& noise, int dim, const std::string& what) {
  BOXPLUS_CHECK(noise.dim() == dim, what, ": noise of dimension ", noise.dim(), ", expected ", dim);
}

}  // namespace

void RegisterPoseFactors(py::module_& m) {
  m.def(
      "prior_factor",
      [](const Problem& p, int id, const Eigen::VectorXd& z, const NoiseModel& noise,
         const std::string& what) {
        return Factor{MakePrior(p.manifold(id), z, noise, what), {id}, noise};
      },
      py::arg("problem"), py::arg("id"), py::arg("z"), py::arg("noise"), py::arg("what") = "prior",
      "r = W (x ⊟ z) on variable id of the problem (any built-in manifold); z in ambient "
      "coordinates; see factors/pose/prior.h.");
  m.def(
      "coordinate_prior_factor",
      [](const Problem& p, int id, const std::vector<int>& indices, const Eigen::VectorXd& z,
         const NoiseModel& noise, const std::string& what) {
        return Factor{MakeCoordinatePrior(p.manifold(id), indices, z, noise, what), {id}, noise};
      },
      py::arg("problem"), py::arg("id"), py::arg("indices"), py::arg("z"), py::arg("noise"),
      py::arg("what") = "prior",
      "r = W (x[indices] − z) on some coordinates of the Rn variable id; the others are "
      "left to the data; see factors/pose/prior.h.");
  m.def(
      "relative_pose_factor",
      [](int world_from_a, int world_from_b, const Eigen::VectorXd& a_from_b,
         const NoiseModel& noise, const std::string& what) {
        if (a_from_b.size() == 3) {  // SE2 [x, y, θ]
          CheckDim(noise, 3, what);
          return Factor{MakeRelativePose2D(a_from_b, noise, PoseErrorConvention::kCompound),
                        {world_from_a, world_from_b},
                        noise};
        }
        BOXPLUS_CHECK(a_from_b.size() == 7, what,
                      ": a_from_b must be an SE2 [x, y, θ] or SE3 [p, q] ambient vector, got ",
                      a_from_b.size(), " numbers");
        CheckDim(noise, 6, what);
        return Factor{MakeRelativePose3D(Pose(a_from_b), noise, PoseErrorConvention::kCompound),
                      {world_from_a, world_from_b},
                      noise};
      },
      py::arg("world_from_a"), py::arg("world_from_b"), py::arg("a_from_b"), py::arg("noise"),
      py::arg("what") = "relative pose",
      "r = W ((world_from_a⁻¹ ∘ world_from_b) ⊟ a_from_b) on SE2 (3-dim noise) or SE3 (6-dim), "
      "tangent [δp, δθ]; "
      "see factors/pose/relative_pose.h.");
  m.def(
      "landmark_2d_factor",
      [](int world_from_pose, int p_in_world, const Eigen::Vector2d& z, const NoiseModel& noise,
         const std::string& what) {
        CheckDim(noise, 2, what);
        return Factor{MakeObservedPoint2D(z, noise), {world_from_pose, p_in_world}, noise};
      },
      py::arg("world_from_pose"), py::arg("p_in_world"), py::arg("z"), py::arg("noise"),
      py::arg("what") = "point",
      "A 2-D landmark (Rn(2) variable) seen from an SE2 pose: r = W (x⁻¹ · l − z); 2-dim noise; "
      "see factors/pose/observed_point.h.");
  m.def(
      "point_factor",
      [](int world_from_rig, int cam_from_rig, int p_in_world_id, const Eigen::Vector3d& z,
         const NoiseModel& noise, const Eigen::Vector3d& p_in_world, const std::string& what) {
        CheckDim(noise, 3, what);
        if (p_in_world_id >= 0) {
          return Factor{MakeObservedLandmarkOnRig(z, noise),
                        {world_from_rig, cam_from_rig, p_in_world_id},
                        noise};
        }
        return Factor{
            MakeObservedPointOnRig(z, noise, p_in_world), {world_from_rig, cam_from_rig}, noise};
      },
      py::arg("world_from_rig"), py::arg("cam_from_rig"), py::arg("p_in_world_id"), py::arg("z"),
      py::arg("noise"), py::arg("p_in_world"), py::arg("what") = "point",
      "3-D point in the camera: r = W (cam_from_rig ∘ world_from_rig⁻¹ ∘ p_in_world − z); "
      "p_in_world_id < 0 uses the constant p_in_world; 3-dim noise; see "
      "factors/pose/observed_point.h.");
}

}  // namespace boxplus::python
