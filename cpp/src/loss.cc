#include "boxplus/loss.h"

#include <algorithm>
#include <cctype>
#include <cmath>

#include "boxplus/errors.h"
#include "boxplus/named_enum.h"

namespace boxplus {

namespace {

const NamedEnum<std::string>& Losses() {
  static const NamedEnum<std::string> names(
      "robust loss", {{"none", "none", {"", "trivial", "l2"}},
                      {"huber", "huber", {}},
                      {"cauchy", "cauchy", {}},
                      {"soft_l1", "soft_l1", {"softl1"}},
                      {"arctan", "arctan", {}},
                      {"tukey", "tukey", {}},
                      {"geman_mcclure", "geman_mcclure", {"gm", "gemanmcclure"}},
                      {"dcs", "dcs", {}}});
  return names;
}

// ρ(s) = δ² s / (δ² + s); ρ' = δ⁴/(δ² + s)², ρ'' = −2δ⁴/(δ² + s)³.
class GemanMcClureLoss final : public ceres::LossFunction {
 public:
  explicit GemanMcClureLoss(double width) : b_(width * width) {}
  void Evaluate(double s, double rho[3]) const override {
    const double d = b_ + s;
    const double w = b_ / d;
    rho[0] = b_ * s / d;
    rho[1] = w * w;
    rho[2] = -2.0 * w * w / d;
  }

 private:
  double b_;  // δ²
};

// Dynamic covariance scaling as an M-estimator (loss.h): least squares up to
// s = Φ, then ρ = Φ(3s − Φ)/(Φ + s), ρ' = 4Φ²/(Φ + s)², ρ'' = −8Φ²/(Φ + s)³.
class DcsLoss final : public ceres::LossFunction {
 public:
  explicit DcsLoss(double width) : phi_(width * width) {}
  void Evaluate(double s, double rho[3]) const override {
    if (s <= phi_) {
      rho[0] = s;
      rho[1] = 1.0;
      rho[2] = 0.0;
      return;
    }
    const double d = phi_ + s;
    const double w = 2.0 * phi_ / d;
    rho[0] = phi_ * (3.0 * s - phi_) / d;
    rho[1] = w * w;
    rho[2] = -2.0 * w * w / d;
  }

 private:
  double phi_;
};

}  // namespace

const std::vector<std::string>& LossNames() {
  static const std::vector<std::string> names = Losses().Names();
  return names;
}

std::string CanonicalLossName(const std::string& name) { return Losses().Parse(name); }

std::shared_ptr<ceres::LossFunction> MakeLoss(const std::string& name, double width) {
  const std::string n = CanonicalLossName(name);
  if (n == "none") return nullptr;
  BOXPLUS_CHECK(std::isfinite(width) && width > 0.0, "robust loss '", name,
                "': the width must be positive and finite, got ", width);
  if (n == "huber") return std::make_shared<ceres::HuberLoss>(width);
  if (n == "cauchy") return std::make_shared<ceres::CauchyLoss>(width);
  if (n == "soft_l1") return std::make_shared<ceres::SoftLOneLoss>(width);
  if (n == "arctan") return std::make_shared<ceres::ArctanLoss>(width);
  if (n == "geman_mcclure") return std::make_shared<GemanMcClureLoss>(width);
  if (n == "dcs") return std::make_shared<DcsLoss>(width);
  return std::make_shared<ceres::TukeyLoss>(width);  // "tukey"
}

}  // namespace boxplus
