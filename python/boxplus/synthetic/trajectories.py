"""True trajectories and loop-closure candidates of the generator's families.

Each family returns the true poses of a robot in the order it visits them
(ambient rows as in g2o files, see :mod:`boxplus.synthetic.se_arrays`) and the
pairs ``(i, j)``, ``i < j − 1``, that a loop closure may connect. Lengths are
in units of ``step`` metres (the distance between consecutive poses, 1 m by
default); angles in radians.

Families (see :data:`FAMILIES`):

``manhattan``
    g2o's simulator / Olson's M3500: the robot drives streets of a square (2D)
    or cubic (3D) lattice of blocks ``block`` steps long, turns at
    intersections (2D: straight ½, left ¼, right ¼; 3D: straight ⅓, yaw ±90°
    or pitch ±90° ⅙ each) and never leaves the town. Candidates: revisits.
``grid``
    A lawn-mower sweep over a square lattice (3D: a stack of layers, each swept
    back along the previous one). Candidates: the lattice neighbour one row
    back (and one layer down) — every pose of a dense grid graph.
``sphere``
    3D: g2o's ``create_sphere`` (rings of poses on a sphere, heading along the
    ring, rising with every pose); 2D: its planar analogue, rings on a spiral
    of concentric circles. Candidates: each pose to the three nearest poses of
    the next ring, as ``create_sphere``.
``torus``
    Rings of poses around the tube of a torus that advance along the torus'
    major circle (2D: the planar epicycle with the same graph). Candidates:
    ring to next ring as ``sphere``, and the last ring to the first (the torus
    closes).
``random_walk``
    A random walk with forward steps of ``step`` and heading changes
    ~ N(0, turn²) per step (3D: rotation vector ~ N(0, turn² I)), folded
    (mirrored) into a box so the robot keeps coming back. Candidates: revisits.

A revisit of pose ``j`` by pose ``k`` (``manhattan``, ``random_walk``): ``j ≤
k − min_gap`` and both lie in the same cell of a lattice of ``radius``-sized
cells and within ``radius`` of each other; each pose gets at most one such
candidate, an earlier visit drawn uniformly.
"""

from __future__ import annotations

import bisect
import inspect
from dataclasses import dataclass
from typing import Callable

import numpy as np

from . import se_arrays as se

__all__ = ["FAMILIES", "Trajectory", "revisits", "trajectory"]


@dataclass
class Trajectory:
    """True poses (N × 3 or N × 7) and loop-closure candidate pairs (K × 2, i < j)."""

    poses: np.ndarray
    candidates: np.ndarray


def _yaw_pose(xy_or_xyz: np.ndarray, yaw: np.ndarray, dim: int) -> np.ndarray:
    if dim == 2:
        return np.column_stack([xy_or_xyz[:, :2], se.wrap_angle(yaw)])
    half = 0.5 * yaw
    z = np.zeros_like(yaw)
    return np.column_stack([xy_or_xyz[:, :3], z, z, np.sin(half), np.cos(half)])


def _quat_zy(rz: np.ndarray, ry: np.ndarray) -> np.ndarray:
    """Quaternions of ``Rz(rz) Ry(ry)`` (x y z w)."""
    cz, sz = np.cos(0.5 * rz), np.sin(0.5 * rz)
    cy, sy = np.cos(0.5 * ry), np.sin(0.5 * ry)
    return np.column_stack([-sz * sy, cz * sy, sz * cy, cz * cy])


# -- revisits -----------------------------------------------------------------
def revisits(positions: np.ndarray, radius: float, min_gap: int,
             rng: np.random.Generator) -> np.ndarray:
    """Pairs ``(j, k)``: pose k revisits an earlier pose j (module docstring)."""
    n = len(positions)
    cells = np.floor(positions / radius).astype(np.int64)
    cells -= cells.min(axis=0)
    span = cells.max(axis=0) + 1
    cell = np.zeros(n, np.int64)
    for axis in range(positions.shape[1]):
        cell = cell * int(span[axis]) + cells[:, axis]
    key = cell * n + np.arange(n)
    order = np.argsort(key, kind="stable")
    sorted_key = key[order]
    start = np.searchsorted(sorted_key, cell * n, side="left")
    # Earlier members of k's cell that are at least min_gap poses back.
    count = np.searchsorted(sorted_key, cell * n + np.arange(n) - min_gap, side="right") - start
    u = rng.random(n)
    has = count > 0
    k = np.nonzero(has)[0]
    j = order[start[k] + np.floor(u[k] * count[k]).astype(np.int64)]
    close = np.linalg.norm(positions[k] - positions[j], axis=1) <= radius
    return np.column_stack([j[close], k[close]])


def _lattice_neighbours(lattice: np.ndarray) -> np.ndarray:
    """Pairs (j, k), j < k − 1, of poses one lattice unit apart along an axis."""
    n = len(lattice)
    lattice = lattice - lattice.min(axis=0)
    span = lattice.max(axis=0) + 2
    flat = np.zeros(n, np.int64)
    for axis in range(lattice.shape[1]):
        flat = flat * int(span[axis]) + lattice[:, axis]
    index = np.full(int(np.prod(span)), -1, np.int64)
    index[flat] = np.arange(n)
    pairs = []
    for axis in range(lattice.shape[1]):
        below = lattice.copy()
        below[:, axis] -= 1
        ok = below[:, axis] >= 0
        fb = np.zeros(n, np.int64)
        for a in range(lattice.shape[1]):
            fb = fb * int(span[a]) + np.where(ok, below[:, a], 0)
        j = np.where(ok, index[fb], -1)
        k = np.arange(n)
        keep = (j >= 0) & (j < k - 1)
        pairs.append(np.column_stack([j[keep], k[keep]]))
        keep = (j > k + 1)  # the lattice neighbour visited later: edge from k to j
        pairs.append(np.column_stack([k[keep], j[keep]]))
    p = np.concatenate(pairs)
    return p[np.lexsort((p[:, 0], p[:, 1]))]


# -- families -----------------------------------------------------------------
def _turn_group(dim: int):
    """The rotations a lattice robot can take: matrices, heading, and the turn table."""
    if dim == 2:
        turns = [np.eye(2, dtype=int), np.array([[0, -1], [1, 0]]), np.array([[0, 1], [-1, 0]])]
        weights = [0.5, 0.25, 0.25]
    else:
        rz = np.array([[0, -1, 0], [1, 0, 0], [0, 0, 1]])
        ry = np.array([[0, 0, 1], [0, 1, 0], [-1, 0, 0]])
        turns = [np.eye(3, dtype=int), rz, rz.T, ry, ry.T]
        weights = [1 / 3] + [1 / 6] * 4
    group = [np.eye(dim, dtype=int)]
    table = []
    i = 0
    while i < len(group):
        row = []
        for t in turns:
            r = group[i] @ t
            g = next((j for j, m in enumerate(group) if np.array_equal(m, r)), None)
            if g is None:
                group.append(r)
                g = len(group) - 1
            row.append(g)
        table.append(row)
        i += 1
    heading = [tuple(int(v) for v in m[:, 0]) for m in group]
    return group, heading, table, weights


def _manhattan(dim: int, n: int, rng: np.random.Generator, step: float, block: int = 5,
               radius: float = 0.5, min_gap: int = 10) -> Trajectory:
    group, heading, table, weights = _turn_group(dim)
    segments = -(-n // block) + 1
    side = max(2, int(round((n / (block * (4 if dim == 2 else 6))) ** (1.0 / dim))))
    u = rng.random(segments).tolist()
    # Per orientation: the orientations reachable by a turn, as (next, axis, sign) of
    # their heading (a signed unit axis), and the cumulative turn weights.
    moves = []
    for row in table:
        opts = []
        for t, r in enumerate(row):
            axis = next(a for a in range(dim) if heading[r][a])
            opts.append((r, axis, heading[r][axis], weights[t]))
        moves.append((opts, np.cumsum([o[3] for o in opts]).tolist()))
    axis_of = [next(a for a in range(dim) if h[a]) for h in heading]
    pos = [side // 2] * dim
    rot = 0
    starts, rots = [], []
    # Sequential over intersections only (n / block of them): where the robot may
    # turn depends on where it is.
    for s in range(segments):
        opts, cum = moves[rot]
        if min(pos) >= 1 and max(pos) <= side - 1:  # inside: every turn is allowed
            pick = opts[bisect.bisect_right(cum, u[s] * cum[-1])][0]
        else:
            # Never empty: of the headings other than back, one points inwards.
            ok = [o for o in opts if 0 <= pos[o[1]] + o[2] <= side]
            total = sum(o[3] for o in ok)
            pick, acc = ok[-1][0], 0.0
            for o in ok:
                acc += o[3] / total
                if u[s] < acc:
                    pick = o[0]
                    break
        rot = pick
        starts.append(tuple(pos))
        rots.append(rot)
        pos[axis_of[rot]] += heading[rot][axis_of[rot]]
    start_of, rot_of = np.array(starts, np.int64), np.array(rots, np.int64)
    k = np.arange(segments * block)[:n]
    seg, off = k // block, k % block
    dirs = np.array(heading)[rot_of[seg]]
    lattice = start_of[seg] * block + off[:, None] * dirs
    positions = lattice * step
    if dim == 2:
        yaw = np.arctan2(dirs[:, 1], dirs[:, 0])
        poses = np.column_stack([positions, yaw])
    else:
        quats = se.quat_from_matrix(np.array(group, float))
        poses = np.column_stack([positions, quats[rot_of[seg]]])
    return Trajectory(poses, revisits(positions, radius * step, min_gap, rng))


def _snake(m: np.ndarray, width: int) -> np.ndarray:
    """Lattice (column, row) of the m-th cell of a boustrophedon over width columns."""
    row, col = m // width, m % width
    return np.column_stack([np.where(row % 2 == 0, col, width - 1 - col), row])


def _grid(dim: int, n: int, rng: np.random.Generator, step: float) -> Trajectory:
    k = np.arange(n)
    if dim == 2:
        width = int(np.ceil(np.sqrt(n)))
        lattice = _snake(k, width)
    else:
        width = int(np.ceil(n ** (1.0 / 3.0)))
        per = width * width
        layer, m = k // per, k % per
        m = np.where(layer % 2 == 0, m, per - 1 - m)  # odd layers retrace the sweep
        lattice = np.column_stack([_snake(m, width), layer])
    positions = lattice * step
    d = np.diff(positions[:, :2], axis=0)
    moving = np.any(d != 0, axis=1)
    yaw = np.where(moving, np.arctan2(d[:, 1], d[:, 0]), 0.0)
    # A vertical move keeps the previous heading: forward-fill the last horizontal one.
    last = np.maximum.accumulate(np.where(moving, np.arange(len(d)), 0))
    yaw = np.concatenate([yaw[last], yaw[last[-1:]]]) if len(d) else np.zeros(1)
    return Trajectory(_yaw_pose(positions, yaw, dim), _lattice_neighbours(lattice))


def _rings(n: int):
    per_level = max(3, int(np.ceil(np.sqrt(n))))
    laps = -(-n // per_level)
    return per_level, laps


def _ring_candidates(n: int, per_level: int, laps: int, wrap: bool) -> np.ndarray:
    """create_sphere's edges from pose nn of ring f − 1 to poses nn − 1, nn, nn + 1 of ring f."""
    f = np.arange(1, laps + (1 if wrap else 0))
    nn = np.arange(per_level)
    off = np.array([-1, 0, 1])
    F, NN, O = np.meshgrid(f, nn, off, indexing="ij")
    src = (F - 1) * per_level + NN
    dst = F * per_level + NN + O
    if wrap:
        dst = np.where(F == laps, NN + O, dst) % (laps * per_level)
    else:
        dst = np.where((F == laps - 1) & (O == 1), -1, dst)  # as create_sphere
    src, dst = src.ravel(), dst.ravel()
    ok = (dst >= 0) & (dst < n) & (src < n) & (np.abs(dst - src) > 1)
    lo, hi = np.minimum(src[ok], dst[ok]), np.maximum(src[ok], dst[ok])
    key = np.sort(lo.astype(np.int64) * n + hi)
    key = key[np.concatenate([[True], key[1:] != key[:-1]])]  # a tiny ring repeats pairs
    return np.column_stack([key // n, key % n])


def _sphere(dim: int, n: int, rng: np.random.Generator, step: float) -> Trajectory:
    per_level, laps = _rings(n)
    k = np.arange(n)
    nn = k % per_level
    # create_sphere: 50 poses per ring on a 100 m sphere; keep that ratio.
    radius = 2.0 * per_level * step
    if dim == 3:
        rotz = -np.pi + 2.0 * np.pi * nn / per_level
        roty = -0.5 * np.pi + (k + 1) * np.pi / (laps * per_level)  # g2o's id is already + 1
        q = _quat_zy(rotz, roty)
        t = se.quat_rotate(q, np.tile([radius, 0.0, 0.0], (n, 1)))
        poses = np.column_stack([t, q])
    else:
        phi = 2.0 * np.pi * nn / per_level
        r = radius * (1.0 + np.pi * k / (laps * per_level))  # spiral outwards ring by ring
        poses = np.column_stack([r * np.cos(phi), r * np.sin(phi), phi + 0.5 * np.pi])
    return Trajectory(poses, _ring_candidates(n, per_level, laps, wrap=False))


def _torus(dim: int, n: int, rng: np.random.Generator, step: float) -> Trajectory:
    per_level, laps = _rings(n)
    k = np.arange(n)
    v = 2.0 * np.pi * (k % per_level) / per_level
    u = 2.0 * np.pi * k / (laps * per_level)
    minor = per_level * step / np.pi
    major = 3.0 * minor * max(1.0, laps / per_level)
    if dim == 3:
        q = _quat_zy(u, v)
        centre = np.column_stack([major * np.cos(u), major * np.sin(u), np.zeros(n)])
        t = centre + se.quat_rotate(q, np.tile([minor, 0.0, 0.0], (n, 1)))
        poses = np.column_stack([t, q])
    else:
        x = major * np.cos(u) + minor * np.cos(u + v)
        y = major * np.sin(u) + minor * np.sin(u + v)
        poses = np.column_stack([x, y, u + v + 0.5 * np.pi])
    wrap = n == laps * per_level
    return Trajectory(poses, _ring_candidates(n, per_level, laps, wrap=wrap))


def _fold(x: np.ndarray, side: float):
    """Mirror x into [0, side] (a triangle wave) and the sign of the mirrored motion."""
    m = np.mod(x, 2.0 * side)
    return np.where(m <= side, m, 2.0 * side - m), np.where(m <= side, 1.0, -1.0)


def _random_walk(dim: int, n: int, rng: np.random.Generator, step: float, turn: float = 0.2,
                 radius: float = 1.0, min_gap: int = 10) -> Trajectory:
    # A box of 1 step² (2D) or ½ step³ (3D) per pose: one revisit candidate for
    # about every third pose, at every size.
    side = (n * (1.0 if dim == 2 else 0.5)) ** (1.0 / dim) * step
    forward = np.zeros((n - 1, dim))
    forward[:, 0] = step
    if dim == 2:
        heading = np.concatenate([[0.0], np.cumsum(rng.normal(0.0, turn, n - 1))])
        moves = np.column_stack([np.cos(heading[1:]), np.sin(heading[1:])]) * step
        free = 0.5 * side + np.concatenate([np.zeros((1, 2)), np.cumsum(moves, axis=0)])
        xy, sign = _fold(free, side)
        yaw = np.arctan2(sign[:, 1] * np.sin(heading), sign[:, 0] * np.cos(heading))
        poses = np.column_stack([xy, yaw])
    else:
        spins = np.concatenate([np.zeros((n - 1, 3)),
                                se.quat_from_rotation_vector(rng.normal(0.0, turn, (n - 1, 3)))],
                               axis=1)
        start = np.array([0.5 * side] * 3 + [0.0, 0.0, 0.0, 1.0])
        frames = se.prefix_compose(start, spins, 3)
        q = frames[:, 3:]
        moves = se.quat_rotate(q[1:], np.tile([step, 0.0, 0.0], (n - 1, 1)))
        free = start[:3] + np.concatenate([np.zeros((1, 3)), np.cumsum(moves, axis=0)])
        xyz, sign = _fold(free, side)
        # The mirrored frame S R has det S = ±1; flipping its y axis when det S = −1 keeps
        # a rotation whose x axis (the heading) is the mirrored motion.
        R = se.matrix_from_quat(q) * sign[:, :, None]
        R[:, :, 1] *= np.prod(sign, axis=1)[:, None]
        poses = np.column_stack([xyz, se.quat_from_matrix(R)])
    return Trajectory(poses, revisits(poses[:, :dim], radius * step, min_gap, rng))


#: Family name → function ``(dim, n, rng, step, **options) -> Trajectory``.
FAMILIES: dict[str, Callable[..., Trajectory]] = {
    "manhattan": _manhattan,
    "grid": _grid,
    "sphere": _sphere,
    "torus": _torus,
    "random_walk": _random_walk,
}


def trajectory(family: str, dim: int, n: int, rng: np.random.Generator, step: float = 1.0,
               **options: float) -> Trajectory:
    """The true poses and candidates of ``family`` (see the module docstring)."""
    if family not in FAMILIES:
        raise ValueError(f"unknown family {family!r}; known: {', '.join(FAMILIES)}")
    make = FAMILIES[family]
    params = inspect.signature(make).parameters
    known = list(params)[4:]
    for name, value in options.items():
        if name not in known:
            raise TypeError(f"family {family!r} has no option {name!r}; its options: "
                            f"{', '.join(known) or 'none'}")
        if not (np.isfinite(value) and value > 0):
            raise ValueError(f"family option {name} must be finite and positive, got {value!r}")
        if isinstance(params[name].default, int) and value != int(value):
            raise ValueError(f"family option {name} must be an integer, got {value!r}")
        if name == "min_gap" and value < 2:
            raise ValueError(f"family option min_gap must be at least 2, got {value!r}")
    options = {k: int(v) if isinstance(params[k].default, int) else float(v)
               for k, v in options.items()}
    return make(dim, n, rng, step, **options)
