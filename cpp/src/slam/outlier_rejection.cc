// The pieces of GNC that are plain functions (outlier_rejection.h): the
// surrogates' weights, the χ² quantile of the inlier threshold, the names,
// the report's file.
#include <cmath>
#include <cstdio>
#include <limits>

#include "boxplus/errors.h"
#include "boxplus/named_enum.h"
#include "boxplus/slam/outlier_rejection.h"

namespace boxplus::slam {

namespace {

const NamedEnum<OutlierMode>& OutlierModes() {
  static const NamedEnum<OutlierMode> names("outlier mode",
                                            {{OutlierMode::kAuto, "auto", {}},
                                             {OutlierMode::kOff, "off", {"none"}},
                                             {OutlierMode::kTls, "gnc-tls", {"tls", "gnc"}},
                                             {OutlierMode::kGm, "gnc-gm", {"gm"}}});
  return names;
}

// Regularised lower incomplete gamma P(a, x): its series for x < a + 1, else
// 1 − the continued fraction of Q (Lentz's method); both converge fast there.
double RegularisedGammaP(double a, double x) {
  if (x <= 0) return 0.0;
  const double log_prefactor = a * std::log(x) - x - std::lgamma(a);
  if (x < a + 1) {
    double term = 1.0 / a, sum = term;
    for (int n = 1; n < 1000; ++n) {
      term *= x / (a + n);
      sum += term;
      if (std::abs(term) < std::abs(sum) * 1e-16) break;
    }
    return sum * std::exp(log_prefactor);
  }
  const double tiny = 1e-300;
  double b = x + 1 - a, c = 1 / tiny, d = 1 / b, h = d;
  for (int n = 1; n < 1000; ++n) {
    const double an = -n * (n - a);
    b += 2;
    d = an * d + b;
    if (std::abs(d) < tiny) d = tiny;
    c = b + an / c;
    if (std::abs(c) < tiny) c = tiny;
    d = 1 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1) < 1e-16) break;
  }
  return 1.0 - std::exp(log_prefactor) * h;
}

}  // namespace

OutlierMode ParseOutlierMode(const std::string& name) { return OutlierModes().Parse(name); }

const std::string& OutlierModeName(OutlierMode mode) { return OutlierModes().Name(mode); }

double ChiSquaredQuantile(int dof, double p) {
  BOXPLUS_CHECK(dof >= 1, "chi-squared quantile: dof ", dof, " < 1");
  BOXPLUS_CHECK(p > 0 && p < 1, "chi-squared quantile: probability ", p, " not in (0, 1)");
  // The CDF of χ²(k) is P(k/2, x/2); bisection on [0, hi] with hi doubled
  // until it brackets p.
  const double a = 0.5 * dof;
  double lo = 0, hi = dof + 10.0;
  while (RegularisedGammaP(a, 0.5 * hi) < p) hi *= 2;
  for (int i = 0; i < 200 && hi - lo > 1e-12 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (RegularisedGammaP(a, 0.5 * mid) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

std::string FormatOutliers(const OutlierReport& r, const std::string& source) {
  char buf[320];
  std::string out = "# boxplus-g2o: loop closures judged wrong in " + source + "\n";
  if (!r.ran)
    return out + "# outlier rejection did not run (plausible graph, or --outlier-mode off)\n";
  std::snprintf(buf, sizeof buf,
                "# %s: %zu of %d loop closures; an edge is wrong when e'Omega e > %.6g at the "
                "inliers' optimum\n",
                r.method.c_str(), r.outliers.size(), r.candidates, r.threshold);
  out += buf;
  if (r.information_scale < 1) {
    std::snprintf(buf, sizeof buf,
                  "# the file's information is under-confident: thresholds x %.6g, the "
                  "inliers' chi2/dof\n",
                  r.information_scale);
    out += buf;
  }
  out += "# line from to chi2 weight\n";
  for (const EdgeVerdict& v : r.outliers) {
    std::snprintf(buf, sizeof buf, "%d %d %d %.9g %.6g\n", v.line, v.from, v.to, v.chi2, v.weight);
    out += buf;
  }
  return out;
}

double TlsWeight(double s, double mu) {
  if (!(s >= 0)) return 0.0;  // NaN: not an inlier
  if (s <= mu / (mu + 1)) return 1.0;
  if (s >= (mu + 1) / mu) return 0.0;
  return std::sqrt(mu * (mu + 1) / s) - mu;
}

double GmWeight(double s, double mu) {
  if (!(s >= 0)) return 0.0;
  const double r = mu / (s + mu);
  return r * r;
}

}  // namespace boxplus::slam
