#include "boxplus/loss.h"

#include <algorithm>
#include <cctype>
#include <cmath>

#include "boxplus/errors.h"
#include "boxplus/named_enum.h"

namespace boxplus {

namespace {

const NamedEnum<std::string>& Losses() {
  static const NamedEnum<std::string> names("robust loss", {{"none", "none", {"", "trivial", "l2"}},
                                                            {"huber", "huber", {}},
                                                            {"cauchy", "cauchy", {}},
                                                            {"soft_l1", "soft_l1", {"softl1"}},
                                                            {"arctan", "arctan", {}},
                                                            {"tukey", "tukey", {}}});
  return names;
}

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
  return std::make_shared<ceres::TukeyLoss>(width);  // "tukey"
}

}  // namespace boxplus
