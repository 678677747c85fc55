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
//   none    ρ(s) = s (plain least squares; MakeLoss returns null)
// Aliases accepted on input: "softl1" (g2o's spelling), "trivial" (Ceres'),
// "l2" for none; names are case-insensitive.
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
