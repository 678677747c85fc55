// Robust losses ρ by name: the one parser of loss names in boxplus.
//
// A loss applies to s = ‖r‖² of one whitened residual (Ceres' convention): the
// cost of a measurement is ½ ρ(s). The width δ > 0 is where the kernel leaves
// least squares, in whitened units, i.e. on ‖r‖ = √(eᵀΩe) (standard
// deviations; g2o's robust-kernel width):
//   huber   ρ(s) = s for s ≤ δ², 2δ√s − δ² beyond
//   cauchy  ρ(s) = δ² log(1 + s/δ²)
//   soft_l1 ρ(s) = 2δ² (√(1 + s/δ²) − 1)
//   arctan  ρ(s) = δ² atan(s/δ²)
//   tukey   ρ(s) = δ²/3 (1 − (1 − s/δ²)³) for s ≤ δ², δ²/3 beyond
//   geman_mcclure  ρ(s) = δ² s / (δ² + s)
//   dcs     ρ(s) = s for s ≤ Φ, Φ (3s − Φ) / (Φ + s) beyond, Φ = δ²
//   none    ρ(s) = s (plain least squares; MakeLoss returns null)
// dcs is dynamic covariance scaling (Agarwal, Tipaldi, Spinello, Stachniss,
// Burgard, ICRA 2013) written as the M-estimator it is: its weight ρ'(s) =
// min(1, 2Φ/(Φ + s))², the square of DCS' scale factor, and ρ the integral of
// that weight. dcs and geman_mcclure redescend (bounded ρ: 3Φ and δ²), like
// tukey, so they reject gross outliers from a good start and can stall from a
// poor one. g2o's DCS and GemanMcClure kernels take their width on s itself
// (Φ = width); here every width is on √s, so g2o's width w is δ = √w.
// Aliases accepted on input: "softl1" (g2o's spelling), "trivial" (Ceres'),
// "l2" for none, "gm" for geman_mcclure; names are case-insensitive.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <ceres/loss_function.h>

namespace boxplus {

// Throws boxplus::Error for an unknown name or a width that is not positive
// and finite. Returns null for "none".
std::shared_ptr<ceres::LossFunction> MakeLoss(const std::string& name, double width = 1.0);

// The canonical name of a loss ("huber", ..., "none"); throws for unknown names.
std::string CanonicalLossName(const std::string& name);

// The canonical names, for help texts and error messages.
const std::vector<std::string>& LossNames();

}  // namespace boxplus
