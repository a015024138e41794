#include "fdml_localization/core/localization/no_return.h"

#include "fdml_localization/core/localization/ranking.h"
#include "fdml_localization/core/localization/robust_search.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace fdml_localization
{
namespace core
{
const char* toString(NoReturnPolicy policy)
{
  switch (policy)
  {
    case NoReturnPolicy::Weak:
      return "weak";
    case NoReturnPolicy::Drop:
      return "drop";
    case NoReturnPolicy::Constraint:
    default:
      return "constraint";
  }
}

NoReturnPolicy parseNoReturn(const std::string& text)
{
  for (NoReturnPolicy p : { NoReturnPolicy::Constraint, NoReturnPolicy::Weak, NoReturnPolicy::Drop })
  {
    if (text == toString(p))
    {
      return p;
    }
  }
  throw std::invalid_argument("unknown no_return '" + text + "' (expected constraint, weak or drop)");
}

std::vector<Reading> readingsWithReturn(const std::vector<Reading>& readings, const LocalizerOptions& options,
                                        std::vector<std::size_t>* kept)
{
  std::vector<Reading> returns;
  kept->clear();
  for (std::size_t i = 0; i < readings.size(); ++i)
  {
    if (std::isfinite(readings[i].range))
    {
      returns.push_back(readings[i]);
      kept->push_back(i);
    }
  }
  const std::size_t needed = std::max(3, options.min_inliers);
  if (returns.size() < needed)
  {
    throw InvalidInput(
        "no_return = " + std::string(toString(options.no_return)) + ": only " + std::to_string(returns.size()) +
        " of " + std::to_string(readings.size()) + " readings have a return; need at least " + std::to_string(needed) +
        (options.min_inliers > 3 ? " (min_inliers)" : "") + " (no_return = constraint uses the others too)");
  }
  return returns;
}

namespace
{
/// No-returns agreeing with the map at @p pose (no wall within max_range - eps, the cone's nearest
/// for a cone: readingResidual()), as constraint does.
int agreeingNoReturns(const MapRayCaster& map, const Pose2& pose, const std::vector<Reading>& readings, double eps)
{
  int agree = 0;
  for (const Reading& r : readings)
  {
    agree += !std::isfinite(r.range) && std::abs(readingResidual(map, pose, r)) < eps ? 1 : 0;
  }
  return agree;
}
}  // namespace

void restoreNoReturns(Result* result, const std::vector<Reading>& readings, const std::vector<std::size_t>& kept,
                      const LocalizerOptions& options, const MapRayCaster& map)
{
  for (Candidate& c : result->candidates)
  {
    std::vector<bool> mask(readings.size(), false);
    for (std::size_t j = 0; j < kept.size() && j < c.inlier_mask.size(); ++j)
    {
      mask[kept[j]] = c.inlier_mask[j];
    }
    c.inlier_mask = std::move(mask);
  }
  if (options.no_return != NoReturnPolicy::Weak || kept.size() == readings.size())
  {
    return;
  }
  std::vector<std::pair<int, Candidate>> scored;
  for (Candidate& c : result->candidates)
  {
    scored.emplace_back(agreeingNoReturns(map, c.pose, readings, options.agreement_tolerance), std::move(c));
  }
  std::stable_sort(scored.begin(), scored.end(), [](const auto& a, const auto& b) {
    const Candidate& ca = a.second;
    const Candidate& cb = b.second;
    if (netConsensus(ca) != netConsensus(cb) || ca.contradicted != cb.contradicted)
    {
      return betterCandidate(ca, cb);
    }
    return a.first != b.first ? a.first > b.first : ca.rms_residual < cb.rms_residual;
  });
  result->candidates.clear();
  for (auto& s : scored)
  {
    result->candidates.push_back(std::move(s.second));
  }
}

}  // namespace core
}  // namespace fdml_localization
