// Binding of the joint-calibration terms (cpp/include/boxplus/factors/joint/terms.h):
// joint_factor(problem, spec, noise, what) -> Factor for Problem.add_factor. The spec is a nested
// dict naming variables by id; the binding maps each distinct variable to one parameter block (a
// variable used twice, e.g. the dh table of a point and of its plane, is one block). boxplus.joint
// builds these dicts; errors from bad dicts are ValueError/KeyError naming the measurement.
#include <map>

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "../bindings.h"
#include "../factor.h"
#include "boxplus/errors.h"
#include "boxplus/factors/joint/terms.h"
#include "boxplus/problem.h"

namespace py = pybind11;

namespace boxplus::python {

namespace {

using joint::kNoBlock;

// Variable ids → block indices, in order of first use.
struct Blocks {
  const Problem& problem;
  const std::string& what;
  std::vector<int> ids, sizes;
  std::map<int, int> index;

  int Map(const py::dict& d, const char* key) {
    if (!d.contains(key) || d[key].is_none()) return kNoBlock;
    const int id = d[key].cast<int>();
    BOXPLUS_CHECK_INDEX(id >= 0 && id < problem.num_variables(), what, ": unknown variable id ", id,
                        " for '", key, "' (the problem has ", problem.num_variables(), ")");
    auto it = index.find(id);
    if (it != index.end()) return it->second;
    const int b = static_cast<int>(ids.size());
    index[id] = b;
    ids.push_back(id);
    sizes.push_back(problem.manifold(id).AmbientSize());
    return b;
  }
};

template <class V>
V Get(const py::dict& d, const char* key, V fallback) {
  return d.contains(key) && !d[key].is_none() ? d[key].cast<V>() : fallback;
}

int Choice(const py::dict& d, const char* key, std::initializer_list<const char*> names,
           const std::string& what) {
  const std::string v = Get<std::string>(d, key, *names.begin());
  int i = 0;
  for (const char* n : names) {
    if (v == n) return i;
    ++i;
  }
  throw Error(what + ": unknown " + key + " '" + v + "'");
}

joint::ChainSpec ParseChain(const py::dict& d, Blocks& b) {
  joint::ChainSpec c;
  c.convention = static_cast<kinematics::DHConvention>(
      Choice(d, "convention", {"standard", "modified"}, b.what));
  c.nominal = d["nominal"].cast<Eigen::MatrixXd>();
  c.unknown = Get<std::vector<int>>(d, "unknown", {});
  c.joints = d["joints"].cast<Eigen::VectorXd>();
  c.dh = b.Map(d, "dh");
  c.encoder = b.Map(d, "encoder");
  c.mount = b.Map(d, "mount");
  c.base_from_chain = Get<joint::Pose7>(d, "base_from_chain", c.base_from_chain);
  c.mount_value = Get<joint::Pose7>(d, "mount_value", c.mount_value);
  return c;
}

joint::PointSpec ParsePoint(const py::dict& d, Blocks& b) {
  joint::PointSpec p;
  p.kind = static_cast<joint::PointKind>(
      Choice(d, "kind", {"constant", "variable", "chain", "sheet", "beam"}, b.what));
  p.c = Get<Eigen::Vector3d>(d, "c", p.c);
  p.block = b.Map(d, "var");
  if (p.kind == joint::PointKind::kChain) p.chain = ParseChain(d["chain"].cast<py::dict>(), b);
  if (p.kind == joint::PointKind::kSheet || p.kind == joint::PointKind::kBeam) {
    p.model = camera::CameraModelIndex(Get<std::string>(d, "model", "simple_radial"));
    p.camera = b.Map(d, "camera");
    p.uv = d["uv"].cast<Eigen::Vector2d>();
    p.beta = Get<double>(d, "beta", 0.0);
    p.sheet = b.Map(d, "sheet");
  }
  p.pose = b.Map(d, "pose");
  return p;
}

joint::SurfaceSpec ParseSurface(const py::dict& d, Blocks& b) {
  joint::SurfaceSpec s;
  s.kind =
      static_cast<joint::SurfaceKind>(Choice(d, "kind", {"plane", "line", "chain_plane"}, b.what));
  s.block = b.Map(d, "var");
  if (s.kind == joint::SurfaceKind::kChainPlane)
    s.chain = ParseChain(d["chain"].cast<py::dict>(), b);
  s.pose = b.Map(d, "pose");
  return s;
}

}  // namespace

void RegisterJointFactors(py::module_& m) {
  m.def(
      "joint_factor",
      [](const Problem& p, const py::dict& spec, const NoiseModel& noise, const std::string& what) {
        Blocks b{p, what, {}, {}, {}};
        joint::TermSpec t;
        t.kind = static_cast<joint::TermKind>(Choice(
            spec, "kind",
            {"link", "distance", "plane", "line", "line_anchor", "projection", "target_projection"},
            what));
        if (spec.contains("a")) t.a = ParsePoint(spec["a"].cast<py::dict>(), b);
        if (spec.contains("b")) t.b = ParsePoint(spec["b"].cast<py::dict>(), b);
        if (spec.contains("surface")) t.surface = ParseSurface(spec["surface"].cast<py::dict>(), b);
        if (spec.contains("camera")) {
          const py::dict c = spec["camera"].cast<py::dict>();
          t.camera.model = camera::CameraModelIndex(Get<std::string>(c, "model", "simple_radial"));
          t.camera.intrinsics = b.Map(c, "intrinsics");
          t.camera.cam_from_system = b.Map(c, "cam_from_system");
          t.camera.pose = b.Map(c, "pose");
        }
        t.z = Get<Eigen::VectorXd>(spec, "z", Eigen::VectorXd());
        t.targets = Get<Eigen::MatrixXd>(spec, "targets", Eigen::MatrixXd());
        t.W = noise.sqrt_information();
        return Factor{joint::MakeJointTerm(t, b.sizes, what), b.ids, noise};
      },
      py::arg("problem"), py::arg("spec"), py::arg("noise"), py::arg("what") = "joint term",
      "One term of joint calibration (link, distance, plane, line, line_anchor, projection, "
      "target_projection) "
      "over 3D-system points (constant, variable, DH chain, light sheet, beam); see "
      "factors/joint/terms.h. Variables are given by id inside the nested dict ``spec``.");
}

}  // namespace boxplus::python
