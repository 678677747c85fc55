// Bindings of the manifold value types: SO2, SO3, SE2, SE3, S2 and Rn.
//
// Every value supports ``x + delta`` (⊞, delta a vector of x.dof entries),
// ``y - x`` (⊟, same type on both sides), ``len(x) == x.dof``, ``x.ambient``
// (a copy of the storage vector), pickling, and ``manifold()``. Rotations and
// poses compose with ``a * b`` (apply b first, then a) and act on points with
// ``a * p`` for p of shape (d,) or (N, d); ``@`` is the same operator.
// Pose tangent order is [translation, rotation]; quaternions are [x, y, z, w].
#include <limits>

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/operators.h>

#include <sstream>

#include "bindings.h"
#include "boxplus/manifolds.h"
#include "manifold_handle.h"

namespace py = pybind11;

namespace boxplus::python {
namespace {

// The largest Rⁿ a measurement can use. Ceres indexes a measurement's block of
// the normal equations (tangent × tangent entries) with int, and
// Problem::AddMeasurement refuses more than 2³¹ − 1 entries, so a larger Rⁿ
// could never be measured: refused at construction, before n doubles are
// allocated. 46340² = 2147395600 ≤ 2³¹ − 1 < 46341².
constexpr long long LargestSquareRootOfIntMax() {
  long long n = 0;
  while ((n + 1) * (n + 1) <= std::numeric_limits<int>::max()) ++n;
  return n;
}
constexpr long long kRnMaxDimension = LargestSquareRootOfIntMax();
static_assert(kRnMaxDimension == 46340);

[[noreturn]] void RnTooLarge(const std::string& n) {
  throw py::value_error("Rn: dimension " + n + " is too large: at most " +
                        std::to_string(kRnMaxDimension) +
                        ", whose n x n block of the normal equations is the most Ceres can "
                        "index with int (2**31 - 1 entries)");
}

Eigen::VectorXd AsVector(const py::handle& obj, Eigen::Index n, const char* what) {
  py::array_t<double, py::array::c_style | py::array::forcecast> a;
  try {
    a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(obj);
  } catch (const py::error_already_set&) {
  }
  if (!a || a.size() != n || (a.ndim() > 1 && a.shape(0) != n)) {
    std::ostringstream msg;
    msg << what << ": expected a vector of " << n << " numbers, got "
        << std::string(py::str(py::repr(obj)));
    throw py::value_error(msg.str());
  }
  return Eigen::Map<const Eigen::VectorXd>(a.data(), n);
}

// obj as a C-ordered float array, or null (not convertible).
py::array_t<double, py::array::c_style | py::array::forcecast> AsArray(const py::handle& obj) {
  try {
    return py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(obj);
  } catch (const py::error_already_set&) {
    return {};
  }
}

// A square matrix of size n from a, which has that shape.
template <int N>
Eigen::Matrix<double, N, N> SquareMatrix(
    const py::array_t<double, py::array::c_style | py::array::forcecast>& a) {
  return Eigen::Map<const Eigen::Matrix<double, N, N, Eigen::RowMajor>>(a.data());
}

bool HasShape(const py::array_t<double, py::array::c_style | py::array::forcecast>& a,
              std::initializer_list<py::ssize_t> shape) {
  if (!a || a.ndim() != static_cast<py::ssize_t>(shape.size())) return false;
  py::ssize_t i = 0;
  for (py::ssize_t n : shape) {
    if (a.shape(i++) != n) return false;
  }
  return true;
}

std::string ShapeOf(const py::handle& obj) {
  const auto a = AsArray(obj);
  if (!a) return "a " + std::string(py::str(py::type::of(obj).attr("__name__")));
  std::string s = "shape (";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) s += (i ? ", " : "") + std::to_string(a.shape(i));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

// A rotation from an SO3, a 3×3 matrix or a quaternion [x, y, z, w].
SO3 RotationFrom(const py::handle& obj, const char* who) {
  if (py::isinstance<SO3>(obj)) return obj.cast<SO3>();
  const auto a = AsArray(obj);
  if (HasShape(a, {3, 3})) return SO3::FromMatrix(SquareMatrix<3>(a));
  if (HasShape(a, {4})) return SO3::FromQuaternion(Eigen::Map<const Eigen::Vector4d>(a.data()));
  throw py::type_error(std::string(who) +
                       ": a rotation is an SO3, a 3x3 matrix or a quaternion [x, y, z, w], got " +
                       ShapeOf(obj));
}

// p of shape (d,) → (d,); (N, d) → (N, d), each row mapped by f.
// A manifold value (anything with `ambient`) is refused: numpy would turn an
// SE2 into its ambient vector, and SE3 * SE2 would silently map it as a point.
template <int D, class F>
py::array_t<double> MapPoints(const py::object& points, F f, const char* who) {
  if (py::hasattr(points, "ambient") && !py::isinstance<py::array>(points)) {
    throw py::type_error(std::string(who) + ": expected points of shape (" + std::to_string(D) +
                         ",) or (N, " + std::to_string(D) + "), got a " +
                         std::string(py::str(py::type::of(points).attr("__name__"))) +
                         " (poses compose only with poses of their own kind)");
  }
  const auto p = AsArray(points);
  if (!p) {
    throw py::type_error(std::string(who) + ": expected an array of points, got a " +
                         std::string(py::str(py::type::of(points).attr("__name__"))));
  }
  if (p.ndim() == 1 && p.shape(0) == D) {
    Eigen::Matrix<double, D, 1> v(p.data());
    const Eigen::Matrix<double, D, 1> r = f(v);
    py::array_t<double> out(D);
    std::copy(r.data(), r.data() + D, out.mutable_data());
    return out;
  }
  if (p.ndim() == 2 && p.shape(1) == D) {
    const auto n = p.shape(0);
    py::array_t<double> out({n, static_cast<py::ssize_t>(D)});
    double* o = out.mutable_data();
    for (py::ssize_t i = 0; i < n; ++i) {
      Eigen::Matrix<double, D, 1> v(p.data() + i * D);
      const Eigen::Matrix<double, D, 1> r = f(v);
      std::copy(r.data(), r.data() + D, o + i * D);
    }
    return out;
  }
  throw py::value_error(std::string(who) + ": points must have shape (" + std::to_string(D) +
                        ",) or (N, " + std::to_string(D) + ")");
}

std::string Fmt(const Eigen::VectorXd& v) {
  std::ostringstream s;
  s.precision(6);
  s << "[";
  for (Eigen::Index i = 0; i < v.size(); ++i) s << (i ? ", " : "") << v[i];
  s << "]";
  return s.str();
}

// The storage vector of a value (Rn keeps no separate ambient).
template <class T>
Eigen::VectorXd AmbientOf(const T& x) {
  return Eigen::VectorXd(x.ambient());
}
Eigen::VectorXd AmbientOf(const Rn& x) { return x.vec(); }

// q and −q are one rotation: the sign is fixed so that the first non-zero of
// (w, x, y, z) is positive, which makes == and hash() agree for both signs.
void CanonicalQuaternion(double* q) {
  const double lead = q[3] != 0.0 ? q[3] : q[0] != 0.0 ? q[0] : q[1] != 0.0 ? q[1] : q[2];
  if (lead < 0.0) {
    for (int i = 0; i < 4; ++i) q[i] = -q[i];
  }
}

// The ambient vector with one representative per value (== and hash()).
template <class T>
Eigen::VectorXd CanonicalAmbient(const T& x) {
  return AmbientOf(x);
}
Eigen::VectorXd CanonicalAmbient(const SO3& x) {
  Eigen::VectorXd a = AmbientOf(x);
  CanonicalQuaternion(a.data());
  return a;
}
Eigen::VectorXd CanonicalAmbient(const SE3& x) {
  Eigen::VectorXd a = AmbientOf(x);
  CanonicalQuaternion(a.data() + 3);
  return a;
}

// ==, hash(), isclose and numpy's __array__, shared by all kinds (Rn too).
// Values are immutable from Python (no setter is bound), so they are hashable
// and equal values hash alike: == compares the stored numbers exactly, with a
// quaternion and its negative equal; isclose compares y ⊟ x with a tolerance.
template <class T, class Cls>
void BindValueProtocol(Cls& cls, const char* kind) {
  cls.def(
         "__eq__",
         [](const T& a, const py::object& b) -> py::object {
           if (!py::isinstance<T>(b)) return py::reinterpret_borrow<py::object>(Py_NotImplemented);
           const T& other = b.cast<const T&>();
           const Eigen::VectorXd x = CanonicalAmbient(a), y = CanonicalAmbient(other);
           return py::bool_(x.size() == y.size() && x == y);
         },
         py::arg("other"))
      .def("__hash__",
           [](const T& a) {
             const Eigen::VectorXd x = CanonicalAmbient(a);
             py::tuple t(x.size() + 1);
             t[0] = py::str(py::type::of(py::cast(a)).attr("__name__"));
             for (Eigen::Index i = 0; i < x.size(); ++i) t[i + 1] = py::float_(x[i]);
             return py::hash(t);
           })
      .def(
          "isclose",
          [kind](const T& a, const py::object& b, double atol) {
            if (!py::isinstance<T>(b)) {
              throw py::type_error(std::string(kind) + ".isclose(other): other must be a " + kind +
                                   ", got " +
                                   std::string(py::str(py::type::of(b).attr("__name__"))));
            }
            if (!(atol >= 0.0)) throw py::value_error("isclose: atol must be >= 0");
            const T& other = b.cast<const T&>();
            const Eigen::VectorXd x = CanonicalAmbient(a), y = CanonicalAmbient(other);
            if (x.size() != y.size()) return false;
            // Equal values are close at any tolerance, also where x ⊟ x rounds to a
            // few ulps (a quaternion a hair off unit length).
            if (x == y) return true;
            const Eigen::VectorXd d = a.boxminus(other);
            return d.size() == 0 || d.cwiseAbs().maxCoeff() <= atol;
          },
          py::arg("other"), py::arg("atol") = 1e-9, R"doc(
Whether every coordinate of ``self ⊟ other`` is at most ``atol`` in magnitude.

Parameters
----------
other : same type as self
atol : float
    Tolerance in the tangent's units (radians for rotations, the position's
    units for translations).

Returns
-------
bool
)doc")
      .def(
          "__array__",
          [](const T& a, const py::object& dtype, const py::object& copy) {
            if (!copy.is_none() && !copy.cast<bool>()) {
              throw py::value_error(
                  "a copy of the ambient vector is always made: copy=False is impossible");
            }
            const Eigen::VectorXd x = AmbientOf(a);
            py::array_t<double> out(x.size());
            std::copy(x.data(), x.data() + x.size(), out.mutable_data());
            if (dtype.is_none()) return py::object(out);
            return out.attr("astype")(dtype);
          },
          py::arg("dtype") = py::none(), py::arg("copy") = py::none(),
          "The ambient vector as a new float array (numpy.asarray(x)).");
}

// ⊞, ⊟, dof, ambient, pickling and the manifold handle, shared by all kinds.
// Unpickling restores the stored bits exactly (FromAmbientExactly): a value sent
// to a worker process is the value itself, so process results equal serial ones.
template <class T, class Cls>
void BindCommon(Cls& cls, const char* kind) {
  cls.def_property_readonly_static(
         "dof", [](py::object) { return T::kDof; }, "Tangent dimension (degrees of freedom).")
      .def("__len__", [](const T&) { return T::kDof; })
      .def(
          "__add__",
          [kind](const T& x, const py::object& delta) {
            const Eigen::VectorXd d =
                AsVector(delta, T::kDof, (std::string(kind) + " ⊞ δ").c_str());
            return x.boxplus(typename T::Tangent(d));
          },
          py::arg("delta"))
      .def(
          "__sub__", [](const T& y, const T& x) { return Eigen::VectorXd(y.boxminus(x)); },
          py::arg("x"))
      .def("__sub__",
           [kind](const T&, const py::object& other) -> Eigen::VectorXd {
             throw py::type_error(std::string(kind) + " - x: x must be a " + kind + ", got " +
                                  std::string(py::str(py::type::of(other).attr("__name__"))));
           })
      .def_property_readonly(
          "ambient", [](const T& x) { return Eigen::VectorXd(x.ambient()); },
          "Copy of the storage vector (the layout the solver uses).")
      .def_static(
          "from_ambient",
          [kind](const Eigen::VectorXd& a) {
            if (a.size() != T::kAmbient) {
              throw py::value_error(std::string(kind) + ".from_ambient: expected " +
                                    std::to_string(T::kAmbient) + " numbers");
            }
            return T::FromAmbient(a.data());
          },
          py::arg("a"))
      .def_static(
          "manifold",
          [kind]() {
            return ManifoldHandle{MakeManifold(kind), kind};
          },
          "The manifold (⊞/⊟ for the solver) of this kind.")
      .def("copy", [](const T& x) { return T(x); })
      .def("__copy__", [](const T& x) { return T(x); })
      .def(
          "__deepcopy__", [](const T& x, py::dict) { return T(x); }, py::arg("memo"))
      .def(py::pickle(
          [](const T& x) { return py::make_tuple(Eigen::VectorXd(x.ambient())); },
          [](const py::tuple& t) { return FromAmbientExactly<T>(t[0].cast<Eigen::VectorXd>()); }));
}

}  // namespace

void RegisterValues(py::module_& m) {
  using Mat = py::array_t<double, py::array::c_style | py::array::forcecast>;

  // ---- SO2 ------------------------------------------------------------------
  py::class_<SO2> so2(m, "SO2", R"doc(
Planar rotation by an angle φ (radians), kept in [-π, π).

Construct with SO2(phi) or SO2(R) (2×2 rotation matrix).

x + δ = wrap(φ + δ);  y - x = wrap(φ_y − φ_x)  (1 DOF).
)doc");
  so2.def(py::init<double>(), py::arg("phi") = 0.0)
      .def(py::init([](const Eigen::Matrix2d& R) { return SO2::FromMatrix(R); }), py::arg("R"))
      .def_static("from_matrix", &SO2::FromMatrix, py::arg("R"))
      .def_property_readonly("phi", &SO2::angle, "The angle in radians.")
      .def_property_readonly("R", &SO2::matrix, "2×2 rotation matrix.")
      .def("inverse", &SO2::inverse)
      .def("__mul__", [](const SO2& a, const SO2& b) { return a * b; })
      .def("__mul__",
           [](const SO2& a, const py::object& p) {
             return MapPoints<2>(
                 p, [&](const Eigen::Vector2d& v) { return Eigen::Vector2d(a * v); }, "SO2 * p");
           })
      .def("__repr__", [](const SO2& a) { return "SO2(phi=" + std::to_string(a.angle()) + ")"; });
  so2.attr("__matmul__") = so2.attr("__mul__");
  BindCommon<SO2>(so2, "SO2");
  BindValueProtocol<SO2>(so2, "SO2");

  // ---- SO3 ------------------------------------------------------------------
  py::class_<SO3> so3(m, "SO3", R"doc(
3D rotation, stored as a unit quaternion [x, y, z, w].

x + δ = x·exp(δ) (δ ∈ R³, body frame);  y - x = log(x⁻¹y), ‖y - x‖ ≤ π.
Construct with SO3() (identity), SO3(R) (R a 3×3 rotation matrix, a quaternion
[x, y, z, w] or an SO3), SO3.from_quat([x, y, z, w]) or SO3.exp(rotation_vector).
)doc");
  so3.def(py::init<>())
      .def(py::init([](const py::object& R) { return RotationFrom(R, "SO3(R)"); }), py::arg("R"))
      .def_static("from_matrix", &SO3::FromMatrix, py::arg("R"))
      .def_static(
          "from_quat",
          [](const py::object& q) { return SO3::FromQuaternion(AsVector(q, 4, "SO3.from_quat")); },
          py::arg("q"), "From a quaternion [x, y, z, w] (normalised).")
      .def_static(
          "exp", [](const py::object& w) { return SO3::Exp(AsVector(w, 3, "SO3.exp")); },
          py::arg("w"), "Rotation by ‖w‖ about w/‖w‖.")
      .def("log", &SO3::Log, "Rotation vector, ‖log‖ ≤ π.")
      .def_property_readonly("R", &SO3::matrix, "3×3 rotation matrix.")
      .def_property_readonly("Q", &SO3::matrix, "3×3 rotation matrix (MTKM's name).")
      .def_property_readonly("quat", &SO3::quat, "Unit quaternion [x, y, z, w].")
      .def("inverse", &SO3::inverse)
      .def("__mul__", [](const SO3& a, const SO3& b) { return a * b; })
      .def("__mul__",
           [](const SO3& a, const py::object& p) {
             return MapPoints<3>(
                 p, [&](const Eigen::Vector3d& v) { return Eigen::Vector3d(a * v); }, "SO3 * p");
           })
      .def("__repr__", [](const SO3& a) { return "SO3(quat=" + Fmt(a.quat()) + ")"; });
  so3.attr("__matmul__") = so3.attr("__mul__");
  BindCommon<SO3>(so3, "SO3");
  BindValueProtocol<SO3>(so3, "SO3");

  // ---- SE2 ------------------------------------------------------------------
  py::class_<SE2> se2(m, "SE2", R"doc(
Planar pose (position p, angle φ) = R² × SO(2), mapping local to parent.

Tangent order [δx, δy, δφ]: x + δ = (p + δp, wrap(φ + δφ)). Construct with
SE2() (identity), SE2(x, y, theta), SE2([x, y, theta]) (the ambient vector),
SE2(T) (3×3 homogeneous matrix), SE2(pos, phi) or SE2(pos, rot) (rot an SO2).
)doc");
  se2.def(py::init<>())
      .def(py::init(
               [](double x, double y, double theta) { return SE2(Eigen::Vector2d(x, y), theta); }),
           py::arg("x"), py::arg("y"), py::arg("theta"))
      .def(py::init([](const py::object& v) {
             const auto a = AsArray(v);
             if (HasShape(a, {3})) return SE2::FromAmbient(a.data());
             if (HasShape(a, {3, 3})) return SE2::FromMatrix(SquareMatrix<3>(a));
             throw py::type_error(
                 "SE2(v): v must be [x, y, theta] or a 3x3 homogeneous matrix, got " + ShapeOf(v));
           }),
           py::arg("v"))
      .def(py::init([](const Eigen::Vector2d& pos, double phi) { return SE2(pos, phi); }),
           py::arg("pos"), py::arg("phi"))
      .def(py::init([](const Eigen::Vector2d& pos, const SO2& r) { return SE2(pos, r); }),
           py::arg("pos"), py::arg("rot"))
      .def_static("from_matrix", &SE2::FromMatrix, py::arg("T"))
      .def_static(
          "exp", [](const py::object& d) { return SE2::Exp(AsVector(d, 3, "SE2.exp")); },
          py::arg("delta"), "identity ⊞ [x, y, φ].")
      .def(
          "log", [](const SE2& x) { return Eigen::VectorXd(x.Log()); }, "x ⊟ identity.")
      .def_property_readonly("pos", &SE2::pos)
      .def_property_readonly("phi", &SE2::angle)
      .def_property_readonly("rot", &SE2::rotation)
      .def_property_readonly("R", [](const SE2& x) { return x.rotation().matrix(); })
      .def("transform", &SE2::transform, "3×3 homogeneous matrix, local → parent.")
      .def(
          "fromlocal",
          [](const SE2& x, const py::object& p) {
            return MapPoints<2>(
                p, [&](const Eigen::Vector2d& v) { return x.fromlocal(v); }, "fromlocal");
          },
          py::arg("v"), "R v + p: local → parent coordinates.")
      .def(
          "tolocal",
          [](const SE2& x, const py::object& p) {
            return MapPoints<2>(
                p, [&](const Eigen::Vector2d& v) { return x.tolocal(v); }, "tolocal");
          },
          py::arg("v"), "Rᵀ(v − p): parent → local coordinates.")
      .def("inverse", &SE2::inverse)
      .def("__mul__", [](const SE2& a, const SE2& b) { return a * b; })
      .def("__mul__",
           [](const SE2& a, const py::object& p) {
             return MapPoints<2>(
                 p, [&](const Eigen::Vector2d& v) { return a.fromlocal(v); }, "SE2 * p");
           })
      .def("__repr__", [](const SE2& a) {
        return "SE2(pos=" + Fmt(a.pos()) + ", phi=" + std::to_string(a.angle()) + ")";
      });
  se2.attr("__matmul__") = se2.attr("__mul__");
  BindCommon<SE2>(se2, "SE2");
  BindValueProtocol<SE2>(se2, "SE2");

  // ---- SE3 ------------------------------------------------------------------
  py::class_<SE3> se3(m, "SE3", R"doc(
Rigid transform (rotation R, position p) = R³ × SO(3), mapping local to parent.

Tangent order [δp (3), δθ (3)]: x + δ = (p + δp, R·exp(δθ)). Construct with
SE3() (identity), SE3(R, t) or SE3(R=..., t=...) (R a 3×3 rotation matrix, a
quaternion [x, y, z, w] or an SO3; either may be left out: identity rotation,
zero translation), SE3(T) (4×4 homogeneous matrix), SE3([px, py, pz, qx, qy, qz,
qw]) (the ambient vector) or SE3.from_matrix(T).
)doc");
  se3.def(py::init<>())
      .def(py::init([](const py::object& R, const py::object& t) {
             if (t.is_none() && !R.is_none() && !py::isinstance<SO3>(R)) {
               const auto a = AsArray(R);
               if (HasShape(a, {4, 4})) return SE3::FromMatrix(SquareMatrix<4>(a));
               if (HasShape(a, {7})) return SE3::FromAmbient(a.data());
             }
             const SO3 rot = R.is_none() ? SO3() : RotationFrom(R, "SE3(R, t)");
             const Eigen::Vector3d pos =
                 t.is_none() ? Eigen::Vector3d::Zero() : Eigen::Vector3d(AsVector(t, 3, "SE3 t"));
             return SE3(rot, pos);
           }),
           py::arg("R") = py::none(), py::arg("t") = py::none())
      .def_static("from_matrix", &SE3::FromMatrix, py::arg("T"))
      .def_static(
          "exp", [](const py::object& d) { return SE3::Exp(AsVector(d, 6, "SE3.exp")); },
          py::arg("delta"), "identity ⊞ [p, w] = (p, exp(w)) (the compound's chart).")
      .def(
          "log", [](const SE3& x) { return Eigen::VectorXd(x.Log()); },
          "x ⊟ identity = [p, log R].")
      .def_property_readonly("pos", &SE3::pos, "Position (translation) p.")
      .def_property_readonly("t", &SE3::pos, "Same as pos.")
      .def_property_readonly("rot", &SE3::rotation, "Orientation as an SO3.")
      .def_property_readonly("R", [](const SE3& x) { return x.rotation().matrix(); })
      .def_property_readonly("Q", [](const SE3& x) { return x.rotation().matrix(); })
      .def_property_readonly("quat", [](const SE3& x) { return x.rotation().quat(); })
      .def("transform", &SE3::transform, "4×4 homogeneous matrix, local → parent.")
      .def("matrix", &SE3::transform, "Same as transform().")
      .def(
          "fromlocal",
          [](const SE3& x, const py::object& p) {
            return MapPoints<3>(
                p, [&](const Eigen::Vector3d& v) { return x.fromlocal(v); }, "fromlocal");
          },
          py::arg("v"), "R v + p: local → parent coordinates.")
      .def(
          "tolocal",
          [](const SE3& x, const py::object& p) {
            return MapPoints<3>(
                p, [&](const Eigen::Vector3d& v) { return x.tolocal(v); }, "tolocal");
          },
          py::arg("v"), "Rᵀ(v − p): parent → local coordinates.")
      .def("inverse", &SE3::inverse)
      .def("__mul__", [](const SE3& a, const SE3& b) { return a * b; })
      .def("__mul__",
           [](const SE3& a, const py::object& p) {
             return MapPoints<3>(
                 p, [&](const Eigen::Vector3d& v) { return a.fromlocal(v); }, "SE3 * p");
           })
      .def("__repr__", [](const SE3& a) {
        return "SE3(pos=" + Fmt(a.pos()) + ", quat=" + Fmt(a.rotation().quat()) + ")";
      });
  se3.attr("__matmul__") = se3.attr("__mul__");
  BindCommon<SE3>(se3, "SE3");
  BindValueProtocol<SE3>(se3, "SE3");

  // ---- S2 -------------------------------------------------------------------
  py::class_<S2> s2(m, "S2", R"doc(
Unit 3-vector (a direction), 2 DOF.

x + δ = cos‖δ‖ x + sinc‖δ‖ B δ, with B = tangent_basis() (3×2, orthonormal,
orthogonal to x); y - x ∈ R², ‖y - x‖ = angle between x and y.
)doc");
  s2.def(py::init<>())
      .def(py::init([](const py::object& v) { return S2(AsVector(v, 3, "S2")); }), py::arg("v"))
      .def_property_readonly("vec", &S2::vec, "The unit vector.")
      .def("tangent_basis", &S2::tangent_basis)
      .def("__repr__", [](const S2& a) { return "S2(" + Fmt(a.vec()) + ")"; });
  BindCommon<S2>(s2, "S2");
  BindValueProtocol<S2>(s2, "S2");

  // ---- Rn -------------------------------------------------------------------
  py::class_<Rn> rn(m, "Rn", R"doc(
A vector of Rⁿ: Rn(n) is the zero vector, Rn(v) holds v. x + δ = x + δ.
)doc");
  rn.def(py::init([](const py::object& arg) {
           if (PyBool_Check(arg.ptr())) {
             throw py::type_error("Rn(n): n must be an int or a vector, got a bool");
           }
           // Any integer scalar (int, numpy.int64, ...: what has __index__ and is
           // not an array) is the dimension n, so Rn(np.int64(3)) is Rn(3).
           if (!py::isinstance<py::array>(arg) && PyIndex_Check(arg.ptr())) {
             const py::int_ as_int = py::reinterpret_steal<py::int_>(PyNumber_Index(arg.ptr()));
             if (!as_int) throw py::error_already_set();
             int overflow = 0;
             const long long n = PyLong_AsLongLongAndOverflow(as_int.ptr(), &overflow);
             if (n < 1 && overflow == 0) throw py::value_error("Rn(n): n must be at least 1");
             if (overflow != 0 || n > kRnMaxDimension) RnTooLarge(std::string(py::str(as_int)));
             return Rn(static_cast<int>(n));
           }
           py::array_t<double, py::array::c_style | py::array::forcecast> a =
               py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(arg);
           if (!a || a.ndim() > 1 || a.size() < 1) {
             throw py::value_error("Rn(v): v must be a non-empty vector or an int n");
           }
           if (a.size() > kRnMaxDimension) RnTooLarge(std::to_string(a.size()));
           return Rn(Eigen::Map<const Eigen::VectorXd>(a.data(), a.size()));
         }),
         py::arg("v"))
      .def_property_readonly("vec", &Rn::vec)
      .def_property_readonly("dof", &Rn::dof)
      .def_property_readonly("ambient", &Rn::vec)
      .def("__len__", &Rn::dof)
      .def("__add__", [](const Rn& x,
                         const py::object& d) { return x.boxplus(AsVector(d, x.dof(), "Rn ⊞ δ")); })
      .def("__sub__", [](const Rn& y, const Rn& x) { return y.boxminus(x); })
      .def("__sub__",
           [](const Rn&, const py::object& other) -> Eigen::VectorXd {
             throw py::type_error("Rn - x: x must be an Rn, got " +
                                  std::string(py::str(py::type::of(other).attr("__name__"))));
           })
      .def("manifold",
           [](const Rn& x) {
             return ManifoldHandle{MakeManifold("Rn", x.dof()), "Rn"};
           })
      .def("copy", [](const Rn& x) { return Rn(x); })
      .def("__copy__", [](const Rn& x) { return Rn(x); })
      .def(
          "__deepcopy__", [](const Rn& x, py::dict) { return Rn(x); }, py::arg("memo"))
      .def(py::pickle([](const Rn& x) { return py::make_tuple(x.vec()); },
                      [](const py::tuple& t) { return Rn(t[0].cast<Eigen::VectorXd>()); }))
      .def("__repr__", [](const Rn& x) { return "Rn(" + Fmt(x.vec()) + ")"; });
  BindValueProtocol<Rn>(rn, "Rn");
}

}  // namespace boxplus::python
