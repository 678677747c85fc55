// Bindings of the built-in C++ factors (autodiff functors): pinhole projection.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "boxplus/factors/pinhole.h"
#include "boxplus/problem.h"
#include "manifold_handle.h"

namespace py = pybind11;

namespace boxplus::python {

void RegisterFactors(py::module_& m) {
  m.def("camera_model_size", &CameraModelSize, py::arg("model"),
        "Number of intrinsic parameters of a camera model.");
  py::class_<Problem> problem = py::reinterpret_borrow<py::class_<Problem>>(m.attr("Problem"));
  problem.def(
      "add_pinhole_point",
      [](Problem& p, const std::string& model, int intrinsics, int x2world, int x2cam,
         const Eigen::Vector2d& z, const Eigen::Matrix2d& sqrt_info, const Eigen::Vector3d& p_world,
         const std::string& name, const LossHandle* loss) {
        return p.AddMeasurement(MakePinholePointFactor(model, z, sqrt_info, p_world),
                                {intrinsics, x2world, x2cam}, loss ? loss->loss : nullptr, name);
      },
      py::arg("model"), py::arg("intrinsics"), py::arg("x2world"), py::arg("x2cam"), py::arg("z"),
      py::arg("sqrt_info"), py::arg("p_world"), py::arg("name") = "", py::arg("loss") = nullptr,
      "Pinhole projection r = W (π(k, x2cam ∘ x2world⁻¹ ∘ p_world) − z); see factors/pinhole.h.");
}

}  // namespace boxplus::python
