/**
 * @file fill_accounting.h
 * @brief What the region fill (region_fill.h) counts as found: the candidates' and the fill's
 *        own places, each with its uniqueness margins and its continuum. Internal to the fill.
 */
#pragma once

#include "fdml_localization/core/geometry/geometry.h"
#include "fdml_localization/core/localization/adaptive/adaptive_search.h"
#include "fdml_localization/core/localization/localizer.h"

#include <Eigen/Cholesky>

#include <algorithm>
#include <vector>

namespace fdml_localization
{
namespace core
{
/// A leaf's centre within this squared Mahalanobis distance of a candidate is its (chi-square,
/// 3 degrees of freedom, 99 %).
constexpr double kChiSquare3Dof = 11.34;

/// What candidates account for: a leaf box holding a candidate's pose within the uniqueness
/// margins (the candidate's own place), or whose centre lies within 3 sigma of the candidate's
/// covariance grown by the leaf's size (its continuum: a corridor, parallel walls). The grown
/// covariance is factorised once per candidate and leaf size.
class Accounting
{
public:
  explicit Accounting(const LocalizerOptions& options) : options_(options)
  {}

  void add(const Candidate& candidate)
  {
    // Factorised here too so that it is never read uninitialised; a leaf size replaces it.
    entries_.push_back(Entry{ candidate, Eigen::LDLT<Eigen::Matrix3d>(candidate.covariance), -1.0, -1.0 });
  }

  /// Forgets every candidate.
  void clear()
  {
    entries_.clear();
  }

  /// The candidate whose pose lies in @p box (within the uniqueness margins), or null.
  const Candidate* holder(const PoseBox& box) const
  {
    const auto e = std::find_if(entries_.begin(), entries_.end(), [&](const Entry& e) {
      return box.contains(e.candidate.pose, options_.uniqueness_distance, options_.uniqueness_angle);
    });
    return e == entries_.end() ? nullptr : &e->candidate;
  }

  /// The candidate whose continuum reaches @p box's centre, or null.
  const Candidate* continuumAt(const PoseBox& box)
  {
    const double cx = box.x1 - box.x0, ct = box.t1 - box.t0;
    const Pose2 centre = box.centre();
    for (Entry& e : entries_)
    {
      if (cx != e.cell_xy || ct != e.cell_theta)
      {
        e.cell_xy = cx;
        e.cell_theta = ct;
        e.spread.compute(e.candidate.covariance +
                         Eigen::Vector3d(cx * cx, cx * cx, ct * ct).asDiagonal().toDenseMatrix());
      }
      const Eigen::Vector3d d = poseDifference(centre, e.candidate.pose);
      if (d.dot(e.spread.solve(d)) <= kChiSquare3Dof)
      {
        return &e.candidate;
      }
    }
    return nullptr;
  }

private:
  struct Entry
  {
    Candidate candidate;
    Eigen::LDLT<Eigen::Matrix3d> spread;  ///< of its covariance + the leaf size below, squared
    double cell_xy, cell_theta;           ///< [m], [rad]
  };
  const LocalizerOptions& options_;
  std::vector<Entry> entries_;
};

}  // namespace core
}  // namespace fdml_localization
