"""Light distortion regularisation: a Gaussian prior that pulls each distortion
term towards zero, measured by what the term does at the edge of the field the
camera saw.

Why: a distortion polynomial or rational function has more freedom than corners
on a board pin down. OpenCV's rational model trades its numerator (k1..k3) against
its denominator (k4..k6) along a valley of equal RMS, and the fit can fold over
inside the calibrated field (:mod:`boxplus.calib.fold`). mrcal adds light
regularisation terms for the same reason. boxplus' form is a prior of fixed width,
so that its pull vanishes as data grow and σ keeps its meaning (mrcal instead
scales its terms with the number of corners):

    r_j = k_j ρ^(n_j) / s

with ρ the largest normalised radius at which the camera saw a corner (tan θ for
the pinhole family and the rational model, θ for Kannala–Brandt, from the start's
board poses) and n_j the power of ρ by which the term changes the radial factor:
k1, k4 → 2, k2, k5 → 4, k3, k6 → 6 (Kannala–Brandt's k_i → 2i), p1, p2 → 1 (their
displacement over the radius). So s is the size of a term's effect at the field's
edge, as a fraction of the radius, that the prior calls one σ; at ρ = 1 the
prior is on the coefficients themselves. The focal lengths and the principal
point are left to the data. Double sphere has no distortion terms to pull: its
ξ and α are the projection itself.

The prior's rows are the measurement group ``"distortion prior <camera>"``;
``Calibration.rms()`` and the per-camera RMS count corners only. Every σ the
report gives includes the prior, which it says.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from boxplus.calib.fold import observed_field
from boxplus.calib.models import model_labels
from boxplus.manifolds import Rn

__all__ = ["DEFAULT_PRIOR_SIGMA", "REGULARIZED_BY_DEFAULT", "DistortionPrior", "add_distortion_prior",
           "distortion_powers"]

# The default width s, chosen on bench/bench_lens_regularisation.py (20 captures per
# family, projection against the true lens): fitted to rational, opencv5 and fisheye
# lenses, the rational model folded over inside the field in 13 of 80 fits without
# the prior (15 of 80 with 10 views instead of 20), in 1 at s = 0.2 and in none at
# s = 0.1 (none with 10 views either). The in-field RMS error against the true lens
# improved or stayed within 0.005 px, except on the fisheye the model cannot
# represent (0.31 → 0.37 px, its worst pixel 35 → 1.8 px). On opencv5 and
# Kannala–Brandt lenses fitted with their own model the prior moved the projection by
# at most 0.003 px; s = 0.05 began to bias the rational fits.
DEFAULT_PRIOR_SIGMA = 0.1

# Regularised unless regularize=False: the models whose fits fold over without it.
# The others are regularised when asked (regularize=True or a width): their fits
# equal OpenCV's when not.
REGULARIZED_BY_DEFAULT = frozenset({"rational"})

_POWERS: dict[str, int] = {"k1": 2, "k2": 4, "k3": 6, "k4": 2, "k5": 4, "k6": 6, "p1": 1, "p2": 1}
_KB_POWERS: dict[str, int] = {"k1": 2, "k2": 4, "k3": 6, "k4": 8}


def distortion_powers(model: str) -> dict[str, int]:
    """{label: power of ρ} of a model's distortion terms ({} for double sphere and the
    pinhole)."""
    if model == "double_sphere":
        return {}
    table = _KB_POWERS if model == "kannala_brandt" else _POWERS
    return {label: table[label] for label in model_labels(model) if label in table}


@dataclass
class DistortionPrior:
    """What regularisation a camera got: its model's terms, the field radius ρ, the
    prior's width s and the measurement id of the prior."""

    camera: str
    labels: list[str]
    rho: float
    sigma: float
    mid: int

    def todict(self) -> dict[str, Any]:
        return {"camera": self.camera, "terms": list(self.labels), "rho": self.rho, "sigma": self.sigma}

    def __str__(self) -> str:
        return (f"{self.camera}: distortion regularised ({', '.join(self.labels)} pulled to 0 with "
                f"σ = {self.sigma:g} of their effect at the field's edge, ρ = {self.rho:.3f}); its σ "
                f"include this prior (regularize=False for none)")


def add_distortion_prior(cal: Any, camera: str, sigma: float) -> DistortionPrior | None:
    """Adds the prior to ``camera``'s intrinsics of a built (not yet solved) calibration;
    None when its model has no distortion terms or the intrinsics are fixed."""
    if not (np.isfinite(sigma) and sigma > 0):
        raise ValueError(f"regularize: the prior's σ must be > 0, got {sigma}")
    model = cal.models.get(camera, cal.model)
    powers = distortion_powers(model)
    o = cal.problem
    vid = cal.ids[camera]
    if not powers or o.is_fixed(vid):
        return None
    theta = observed_field(cal, camera)
    if model == "kannala_brandt":
        rho = theta
    else:
        rho = float(np.tan(min(theta, np.radians(85.0))))
    rho = max(rho, 1e-3)
    labels = list(powers)
    std = [sigma / rho ** powers[label] for label in labels]
    mid = o.add_prior(vid, Rn(np.zeros(len(labels))), sigma=std, coordinates=labels,
                      name=f"distortion prior {camera}", group=f"distortion prior {camera}")
    return DistortionPrior(camera, labels, rho, float(sigma), mid)
