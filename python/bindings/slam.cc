// Bindings of graph SLAM: g2o/TORO files as pose graphs (boxplus._core.PoseGraph).
//
// The file is read and the problem built in C++ (no per-edge Python call).
// Poses: SE2 ambient [x, y, θ]; SE3 ambient [px, py, pz, qx, qy, qz, qw],
// tangent [δp, δθ] (translation first). Information matrices are in the
// order of each edge's error (SE3: [translation, rotation]).
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "boxplus/io/g2o.h"
#include "boxplus/problem.h"
#include "boxplus/slam/load.h"
#include "boxplus/slam/pose_graph.h"
#include "solve_from_python.h"

namespace py = pybind11;

namespace boxplus::python {
namespace {

using slam::PoseGraph;

const char* KindName(io::VertexKind k) {
  switch (k) {
    case io::VertexKind::kSE2:
      return "SE2";
    case io::VertexKind::kSE3:
      return "SE3";
    case io::VertexKind::kPoint2:
      return "XY";
    case io::VertexKind::kPoint3:
      return "XYZ";
  }
  return "?";
}

io::VertexKind ParseVertexKind(const std::string& s) {
  if (s == "SE2") return io::VertexKind::kSE2;
  if (s == "SE3") return io::VertexKind::kSE3;
  if (s == "XY") return io::VertexKind::kPoint2;
  if (s == "XYZ") return io::VertexKind::kPoint3;
  throw py::value_error("unknown vertex kind '" + s + "' (SE2, SE3, XY or XYZ)");
}

io::EdgeKind ParseEdgeKind(const std::string& s) {
  if (s == "SE2") return io::EdgeKind::kSE2;
  if (s == "SE3") return io::EdgeKind::kSE3;
  if (s == "SE2_XY") return io::EdgeKind::kSE2Point2;
  if (s == "SE3_XYZ") return io::EdgeKind::kSE3Point3;
  if (s == "SE2_BEARING_RANGE") return io::EdgeKind::kSE2BearingRange;
  throw py::value_error("unknown edge kind '" + s +
                        "' (SE2, SE3, SE2_XY, SE3_XYZ or SE2_BEARING_RANGE)");
}

// Stacks the estimates of the vertices of one kind (rows in file order).
Eigen::MatrixXd Stack(PoseGraph& pg, io::VertexKind kind) {
  const auto& vs = pg.graph().vertices;
  int n = 0;
  for (const auto& v : vs) n += v.kind == kind;
  const int a = io::AmbientSize(kind);
  Eigen::MatrixXd out(n, a);
  int r = 0;
  for (size_t i = 0; i < vs.size(); ++i) {
    if (vs[i].kind != kind) continue;
    // By index: a landmark may share its id with a pose (own id ranges).
    const double* x = pg.problem().value(pg.variable_at(static_cast<int>(i)));
    for (int c = 0; c < a; ++c) out(r, c) = x[c];
    ++r;
  }
  return out;
}

}  // namespace

void RegisterSlam(py::module_& m) {
  m.def(
      "g2o_record_tags",
      [] {
        py::list tags;
        for (const io::TagInfo& t : io::RecordTags()) {
          tags.append(py::make_tuple(t.tag, io::ToString(t.family), t.fields));
        }
        return tags;
      },
      "The record tags the g2o/TORO reader accepts, as (tag, format, fields) from the "
      "reader's one tag table (boxplus::io::RecordTags).");
  m.def(
      "pose_graph_solver_defaults",
      [] {
        const SolverOptions o = slam::DefaultSolverOptions();
        py::dict d;
        d["method"] = MethodName(o.method);
        d["initial_trust_region_radius"] = o.initial_trust_region_radius;
        d["damping"] = o.damping == Damping::kLevenberg ? "levenberg" : "marquardt";
        d["jacobi_scaling"] = o.jacobi_scaling;
        d["nonmonotonic_steps"] =
            o.use_nonmonotonic_steps ? o.max_consecutive_nonmonotonic_steps : 0;
        return d;
      },
      "The solver settings boxplus uses for pose graphs "
      "(boxplus::slam::DefaultSolverOptions), as keyword arguments of Problem.solve.");

  m.attr("pose_graph_implausible_chi2_per_dof") = slam::kImplausibleChi2PerDof;

  py::class_<io::ReadReport>(m, "ReadReport", "What the g2o reader counted.")
      .def_readonly("lines", &io::ReadReport::lines)
      .def_readonly("unknown_skipped", &io::ReadReport::unknown_skipped)
      .def_readonly("unknown_tags", &io::ReadReport::unknown_tags,
                    "Skipped tag → count (bytes outside ASCII escaped as \\xNN).")
      .def_readonly("repaired_information", &io::ReadReport::repaired_information)
      .def("todict", &PropertiesToDict, kToDictDoc)
      .def_readonly("repaired_lines", &io::ReadReport::repaired_lines);

  py::class_<slam::LoadReport>(m, "LoadReport", R"doc(
What loading a pose graph did (boxplus::slam::LoadReport): the reader's counts
(``unknown_skipped``, ``unknown_tags``, ``repaired_information``,
``repaired_lines``, ``lines``), its ``warnings`` ("" if none),
``estimates_from_file`` (False: no VERTEX lines, initialised by spanning tree),
``start`` (the start the solve begins from: "file", "spanning-tree" or
"chordal"; what init="best" chose) and the seconds of the three steps (``read_s``, ``init_s``, ``build_s``).
)doc")
      .def_property_readonly("lines", [](const slam::LoadReport& r) { return r.read.lines; })
      .def_property_readonly("unknown_skipped",
                             [](const slam::LoadReport& r) { return r.read.unknown_skipped; })
      .def_property_readonly("unknown_tags",
                             [](const slam::LoadReport& r) { return r.read.unknown_tags; })
      .def_property_readonly("repaired_information",
                             [](const slam::LoadReport& r) { return r.read.repaired_information; })
      .def_property_readonly("repaired_lines",
                             [](const slam::LoadReport& r) { return r.read.repaired_lines; })
      .def_readonly("warnings", &slam::LoadReport::warnings)
      .def_readonly("estimates_from_file", &slam::LoadReport::estimates_from_file)
      .def_readonly("start", &slam::LoadReport::start)
      .def_readonly("read_s", &slam::LoadReport::read_s)
      .def_readonly("init_s", &slam::LoadReport::init_s)
      .def_readonly("build_s", &slam::LoadReport::build_s)
      .def("todict", &PropertiesToDict, kToDictDoc)
      .def("__repr__", [](const slam::LoadReport& r) {
        return "LoadReport(lines=" + std::to_string(r.read.lines) +
               ", unknown_skipped=" + std::to_string(r.read.unknown_skipped) +
               ", repaired_information=" + std::to_string(r.read.repaired_information) +
               ", estimates_from_file=" + (r.estimates_from_file ? "True" : "False") + ", start='" +
               r.start + "')";
      });

  py::class_<slam::EdgeVerdict>(m, "EdgeVerdict",
                                "An edge judged a wrong loop closure (boxplus::slam::EdgeVerdict).")
      .def_readonly("edge", &slam::EdgeVerdict::edge, "Index among the graph's edges.")
      .def_readonly("line", &slam::EdgeVerdict::line, "Line of the file (0: added in code).")
      .def_readonly("from_id", &slam::EdgeVerdict::from)
      .def_readonly("to_id", &slam::EdgeVerdict::to)
      .def_readonly("weight", &slam::EdgeVerdict::weight, "GNC's last weight (0).")
      .def_readonly("chi2", &slam::EdgeVerdict::chi2, "eᵀΩe at the returned estimate.")
      .def("todict", &PropertiesToDict, kToDictDoc)
      .def("__repr__", [](const slam::EdgeVerdict& v) {
        return "EdgeVerdict(line=" + std::to_string(v.line) +
               ", from_id=" + std::to_string(v.from) + ", to_id=" + std::to_string(v.to) +
               ", chi2=" + std::to_string(v.chi2) + ")";
      });
  py::class_<slam::OutlierReport>(m, "OutlierReport", R"doc(
What the last solve decided about wrong loop closures
(boxplus::slam::OutlierReport; docs/guide/slam.md "Wrong loop closures"):
``ran`` (GNC ran), ``method`` ('gnc-tls' / 'gnc-gm'), ``threshold`` (c̄² of
a 2D/3D pose edge, times ``information_scale``: eᵀΩe above it is an
outlier), ``information_scale`` (1, or the inliers' χ²/dof when it showed
the file's information under-confident and GNC judged again in those
units), ``candidates`` (loop closures judged), ``rounds``, ``outliers``
(EdgeVerdict list, file order).
)doc")
      .def_readonly("ran", &slam::OutlierReport::ran)
      .def_readonly("method", &slam::OutlierReport::method)
      .def_readonly("threshold", &slam::OutlierReport::threshold)
      .def_readonly("information_scale", &slam::OutlierReport::information_scale)
      .def_readonly("candidates", &slam::OutlierReport::candidates)
      .def_readonly("rounds", &slam::OutlierReport::rounds)
      .def_readonly("outliers", &slam::OutlierReport::outliers)
      .def("todict", &PropertiesToDict, kToDictDoc)
      .def("__repr__", [](const slam::OutlierReport& r) {
        return "OutlierReport(ran=" + std::string(r.ran ? "True" : "False") + ", method='" +
               r.method + "', outliers=" + std::to_string(r.outliers.size()) +
               ", candidates=" + std::to_string(r.candidates) + ")";
      });

  py::class_<PoseGraph>(m, "PoseGraph", R"doc(
A pose graph read from a g2o/TORO file, as a boxplus Problem
(boxplus::slam::PoseGraph; boxplus.slam.PoseGraph extends it).

``PoseGraph(path, ...)`` reads, initialises and builds it in C++
(boxplus::slam::LoadPoseGraph, the command line's path too); ``problem`` is the
underlying ``boxplus.Problem`` (extend it, fix variables, solve it), its
lifetime tied to this object; ``report`` the LoadReport.
)doc")
      .def(py::init([](const std::string& path, const std::string& convention,
                       const std::string& robust, double robust_width, const std::string& init,
                       bool skip_unknown, bool repair_information, const py::object& progress) {
             slam::LoadOptions o;
             o.read.skip_unknown_tags = skip_unknown;
             o.read.repair_information = repair_information;
             o.graph.convention = ParsePoseErrorConvention(convention);
             o.graph.robust = robust;
             o.graph.robust_width = robust_width;
             o.init = slam::ParseInitMethod(init);
             if (!progress.is_none() && !PyCallable_Check(progress.ptr())) {
               throw py::type_error("progress must be callable, got " +
                                    std::string(py::str(py::type::of(progress).attr("__name__"))));
             }
             // The read runs without the GIL; every few thousand lines it takes
             // it to let Ctrl-C stop the load and to call `progress`. A Python
             // error there ends the read (StopRead) and is raised here.
             struct StopRead {};
             std::unique_ptr<py::error_already_set> error;
             if (!progress.is_none()) o.read.progress_lines = 1 << 12;
             o.read.on_progress = [&](const io::ReadProgress& rp) {
               py::gil_scoped_acquire gil;
               try {
                 if (PyErr_CheckSignals() != 0) throw py::error_already_set();
                 if (!progress.is_none()) progress(rp.lines, rp.bytes, rp.bytes_total);
               } catch (py::error_already_set& e) {
                 error = std::make_unique<py::error_already_set>(std::move(e));
                 throw StopRead{};
               }
             };
             slam::LoadReport report;
             std::unique_ptr<PoseGraph> pg;
             try {
               py::gil_scoped_release release;
               pg = slam::LoadPoseGraph(path, o, &report);
             } catch (const StopRead&) {
               throw std::move(*error);
             }
             pg->set_load_report(std::move(report));
             return pg;
           }),
           py::arg("path"), py::arg("convention") = "g2o", py::arg("robust") = "none",
           py::arg("robust_width") = 1.0, py::arg("init") = "best", py::arg("skip_unknown") = false,
           py::arg("repair_information") = false, py::arg("progress") = py::none(),
           "Reads a file and builds the problem (raises boxplus.ParseError naming file:line); "
           "progress(lines, bytes_read, bytes_total), if given, is called every 4096 lines of "
           "the read.")
      .def("__repr__",
           [](PoseGraph& pg) {
             const auto& g = pg.graph();
             int points = 0;
             for (const auto& v : g.vertices) {
               points += v.kind == io::VertexKind::kPoint2 || v.kind == io::VertexKind::kPoint3;
             }
             return "<PoseGraph " + std::to_string(g.dimension) +
                    "D: " + std::to_string(g.vertices.size() - points) + " poses, " +
                    std::to_string(points) + " landmarks, " + std::to_string(g.edges.size()) +
                    " edges, convention '" + ToString(pg.options().convention) + "'>";
           })
      .def_property_readonly("report", &PoseGraph::load_report,
                             py::return_value_policy::reference_internal,
                             "The LoadReport of the file.")
      .def_property_readonly("problem", &PoseGraph::problem,
                             py::return_value_policy::reference_internal,
                             "The boxplus.Problem (owned by this graph).")
      .def_property_readonly("dimension", [](PoseGraph& pg) { return pg.graph().dimension; })
      .def_property_readonly(
          "num_edges", [](PoseGraph& pg) { return static_cast<int>(pg.graph().edges.size()); })
      .def_property_readonly("vertex_ids", &PoseGraph::vertex_ids)
      .def(
          "edge_chi2",
          [](const PoseGraph& pg) {
            const int m = static_cast<int>(pg.graph().edges.size());
            py::array_t<double> out(m);
            auto o = out.mutable_unchecked<1>();
            for (int k = 0; k < m; ++k) o(k) = pg.EdgeChi2At(k);
            return out;
          },
          "eᵀΩe of every edge at the current values (file order, the graph's convention): "
          "which measurements carry the error.")
      .def(
          "edge_vertices",
          [](const PoseGraph& pg) {
            const auto& edges = pg.graph().edges;
            py::array_t<int64_t> out({static_cast<py::ssize_t>(edges.size()), py::ssize_t{2}});
            auto o = out.mutable_unchecked<2>();
            for (size_t k = 0; k < edges.size(); ++k) {
              o(k, 0) = edges[k].from;
              o(k, 1) = io::IsUnary(edges[k].kind) ? -1 : edges[k].to;
            }
            return out;
          },
          "(from, to) vertex ids of every edge of the file, file order; to = -1 for a file's "
          "unary edge (a prior record).")
      .def_property_readonly("gauge_vertex", &PoseGraph::gauge_vertex)
      .def_property_readonly(
          "convention",
          [](PoseGraph& pg) { return std::string(ToString(pg.options().convention)); })
      .def("variable", &PoseGraph::variable, py::arg("vertex_id"),
           "Variable id (in ``problem``) of a vertex id.")
      .def(
          "vertex_kind",
          [](PoseGraph& pg, int id) {
            return std::string(KindName(pg.graph().vertices[pg.graph().VertexIndex(id)].kind));
          },
          py::arg("vertex_id"))
      .def("fix", &PoseGraph::Fix, py::arg("vertex_id"), py::arg("fixed") = true)
      .def(
          "add_vertex",
          [](PoseGraph& pg, int id, const std::string& kind, const Eigen::VectorXd& estimate) {
            io::Vertex v;
            v.id = id;
            v.kind = ParseVertexKind(kind);
            v.estimate = estimate;
            return pg.AddVertex(v);
          },
          py::arg("vertex_id"), py::arg("kind"), py::arg("estimate"),
          "Adds a vertex ('SE2', 'SE3', 'XY', 'XYZ'); returns its variable id. The call "
          "is checked completely first: one that raises leaves the graph unchanged.")
      .def(
          "add_edge",
          [](PoseGraph& pg, const std::string& kind, int from, int to,
             const Eigen::VectorXd& measurement, const Eigen::MatrixXd& information) {
            io::Edge e;
            e.kind = ParseEdgeKind(kind);
            e.from = from;
            e.to = to;
            e.measurement = measurement;
            e.information = information;
            return pg.AddEdge(e);
          },
          py::arg("kind"), py::arg("from_id"), py::arg("to_id"), py::arg("measurement"),
          py::arg("information"), R"doc(
Adds an edge to the graph (saved with it) and the problem; returns the
measurement id. kind: 'SE2', 'SE3' (measurement [t, qx, qy, qz, qw]), 'SE2_XY',
'SE3_XYZ', 'SE2_BEARING_RANGE' ([bearing, range]). information: the full
symmetric information matrix in the error's order. The call is checked
completely first: one that raises leaves the graph unchanged.
)doc")
      .def(
          "solve",
          [](PoseGraph& pg, const py::object& options, const py::object& callback,
             const py::kwargs& overrides) {
            return SolveFromPython(pg.problem(), options, callback, overrides,
                                   [&pg](const SolverOptions& o) { return pg.Solve(o); });
          },
          py::arg("options") = py::none(), py::arg("callback") = py::none(),
          "Solves in place (boxplus::slam::PoseGraph::Solve: when restart_when_implausible is "
          "on and the solution is implausible (see chi2_per_dof), judges the loop closures by "
          "GNC and returns the inliers' optimum (outlier_mode 'auto'; outlier_report says "
          "which), or with outlier_mode 'off' also solves from the file's estimate and from a "
          "Huber-kernel solution, keeping the lowest chi2); the arguments of Problem.solve.")
      .def_property(
          "outlier_mode",
          [](const PoseGraph& pg) { return slam::OutlierModeName(pg.outlier_options().mode); },
          [](PoseGraph& pg, const std::string& mode) {
            slam::OutlierOptions o = pg.outlier_options();
            o.mode = slam::ParseOutlierMode(mode);
            pg.set_outlier_options(o);
          },
          "What solve() does about wrong loop closures: 'auto' (GNC-TLS when the "
          "least-squares solution is implausible), 'gnc-tls' or 'gnc-gm' (always), 'off' "
          "(never: the lowest least-squares minimum).")
      .def_property(
          "inlier_probability",
          [](const PoseGraph& pg) { return pg.outlier_options().inlier_probability; },
          [](PoseGraph& pg, double p) {
            slam::OutlierOptions o = pg.outlier_options();
            o.inlier_probability = p;
            pg.set_outlier_options(o);
          },
          "GNC's inlier threshold: the quantile of χ²(d) at this probability (0.99).")
      .def_property_readonly("outlier_report", &PoseGraph::outlier_report,
                             py::return_value_policy::copy, "The OutlierReport of the last solve.")
      .def("chi2_per_dof", &PoseGraph::Chi2PerDof,
           "χ² / (residuals − free tangent dimensions) at the current values: ≈ 1 for a graph "
           "whose information matrices fit its errors; NaN without degrees of freedom.")
      .def_property_readonly("has_second_start", &PoseGraph::has_second_start,
                             "Whether the next solve may also start from the file's estimate.")
      .def_property("restart_when_implausible", &PoseGraph::restart_when_implausible,
                    &PoseGraph::set_restart_when_implausible,
                    "Whether the next solve, if its solution is implausible (chi2_per_dof > "
                    "IMPLAUSIBLE_CHI2_PER_DOF), also solves from other starts and keeps the "
                    "lowest chi2: on after load_g2o(..., init='best').")
      .def(
          "chi2",
          [](const PoseGraph& pg, const std::string& convention) {
            return convention.empty() ? pg.Chi2() : pg.Chi2(ParsePoseErrorConvention(convention));
          },
          py::arg("convention") = "",
          "Σ eᵀΩe over the graph's edges at the current values ('g2o', 'log', 'compound' or "
          "'sesync'; "
          "default: the graph's convention).")
      .def(
          "poses",
          [](PoseGraph& pg) {
            return Stack(pg,
                         pg.graph().dimension == 3 ? io::VertexKind::kSE3 : io::VertexKind::kSE2);
          },
          "Current pose estimates, one ambient row per pose vertex (file order).")
      .def(
          "landmarks",
          [](PoseGraph& pg) {
            return Stack(
                pg, pg.graph().dimension == 3 ? io::VertexKind::kPoint3 : io::VertexKind::kPoint2);
          },
          "Current landmark positions, one row per point vertex (file order).")
      .def("write_back", &PoseGraph::WriteBack)
      .def("save", &PoseGraph::Save, py::arg("path"),
           "Writes the graph with the current values (file's ids, order and tags).")
      .def(
          "to_string",
          [](PoseGraph& pg) {
            pg.WriteBack();
            return io::FormatG2o(pg.graph());
          },
          "The file that save() would write.");
}

}  // namespace boxplus::python
