"""Every result type has todict(): plain Python values that json.dumps takes and that
name what the result's attributes say (#31). The C++ results convert their
properties, the Python results their fields, through one helper (boxplus/_plain.py)."""

import inspect
import json
import math
import pkgutil
import warnings

import boxplus
import boxplus.slam as slam
import numpy as np
import pytest
from boxplus import Rn
from boxplus.synthetic.pose_graphs import OUTLIER, generate

RESULT_SUFFIXES = ("Result", "Report", "Summary", "Verdict", "Uncertainty", "Suggestion",
                   "Calibration", "Validation", "Determinedness", "Rectification")


def _round_trip(d):
    assert isinstance(d, dict)
    return json.loads(json.dumps(d))


def test_every_public_result_class_has_todict():
    classes = {}
    for m in pkgutil.walk_packages(boxplus.__path__, "boxplus."):
        if any(part.startswith("_") for part in m.name.split(".")) or m.name.endswith(".cli"):
            continue
        module = __import__(m.name, fromlist=["_"])
        for name, cls in inspect.getmembers(module, inspect.isclass):
            if name.endswith(RESULT_SUFFIXES) and cls.__module__.startswith("boxplus"):
                classes[name] = cls
    for name, cls in inspect.getmembers(boxplus._core, inspect.isclass):
        if name.endswith(RESULT_SUFFIXES):
            classes[name] = cls
    assert {"CertifyResult", "OutlierReport", "LoadReport", "EdgeVerdict", "RestartResult",
            "TaskResult", "RigResult", "CameraImuCalibration", "ProjectionUncertainty",
            "ViewSuggestion", "CrossValidation", "Determinedness"} <= set(classes)
    missing = sorted(n for n, c in classes.items() if not callable(getattr(c, "todict", None)))
    assert not missing, missing


def test_pose_graph_results(tmp_path):
    generated = generate("manhattan", 2, 300, noise="medium", outlier_fraction=0.2, seed=1)
    path = tmp_path / "g.g2o"
    generated.write(path)
    graph = slam.load_g2o(path)
    summary = graph.solve()
    report = _round_trip(graph.outlier_report.todict())
    assert report["ran"] and report["method"] == "gnc-tls"
    wrong = set(map(tuple, generated.edges[generated.kind == OUTLIER].tolist()))
    assert {(v["from_id"], v["to_id"]) for v in report["outliers"]} == wrong
    first = report["outliers"][0]
    assert set(first) == {"edge", "line", "from_id", "to_id", "weight", "chi2"}
    assert first["line"] == graph.outliers[0].line
    load = _round_trip(graph.report.todict())
    assert load["lines"] == len(path.read_text().splitlines()) and load["start"] in (
        "file", "chordal", "spanning-tree")
    assert _round_trip(summary.todict())["iterations"] == summary.iterations

    clean = tmp_path / "clean.g2o"
    generate("manhattan", 2, 300, noise="medium", seed=1).write(clean)
    g = slam.load_g2o(clean, convention="sesync")
    g.solve()
    cert = g.certify().todict()
    assert cert["objective"] == pytest.approx(g.certify().objective)
    assert isinstance(json.dumps(cert), str)  # NaN (lambda_min) is written as NaN


def test_determinedness_names_the_free_directions():
    o = boxplus.OptimizationProblem()
    a = o.add_random_var(Rn(2), name="a")
    b = o.add_random_var(Rn(2), name="b")
    o.add_measurement(np.zeros(2), lambda a, b: b - a, [a, b], sigma=1.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        o.solve()
    d = _round_trip(o.check_determined().todict())
    assert d["determined"] is False and d["nullity"] == 2 and d["num_columns"] == 4
    assert sorted(u["variable"] for u in d["undetermined"]) == sorted([a, b])
    assert np.asarray(d["undetermined"][0]["directions"]).shape == (2, 2)


def test_python_results():
    from boxplus.calib.camera_imu import calibrate_camera_imu
    from boxplus.parallel import solve_many
    from boxplus.restarts import solve_with_restarts
    from boxplus.synthetic.camera_imu import simulate_camera_imu

    def problem():
        o = boxplus.OptimizationProblem()
        x = o.add_random_var(Rn([1.0]), name="x")
        o.add_measurement(np.array([2.0]), lambda x: x.vec * x.vec, [x], sigma=0.1)
        return o

    restarts = _round_trip(solve_with_restarts(problem(), 3, seed=1).todict())
    assert len(restarts["costs"]) == 4 and restarts["best"]["termination"]
    tasks = solve_many([problem(), problem()], extract=lambda o, s: float(o.value(0).vec[0]))
    t = _round_trip(tasks[0].todict())
    assert t["error"] is None and abs(t["value"]) == pytest.approx(math.sqrt(2), rel=1e-6)

    data, truth, K = simulate_camera_imu(np.random.default_rng(0), duration=3.0)
    cal = calibrate_camera_imu(data, K, pixel_sigma=0.3)
    d = _round_trip(cal.todict())
    assert d["imu_from_cam"] == pytest.approx(np.asarray(cal.imu_from_cam.ambient).tolist())
    assert d["time_offset"] == cal.time_offset and len(d["std"]["imu_from_cam"]) == 6
    assert d["summary"]["termination"] == "convergence" and d["knots"] > 4
