"""Reference pose-graph objectives in plain numpy, independent of the C++ code.

Used by the tests and the benchmark to score any solution (boxplus', GTSAM's,
g2o's) with one function. ``chi2 = Σ eᵀΩe`` with Ω the file's information
matrix and, for Δ = z⁻¹ (xᵢ⁻¹ xⱼ):

* ``g2o``: 2D ``e = [t(Δ), wrap(θ(Δ))]`` (g2o's EdgeSE2); 3D
  ``e = [t(Δ), vec(q(Δ))]``, ``q(Δ)`` with ``w ≥ 0`` (g2o's EdgeSE3);
* ``log``: ``e = [u, ω]`` from ``(ω, u) = Log_SE(d)(Δ)``, ``u = V(ω)⁻¹ t(Δ)``
  (GTSAM's BetweenFactor<Pose2/Pose3>; GTSAM's own error is ½ chi2).

``chi2_sesync`` is SE-Sync's objective instead (Rosen et al., IJRR 2019):
``f = Σ κ‖Rⱼ − RᵢR̃ᵢⱼ‖²_F + τ‖tⱼ − tᵢ − Rᵢt̃ᵢⱼ‖²`` with the isotropic
precisions of SE-Sync's ``read_g2o_file``: 3D ``τ = 3 / tr(Ω_t⁻¹)``,
``κ = 3 / (2 tr(Ω_R⁻¹))``; 2D ``τ = 2 / tr(Ω_t⁻¹)``, ``κ = Ω_θθ``. The
optimal values in the SE-Sync paper are this ``f`` (its ``tr(Q YᵀY)``, no ½).

Only the pose-graph tags of the benchmark files are read here
(VERTEX_SE2, EDGE_SE2, VERTEX_SE3:QUAT, EDGE_SE3:QUAT).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["read_g2o_arrays", "chi2_g2o", "chi2_log", "chi2_sesync", "edge_errors"]


def read_g2o_arrays(path):
    """Reads a pose-graph g2o file into arrays.

    Returns
    -------
    dict
        ``dim`` (2 or 3), ``ids`` (vertex ids in file order; for files without
        vertices, the sorted ids of the edges), ``poses`` (N × 3 or N × 7, NaN
        where the file has no vertex), ``edge_index`` (M × 2 indices into
        ``ids``), ``z`` (M × 3 or M × 7), ``info`` (M × d × d).
    """
    verts: dict[int, np.ndarray] = {}
    edges: list[tuple[int, int, list[float]]] = []
    order = []
    dim = 0
    with open(path) as f:
        for line in f:
            t = line.split()
            if not t or t[0].startswith("#"):
                continue
            if t[0] == "VERTEX_SE2":
                dim = 2
                v = np.array([float(x) for x in t[2:5]])
                v[2] = _angle(v[2])
                verts[int(t[1])] = v
                order.append(int(t[1]))
            elif t[0] == "VERTEX_SE3:QUAT":
                dim = 3
                v = np.array([float(x) for x in t[2:9]])
                v[3:] = _unit(v[3:])
                verts[int(t[1])] = v
                order.append(int(t[1]))
            elif t[0] == "EDGE_SE2":
                dim = 2
                meas = [float(x) for x in t[3:12]]
                meas[2] = _angle(meas[2])
                edges.append((int(t[1]), int(t[2]), meas))
            elif t[0] == "EDGE_SE3:QUAT":
                dim = 3
                edges.append((int(t[1]), int(t[2]), [float(x) for x in t[3:33]]))
    if not order:
        order = sorted({i for e in edges for i in e[:2]})
    index = {vid: k for k, vid in enumerate(order)}
    na = 3 if dim == 2 else 7
    poses = np.full((len(order), na), np.nan)
    for vid, v in verts.items():
        poses[index[vid]] = v
    nz, d = (3, 3) if dim == 2 else (7, 6)
    m = len(edges)
    z = np.empty((m, nz))
    info = np.empty((m, d, d))
    iu = np.triu_indices(d)
    for k, (_, _, vals) in enumerate(edges):
        z[k] = vals[:nz]
        upper = np.zeros((d, d))
        upper[iu] = vals[nz:]
        info[k] = upper + np.triu(upper, 1).T
    if dim == 3:
        z[:, 3:] = _unit(z[:, 3:])
    edge_index = np.array([[index[a], index[b]] for a, b, _ in edges], dtype=int).reshape(-1, 2)
    return {"dim": dim, "ids": order, "poses": poses, "edge_index": edge_index, "z": z,
            "info": info}


def _angle(a: float) -> float:
    """An angle as the number in the file means it, mod 2π, to an ulp for every
    finite double: sin and cos reduce their argument exactly, whereas
    remainder(a, 2 * pi) divides by a double that is not 2π (4e-5 rad off at 1e12)."""
    if -math.pi <= a < math.pi:
        return a
    r = math.atan2(math.sin(a), math.cos(a))
    return -math.pi if r >= math.pi else r


def _unit(q):
    """q / ‖q‖ along the last axis, scaled by the largest |component| first so
    that huge components (1e200) do not overflow the norm."""
    q = np.asarray(q, float)
    s = np.max(np.abs(q), axis=-1, keepdims=True)
    q = q / s
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def _qmul(a, b):
    ax, ay, az, aw = a.T
    bx, by, bz, bw = b.T
    return np.stack(
        [
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz,
        ],
        axis=1,
    )


def _qconj(q):
    return q * np.array([-1.0, -1.0, -1.0, 1.0])


def _qrot(q, v):
    u, w = q[:, :3], q[:, 3:4]
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)


def edge_errors(data, poses, convention="g2o"):
    """Error vectors e (M × d) of every edge at ``poses`` (rows aligned with ``data['ids']``)."""
    poses = np.asarray(poses, float)
    i, j = data["edge_index"].T
    z = data["z"]
    if data["dim"] == 2:
        xi, xj = poses[i], poses[j]
        c, s = np.cos(xi[:, 2]), np.sin(xi[:, 2])
        dx, dy = xj[:, 0] - xi[:, 0], xj[:, 1] - xi[:, 1]
        tx = c * dx + s * dy - z[:, 0]
        ty = -s * dx + c * dy - z[:, 1]
        cz, sz = np.cos(z[:, 2]), np.sin(z[:, 2])
        th = xj[:, 2] - xi[:, 2] - z[:, 2]
        th = (th + np.pi) % (2 * np.pi) - np.pi
        ex, ey = cz * tx + sz * ty, -sz * tx + cz * ty
        if convention == "log":
            b = th / 2.0
            with np.errstate(divide="ignore", invalid="ignore"):
                a = np.where(th**2 < 1e-6, 1.0 - th**2 / 12.0 - th**4 / 720.0, b / np.tan(b))
            ex, ey = a * ex + b * ey, -b * ex + a * ey
        elif convention != "g2o":
            raise ValueError(f"unknown convention {convention!r}")
        return np.stack([ex, ey, th], axis=1)
    qi = poses[i, 3:] / np.linalg.norm(poses[i, 3:], axis=1, keepdims=True)
    qj = poses[j, 3:] / np.linalg.norm(poses[j, 3:], axis=1, keepdims=True)
    tij = _qrot(_qconj(qi), poses[j, :3] - poses[i, :3])
    qij = _qmul(_qconj(qi), qj)
    qz = z[:, 3:]
    t = _qrot(_qconj(qz), tij - z[:, :3])
    q = _qmul(_qconj(qz), qij)
    q = np.where(q[:, 3:4] < 0, -q, q)
    if convention == "g2o":
        return np.concatenate([t, q[:, :3]], axis=1)
    if convention != "log":
        raise ValueError(f"unknown convention {convention!r}")
    vn = np.linalg.norm(q[:, :3], axis=1)
    theta = 2.0 * np.arctan2(vn, q[:, 3])
    k = np.where(vn > 1e-12, theta / np.maximum(vn, 1e-300), 2.0 / q[:, 3])
    w = k[:, None] * q[:, :3]
    th2 = theta**2
    with np.errstate(divide="ignore", invalid="ignore"):
        cfull = (1.0 - theta / (2.0 * np.tan(theta / 2.0))) / th2
    c = np.where(th2 < 1e-6, 1.0 / 12.0 + th2 / 720.0, cfull)
    wt = np.cross(w, t)
    u = t - 0.5 * wt + c[:, None] * np.cross(w, wt)
    return np.concatenate([u, w], axis=1)


def _chi2(data, poses, convention):
    e = edge_errors(data, poses, convention)
    return float(np.einsum("mi,mij,mj->", e, data["info"], e))


def chi2_g2o(data, poses):
    """Σ eᵀΩe in g2o's convention (g2o's ``optimizer.chi2()``)."""
    return _chi2(data, poses, "g2o")


def chi2_log(data, poses):
    """Σ eᵀΩe in GTSAM's SE(d)-log convention (2 × GTSAM's ``graph.error``)."""
    return _chi2(data, poses, "log")


def _rotations(poses, dim):
    """Rotation matrices (N × d × d) of ambient poses."""
    if dim == 2:
        c, s = np.cos(poses[:, 2]), np.sin(poses[:, 2])
        return np.stack([np.stack([c, -s], 1), np.stack([s, c], 1)], 1)
    q = poses[:, 3:] / np.linalg.norm(poses[:, 3:], axis=1, keepdims=True)
    x, y, z, w = q.T
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], 1),
        np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], 1),
        np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], 1),
    ], 1)


def sesync_precisions(data):
    """``(τ, κ)`` per edge (M each), as SE-Sync's ``read_g2o_file``."""
    d = data["dim"]
    info = data["info"]
    tau = d / np.trace(np.linalg.inv(info[:, :d, :d]), axis1=1, axis2=2)
    if d == 2:
        kappa = info[:, 2, 2].copy()
    else:
        kappa = 3.0 / (2.0 * np.trace(np.linalg.inv(info[:, 3:, 3:]), axis1=1, axis2=2))
    return tau, kappa


def chi2_sesync(data, poses):
    """SE-Sync's objective ``f`` (module docstring) at ``poses``."""
    poses = np.asarray(poses, float)
    d = data["dim"]
    i, j = data["edge_index"].T
    R = _rotations(poses, d)
    Rz = _rotations(data["z"], d)
    t = poses[:, :d]
    tz = data["z"][:, :d]
    tau, kappa = sesync_precisions(data)
    rt = t[j] - t[i] - np.einsum("mab,mb->ma", R[i], tz)
    rr = R[j] - R[i] @ Rz
    return float(np.sum(tau * np.sum(rt**2, axis=1)) + np.sum(kappa * np.sum(rr**2, axis=(1, 2))))
