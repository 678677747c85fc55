"""The report a calibration user reads first: what matters, in the units they use.

:func:`summarise` leads with the RMS reprojection error per camera and per
image (the worst images by name), then each camera's intrinsics with σ, the
poses between the cameras (translation in the target's unit, rotation in
degrees) with σ and, for a stereo pair, the baseline; then what was left out
(views skipped, corners dropped) and every warning (parameters the data do not
determine, a rig that moved a camera's intrinsics far from its own mono fit).
The board poses — one per view, most of a calibration's parameters — go to
their own file (:func:`board_poses_csv`), not into the report.

σ convention (as :mod:`boxplus.calib.report`): σ from the corner noise the
calibration was given, with the σ rescaled by the fit's residual σ̂ beside it
in brackets.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["board_poses_csv", "camera_rms", "summarise"]


def camera_rms(cal: Any, camera: str) -> float:
    """RMS of the 2-D reprojection errors of one camera (px)."""
    E = cal.problem.measurement_errors(cal.view_ids[camera])
    return float(np.sqrt(np.mean(np.sum(E**2, axis=1))))


def _per_image_rms(cal: Any, camera: str) -> list[tuple[int, float, int]]:
    """(view index, RMS px, corners) of every image of a camera."""
    out = []
    for mid, view in zip(cal.view_ids[camera], cal.view_index[camera]):
        E = cal.problem.measurement_errors(mid)
        out.append((view, float(np.sqrt(np.mean(np.sum(E**2, axis=1)))), len(E)))
    return out


def _fmt(values: np.ndarray, std: np.ndarray, other: np.ndarray, labels: list[str],
         scale: float = 1.0) -> list[str]:
    return [f"{lab} {v * scale:.6g} ± {s * scale:.3g} [{o * scale:.3g}]"
            for lab, v, s, o in zip(labels, values, std, other)]


def summarise(cal: Any, report: Any, file_names: dict[str, list[str]] | None = None,
              target: str = "", rectification: Any = None, worst: int = 5) -> str:
    """The calibration's report as text (see the module docstring).

    Parameters
    ----------
    cal : boxplus.calib.Calibration
    report : boxplus.calib.CalibrationReport
        ``cal.report()`` (σ from the given noise).
    file_names : {camera: [file name per kept view]}, optional
        Names images by file in the worst-images list.
    rectification : boxplus.calib.rectify.StereoRectification, optional
        A stereo pair's rectification: its baseline is reported.
    """
    o = cal.problem
    cams = list(cal.view_ids)
    n_corners = sum(len(o.measurement_errors(cal.view_ids[c])) for c in cams if cal.view_ids[c])
    lines = [f"boxplus-calib: {len(cams)} camera(s), {len(cal.view_names)} views"
             + (f", target {target}" if target else ""),
             f"RMS reprojection error {cal.rms():.4f} px over {n_corners} corners"]
    for c in cams:
        lines.append(f"  {c} ({cal.models[c]}): RMS {camera_rms(cal, c):.4f} px, "
                     f"{len(cal.view_ids[c])} views")
    factor = report.sigma_factor
    lines.append(f"Intrinsics: value ± σ (from the corner noise) [σ·σ̂, σ̂ = {factor:.4f}]")
    for c in cams:
        vals = o[cal.ids[c]].vec
        std = report.std(c)
        labels = o.labels(cal.ids[c])
        held = " (held fixed: known intrinsics)" if o.is_fixed(cal.ids[c]) else ""
        lines.append(f"  {c}{held}: " + ", ".join(_fmt(vals, std, std * factor, labels)))
    for prior in getattr(cal, "priors", []):
        lines.append(f"  {prior}")
    for c in cams:
        if cal.models[c] == "double_sphere" and not o.is_fixed(cal.ids[c]):
            lines.append(f"  {c}: double sphere: fx, fy, ξ and α trade along a curved valley, where "
                         f"their σ is linearised and too small (1.4× on simulated wide captures, α "
                         f"more); the projection uncertainty is the figure to trust, and "
                         f"cal.profile('{c}', 'alpha') (boxplus-calib --profile) gives a parameter's "
                         f"profile-likelihood interval")
    others = [c for c in cams if c != cal.reference]
    if others:
        lines.append(f"Extrinsics: <camera>_from_{cal.reference}, translation in the target's "
                     f"unit, rotation vector in degrees, ± σ [σ·σ̂]")
        for c in others:
            name = f"{c}_from_{cal.reference}"
            pose = o[cal.ids[name]]
            std = report.std(name)
            d = o.codec(cal.ids[name]).display(pose)
            t = _fmt(d[:3], std[:3], std[:3] * factor, ["x", "y", "z"])
            r = _fmt(d[3:], std[3:], std[3:] * factor, ["rx", "ry", "rz"], np.degrees(1.0))
            lines.append(f"  {c}: " + ", ".join(t) + "; " + ", ".join(r))
    if rectification is not None:
        lines.append(f"Stereo baseline {abs(rectification.baseline):.6g} (target unit), "
                     f"rectified focal length {rectification.P1[0, 0]:.6g} px"
                     + (" (a vertical pair)" if rectification.vertical else ""))
    def image(camera: str, view: int) -> str:
        names = (file_names or {}).get(camera)
        return names[view] if names and view < len(names) and names[view] else cal.view_names[view]

    rows = []
    for c in cams:
        for view, rms, n in _per_image_rms(cal, c):
            rows.append((rms, c, image(c, view), n))
    rows.sort(reverse=True)
    if rows:
        lines.append("Worst images (RMS px, corners): " + "; ".join(
            f"{c} {f} {r:.3f} ({n})" for r, c, f, n in rows[:worst]))
    for s in getattr(cal, "skipped", []):
        lines.append(f"Skipped: {s.camera} {image(s.camera, s.view)}: {s.reason}")
    if cal.dropped:
        lines.append(f"Dropped {len(cal.dropped)} corner(s) beyond the robust threshold: " + "; ".join(
            f"{d.camera} {image(d.camera, d.view)} corner {d.corner} ({d.error_px:.2f} px)"
            for d in cal.dropped[:20]) + (" ..." if len(cal.dropped) > 20 else ""))
    warnings = list(report.warnings)
    warnings += [str(s) for s in getattr(cal, "intrinsics_shift", []) if s.worst_sigmas > 5.0]
    for w in warnings:
        lines.append("WARNING: " + w)
    return "\n".join(lines)


def board_poses_csv(cal: Any, report: Any, file_names: dict[str, list[str]] | None = None) -> str:
    """One line per view: its name and world_from_<reference> (position, quaternion
    [x, y, z, w]) with the σ of its tangent [δp, δθ] (target unit, rad)."""
    o = cal.problem
    head = ("view,name,x,y,z,qx,qy,qz,qw,sigma_x,sigma_y,sigma_z,sigma_rx,sigma_ry,sigma_rz")
    lines = [head]
    for i, v in enumerate(cal.world_from_ref):
        if v is None:
            continue
        pose = o[v]
        std = report.std(o.variable_name(v))
        name = cal.view_names[i]
        vals = [*pose.pos, *pose.rot.quat, *std]
        lines.append(f"{i},{name}," + ",".join(repr(float(x)) for x in vals))
    return "\n".join(lines) + "\n"
