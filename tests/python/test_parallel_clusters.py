"""A small fleet (examples/fleet_calibration.py) on a local Dask and a local Ray
cluster: the serial answer to the last bit, the broken rigs named. Skipped only
when the package is not installed (`make venv` installs both)."""

import importlib
import os
import sys
from pathlib import Path

import boxplus as bp
import numpy as np
import pytest

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.fixture(scope="module")
def ex():
    # The workers import the example by name, like the library: its folder goes on
    # this process' path (spawned Dask workers inherit it) and on PYTHONPATH (Ray's
    # workers inherit the environment).
    saved_path, saved_env = list(sys.path), os.environ.get("PYTHONPATH")
    sys.path.insert(0, str(EXAMPLES))
    os.environ["PYTHONPATH"] = os.pathsep.join(filter(None, [str(EXAMPLES), saved_env]))
    try:
        yield importlib.import_module("fleet_calibration")
    finally:
        sys.path[:] = saved_path
        if saved_env is None:
            os.environ.pop("PYTHONPATH", None)
        else:
            os.environ["PYTHONPATH"] = saved_env


@pytest.fixture(scope="module")
def small_fleet(ex):
    rigs = ex.fleet(6, seed=4, faults={1: "nan", 4: "oneview"})
    return rigs, ex.run_fleet(rigs)


def _check(ex, rigs, results, serial):
    assert ex.same_bits(results, serial)
    bad = ex.verdicts(results, rigs)
    assert sorted(bad) == [rigs[1].name, rigs[4].name] == ["rig-0001-nan", "rig-0004-oneview"]
    assert "failed:" in bad["rig-0001-nan"] and "non-finite" in bad["rig-0001-nan"]
    assert bad["rig-0004-oneview"].startswith("degenerate: not determined by the data")
    assert "k_right" in bad["rig-0004-oneview"]


def test_serial_fleet_is_accurate(ex, small_fleet):
    # Each rig against its own truth, within 4σ of what boxplus reports.
    rigs, serial = small_fleet
    bad = ex.verdicts(serial, rigs)
    checked = 0
    for r, rig in zip(serial, rigs):
        if rig.name in bad:
            continue
        v, sd, t = r.value["values"], r.value["std"], rig.truth
        for cam in ("k_left", "k_right"):  # fx fy cx cy
            assert np.all(np.abs(v[cam][:4] - t[cam][:4]) < 4 * sd[cam][:4]), (rig.name, cam)
        d = v["right_from_left"][:3] - t["right_from_left"].pos
        assert np.all(np.abs(d) < 4 * sd["right_from_left"][:3]), rig.name
        dr = (t["imu_from_rig"].rot.inverse() * bp.SE3.from_ambient(v["imu_from_rig"]).rot).log()
        assert np.all(np.abs(dr) < 4 * sd["imu_from_rig"][3:]), rig.name
        checked += 1
    assert checked == 4 == len(ex.accuracy(serial, rigs))


def test_dask_local_cluster(ex, small_fleet):
    pytest.importorskip("distributed")
    rigs, serial = small_fleet
    client, close = ex._dask_executor(2, None)
    try:
        _check(ex, rigs, ex.run_fleet(rigs, client), serial)
        _check(ex, rigs, ex.run_fleet(rigs, client.get_executor()), serial)
    finally:
        close()


def test_ray_local_cluster(ex, small_fleet):
    pytest.importorskip("ray")
    rigs, serial = small_fleet
    executor, close = ex._ray_executor(2, None)
    try:
        _check(ex, rigs, ex.run_fleet(rigs, executor), serial)
        from ray.util.multiprocessing import Pool

        with Pool(processes=2) as pool:
            _check(ex, rigs, ex.run_fleet(rigs, pool), serial)
    finally:
        close()


def test_fleet_plot(ex, small_fleet, tmp_path):
    pytest.importorskip("matplotlib")
    rigs, serial = small_fleet
    ex.plot_accuracy(ex.accuracy(serial, rigs), tmp_path / "fleet.png")
    assert (tmp_path / "fleet.png").stat().st_size > 10_000
    assert np.isfinite([v for e in ex.accuracy(serial, rigs) for v in e.values()]).all()
