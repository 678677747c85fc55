#include "boxplus/loss.h"

#include <algorithm>
#include <cctype>
#include <cmath>

#include "boxplus/errors.h"

namespace boxplus {

const std::vector<std::string>& LossNames() {
  static const std::vector<std::string> names = {"none",    "huber",  "cauchy",
                                                 "soft_l1", "arctan", "tukey"};
  return names;
}

std::string CanonicalLossName(const std::string& name) {
  std::string n = name;
  std::transform(n.begin(), n.end(), n.begin(), [](unsigned char c) { return std::tolower(c); });
  if (n.empty() || n == "trivial" || n == "l2") return "none";
  if (n == "softl1" || n == "soft-l1") return "soft_l1";
  for (const std::string& known : LossNames()) {
    if (n == known) return known;
  }
  std::string list;
  for (const std::string& known : LossNames()) list += (list.empty() ? "" : ", ") + known;
  throw Error("unknown robust loss '" + name + "' (expected one of " + list + ")");
}

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
