"""Seeded pose-graph generator: g2o files with their ground truth beside them.

>>> from boxplus.synthetic.pose_graphs import generate
>>> g = generate("sphere", 3, 2500, noise=(0.1, 0.05), seed=3)
>>> g.write("sphere.g2o")              # initial estimate: odometry composed
>>> g.write_truth("sphere_truth.g2o")  # the same edges, the true poses

Command line::

    python -m boxplus.synthetic.pose_graphs --family sphere --poses 2500 --noise 0.1,0.05 \\
        --seed 3 -o out.g2o            # also writes out_truth.g2o

Families (:mod:`boxplus.synthetic.trajectories` describes their geometry):
``manhattan`` (streets of a lattice town, g2o's simulator / M3500), ``grid``
(a lawn-mower sweep, dense lattice closures), ``sphere`` (g2o's
``create_sphere``), ``torus`` (rings around a torus' tube, closing on
itself), ``random_walk`` (a folded random walk with revisits). Each in 2D and
3D; distances in metres, angles in radians.

Noise model
-----------
Poses are SE(2) ``[x, y, θ]`` or SE(3) ``[t, qx, qy, qz, qw]`` (quaternion
x y z w); tangent order [translation, rotation] (translation first). For every
edge ``i → j`` with true relative pose ``T = xᵢ⁻¹ xⱼ`` the generator draws
``n ~ N(0, Σ)`` (Σ over ``[δt, δθ]``) and writes

    z = T ⊞ n := T · D(n)⁻¹,   so that   z⁻¹ (xᵢ⁻¹ xⱼ) = D(n)

and the file's error at the truth, ``e = chart(z⁻¹ xᵢ⁻¹ xⱼ)``, is exactly ``n``
for the chart of the chosen ``convention`` (the loader's ``convention=``):

* ``'g2o'`` (default; g2o's EdgeSE2/EdgeSE3): 2D ``D(n) = (n_t, n_θ)``, error
  ``[t(Δ), θ(Δ)]``; 3D ``D(n) = (n_t, q)`` with ``vec(q) = n_θ / 2``,
  ``w = √(1 − ‖n_θ‖²/4)``, error ``[t(Δ), vec(q(Δ))] = S n``,
  ``S = diag(1, 1, 1, ½, ½, ½)``. The rotation of ``D`` is by
  ``2 asin(‖n_θ‖/2) = ‖n_θ‖ + O(‖n_θ‖³)`` radians, so σ_θ is in radians.
* ``'log'`` (GTSAM's BetweenFactor): ``D(n) = Exp(n)``, the SE(d)
  exponential; error ``Log(Δ) = n``.

The written information matrix is the inverse covariance of that error:
``Ω = Σ⁻¹`` ('log', and 'g2o' in 2D), ``Ω = S⁻¹ Σ⁻¹ S⁻¹`` ('g2o' in 3D).
Hence at the true poses ``eᵀ Ω e = nᵀ Σ⁻¹ n ~ χ²(d)`` per edge (d = 3 in 2D, 6
in 3D): the file is statistically consistent. Rotation noise is drawn with
``‖n_θ‖ < π`` (``< 2`` for 'g2o' in 3D), the domain of the chart; σ_θ is
limited so that the truncation is below 10⁻⁸.

Loop closures and outliers
--------------------------
Each loop-closure candidate of the family is kept with probability
``loop_closure_probability``. ``outlier_fraction`` f adds wrong loop
closures between random pose pairs (``|i − j| ≥ 2``) so that they are the
fraction f of all loop-closure edges: ``round(f · K / (1 − f))`` of them for K
kept closures. Their measurement is a random pose (translation uniform in
``[−5 step, 5 step]^d``, rotation uniform) with the inliers' information.
With ``outlier_model='clustered'`` the wrong closures come in groups of
``cluster_size`` between two stretches of the trajectory, ``(i + t, j + t)``,
and agree with each other and with the odometry, as perceptual aliasing
makes them (a corridor that looks like another): the group says the stretch
at ``j`` lies where the map ``A = xᵢ z₀ xⱼ⁻¹`` puts it, ``z₀`` a random pose
as above, so its edges are ``xᵢ₊ₜ⁻¹ A xⱼ₊ₜ``. A cycle test cannot reject one
such closure by the others; only the rest of the graph can.

The initial estimate written by :meth:`GeneratedGraph.write` is the odometry
(the edges ``k → k + 1``) composed from the true first pose, as a real
front end would produce; vertex 0 is fixed (``FIX 0``) at its true pose.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Sequence
from dataclasses import asdict, dataclass, field, replace
from os import PathLike
from pathlib import Path
from typing import Union

import numpy as np

from boxplus.noise import NoiseModel, noise_model

from . import se_arrays as se
from .trajectories import FAMILIES, trajectory

__all__ = [
    "NOISE_LEVELS",
    "GeneratedGraph",
    "GraphSpec",
    "benchmark_suite",
    "generate",
    "main",
    "noise_covariance",
    "with_near_misses",
]

PathType = Union[str, "PathLike[str]"]

#: Named noise levels ``(σ_t [m], σ_θ [rad])`` per edge, isotropic in each block.
#: 'bignoise' is the regime of GTSAM's ``sphere_bignoise`` examples, where the
#: composed odometry is far from the truth and local solvers need a good start.
NOISE_LEVELS: dict[str, tuple[float, float]] = {
    "tiny": (1e-3, 1e-4),
    "low": (0.01, 0.002),
    "medium": (0.05, 0.01),
    "high": (0.1, 0.05),
    "bignoise": (0.2, 0.2),
}

#: Largest rotational σ (rad, per axis) per (dimension, convention): the chart's
#: domain is cut at ‖n_θ‖ = π (2 for 'g2o' 3D), and beyond these σ more than 10⁻⁸
#: of the draws would be cut.
_MAX_ROTATION_SIGMA = {(2, "g2o"): 0.5, (2, "log"): 0.5, (3, "g2o"): 0.3, (3, "log"): 0.45}
_ROTATION_LIMIT = {(2, "g2o"): np.pi, (2, "log"): np.pi, (3, "g2o"): 2.0, (3, "log"): np.pi}

CONVENTIONS = ("g2o", "log")
ODOMETRY, LOOP_CLOSURE, OUTLIER = 0, 1, 2

NoiseSpec = Union[str, Sequence[float], np.ndarray, NoiseModel]


def _error_dim(dim: int) -> int:
    return 3 if dim == 2 else 6


def noise_covariance(noise: NoiseSpec, dim: int) -> np.ndarray:
    """Σ (d × d, tangent order [translation, rotation]) of a noise specification,
    checked by the core noise vocabulary (:func:`boxplus.noise.noise_model`).

    Parameters
    ----------
    noise : str, array_like or boxplus.NoiseModel
        A name of :data:`NOISE_LEVELS`; a pair ``(σ_t, σ_θ)`` (metres,
        radians; isotropic per block); d standard deviations (2D
        ``[σx, σy, σθ]``, 3D ``[σx, σy, σz, σ_rx, σ_ry, σ_rz]``); a full
        d × d covariance Σ; or a :class:`boxplus.NoiseModel` of dimension d.
    dim : {2, 3}

    Raises
    ------
    ValueError
        Unknown name, wrong shape, a σ that is not finite and positive, or a Σ
        that is not symmetric positive definite.
    """
    d = _error_dim(dim)
    what = f"edge noise ({dim}D)"
    if isinstance(noise, NoiseModel):
        return noise_model(d, noise=noise, what=what).covariance_matrix
    if isinstance(noise, str):
        if noise not in NOISE_LEVELS:
            raise ValueError(f"unknown noise level {noise!r}; known: {', '.join(NOISE_LEVELS)} "
                             "or 'σ_t,σ_θ'")
        noise = NOISE_LEVELS[noise]
    a = np.asarray(noise, float)
    if a.ndim == 1 and a.size == 2 and d != 2:
        a = np.repeat(a, [dim, d - dim])  # (σ_t, σ_θ): isotropic per block
    if a.ndim == 2:
        return noise_model(d, covariance=a, what=what).covariance_matrix
    if a.ndim != 1 or a.size != d:
        raise ValueError(f"noise must be a level name, (σ_t, σ_θ), {d} sigmas or a {d}×{d} "
                         f"covariance; got shape {a.shape}")
    return noise_model(d, sigma=a, what=what).covariance_matrix


def _chart_scale(dim: int, convention: str) -> np.ndarray:
    """S: the error is S n ('g2o' 3D stores vec(q) = n_θ / 2)."""
    s = np.ones(_error_dim(dim))
    if dim == 3 and convention == "g2o":
        s[3:] = 0.5
    return s


def _perturbation(n: np.ndarray, dim: int, convention: str) -> np.ndarray:
    """D(n) as ambient rows (module docstring)."""
    if convention == "log":
        return se.exp(n, dim)
    if dim == 2:
        return n.copy()
    v = 0.5 * n[:, 3:]
    w = np.sqrt(1.0 - np.sum(v * v, axis=1, keepdims=True))
    return np.concatenate([n[:, :3], v, w], axis=1)


def _draw_noise(rng: np.random.Generator, m: int, sigma: np.ndarray, dim: int,
                convention: str) -> np.ndarray:
    """m draws of N(0, Σ), redrawing the (≤ 10⁻⁸) ones outside the chart's domain."""
    L = np.linalg.cholesky(sigma)
    n = rng.standard_normal((m, len(sigma))) @ L.T
    limit = _ROTATION_LIMIT[(dim, convention)]
    while True:
        bad = np.nonzero(np.linalg.norm(n[:, dim:], axis=1) >= limit)[0]
        if not len(bad):
            return n
        n[bad] = rng.standard_normal((len(bad), len(sigma))) @ L.T


def _random_poses(rng: np.random.Generator, m: int, dim: int, reach: float) -> np.ndarray:
    t = rng.uniform(-reach, reach, (m, dim))
    if dim == 2:
        return np.column_stack([t, rng.uniform(-np.pi, np.pi, m)])
    q = rng.standard_normal((m, 4))  # a normalised Gaussian is uniform on SO(3)
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    return np.concatenate([t, q], axis=1)


def _canonical(poses: np.ndarray, dim: int) -> np.ndarray:
    """Angles in [−π, π), quaternions of unit norm with w ≥ 0."""
    p = np.array(poses, float)
    if dim == 2:
        p[:, 2] = se.wrap_angle(p[:, 2])
    else:
        q = p[:, 3:] / np.linalg.norm(p[:, 3:], axis=1, keepdims=True)
        p[:, 3:] = np.where(q[:, 3:] < 0, -q, q)
    return p


@dataclass
class GeneratedGraph:
    """A generated pose graph: true poses, initial estimate, edges and noise.

    Attributes
    ----------
    family, dimension, convention, seed
        As given to :func:`generate`.
    truth : ndarray, shape (N, 3) or (N, 7)
        True poses, vertex id k in row k.
    estimate : ndarray, same shape
        Odometry composed from ``truth[0]``: the initial estimate the file holds.
    edges : ndarray of int, shape (M, 2)
        ``(from, to)`` vertex ids, in file order (sorted by the later vertex).
    measurements : ndarray, shape (M, 3) or (M, 7)
        ``z`` per edge (module docstring).
    kind : ndarray of int8, shape (M,)
        ``ODOMETRY`` (0), ``LOOP_CLOSURE`` (1) or ``OUTLIER`` (2).
    covariance : ndarray (d, d)
        Σ of the noise n, tangent order [translation, rotation].
    information : ndarray (d, d)
        Ω written on every edge (``Σ⁻¹``, or ``S⁻¹Σ⁻¹S⁻¹`` for 'g2o' 3D).
    """

    family: str
    dimension: int
    convention: str
    seed: int
    truth: np.ndarray
    estimate: np.ndarray
    edges: np.ndarray
    measurements: np.ndarray
    kind: np.ndarray
    covariance: np.ndarray
    information: np.ndarray
    options: dict[str, float] = field(default_factory=dict)

    @property
    def num_poses(self) -> int:
        return len(self.truth)

    @property
    def num_edges(self) -> int:
        return len(self.edges)

    @property
    def is_outlier(self) -> np.ndarray:
        """Boolean mask (M,) of the wrong loop closures."""
        return self.kind == OUTLIER

    @property
    def num_loop_closures(self) -> int:
        """Loop-closure edges including the outliers."""
        return int(np.count_nonzero(self.kind != ODOMETRY))

    @property
    def num_outliers(self) -> int:
        return int(np.count_nonzero(self.kind == OUTLIER))

    def write(self, path: PathType, poses: np.ndarray | None = None) -> None:
        """Writes the g2o file with ``poses`` (default: :attr:`estimate`) as vertices."""
        self._write(path, self.estimate if poses is None else poses)

    def write_truth(self, path: PathType) -> None:
        """Writes the same graph with the true poses as vertices."""
        self._write(path, self.truth)

    def _write(self, path: PathType, poses: np.ndarray) -> None:
        poses = np.asarray(poses, float)
        if poses.shape != self.truth.shape:
            raise ValueError(f"poses must have shape {self.truth.shape}, got {poses.shape}")
        with open(path, "w") as f:
            f.writelines(self._text(poses))

    def _text(self, poses: np.ndarray):
        """The file in chunks; 17 significant digits, so reading is exact."""
        dim = self.dimension
        poses = _canonical(poses, dim)
        z = _canonical(self.measurements, dim)
        vtag, etag = ("VERTEX_SE2", "EDGE_SE2") if dim == 2 else ("VERTEX_SE3:QUAT",
                                                                  "EDGE_SE3:QUAT")
        na = poses.shape[1]
        upper = self.information[np.triu_indices(len(self.information))]
        info = " ".join(repr(float(v)) for v in upper)
        # No comment line: SE-Sync's reader stops at a tag it does not know.
        vline = vtag + " %d" + " %.17g" * na + "\n"
        eline = etag + " %d %d" + " %.17g" * na + " " + info + "\n"
        ids = np.arange(self.num_poses, dtype=float)[:, None]
        yield from _format_rows(vline, np.hstack([ids, poses]))
        yield "FIX 0\n"
        yield from _format_rows(eline, np.hstack([self.edges.astype(float), z]))


def _format_rows(line: str, rows: np.ndarray, chunk: int = 1 << 16):
    # One % over a chunk's flat tuple: formatting costs per number, not per Python call.
    for start in range(0, len(rows), chunk):
        block = rows[start:start + chunk]
        yield (line * len(block)) % tuple(block.ravel().tolist())


def _check_probability(value: float, name: str, upper_open: bool = False) -> float:
    v = float(value)
    if not np.isfinite(v) or v < 0 or v > 1 or (upper_open and v >= 1):
        raise ValueError(f"{name} must be in [0, 1{')' if upper_open else ']'}, got {value!r}")
    return v


def generate(
    family: str,
    dimension: int,
    num_poses: int,
    *,
    noise: NoiseSpec = "medium",
    loop_closure_probability: float = 1.0,
    outlier_fraction: float = 0.0,
    outlier_model: str = "random",
    cluster_size: int = 10,
    seed: int = 0,
    convention: str = "g2o",
    step: float = 1.0,
    **family_options: float,
) -> GeneratedGraph:
    """Generates a pose graph of ``family`` (module docstring for the model).

    Parameters
    ----------
    family : {'manhattan', 'grid', 'sphere', 'torus', 'random_walk'}
        The trajectory and its loop-closure candidates
        (:mod:`boxplus.synthetic.trajectories`).
    dimension : {2, 3}
        SE(2) or SE(3) poses.
    num_poses : int
        Number of poses N (≥ 3), vertex ids 0 … N − 1 in the order driven.
    noise : str or array_like
        Per-edge noise (see :func:`noise_covariance`): a level of
        :data:`NOISE_LEVELS` ('tiny' … 'bignoise'), ``(σ_t, σ_θ)`` in metres and
        radians, d sigmas or a d × d Σ; the same Σ for every edge.
    loop_closure_probability : float in [0, 1]
        Probability that each candidate loop closure is kept (the density).
    outlier_fraction : float in [0, 1)
        Fraction of the loop-closure edges that are wrong (module docstring).
    outlier_model : {'random', 'clustered'}
        Independent wrong closures, or groups of ``cluster_size`` mutually
        consistent ones (module docstring).
    cluster_size : int
        Wrong closures per group of the 'clustered' model (≥ 1).
    seed : int
        Seed of ``numpy.random.default_rng``; the same seed gives the same file.
    convention : {'g2o', 'log'}
        The error chart the noise and Ω are consistent with (module docstring).
    step : float
        Metres between consecutive poses (the family's length unit).
    **family_options
        ``manhattan``: ``block`` (steps per street block, 5), ``radius``
        (revisit radius in steps, 0.5), ``min_gap`` (poses, 10);
        ``random_walk``: ``turn`` (σ of the heading change per step, rad, 0.2),
        ``radius`` (1.0), ``min_gap`` (10).

    Returns
    -------
    GeneratedGraph

    Raises
    ------
    ValueError, TypeError
        An unknown family, option or convention, or a parameter out of range
        (the message names it).
    """
    if family not in FAMILIES:
        raise ValueError(f"unknown family {family!r}; known: {', '.join(FAMILIES)}")
    if dimension not in (2, 3):
        raise ValueError(f"dimension must be 2 or 3, got {dimension!r}")
    if isinstance(num_poses, bool) or int(num_poses) != num_poses or num_poses < 3:
        raise ValueError(f"num_poses must be an integer ≥ 3, got {num_poses!r}")
    if convention not in CONVENTIONS:
        raise ValueError(f"convention must be one of {CONVENTIONS}, got {convention!r}")
    if isinstance(seed, bool) or int(seed) != seed or seed < 0:
        raise ValueError(f"seed must be a non-negative integer, got {seed!r}")
    step = float(step)
    if not (np.isfinite(step) and step > 0):
        raise ValueError(f"step must be finite and positive, got {step!r}")
    p = _check_probability(loop_closure_probability, "loop_closure_probability")
    f = _check_probability(outlier_fraction, "outlier_fraction", upper_open=True)
    if outlier_model not in ("random", "clustered"):
        raise ValueError(f"outlier_model must be 'random' or 'clustered', got {outlier_model!r}")
    if isinstance(cluster_size, bool) or int(cluster_size) != cluster_size or cluster_size < 1:
        raise ValueError(f"cluster_size must be an integer ≥ 1, got {cluster_size!r}")
    n, dim = int(num_poses), int(dimension)
    sigma = noise_covariance(noise, dim)
    rot_sigma = float(np.sqrt(np.linalg.eigvalsh(sigma[dim:, dim:])[-1]))
    limit = _MAX_ROTATION_SIGMA[(dim, convention)]
    if rot_sigma > limit:
        raise ValueError(f"rotation noise σ_θ = {rot_sigma:g} rad exceeds {limit:g} rad, the "
                         f"largest the {convention!r} chart represents without truncation")

    rng = np.random.default_rng(int(seed))
    traj = trajectory(family, dim, n, rng, step, **family_options)
    truth = _canonical(traj.poses, dim)
    cand = traj.candidates.reshape(-1, 2)
    closures = cand[rng.random(len(cand)) < p]
    num_out = int(round(f * len(closures) / (1.0 - f)))
    wrong = np.empty((0, 2), np.int64)
    alias = np.empty((0, truth.shape[1]))  # the map A of each clustered closure
    if outlier_model == "random":
        while len(wrong) < num_out:
            draw = rng.integers(0, n, (num_out - len(wrong), 2))
            draw = np.sort(draw[np.abs(draw[:, 0] - draw[:, 1]) >= 2], axis=1)
            wrong = np.concatenate([wrong, draw])
    else:
        size = min(int(cluster_size), max(1, (n - 2) // 3))
        groups: list[np.ndarray] = []
        group_maps: list[np.ndarray] = []
        drawn = 0
        while drawn < num_out:
            i, j = np.sort(rng.integers(0, n - size + 1, 2))
            if j - i < size + 2:
                continue
            t = np.arange(min(size, num_out - drawn))
            drawn += len(t)
            groups.append(np.column_stack([i + t, j + t]))
            z0 = _random_poses(rng, 1, dim, 5.0 * step)
            a = se.compose(se.compose(truth[i:i + 1], z0, dim), se.inverse(truth[j:j + 1], dim),
                           dim)
            group_maps.append(np.repeat(a, len(t), axis=0))
        if groups:
            wrong, alias = np.concatenate(groups), np.concatenate(group_maps)
    odometry = np.column_stack([np.arange(n - 1), np.arange(1, n)])
    edges = np.concatenate([odometry, closures, wrong]).astype(np.int64)
    kind = np.repeat(np.array([ODOMETRY, LOOP_CLOSURE, OUTLIER], np.int8),
                     [len(odometry), len(closures), len(wrong)])
    maps = np.zeros((len(edges), truth.shape[1]))
    maps[len(edges) - len(alias):] = alias
    order = np.lexsort((edges[:, 0], kind, edges[:, 1]))
    edges, kind, maps = edges[order], kind[order], maps[order]

    relative = se.between(truth[edges[:, 0]], truth[edges[:, 1]], dim)
    out = kind == OUTLIER
    if outlier_model == "random":
        relative[out] = _random_poses(rng, int(out.sum()), dim, 5.0 * step)
    elif out.any():
        aliased = se.compose(maps[out], truth[edges[out, 1]], dim)
        relative[out] = se.between(truth[edges[out, 0]], aliased, dim)
    noise_draws = _draw_noise(rng, len(edges), sigma, dim, convention)
    z = se.compose(relative, se.inverse(_perturbation(noise_draws, dim, convention), dim), dim)
    z = _canonical(z, dim)

    odo = np.nonzero(kind == ODOMETRY)[0]
    odo = odo[np.argsort(edges[odo, 0])]
    estimate = _canonical(se.prefix_compose(truth[0], z[odo], dim), dim)

    s_inv = 1.0 / _chart_scale(dim, convention)
    information = s_inv[:, None] * np.linalg.inv(sigma) * s_inv[None, :]
    information = 0.5 * (information + information.T)
    return GeneratedGraph(family, dim, convention, int(seed), truth, estimate, edges, z, kind,
                          sigma, information, dict(family_options))


# -- benchmark suite ----------------------------------------------------------
@dataclass(frozen=True)
class GraphSpec:
    """One named graph of :func:`benchmark_suite`; :meth:`generate` builds it."""

    name: str
    family: str
    dimension: int
    num_poses: int
    noise: str
    loop_closure_probability: float
    outlier_fraction: float
    seed: int

    def generate(self) -> GeneratedGraph:
        return generate(self.family, self.dimension, self.num_poses, noise=self.noise,
                        loop_closure_probability=self.loop_closure_probability,
                        outlier_fraction=self.outlier_fraction, seed=self.seed)

    def as_dict(self) -> dict:
        return asdict(self)


def with_near_misses(graph: GeneratedGraph, share: float, sigmas: tuple[float, float],
                     seed: int = 0) -> GeneratedGraph:
    """The same graph with ``share`` of its wrong closures made near misses.

    A near miss keeps its (wrong) pair of poses, but its measurement is their
    true relative pose perturbed by noise drawn as the edges' own, times a
    factor uniform in ``sigmas`` (a place recognised a little off, where
    :func:`generate`'s wrong closures are random poses). With the information
    far too small, as many real files state it, such closures pass χ²
    thresholds in the file's units while the random ones do not.

    Parameters
    ----------
    graph : GeneratedGraph
    share : float in [0, 1]
        Probability that each wrong closure becomes a near miss.
    sigmas : (low, high)
        The factor's range, in standard deviations of the edge noise (> 0).
    seed : int
        Seed of the draws.
    """
    share = _check_probability(share, "share")
    low, high = (float(v) for v in sigmas)
    if not (0 < low <= high and np.isfinite(high)):
        raise ValueError(f"sigmas must be 0 < low <= high, finite; got {sigmas!r}")
    rng = np.random.default_rng(int(seed))
    pick = np.nonzero(graph.is_outlier)[0]
    pick = pick[rng.random(len(pick)) < share]
    dim = graph.dimension
    true = se.between(graph.truth[graph.edges[pick, 0]], graph.truth[graph.edges[pick, 1]], dim)
    n = _draw_noise(rng, len(pick), graph.covariance, dim, graph.convention)
    n *= rng.uniform(low, high, len(pick))[:, None]
    z = graph.measurements.copy()
    z[pick] = _canonical(se.compose(true, _perturbation(n, dim, graph.convention), dim), dim)
    return replace(graph, measurements=z)


def _spec_name(family, dim, n, noise, p, f) -> str:
    name = f"{family}-{dim}d-{n}-{noise}-lc{p:g}"
    return name + (f"-out{f:g}" if f else "")


def benchmark_suite(seed: int = 0, include_million: bool = False) -> list[GraphSpec]:
    """Named graph specifications for benchmarks, deterministic from ``seed``.

    The design is fixed; ``seed`` draws each graph's own seed. 65 graphs:

    * every family × dimension at 10², 10³, 10⁴ and 10⁵ poses (40), the noise
      level and the loop-closure probability (1, 0.5, 0.2) rotating over the
      five levels and three densities from one family × dimension to the next;
    * every family × dimension at 10³ poses in the 'bignoise' regime, at a
      density the rotation did not give it (10);
    * every family with outliers: in 2D at 10³ poses, 'medium', density 1, 5 %
      of the loop closures wrong; in 3D at 10⁴ poses, 'low', density 0.5, 10 %
      wrong (10);
    * the same 3D graphs with outliers at 10³ poses (5), appended last. Their
      peers' runs at 10⁴ poses take an hour each, so a suite run within a
      session of the 3D outlier graphs reaches only these.

    ``include_million`` appends every family in 2D at 10⁶ poses ('medium',
    density 0.5): 70 graphs. The first 65 do not change with it, and the
    graphs of earlier versions of the suite keep their names and seeds.

    Returns
    -------
    list of GraphSpec
        Unique names, e.g. ``'sphere-3d-1000-medium-lc1'``.
    """
    levels = list(NOISE_LEVELS)
    densities = [1.0, 0.5, 0.2]
    rows = []
    combos = [(fam, dim) for fam in FAMILIES for dim in (2, 3)]
    for c, (fam, dim) in enumerate(combos):
        for s, n in enumerate([100, 1000, 10_000, 100_000]):
            rows.append((fam, dim, n, levels[(c + s) % 5], densities[(c + s) % 3], 0.0))
    for c, (fam, dim) in enumerate(combos):  # a density the rotation above did not give
        rows.append((fam, dim, 1000, "bignoise", densities[(c + 2) % 3], 0.0))
    for c, (fam, dim) in enumerate(combos):
        if c % 2 == 0:
            rows.append((fam, dim, 1000, "medium", 1.0, 0.05))
        else:
            rows.append((fam, dim, 10_000, "low", 0.5, 0.1))
    extra = [(fam, 2, 1_000_000, "medium", 0.5, 0.0) for fam in FAMILIES]
    rng = np.random.default_rng(seed)
    seeds = rng.integers(0, 2**31 - 1, len(rows) + len(extra)).tolist()
    # Drawn after the million-pose graphs' seeds, which so keep theirs.
    later = [(fam, 3, 1000, "low", 0.5, 0.1) for fam in FAMILIES]
    later_seeds = rng.integers(0, 2**31 - 1, len(later)).tolist()
    seeds = seeds[:len(rows)] + later_seeds + seeds[len(rows):]
    rows += later
    if include_million:
        rows += extra
    return [GraphSpec(_spec_name(*r), r[0], r[1], r[2], r[3], r[4], r[5], int(sd))
            for r, sd in zip(rows, seeds)]


# -- command line -------------------------------------------------------------
def _parse_noise(text: str):
    if text in NOISE_LEVELS:
        return text
    try:
        return [float(v) for v in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"--noise {text!r}: a level ({', '.join(NOISE_LEVELS)}) or σ_t,σ_θ (m, rad) "
            "or comma-separated sigmas") from None


def _truth_path(out: Path) -> Path:
    return out.with_name(out.stem + "_truth" + (out.suffix or ".g2o"))


def _write_graph(graph: GeneratedGraph, out: Path, truth: Path | None) -> str:
    graph.write(out)
    if truth is not None:
        graph.write_truth(truth)
    return (f"{out}: {graph.family} {graph.dimension}D, {graph.num_poses} poses, "
            f"{graph.num_edges} edges ({graph.num_loop_closures} loop closures, "
            f"{graph.num_outliers} outliers)")


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m boxplus.synthetic.pose_graphs``: writes a generated graph (and its truth)."""
    ap = argparse.ArgumentParser(
        prog="python -m boxplus.synthetic.pose_graphs",
        description="Writes a seeded pose graph as g2o, with the ground truth beside it.")
    ap.add_argument("--family", choices=list(FAMILIES))
    ap.add_argument("--dimension", type=int, choices=(2, 3),
                    help="2 or 3 (default: 3 for sphere and torus, else 2)")
    ap.add_argument("--poses", type=int, default=1000)
    ap.add_argument("--noise", type=_parse_noise, default="medium",
                    help="level or σ_t,σ_θ (m, rad) or d sigmas (default: medium)")
    ap.add_argument("--loop-closures", type=float, default=1.0, metavar="P",
                    help="probability of keeping each loop-closure candidate (default 1)")
    ap.add_argument("--outliers", type=float, default=0.0, metavar="F",
                    help="fraction of loop closures that are wrong (default 0)")
    ap.add_argument("--outlier-model", choices=("random", "clustered"), default="random",
                    help="independent wrong closures, or groups that agree (perceptual aliasing)")
    ap.add_argument("--cluster-size", type=int, default=10, metavar="K",
                    help="wrong closures per group of the clustered model (default 10)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--convention", choices=CONVENTIONS, default="g2o")
    ap.add_argument("--step", type=float, default=1.0, help="metres between poses")
    ap.add_argument("-o", "--output", type=Path, help="g2o file to write")
    ap.add_argument("--truth", type=Path, help="truth file (default: OUTPUT_truth.g2o)")
    ap.add_argument("--no-truth", action="store_true", help="do not write the truth file")
    ap.add_argument("--suite", type=Path, metavar="DIR",
                    help="write every graph of benchmark_suite(--seed) into DIR")
    ap.add_argument("--million", action="store_true", help="with --suite: add the 10⁶ graphs")
    ap.add_argument("--list-suite", action="store_true", help="print the suite and exit")
    a = ap.parse_args(argv)

    if a.list_suite or a.suite:
        specs = benchmark_suite(a.seed, include_million=a.million)
        if a.list_suite:
            for s in specs:
                print(s.name, s.seed)
            return 0
        a.suite.mkdir(parents=True, exist_ok=True)
        for s in specs:
            t0 = time.perf_counter()
            msg = _write_graph(s.generate(), a.suite / f"{s.name}.g2o",
                               a.suite / f"{s.name}_truth.g2o")
            print(f"{msg} in {time.perf_counter() - t0:.2f} s", file=sys.stderr)
        return 0
    if a.family is None or a.output is None:
        ap.error("--family and -o/--output are required (or --suite DIR / --list-suite)")
    dim = a.dimension or (3 if a.family in ("sphere", "torus") else 2)
    t0 = time.perf_counter()
    try:
        graph = generate(a.family, dim, a.poses, noise=a.noise,
                         loop_closure_probability=a.loop_closures, outlier_fraction=a.outliers,
                         outlier_model=a.outlier_model, cluster_size=a.cluster_size,
                         seed=a.seed, convention=a.convention, step=a.step)
    except (ValueError, TypeError) as e:
        ap.error(str(e))
    truth = None if a.no_truth else (a.truth or _truth_path(a.output))
    msg = _write_graph(graph, a.output, truth)
    print(f"{msg} in {time.perf_counter() - t0:.2f} s", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
