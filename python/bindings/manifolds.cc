// Bindings of the ceres::Manifold objects that define ⊞/⊟ for the solver:
// built-in kinds, run-time compounds, and batched ⊞/⊟ over rows of arrays.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "boxplus/manifolds.h"
#include "manifold_handle.h"

namespace py = pybind11;

namespace boxplus::python {
namespace {

using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

void CheckSize(const Eigen::Ref<const Eigen::VectorXd>& v, int n, const char* what) {
  if (v.size() != n) {
    throw py::value_error(std::string(what) + " must have " + std::to_string(n) + " entries, got " +
                          std::to_string(v.size()));
  }
}

}  // namespace

void RegisterManifolds(py::module_& m) {
  py::class_<ManifoldHandle>(m, "Manifold", R"doc(
A manifold as the solver sees it: ambient (storage) coordinates and ⊞/⊟.

Jacobians are those Ceres defines: ``plus_jacobian(x)`` is d(x ⊞ δ)/dδ at
δ = 0 (ambient × tangent), ``minus_jacobian(x)`` is d(y ⊟ x)/dy at y = x
(tangent × ambient).
)doc")
      .def_property_readonly("kind", [](const ManifoldHandle& h) { return h.kind; })
      .def_property_readonly("ambient_size",
                             [](const ManifoldHandle& h) { return h.manifold->AmbientSize(); })
      .def_property_readonly("tangent_size",
                             [](const ManifoldHandle& h) { return h.manifold->TangentSize(); })
      .def(
          "plus",
          [](const ManifoldHandle& h, const Eigen::VectorXd& x, const Eigen::VectorXd& d) {
            CheckSize(x, h.manifold->AmbientSize(), "x");
            CheckSize(d, h.manifold->TangentSize(), "delta");
            Eigen::VectorXd out(h.manifold->AmbientSize());
            h.manifold->Plus(x.data(), d.data(), out.data());
            return out;
          },
          py::arg("x"), py::arg("delta"), "x ⊞ δ in ambient coordinates.")
      .def(
          "minus",
          [](const ManifoldHandle& h, const Eigen::VectorXd& y, const Eigen::VectorXd& x) {
            CheckSize(y, h.manifold->AmbientSize(), "y");
            CheckSize(x, h.manifold->AmbientSize(), "x");
            Eigen::VectorXd out(h.manifold->TangentSize());
            h.manifold->Minus(y.data(), x.data(), out.data());
            return out;
          },
          py::arg("y"), py::arg("x"), "y ⊟ x in ambient coordinates.")
      .def(
          "plus_batch",
          [](const ManifoldHandle& h, const RowMatrix& X, const RowMatrix& D) {
            const int a = h.manifold->AmbientSize(), t = h.manifold->TangentSize();
            if (X.cols() != a || D.cols() != t || X.rows() != D.rows()) {
              throw py::value_error("plus_batch: expected X (N, " + std::to_string(a) +
                                    ") and D (N, " + std::to_string(t) + ")");
            }
            RowMatrix out(X.rows(), a);
            for (Eigen::Index i = 0; i < X.rows(); ++i) {
              h.manifold->Plus(X.row(i).data(), D.row(i).data(), out.row(i).data());
            }
            return out;
          },
          py::arg("X"), py::arg("D"), "Row-wise x ⊞ δ over (N, ambient) and (N, tangent).")
      .def(
          "minus_batch",
          [](const ManifoldHandle& h, const RowMatrix& Y, const RowMatrix& X) {
            const int a = h.manifold->AmbientSize(), t = h.manifold->TangentSize();
            if (X.cols() != a || Y.cols() != a || X.rows() != Y.rows()) {
              throw py::value_error("minus_batch: expected Y and X of shape (N, " +
                                    std::to_string(a) + ")");
            }
            RowMatrix out(X.rows(), t);
            for (Eigen::Index i = 0; i < X.rows(); ++i) {
              h.manifold->Minus(Y.row(i).data(), X.row(i).data(), out.row(i).data());
            }
            return out;
          },
          py::arg("Y"), py::arg("X"), "Row-wise y ⊟ x over (N, ambient) arrays.")
      .def(
          "plus_jacobian",
          [](const ManifoldHandle& h, const Eigen::VectorXd& x) {
            CheckSize(x, h.manifold->AmbientSize(), "x");
            RowMatrix J(h.manifold->AmbientSize(), h.manifold->TangentSize());
            h.manifold->PlusJacobian(x.data(), J.data());
            return J;
          },
          py::arg("x"))
      .def(
          "minus_jacobian",
          [](const ManifoldHandle& h, const Eigen::VectorXd& x) {
            CheckSize(x, h.manifold->AmbientSize(), "x");
            RowMatrix J(h.manifold->TangentSize(), h.manifold->AmbientSize());
            h.manifold->MinusJacobian(x.data(), J.data());
            return J;
          },
          py::arg("x"))
      .def("__repr__", [](const ManifoldHandle& h) {
        return "<boxplus.Manifold " + h.kind +
               " ambient=" + std::to_string(h.manifold->AmbientSize()) +
               " tangent=" + std::to_string(h.manifold->TangentSize()) + ">";
      });

  m.def(
      "make_manifold",
      [](const std::string& kind, int n) {
        return ManifoldHandle{MakeManifold(kind, n), kind};
      },
      py::arg("kind"), py::arg("n") = 0,
      "The manifold of a built-in kind: 'Rn' (with n), 'SO2', 'SO3', 'SE2', 'SE3', 'S2'.");
  m.def(
      "make_product_manifold",
      [](const std::vector<ManifoldHandle>& members) {
        std::vector<std::shared_ptr<const ceres::Manifold>> ms;
        for (const auto& h : members) ms.push_back(h.manifold);
        return ManifoldHandle{std::make_shared<ProductManifold>(ms), "Compound"};
      },
      py::arg("members"), "The Cartesian product of the given manifolds; ⊞/⊟ act member-wise.");
}

}  // namespace boxplus::python
