"""boxplus.solve_many on every kind of executor: the serial answer to the last bit,
per-task seeds, task errors reported, worker failures retried (a bounded number
of times) and reported by task."""

import concurrent.futures
import multiprocessing
import os
import sys

import boxplus as bp
import numpy as np
import pytest
from boxplus.parallel import map_tasks, solve_many


def build(seed, rng=None):
    """A small pose chain with C++ factors; its start drawn from ``rng`` when given."""
    rng_truth = np.random.default_rng(seed)
    start = rng if rng is not None else np.random.default_rng(1000 + seed)
    o = bp.OptimizationProblem()
    truth = [bp.SE3(bp.SO3.exp(rng_truth.normal(0, 0.5, 3)), rng_truth.normal(0, 2, 3)) for _ in range(8)]
    ids = [o.add_random_var(t + start.normal(0, 0.2, 6)) for t in truth]
    o.add_prior(ids[0], truth[0], sigma=0.01)
    for i in range(7):
        o.add_relative_pose(truth[i].inverse() * truth[i + 1] + rng_truth.normal(0, 0.01, 6),
                            ids[i], ids[i + 1], sigma=0.01)
    return o


def build_every_kind(seed, rng=None):
    """One variable of every kind (Rn, SO2, SO3, SE2, SE3, S2, a Plane and a Line
    compound), each pulled towards a noisy truth (C++ priors for the built-in kinds, a
    Python measurement for the compounds), so that a process worker must rebuild every
    kind from its pickled values."""
    from boxplus.joint import Line, Plane

    rng_truth = np.random.default_rng(seed)
    start = rng if rng is not None else np.random.default_rng(1000 + seed)
    truth = [bp.Rn(rng_truth.normal(size=3)), bp.SO2(rng_truth.uniform(-3, 3)),
             bp.SO3.exp(rng_truth.normal(size=3)), bp.SE2(rng_truth.normal(size=2), 0.3),
             bp.SE3(bp.SO3.exp(rng_truth.normal(size=3)), rng_truth.normal(size=3)),
             bp.S2(rng_truth.normal(size=3)),
             Plane(normal=bp.S2(rng_truth.normal(size=3)), distance=bp.Rn([0.7])),
             Line(direction=bp.S2(rng_truth.normal(size=3)), point=bp.Rn(rng_truth.normal(size=3)))]
    o = bp.OptimizationProblem()
    for t in truth:
        vid = o.add_random_var(t + start.normal(0, 0.3, t.dof))
        z = t + rng_truth.normal(0, 0.01, t.dof)
        if isinstance(t, (Plane, Line)):
            o.add_measurement(z, _itself, [vid], sigma=0.05)
        else:
            o.add_prior(vid, z, sigma=0.05)
    return o


def _itself(x):
    return x


def ambient(o, summary=None):
    return [np.asarray(o._core.value(v)) for v in range(o.num_variables)]


def broken(seed, rng=None):
    if seed == 2:
        raise ValueError("rig 2 has no data")
    return build(seed, rng)


def _same(a, b):
    return len(a) == len(b) and all(np.array_equal(u, v) for u, v in zip(a, b))


def _check_same(results, reference):
    assert [r.index for r in results] == list(range(len(reference)))
    for r, ref in zip(results, reference):
        assert r.ok, r.error
        assert _same(r.value, ref.value), f"task {r.index}"
        assert r.summary.final_cost == ref.summary.final_cost


def test_problems_serially_are_solved_in_place():
    problems = [build(s) for s in range(4)]
    results = solve_many(problems)
    for p, r in zip(problems, results):
        assert r.ok and r.value is p and r.summary.usable and r.attempts == 1
    fresh = build(0)
    fresh.solve()
    assert _same(ambient(problems[0]), ambient(fresh))


@pytest.mark.parametrize("kind", ["thread", "process"])
def test_executors_give_the_serial_answer_bit_for_bit(kind):
    reference = solve_many(build, range(6), seed=11, extract=ambient)
    if kind == "thread":
        pool = concurrent.futures.ThreadPoolExecutor(2)
    else:
        pool = concurrent.futures.ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("spawn"))
    with pool:
        _check_same(solve_many(build, range(6), seed=11, extract=ambient, executor=pool), reference)
        # ready problems travel pickled to processes and come back solved
        problems = solve_many([build(s, np.random.default_rng([11, s])) for s in range(6)], executor=pool,
                              extract=ambient)
        _check_same(problems, reference)
    # the builder pair form and a different seed
    assert solve_many((build, range(2)), seed=11, extract=ambient)[1].value[3].tolist() == \
        reference[1].value[3].tolist()
    other = solve_many(build, range(2), seed=12, extract=ambient)
    assert not _same(other[1].value, reference[1].value)


def test_every_kind_of_value_solves_in_a_process_as_in_this_one():
    # the starts and the journal's values travel pickled: each comes back with its
    # exact numbers, so a worker's solve is this process' solve to the last bit
    reference = solve_many(build_every_kind, range(3), seed=5, extract=ambient)
    pool = concurrent.futures.ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("spawn"))
    with pool:
        _check_same(solve_many(build_every_kind, range(3), seed=5, extract=ambient, executor=pool),
                    reference)


def test_task_errors_are_reported_by_task_and_not_retried():
    results = solve_many(broken, range(4), seed=0, extract=ambient, retries=3)
    assert [r.ok for r in results] == [True, True, False, True]
    bad = results[2]
    assert "ValueError: rig 2 has no data" in bad.error and "Traceback" in bad.error
    assert bad.attempts == 1 and not bad.worker_failed


class FlakyExecutor(concurrent.futures.Executor):
    """Loses the first ``lose[i]`` submissions of task i as a dead worker would."""

    def __init__(self, lose):
        self.lose = dict(lose)
        self.submitted = []

    def submit(self, fn, /, *args, **kwargs):
        index = args[1]  # map_tasks submits _run(fn, index, args)
        self.submitted.append(index)
        f = concurrent.futures.Future()
        if self.lose.get(index, 0) > 0:
            self.lose[index] -= 1
            f.set_exception(ConnectionResetError(f"worker running task {index} died"))
        else:
            f.set_result(fn(*args, **kwargs))
        return f


def test_worker_failures_are_retried_then_reported():
    reference = solve_many(build, range(4), seed=3, extract=ambient)
    flaky = FlakyExecutor({1: 2, 3: 5})
    results = solve_many(build, range(4), seed=3, extract=ambient, executor=flaky, retries=2)
    assert [r.attempts for r in results] == [1, 3, 1, 3]
    _check_same(results[:3], reference[:3])
    lost = results[3]
    assert not lost.ok and lost.worker_failed and lost.value is None
    assert "worker failure after 3 attempts: ConnectionResetError: worker running task 3 died" in lost.error
    assert sorted(flaky.submitted) == [0, 1, 1, 1, 2, 3, 3, 3]


def _die(i):
    if i == 1:
        os._exit(3)
    return i * i


def test_a_dead_process_is_reported_not_raised():
    # A process pool is broken for good once a worker dies: the resubmission is
    # refused, and every task reports what happened instead of raising.
    ctx = multiprocessing.get_context("spawn")
    with concurrent.futures.ProcessPoolExecutor(1, mp_context=ctx) as pool:
        results = map_tasks(_die, [(i,) for i in range(3)], executor=pool, retries=1)
    assert results[0].ok and results[0].value == 0
    assert results[1].worker_failed and "BrokenProcessPool" in results[1].error


def test_bad_arguments_are_named():
    with pytest.raises(TypeError, match="a builder needs its inputs"):
        solve_many(build)
    with pytest.raises(TypeError, match="problem 1 is a int"):
        solve_many([build(0), 3])
    with pytest.raises(TypeError, match="inputs go with a builder"):
        solve_many([build(0)], [1])
    with pytest.raises(ValueError, match="retries must be a non-negative integer"):
        solve_many([build(0)], retries=-1)
    with pytest.raises(TypeError, match="executor must be None"):
        solve_many([build(0)], executor=object())


def test_solve_many_refuses_the_same_problem_twice():
    o = build(0)
    with pytest.raises(ValueError, match="same problem object is listed twice"):
        solve_many([o, o])


def test_ray_and_dask_are_not_imported_by_boxplus():
    import subprocess

    code = "import sys, boxplus; print(sorted(m for m in ('ray', 'dask', 'distributed') if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def _cv_fit(split):
    if len(split["items"]) < 4:
        raise ValueError("too few items to fit (a user's own error)")
    return float(np.mean(split["items"]))


def _cv_validate(model, split):
    return np.abs(np.asarray(split["items"], float) - model)


def test_restarts_and_folds_fan_out_through_one_executor_path():
    # solve_with_restarts and cross_validate run their tasks through parallel.map_values:
    # the same answer as serially, and a task's own error comes back with its traceback
    from boxplus.crossval import cross_validate
    from boxplus.parallel import TaskError
    from boxplus.restarts import solve_with_restarts

    def problem():
        o = bp.OptimizationProblem()
        x = o.add_random_var(bp.Rn([0.3]), name="x")
        o.add_measurement(np.array([2.0]), lambda x: x.vec ** 2, [x], sigma=0.1)
        return o

    serial = solve_with_restarts(problem(), 4, seed=3, factory=problem)
    with concurrent.futures.ThreadPoolExecutor(2) as pool:
        threaded = solve_with_restarts(problem(), 4, seed=3, factory=problem, executor=pool)
        folds = [({"items": list(range(k, k + 6))}, {"items": [k + 7]}) for k in range(3)]
        a = cross_validate({"mean": _cv_fit}, _cv_validate, folds=folds, executor=pool)
        b = cross_validate({"mean": _cv_fit}, _cv_validate, folds=folds)
        assert a.fold_errors == b.fold_errors
        bad = folds + [({"items": [1, 2]}, {"items": [3]})]
        with pytest.raises(TaskError, match=r"(?s)cross_validate: task 3 failed:.*_cv_fit.*"
                                            r"ValueError: too few items to fit"):
            cross_validate({"mean": _cv_fit}, _cv_validate, folds=bad, executor=pool)
    assert threaded.costs == serial.costs
