"""Pictures of a calibration (matplotlib): reprojection errors per image and
as vectors, the coverage of the image by the corners, the projection
uncertainty as a heat map, and the rig in 3-D (sensor frames, every board
pose as a frame, IMU, hand markers).

Every function takes an optional ``ax`` (a matplotlib Axes; 3-D for
:func:`plot_rig`) to draw into, else makes its own Figure; it returns the
Figure, and saves it as a PNG when given a ``path``. Figures are made with
``matplotlib.figure.Figure``, not pyplot: nothing here selects or switches
the matplotlib backend, so notebooks and GUIs keep theirs.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from boxplus._optional import require
from boxplus.files import save_figure
from boxplus.manifolds import SE3

__all__ = ["plot_coverage", "plot_error_vectors", "plot_projection_uncertainty",
           "plot_reprojection_errors", "plot_rig", "plot_rms_per_image", "plot_suggestions"]


def _figure(ax: Any, figsize: tuple[float, float], projection: str | None = None) -> tuple[Any, Any]:
    if ax is not None:
        return ax.figure, ax
    Figure = require("matplotlib.figure", "plotting").Figure
    fig = Figure(figsize=figsize)
    return fig, fig.add_subplot(projection=projection)


def _finish(fig: Any, path: Any, title: str | None = None) -> Any:
    if title:
        fig.suptitle(title)
    if path is not None:
        fig.tight_layout()
        save_figure(fig, path, dpi=100)
    return fig


def _groups(o, mids: Mapping[str, Sequence[int]] | None) -> Mapping[str, Sequence[int]]:
    if mids is not None:
        return mids
    return {g: mids for g, mids in o.groups().items() if not g.startswith("prior")}


def _rms(e: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.sum(e**2, axis=1))))


def plot_rms_per_image(o, mids: Mapping[str, Sequence[int]] | None = None,
                       names: Mapping[str, Sequence[str]] | None = None, ax: Any = None,
                       path: Any = None, title: str | None = None) -> Any:
    """Bar chart of the RMS reprojection error (px) of each image (one built-in
    board/marker measurement each), one colour per group; ``names`` {group: a
    label per measurement} (e.g. file names) label the bars."""
    fig, ax = _figure(ax, (max(6.0, 0.25 * sum(len(v) for v in _groups(o, mids).values())), 4.5))
    x0 = 0
    ticks, labels = [], []
    for label, ids in _groups(o, mids).items():
        per = [_rms(o.measurement_errors(m)) for m in ids]
        xs = np.arange(x0, x0 + len(per))
        ax.bar(xs, per, label=label)
        ticks += list(xs)
        labels += list(names[label]) if names and label in names else [str(i) for i in range(len(per))]
        x0 += len(per) + 1
    ax.set_xticks(ticks)
    ax.set_xticklabels(labels, rotation=90, fontsize=7)
    ax.set_xlabel("image")
    ax.set_ylabel("RMS reprojection error (px)")
    ax.legend()
    return _finish(fig, path, title)


def plot_error_vectors(o, mids: Mapping[str, Sequence[int]] | None = None, ax: Any = None,
                       path: Any = None, title: str | None = None) -> Any:
    """All reprojection error vectors (px) as a scatter, one colour per group."""
    fig, ax = _figure(ax, (5.5, 5.0))
    for label, ids in _groups(o, mids).items():
        E = np.concatenate([o.measurement_errors(m) for m in ids])
        ax.scatter(E[:, 0], E[:, 1], s=4, alpha=0.6, label=label)
    ax.set_aspect("equal")
    ax.set_xlabel("error u (px)")
    ax.set_ylabel("error v (px)")
    ax.axhline(0, color="k", lw=0.5)
    ax.axvline(0, color="k", lw=0.5)
    ax.legend()
    return _finish(fig, path, title)


def plot_reprojection_errors(o, path: Any = None, mids: Mapping[str, Sequence[int]] | None = None,
                             title: str = "reprojection errors", ax: Any = None,
                             names: Mapping[str, Sequence[str]] | None = None) -> Any:
    """:func:`plot_rms_per_image` and :func:`plot_error_vectors` side by side; ``ax``: a
    pair of Axes, or None for a new Figure."""
    if ax is None:
        from matplotlib.figure import Figure

        fig = Figure(figsize=(13, 4.8))
        ax = fig.subplots(1, 2, gridspec_kw={"width_ratios": [2, 1]})
    else:
        fig = ax[0].figure
    plot_rms_per_image(o, mids, names, ax=ax[0])
    plot_error_vectors(o, mids, ax=ax[1])
    return _finish(fig, path, title)


def _camera_errors(cal: Any, camera: str) -> tuple[np.ndarray, np.ndarray]:
    """(corners z, errors e) of ``camera``'s board views, (N, 2) each, in pixels."""
    E = [cal.problem.measurement_errors(m) for m in cal.view_ids[camera]]
    Z = [ob.z for ob in cal.observations if ob.camera == camera]
    return np.concatenate(Z), np.concatenate(E)


def plot_residual_field(cal: Any, camera: str, ax: Any = None, path: Any = None,
                        scale: float = 20.0, title: str | None = None,
                        grid: tuple[int, int] = (8, 6)) -> Any:
    """The reprojection errors of ``camera`` (a Calibration) over the image.

    Without ``ax``: two panels, the error vectors at their corners (magnified
    ``scale`` times, coloured by their length in px) and the RMS error binned by
    image region (``grid`` columns × rows; the number in a cell is its corner
    count, an empty cell had none). A region whose RMS stands out is where the
    lens model or the detection fails; a uniform picture is noise. With ``ax``:
    the vectors only, on that axes."""
    z, e = _camera_errors(cal, camera)
    mag = np.linalg.norm(e, axis=1)
    w, h = cal.image_size[camera]
    if ax is None:
        Figure = require("matplotlib.figure", "plotting").Figure
        fig = Figure(figsize=(13, 5))
        ax, ax_bins = fig.subplots(1, 2)
    else:
        fig, ax_bins = ax.figure, None
    q = ax.quiver(z[:, 0], z[:, 1], e[:, 0], e[:, 1], mag, angles="xy", scale_units="xy",
                  scale=1 / scale, width=0.004, cmap="plasma")
    ax.set_facecolor("0.9")  # the short, dark arrows stand out on grey
    fig.colorbar(q, ax=ax, label="|error| (px)", shrink=0.8)
    _image_axes(ax, w, h)
    ax.set_title(title or f"{camera}: reprojection errors ×{scale:g}, coloured by length")
    if ax_bins is not None:
        cols, rows = grid
        iu = np.clip((z[:, 0] / w * cols).astype(int), 0, cols - 1)
        iv = np.clip((z[:, 1] / h * rows).astype(int), 0, rows - 1)
        sq = np.zeros((rows, cols))
        count = np.zeros((rows, cols), int)
        np.add.at(sq, (iv, iu), mag ** 2)
        np.add.at(count, (iv, iu), 1)
        with np.errstate(invalid="ignore", divide="ignore"):
            rms = np.where(count > 0, np.sqrt(sq / np.maximum(count, 1)), np.nan)
        im = ax_bins.imshow(rms, extent=(0, w, h, 0), cmap="magma", interpolation="nearest",
                            vmin=0)
        fig.colorbar(im, ax=ax_bins, label="RMS |error| (px)", shrink=0.8)
        top = np.nanmax(rms) if np.isfinite(rms).any() else 1.0
        for r in range(rows):
            for c in range(cols):
                if count[r, c]:
                    ax_bins.text((c + 0.5) * w / cols, (r + 0.5) * h / rows, str(count[r, c]),
                                 ha="center", va="center", fontsize=7,
                                 color="white" if rms[r, c] < 0.6 * top else "black")
        _image_axes(ax_bins, w, h)
        ax_bins.set_title(f"{camera}: RMS error per image region (corners per cell)")
    return _finish(fig, path)


def plot_coverage(cal: Any, camera: str, ax: Any = None, path: Any = None,
                  title: str | None = None) -> Any:
    """The corners ``camera`` used, over its image, one colour per view, with each
    view's outline: where the image is empty the lens model is extrapolated."""
    fig, ax = _figure(ax, (7, 5.5))
    w, h = cal.image_size[camera]
    for ob in cal.observations:
        if ob.camera != camera:
            continue
        ax.scatter(ob.z[:, 0], ob.z[:, 1], s=3)
    _image_axes(ax, w, h)
    n = sum(len(ob.z) for ob in cal.observations if ob.camera == camera)
    ax.set_title(title or f"{camera}: coverage ({n} corners)")
    return _finish(fig, path)


def plot_suggestions(cal: Any, suggestions: Sequence[Any], camera: str, ax: Any = None,
                     path: Any = None, title: str | None = None) -> Any:
    """Where to hold the board next (:func:`boxplus.calib.suggest.suggest_views`): the
    corners seen so far (grey) and each suggested board's outline in the image,
    numbered by rank, with its tilt and the worst projection σ after it."""
    from matplotlib.patches import Polygon

    fig, ax = _figure(ax, (7, 5.5))
    w, h = cal.image_size[camera]
    for ob in cal.observations:
        if ob.camera == camera:
            ax.scatter(ob.z[:, 0], ob.z[:, 1], s=2, color="0.7")
    colours = ["tab:red", "tab:blue", "tab:green", "tab:orange", "tab:purple", "tab:brown"]
    for s in suggestions:
        c = colours[(s.rank - 1) % len(colours)]
        ax.add_patch(Polygon(s.footprint_px, closed=True, fill=False, color=c, lw=1.8))
        ax.text(*s.footprint_px.mean(axis=0), str(s.rank), color=c, fontsize=14, ha="center",
                va="center", weight="bold")
        ax.plot([], [], color=c, label=f"{s.rank}: {s.distance:.2g} away, tilt x {s.tilt_deg[0]:+.0f}°, "
                f"y {s.tilt_deg[1]:+.0f}° → σ {s.score_after:.3g} px")
    _image_axes(ax, w, h)
    if suggestions:
        ax.legend(loc="lower center", fontsize=7, bbox_to_anchor=(0.5, -0.32))
    before = suggestions[0].score_before if suggestions else float("nan")
    ax.set_title(title or f"{camera}: capture next (worst projection σ now {before:.3g} px)")
    return _finish(fig, path)


def _image_axes(ax: Any, w: float, h: float) -> None:
    """The image's outline, its extent (v down) and pixel-labelled axes."""
    ax.add_patch(_rect(w, h))
    ax.set_xlim(-0.02 * w, 1.02 * w)
    ax.set_ylim(1.02 * h, -0.02 * h)
    ax.set_aspect("equal")
    ax.set_xlabel("u (px)")
    ax.set_ylabel("v (px)")


def _rect(w: float, h: float) -> Any:
    from matplotlib.patches import Rectangle

    return Rectangle((0, 0), w, h, fill=False, color="k", lw=0.8)


def plot_projection_uncertainty(unc: Any, ax: Any = None, path: Any = None,
                                title: str | None = None) -> Any:
    """Heat map (with contours) of a :class:`boxplus.calib.uncertainty.ProjectionUncertainty`:
    σ of the projection in px over the image."""
    from matplotlib.colors import LogNorm

    fig, ax = _figure(ax, (7, 5.5))
    du = (unc.u[1] - unc.u[0]) / 2 if len(unc.u) > 1 else 0.5
    dv = (unc.v[1] - unc.v[0]) / 2 if len(unc.v) > 1 else 0.5
    # a log scale: σ grows by orders of magnitude where no corner was seen
    s = unc.sigma[np.isfinite(unc.sigma) & (unc.sigma > 0)]
    norm = LogNorm(vmin=s.min(), vmax=s.max()) if s.size and s.max() > s.min() else None
    im = ax.imshow(unc.sigma, extent=(unc.u[0] - du, unc.u[-1] + du, unc.v[-1] + dv, unc.v[0] - dv),
                   cmap="viridis", aspect="equal", norm=norm)
    if norm is not None and len(unc.u) > 1 and len(unc.v) > 1:
        levels = [x for x in (0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1, 2, 5, 10, 20, 50, 100)
                  if s.min() < x < s.max()]
        if levels:
            cs = ax.contour(unc.u, unc.v, unc.sigma, levels=levels, colors="w", linewidths=0.6)
            ax.clabel(cs, fontsize=7)
    fig.colorbar(im, ax=ax, label="σ of the projection (px)")
    ax.set_xlabel("u (px)")
    ax.set_ylabel("v (px)")
    ax.set_title(title or f"{unc.camera}: projection σ at {unc.distance:g} "
                 f"({'intrinsics + poses' if unc.poses else 'intrinsics'})")
    return _finish(fig, path)


def _axes(ax, pose, length: float, label: str, lw: float = 1.5) -> None:
    R, t = pose.rot.R, pose.pos
    for k, c in enumerate("rgb"):
        e = t + length * R[:, k]
        ax.plot([t[0], e[0]], [t[1], e[1]], [t[2], e[2]], c, lw=lw)
    if label:
        ax.text(*t, label, fontsize=8)


def plot_rig(path: Any = None, frames: Mapping[str, SE3] | None = None,
             boards: Sequence[tuple[SE3, np.ndarray]] = (),
             points: dict[str, np.ndarray] | None = None, length: float = 1.0,
             title: str = "rig", ax: Any = None,
             board_names: Sequence[str] | None = None) -> Any:
    """The rig in one reference frame: ``frames`` {name: ref_from_frame (SE3)} drawn as
    axes (x red, y green, z blue); ``boards`` [(ref_from_board, p_in_board (N, 3))]
    each as its own frame (axes at the board's origin, half length, labelled by
    ``board_names`` or its index) with its outline; ``points`` {name: (N, 3) in
    ref} (e.g. hand markers)."""
    fig, ax = _figure(ax, (7, 6), projection="3d")
    allp = []
    for name, pose in (frames or {}).items():
        _axes(ax, pose, length, name)
        allp.append(pose.pos[None])
    for i, (pose, p) in enumerate(boards):
        q = p @ pose.rot.R.T + pose.pos
        lo, hi = p.min(axis=0), p.max(axis=0)
        outline = np.array([[lo[0], lo[1], 0], [hi[0], lo[1], 0], [hi[0], hi[1], 0],
                            [lo[0], hi[1], 0], [lo[0], lo[1], 0]]) @ pose.rot.R.T + pose.pos
        ax.plot(outline[:, 0], outline[:, 1], outline[:, 2], color="0.5", lw=0.8)
        _axes(ax, pose, length / 2, board_names[i] if board_names else str(i), lw=0.8)
        allp.append(q)
    for name, p in (points or {}).items():
        p = np.atleast_2d(p)
        ax.scatter(p[:, 0], p[:, 1], p[:, 2], s=12, label=name)
        allp.append(p)
    if points:
        ax.legend()
    if allp:
        P = np.concatenate(allp)
        c, r = P.mean(axis=0), max(np.ptp(P, axis=0).max() / 2, length)
        ax.set_xlim(c[0] - r, c[0] + r)
        ax.set_ylim(c[1] - r, c[1] + r)
        ax.set_zlim(c[2] - r, c[2] + r)
    ax.set_title(title)
    return _finish(fig, path)


def plot_camera_imu(cal: Any, data: Any, path: Any = None, seconds: float = 2.0) -> Any:
    """A camera–IMU calibration (:func:`boxplus.calib.camera_imu.calibrate_camera_imu`)
    beside its data: ``seconds`` of gyroscope samples (dots) against the fitted
    trajectory's angular velocity plus the bias (lines), and the corners' reprojection
    errors (px)."""
    Figure = require("matplotlib.figure", "plotting").Figure
    fig = Figure(figsize=(12, 4.5))
    a, b = fig.subplots(1, 2)
    t_all = np.asarray(data.imu_times, float)
    lo = cal.t0 + cal.knot_spacing  # inside the spline, past its first segment
    window = (t_all >= lo) & (t_all < lo + seconds) & \
        (t_all < cal.t0 + (cal.n_knots - 4) * cal.knot_spacing)
    t = t_all[window]
    fitted = np.array([cal.angular_velocity(ti) for ti in t]).reshape(-1, 3) + cal.gyro_bias
    for j, axis in enumerate("xyz"):
        a.plot(t, np.asarray(data.gyro)[window, j], ".", ms=2, color=f"C{j}", label=f"gyro {axis}")
        a.plot(t, fitted[:, j], "-", lw=1, color=f"C{j}")
    a.set(xlabel="IMU time (s)", ylabel="angular velocity (rad/s)",
          title="gyroscope samples (dots) and the fitted trajectory (lines)")
    a.legend(fontsize=8, ncol=3)
    # one group per camera when the rig has several ("reprojection <name>")
    groups = {g: e for g, e in cal.problem.errors().items() if g.startswith("reprojection")}
    for j, (g, e) in enumerate(groups.items()):
        name = g.removeprefix("reprojection").strip() or "camera"
        b.plot(e[:, 0], e[:, 1], ".", ms=1.5, alpha=0.5, color=f"C{j}",
               label=f"{name}: RMS {np.sqrt(np.mean(e ** 2)):.3f} px")
    e = np.concatenate(list(groups.values()))
    b.set(xlabel="error u (px)", ylabel="error v (px)", aspect="equal",
          title=f"reprojection errors of {len(e)} corners, RMS {np.sqrt(np.mean(e ** 2)):.3f} px")
    if len(groups) > 1:
        b.legend(fontsize=8, markerscale=4)
    return _finish(fig, path)

