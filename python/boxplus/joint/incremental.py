"""Incremental (one group at a time) calibration, for comparison with joint calibration.

The standard procedure of Le & Ng's Fig. 1 and Fig. 8: calibrate one group of
sensors, hold its result fixed, calibrate the next group with it, ..., and
finally the transforms between the groups with every intrinsic parameter
fixed. Each step is a solve of the same :class:`JointCalibration` restricted
to some systems; a parameter shared with an earlier step keeps the earlier
step's value (e.g. camera 1 calibrated with the stereo pair, then used as is
by the laser–camera system).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from boxplus.joint.calibrator import JointCalibration, JointResult

__all__ = ["EXTRINSICS", "calibrate_incrementally"]

EXTRINSICS = "extrinsics"


def calibrate_incrementally(
    jc: JointCalibration,
    steps: Sequence[str | Sequence[str]],
    restarts: int = 0,
    seed: int = 0,
    **solve_kw: Any,
) -> list[JointResult]:
    """Runs ``steps`` in order, each fixing what the earlier ones estimated.

    Parameters
    ----------
    jc : JointCalibration
        Systems and data; its values are updated step by step.
    steps : sequence
        Each a sequence of system names (their intrinsic terms and the links
        among them), or :data:`EXTRINSICS` ("extrinsics"): the poses of all
        systems from all links, every intrinsic parameter fixed.
    restarts, seed, **solve_kw
        Passed to every :meth:`JointCalibration.solve`.

    Returns
    -------
    list of JointResult
        One per step.
    """
    if not steps:
        raise ValueError("calibrate_incrementally: no steps")
    done: set = set()
    out = []
    for k, step in enumerate(steps):
        if isinstance(step, str):
            if step != EXTRINSICS:
                raise ValueError(f"step {k}: expected a list of systems or '{EXTRINSICS}', got '{step}'")
            fixed = set(jc.values)
            r = jc.solve(None, True, fixed, restarts=restarts, seed=seed + k, **solve_kw)
        else:
            names = list(step)
            r = jc.solve(names, len(names) > 1, done, restarts=restarts, seed=seed + k, **solve_kw)
            for s in names:
                done.update(jc.parameter_keys(s))
        out.append(r)
    return out
