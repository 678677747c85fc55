"""Joint intrinsic + extrinsic calibration of a graph of 3D systems.

Le & Ng, "Joint calibration of multiple sensors", IROS 2009, eq. 8 for any
number of systems: one objective

    Σ_systems Intr(α_s)  +  γ Σ_links Extr(link)

with Intr the distance, coplanarity and collinearity terms of
:mod:`boxplus.joint.constraints` and Extr, for corresponding data (u_a, u_b)
of two systems a and b seen at the same physical point,

    r = T_a · I_a(α_a, u_a) − T_b · I_b(α_b, u_b)  ~  N(0, σ²/γ · I₃)   (eq. 4).

T_s = ``root_from_s`` is the pose of system s in the frame of the root
system (the first one added unless said otherwise; its pose is the
identity). One pose per system rather than one transform per link keeps the
transforms of a graph with loops consistent; along a tree both are the same
model. Poses are SE3 = R³ × SO(3), tangent [translation, rotation].

*Sharing* a sensor between systems means that they use the same variable for
its parameters: ``add_system(s, share={"cam1": "camera1"})`` names the
variable of parameter ``cam1`` of ``s`` "camera1"; systems naming the same
variable share it. Unshared parameters are named "<system>.<parameter>".
"""

from __future__ import annotations

from collections import deque
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from types import SimpleNamespace
from typing import Any, Callable

import numpy as np

from boxplus.joint.constraints import (
    fit_line,
    fit_plane,
    point_line_residual,
    point_plane_residual,
)
from boxplus.joint.horn import horn
from boxplus.joint.restarts import RestartResult, solve_with_restarts
from boxplus.joint.systems import ThreeDSystem
from boxplus.manifolds import SE3, codec_of
from boxplus.problem import OptimizationProblem

_MEMO_SIZE = 4  # the unperturbed points of a term's (at most two) systems, and their ± steps

__all__ = ["JointCalibration", "JointResult"]


@dataclass
class _Distances:
    system: str
    Ui: np.ndarray
    Uj: np.ndarray
    d: np.ndarray
    sigma: float
    name: str


@dataclass
class _PointGroup:
    kind: str  # "plane" or "line"
    system: str
    U: np.ndarray
    sigma: float
    name: str


@dataclass
class _Link:
    a: str
    b: str
    Ua: np.ndarray
    Ub: np.ndarray
    sigma: float
    name: str


@dataclass
class JointResult:
    """What :meth:`JointCalibration.solve` did.

    Attributes
    ----------
    cost : float
        Final ½ Σ ‖r‖².
    termination : str
        Of the best solve.
    rms : dict
        RMS of the unwhitened errors per term group (metres for points).
    restarts : RestartResult
        Costs of the single solve and of every restart.
    """

    cost: float
    termination: str
    rms: dict[str, float]
    restarts: RestartResult = field(repr=False)
    problem: OptimizationProblem = field(repr=False)


class JointCalibration:
    """All systems, their data and the links between them; solved as one problem.

    Parameters
    ----------
    gamma : float
        Weight γ of the extrinsic terms against the intrinsic ones (eq. 8): a
        link's residual is whitened by √γ / σ.
    root : str, optional
        The system whose frame the poses are expressed in (default: the first
        system added).

    Examples
    --------
    >>> jc = JointCalibration(gamma=1.0)
    >>> jc.add_system(stereo, share={"cam1": "camera1"})
    >>> jc.add_system(arm)
    >>> jc.add_distances("stereo", U[i], U[j], d, sigma=0.001)
    >>> jc.add_correspondences("stereo", "arm", U_stereo, E_arm, sigma=0.002)
    >>> jc.solve(restarts=3, seed=0)
    >>> jc.transform("stereo", "arm")   # arm_from_stereo
    """

    def __init__(self, gamma: float = 1.0, root: str | None = None) -> None:
        if not np.isfinite(gamma) or gamma <= 0:
            raise ValueError(f"gamma must be a positive number, got {gamma}")
        self.gamma = float(gamma)
        self._root = root
        self.systems: dict[str, ThreeDSystem] = {}
        self._binding: dict[str, dict[str, str]] = {}
        self.values: dict[str, Any] = {}
        self.poses: dict[str, SE3] = {}
        self.group_values: dict[str, Any] = {}
        self._distances: list[_Distances] = []
        self._groups: list[_PointGroup] = []
        self._links: list[_Link] = []

    # ---- declaring the systems and their data ----------------------------------------
    @property
    def root(self) -> str:
        if self._root is not None:
            return self._root
        if not self.systems:
            raise ValueError("the calibration has no systems")
        return next(iter(self.systems))

    def add_system(self, system: ThreeDSystem, share: Mapping[str, str] | None = None) -> ThreeDSystem:
        """Adds a system; ``share`` maps its parameter names to shared variable names."""
        if not isinstance(system, ThreeDSystem):
            raise TypeError(f"add_system: expected a ThreeDSystem, got {type(system).__name__}")
        if system.name in self.systems:
            raise ValueError(f"a system named '{system.name}' was already added")
        share = dict(share or {})
        unknown = [p for p in share if p not in system.parameter_names]
        if unknown:
            raise ValueError(
                f"system '{system.name}': cannot share {unknown}: its parameters are "
                f"{list(system.parameter_names)}"
            )
        binding = {}
        for p, v in system.parameters.items():
            key = share.get(p, f"{system.name}.{p}")
            if key in self.values:
                if codec_of(self.values[key]) is not codec_of(v):
                    raise TypeError(
                        f"system '{system.name}': parameter '{p}' ({codec_of(v).name}) cannot share "
                        f"variable '{key}', which holds a {codec_of(self.values[key]).name}"
                    )
            else:
                self.values[key] = v
            binding[p] = key
        self.systems[system.name] = system
        self._binding[system.name] = binding
        return system

    def _system(self, name: str, what: str) -> ThreeDSystem:
        if name not in self.systems:
            raise KeyError(f"{what}: unknown system '{name}' (systems: {list(self.systems)})")
        return self.systems[name]

    def add_distances(self, system: str, U_i: Any, U_j: Any, distances: Any, sigma: float,
                      name: str | None = None) -> None:
        """Distance preservation: ‖I(α, uᵢ) − I(α, uⱼ)‖ − d̄ᵢⱼ ~ N(0, σ²) (eq. 5)."""
        name = name or f"{system}.distances{len(self._distances)}"
        s = self._system(system, f"distances '{name}'")
        Ui, Uj = s.check_data(U_i, f"distances '{name}'"), s.check_data(U_j, f"distances '{name}'")
        d = np.asarray(distances, dtype=float).reshape(-1)
        if not (len(Ui) == len(Uj) == len(d)) or len(d) == 0:
            raise ValueError(
                f"distances '{name}' of system '{system}': need the same number (> 0) of U_i, "
                f"U_j and distances, got {len(Ui)}, {len(Uj)}, {len(d)}"
            )
        self._distances.append(_Distances(system, Ui, Uj, d, _sigma(sigma, name), name))

    def add_coplanar(self, system: str, U: Any, sigma: float, name: str | None = None) -> None:
        """Coplanarity: the points I(α, U) lie on one (estimated) plane."""
        self._add_group("plane", 3, system, U, sigma, name)

    def add_collinear(self, system: str, U: Any, sigma: float, name: str | None = None) -> None:
        """Collinearity: the points I(α, U) lie on one (estimated) line."""
        self._add_group("line", 3, system, U, sigma, name)

    def _add_group(self, kind, minimum, system, U, sigma, name) -> None:
        name = name or f"{system}.{kind}{len(self._groups)}"
        what = f"{kind} group '{name}'"
        s = self._system(system, what)
        U = s.check_data(U, what)
        if len(U) < minimum:
            raise ValueError(f"{what} of system '{system}' has {len(U)} points; a {kind} group needs at least {minimum}")
        if any(g.name == name for g in self._groups):
            raise ValueError(f"{what}: a group of that name exists already")
        self._groups.append(_PointGroup(kind, system, U, _sigma(sigma, name), name))

    def add_correspondences(self, a: str, b: str, U_a: Any, U_b: Any, sigma: float,
                            name: str | None = None) -> None:
        """A link: data U_a of system a and U_b of system b seen at the same points (eq. 4)."""
        name = name or f"{a}-{b}"
        what = f"correspondences '{name}'"
        sa, sb = self._system(a, what), self._system(b, what)
        if a == b:
            raise ValueError(f"{what}: a link needs two different systems, got '{a}' twice")
        Ua, Ub = sa.check_data(U_a, what), sb.check_data(U_b, what)
        if len(Ua) != len(Ub) or len(Ua) == 0:
            raise ValueError(f"{what}: need the same number (> 0) of data of '{a}' and '{b}', got {len(Ua)} and {len(Ub)}")
        self._links.append(_Link(a, b, Ua, Ub, _sigma(sigma, name), name))

    # ---- results ---------------------------------------------------------------------
    def parameter_keys(self, system: str) -> list[str]:
        """Names of the variables holding the parameters of ``system``."""
        self._system(system, "parameter_keys")
        return list(self._binding[system].values())

    def parameters(self, system: str) -> dict[str, Any]:
        """Current values of the parameters of ``system``, by parameter name."""
        self._system(system, "parameters")
        return {p: self.values[k] for p, k in self._binding[system].items()}

    def points(self, system: str, U: Any) -> np.ndarray:
        """I(α, U) in the system's frame at the current values."""
        return self._system(system, "points").evaluate(U, self.parameters(system))

    def pose(self, system: str) -> SE3:
        """root_from_system (identity for the root)."""
        self._system(system, "pose")
        if system == self.root:
            return SE3()
        if system not in self.poses:
            raise ValueError(f"system '{system}' has no pose yet: solve with extrinsics first")
        return self.poses[system]

    def transform(self, a: str, b: str) -> SE3:
        """b_from_a: maps points of system a into the frame of system b."""
        return self.pose(b).inverse() * self.pose(a)

    def points_in_root(self, system: str, U: Any) -> np.ndarray:
        T = self.pose(system)
        return self.points(system, U) @ T.R.T + T.pos

    def link_errors(self, a: str, b: str, U_a: Any, U_b: Any) -> np.ndarray:
        """‖T_a I_a(u_a) − T_b I_b(u_b)‖ per correspondence (validation error)."""
        return np.linalg.norm(self.points_in_root(a, U_a) - self.points_in_root(b, U_b), axis=1)

    # ---- checks ----------------------------------------------------------------------
    def check(self, systems: Sequence[str] | None = None, extrinsics: bool = True) -> None:
        """Raises ValueError naming the culprit if the problem cannot be solved as declared."""
        active = self._active(systems)
        for s in active:
            has = (any(d.system == s for d in self._distances) or any(g.system == s for g in self._groups)
                   or any(s in (l.a, l.b) for l in self._links))
            if not has:
                raise ValueError(
                    f"system '{s}' has no data: add distances, plane or line groups, or "
                    f"correspondences with another system"
                )
        links = self._active_links(active, extrinsics)
        for s in active:
            if not self.systems[s].parameter_names:
                continue
            scale = any(d.system == s for d in self._distances) or any(s in (l.a, l.b) for l in links)
            if any(g.system == s for g in self._groups) and not scale:
                raise ValueError(
                    f"system '{s}': plane and line groups do not fix scale; add at least one "
                    f"distance constraint or a link to another system"
                )
            if not scale and not any(g.system == s for g in self._groups):
                raise ValueError(f"system '{s}' has no data in this solve (no constraints and no links)")
        if extrinsics and len(active) > 1:
            root = self._solve_root(active)
            reached = self._tree(active, links, root)
            missing = [s for s in active if s not in reached]
            if missing:
                raise ValueError(
                    f"the systems {missing} are not connected to '{root}' by correspondences: "
                    f"the graph of systems must be connected (add correspondences)"
                )

    def _active(self, systems: Iterable[str] | None) -> list[str]:
        if not self.systems:
            raise ValueError("the calibration has no systems")
        if systems is None:
            return list(self.systems)
        out = list(dict.fromkeys(systems))
        for s in out:
            self._system(s, "solve")
        return out

    def _active_links(self, active: Sequence[str], extrinsics: bool) -> list[_Link]:
        if not extrinsics:
            return []
        return [l for l in self._links if l.a in active and l.b in active]

    def _solve_root(self, active: Sequence[str]) -> str:
        return self.root if self.root in active else active[0]

    @staticmethod
    def _tree(active, links, root) -> dict[str, _Link | None]:
        """Breadth-first spanning tree: system -> the link it was reached by."""
        reached: dict[str, _Link | None] = {root: None}
        queue = deque([root])
        while queue:
            s = queue.popleft()
            for l in links:
                for u, v in ((l.a, l.b), (l.b, l.a)):
                    if u == s and v not in reached:
                        reached[v] = l
                        queue.append(v)
        return reached

    # ---- initialisation --------------------------------------------------------------
    def initialise_poses(self, systems: Sequence[str] | None = None, overwrite: bool = False) -> None:
        """Poses along a breadth-first tree from the root by Horn's method, at the current intrinsics."""
        active = self._active(systems)
        links = self._active_links(active, True)
        root = self._solve_root(active)
        tree = self._tree(active, links, root)
        order = sorted(tree, key=lambda s: _depth(tree, s))
        for s in order:
            l = tree[s]
            if l is None or (s in self.poses and not overwrite):
                continue
            parent, U_parent, U_s = (l.a, l.Ua, l.Ub) if l.b == s else (l.b, l.Ub, l.Ua)
            T_parent = SE3() if parent == root else self.poses[parent]
            p_parent = self.points(parent, U_parent) @ T_parent.R.T + T_parent.pos
            try:
                self.poses[s] = horn(self.points(s, U_s), p_parent)
            except ValueError as e:
                raise ValueError(f"initialising the pose of '{s}' from correspondences '{l.name}': {e}") from None

    # ---- the objective ---------------------------------------------------------------
    def build(self, systems: Sequence[str] | None = None, extrinsics: bool = True,
              fixed: Iterable[str] = ()) -> tuple:
        """The OptimizationProblem of eq. 8 over ``systems`` (default: all).

        Returns
        -------
        (OptimizationProblem, dict)
            The problem and the variable id of every parameter ("<key>"), pose
            ("pose:<system>") and plane/line ("group:<name>").
        """
        self.check(systems, extrinsics)
        active = self._active(systems)
        links = self._active_links(active, extrinsics)
        root = self._solve_root(active)
        if root != self.root and links:
            raise ValueError(f"a solve with extrinsics must include the root system '{self.root}'")
        fixed = set(fixed)
        unknown = fixed - set(self.values)
        if unknown:
            raise KeyError(f"fixed: unknown parameter variables {sorted(unknown)}")
        o = OptimizationProblem()
        ids: dict[str, int] = {}
        for s in active:
            for key in self._binding[s].values():
                if key not in ids:
                    ids[key] = o.add_random_var(self.values[key], fixed=key in fixed, name=key)
        if links:
            self.initialise_poses(active)
            for s in active:
                if s != root:
                    ids[f"pose:{s}"] = o.add_random_var(self.poses[s], name=f"pose:{s}")
        for g in self._groups:
            if g.system in active:
                if g.name not in self.group_values:
                    pts = self.points(g.system, g.U)
                    self.group_values[g.name] = fit_plane(pts) if g.kind == "plane" else fit_line(pts)
                ids[f"group:{g.name}"] = o.add_random_var(self.group_values[g.name], name=f"group:{g.name}")
        self._add_intrinsic_terms(o, ids, active)
        for pair in dict.fromkeys((l.a, l.b) for l in links):
            self._add_link_terms(o, ids, [l for l in links if (l.a, l.b) == pair], root)
        return o, ids

    def _points_fn(self, system: str) -> Callable[[dict[str, Any], np.ndarray], np.ndarray]:
        sys_ = self.systems[system]
        binding = self._binding[system]
        # The solver's central differences perturb one variable at a time and pass
        # the same (immutable) batch objects for all the others, so the points of a
        # system none of whose parameters moved are those of the last calls: a few
        # results are kept, keyed by the identity of their inputs (which the entry
        # holds, so that the ids cannot be reused while it lives).
        memo: deque = deque(maxlen=_MEMO_SIZE)

        def pts(b: dict[str, Any], U: np.ndarray) -> np.ndarray:
            args = [b[k] for k in binding.values()]
            for inputs, out in memo:
                if inputs[0] is U and all(x is y for x, y in zip(inputs[1:], args)):
                    return out
            out = sys_.points(SimpleNamespace(**dict(zip(binding, args))), U)
            memo.append(((U, *args), out))
            return out

        return pts

    @staticmethod
    def _term(name, keys, compute, per_row=False):
        """A vectorised measurement function over the variables ``keys`` (deduplicated,
        the same in every row) and, if ``per_row``, one more variable chosen per row."""
        keys = list(dict.fromkeys(keys))
        K = len(keys)

        def term(*args):
            b = dict(zip(keys, args[:K]))
            extra = args[K] if per_row else None
            return compute(b, extra, *args[K + per_row:])

        term.__name__ = name
        term.keys = keys  # type: ignore[attr-defined]  # mypy has no way to declare a function's attribute
        return term

    @staticmethod
    def _add_rows(o, ids, term, Z, sigma, consts, per_row_ids=None) -> None:
        """Adds the rows Z of ``term``; terms without any variable are constants and skipped."""
        if not term.keys and per_row_ids is None:
            return
        rows = np.tile(np.asarray([ids[k] for k in term.keys], dtype=int), (len(Z), 1))
        if per_row_ids is not None:
            rows = np.column_stack([rows, per_row_ids]).astype(int)
        o.add_measurements(Z, term, rows, constants=consts, sigma=sigma, name=term.__name__)

    def _add_intrinsic_terms(self, o, ids, active) -> None:
        for s in active:
            keys = list(self._binding[s].values())
            pts = self._points_fn(s)

            def dist(b, _, Ui, Uj, pts=pts):
                return np.linalg.norm(pts(b, Ui) - pts(b, Uj), axis=1, keepdims=True)

            term = self._term(f"distance[{s}]", keys, dist)
            for d in self._distances:
                if d.system == s:
                    self._add_rows(o, ids, term, d.d[:, None], d.sigma, (d.Ui, d.Uj))
            for kind, resid, m in (("plane", point_plane_residual, 1), ("line", point_line_residual, 3)):

                def on(b, g, U, pts=pts, resid=resid):
                    return resid(g, pts(b, U))

                def anchor(b, g):
                    return np.sum(g.direction.vec * g.point.vec, axis=1, keepdims=True)

                term = self._term(f"{kind}[{s}]", keys, on, per_row=True)
                term_anchor = self._term(f"line_anchor[{s}]", [], anchor, per_row=True)
                for g in self._groups:
                    if g.system == s and g.kind == kind:
                        gid = np.full(len(g.U), ids[f"group:{g.name}"])
                        self._add_rows(o, ids, term, np.zeros((len(g.U), m)), g.sigma, (g.U,), gid)
                        if kind == "line":
                            self._add_rows(o, ids, term_anchor, np.zeros((1, 1)), g.sigma, (), gid[:1])

    def _add_link_terms(self, o, ids, links: list[_Link], root: str) -> None:
        """The links between one pair of systems, evaluated together."""
        l = links[0]
        pa, pb = self._points_fn(l.a), self._points_fn(l.b)
        pose_a = None if l.a == root else f"pose:{l.a}"
        pose_b = None if l.b == root else f"pose:{l.b}"
        keys = list(self._binding[l.a].values()) + list(self._binding[l.b].values())
        keys += [k for k in (pose_a, pose_b) if k is not None]

        def extr(b, _, Ua, Ub):
            qa, qb = pa(b, Ua), pb(b, Ub)
            if pose_a is not None:
                qa = b[pose_a].fromlocal(qa)
            if pose_b is not None:
                qb = b[pose_b].fromlocal(qb)
            return qa - qb

        term = self._term(f"link[{l.a}-{l.b}]", keys, extr)
        for l in links:
            self._add_rows(o, ids, term, np.zeros((len(l.Ua), 3)), l.sigma / np.sqrt(self.gamma), (l.Ua, l.Ub))

    # ---- solving ---------------------------------------------------------------------
    def solve(self, systems: Sequence[str] | None = None, extrinsics: bool = True,
              fixed: Iterable[str] = (), restarts: int = 0, seed: int | None = 0,
              perturbation: Callable[[Any], np.ndarray] | None = None, **solve_kw: Any) -> JointResult:
        """Builds eq. 8 over ``systems`` (default all), solves it with random restarts, stores the estimates.

        Parameters
        ----------
        systems : sequence of str, optional
            The systems whose terms enter (their links to each other too).
        extrinsics : bool
            Include the links (and the poses); False: intrinsic terms only.
        fixed : iterable of str
            Parameter variables (see :meth:`parameter_keys`) held constant.
        restarts, seed, perturbation
            Random restarts, see :func:`boxplus.joint.solve_with_restarts`.
        **solve_kw
            Passed to :meth:`OptimizationProblem.solve`.
        """
        o, ids = self.build(systems, extrinsics, fixed)
        rr = solve_with_restarts(o, restarts, seed=seed, perturbation=perturbation, **solve_kw)
        for key, vid in ids.items():
            if key.startswith("pose:"):
                self.poses[key[5:]] = o[vid]
            elif key.startswith("group:"):
                self.group_values[key[6:]] = o[vid]
            else:
                self.values[key] = o[vid]
        rms = dict(o.rms().items())
        return JointResult(rr.best_cost, rr.best.termination, rms, rr, o)


def _sigma(sigma: Any, name: str) -> float:
    s = float(sigma)
    if not np.isfinite(s) or s <= 0:
        raise ValueError(f"'{name}': sigma must be a positive number, got {sigma}")
    return s


def _depth(tree: dict[str, Any], s: str) -> int:
    d = 0
    while tree[s] is not None:
        l = tree[s]
        s = l.a if l.b == s else l.b
        d += 1
    return d
