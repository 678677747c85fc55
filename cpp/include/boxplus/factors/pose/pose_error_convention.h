// Which residual a relative-pose measurement uses, chosen at run time (a pose
// graph's option, the CLI's --convention, Python's convention=). Three are
// errors e of the relative pose, whitened as r = W e (relative_pose.h; each
// has a tag type there, so that the error templates are instantiated for
// errors only):
//   kG2o       g2o's EdgeSE2/EdgeSE3:  e = [t_Δ, θ_Δ] / [t_Δ, vec(q_Δ)]
//   kLog       GTSAM's BetweenFactor:  e = Log(Δ), ordered [u, ω]
//   kCompound  boxplus' ⊟ of the compound Rᵈ × SO(d): e = (xᵢ⁻¹xⱼ) ⊟ z
// and one is not an error of Δ but its own residual kind:
//   kSESync    SE-Sync's chordal residual (Rosen et al., IJRR 2019),
//              r = [√τ (tⱼ − tᵢ − Rᵢt̃ᵢⱼ), √κ vec(Rⱼ − RᵢR̃ᵢⱼ)]
//              (chordal_relative_pose.h); Σ‖r‖² is SE-Sync's f.
#pragma once

#include <string>

namespace boxplus {

enum class PoseErrorConvention { kG2o, kLog, kSESync, kCompound };

// "g2o", "log" (also "gtsam", "se3log", "se2log"), "compound" or "sesync"
// (also "chordal"); throws boxplus::Error naming the accepted names.
PoseErrorConvention ParsePoseErrorConvention(const std::string& name);
// "g2o", "log", "compound" or "sesync".
const char* ToString(PoseErrorConvention c);

}  // namespace boxplus
