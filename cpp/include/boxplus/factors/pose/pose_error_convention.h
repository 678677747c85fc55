// Which error a relative-pose factor uses (2D and 3D), for Δ = z⁻¹ (xᵢ⁻¹ xⱼ):
//   kG2o  g2o's: 2D e = [t_Δ, θ_Δ]; 3D e = [t_Δ, vec(q_Δ)] with q_Δ.w ≥ 0.
//   kLog  GTSAM's (BetweenFactor with the Lie-group chart, "SO(3)-log"
//         convention): e = Log_SE(d)(Δ), reordered [translation part u,
//         rotation part ω] so that the file's information matrix applies
//         unchanged. u = V(ω)⁻¹ t_Δ (V the left Jacobian), which differs from
//         t_Δ by O(|ω|·|t|).
//   kSESync SE-Sync's chordal objective (Rosen et al., IJRR 2019), not an
//         error of Δ: r = [√τ (tⱼ − tᵢ − Rᵢt̃ᵢⱼ), √κ vec(Rⱼ − RᵢR̃ᵢⱼ)] with
//         isotropic precisions τ, κ from Ω (relative_pose_sesync.h); its
//         chi2 is Σ‖r‖², SE-Sync's f.
// Details and Jacobians: relative_pose2d.h, relative_pose3d.h,
// relative_pose_sesync.h.
#pragma once

#include <string>

namespace boxplus {

enum class PoseErrorConvention { kG2o, kLog, kSESync };

// "g2o", "log" (also "gtsam", "se3log", "se2log") or "sesync" (also
// "chordal"); throws boxplus::Error.
PoseErrorConvention ParsePoseErrorConvention(const std::string& name);
// "g2o", "log" or "sesync".
const char* ToString(PoseErrorConvention c);

}  // namespace boxplus
