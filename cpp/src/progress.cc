#include "boxplus/progress.h"

#include <cstdio>

namespace boxplus {

std::string ProgressHeader() {
  char buf[160];
  std::snprintf(buf, sizeof buf, "%4s  %14s  %10s  %10s  %10s  %9s  %9s", "iter", "chi2", "change",
                "|gradient|", "|step|", "radius/α", "time");
  return buf;
}

std::string FormatProgress(const IterationInfo& i) {
  char buf[200];
  if (i.iteration == 0) {
    std::snprintf(buf, sizeof buf, "%4d  %14.8e", i.iteration, 2.0 * i.cost);
    return buf;
  }
  const bool line_search = i.trust_region_radius == 0.0;
  std::snprintf(buf, sizeof buf, "%4d  %14.8e  %+10.3e  %10.3e  %10.3e  %9.2e  %7.3f s%s",
                i.iteration, 2.0 * i.cost, -2.0 * i.cost_change, i.gradient_max_norm, i.step_norm,
                line_search ? i.step_length : i.trust_region_radius, i.cumulative_time_s,
                i.step_is_successful ? "" : "  (rejected)");
  return buf;
}

std::string FormatSummary(const SolveSummary& s) {
  char buf[256];
  std::snprintf(buf, sizeof buf, "%s: chi2 %.10g -> %.10g in %d iterations, %.3f s",
                s.termination.c_str(), 2.0 * s.initial_cost, 2.0 * s.final_cost, s.iterations,
                s.time_s);
  return buf;
}

}  // namespace boxplus
