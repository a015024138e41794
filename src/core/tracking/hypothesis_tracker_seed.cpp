// The tracker's seeding: a global search's candidates merged (new places carried through the
// remembered batches first), a user's hint.
#include "fdml_localization/core/tracking/hypothesis_tracker.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <utility>

namespace fdml_localization
{
namespace core
{
Hypothesis* HypothesisTracker::holding(const Pose2& pose, const Pose2& reference)
{
  const auto found = std::find_if(hypotheses_.begin(), hypotheses_.end(), [&](const Hypothesis& h) {
    return samePlace(compose(h.map_to_odom, reference), pose);
  });
  return found == hypotheses_.end() ? nullptr : &*found;
}

void HypothesisTracker::add(const std::vector<Candidate>& candidates, const Pose2& reference, double support,
                            int confirmations, const Eigen::Matrix3d& spread)
{
  if (!have_reference_)
  {
    last_reference_ = reference;
    have_reference_ = true;
  }
  for (const Candidate& c : candidates)
  {
    if (Hypothesis* duplicate = holding(c.pose, reference))
    {
      duplicate->support = std::max(duplicate->support, support);
      continue;
    }
    Hypothesis h;
    h.id = next_id_++;
    h.map_to_odom = compose(c.pose, inverse(reference));
    h.support = support;
    h.last_fix = c;
    h.covariance = initialCovariance(c) + spread;
    h.confirmations = confirmations;
    hypotheses_.push_back(std::move(h));
  }
}

void HypothesisTracker::seed(const std::vector<Candidate>& candidates, const Pose2& reference, double support,
                             std::size_t since)
{
  std::vector<Candidate> fresh;
  for (const Candidate& c : candidates)
  {
    Hypothesis* duplicate = holding(c.pose, reference);
    if (duplicate)
    {
      duplicate->support = std::max(duplicate->support, support);
    }
    else
    {
      fresh.push_back(c);
    }
  }
  double best = 0.0;
  for (Hypothesis& h : hypotheses_)
  {
    ++h.confirmations;
    best = std::max(best, h.support);
  }
  failed_updates_ = candidates.empty() ? failed_updates_ : 0;
  // The new places go alone through the remembered batches: history_batches before the search's
  // batch, that batch and the `since` after it; the others already stand at the newest.
  const std::size_t remembered = history_.size();
  const std::size_t window = std::min(since, remembered) + 1 + static_cast<std::size_t>(options_.history_batches);
  const std::size_t first = remembered > window ? remembered - window : 0;
  const std::size_t searched = remembered - std::min(since, remembered);
  std::vector<Hypothesis> others;
  others.swap(hypotheses_);
  const int failed = failed_updates_;
  const bool had_reference = have_reference_;
  const Pose2 latest = last_reference_;
  if (first < remembered)
  {
    last_reference_ = history_[first].reference;
    have_reference_ = true;
  }
  // Before the remembered batches nothing tells the new places from the best: they start with
  // its support (about what it had then), which the batches they are carried through decay as
  // they decayed the best's, and earn the rest on the same readings.
  const double start = std::max(support, best);
  add(fresh, reference, start, 0, replaySpread(first, searched));
  replay(first);
  hypotheses_.insert(hypotheses_.end(), std::make_move_iterator(others.begin()), std::make_move_iterator(others.end()));
  failed_updates_ = std::min(failed, failed_updates_);
  last_reference_ = had_reference ? latest : last_reference_;
  prune();
}

void HypothesisTracker::replay(std::size_t first)
{
  struct Replaying
  {
    bool& flag;
    ~Replaying()
    {
      flag = false;
    }
  } guard{ replaying_ };
  replaying_ = true;
  for (std::size_t i = first; i < history_.size(); ++i)
  {
    update(history_[i].readings, history_[i].reference);
  }
}

Eigen::Matrix3d HypothesisTracker::replaySpread(std::size_t first, std::size_t last) const
{
  double travelled = 0.0, turned = 0.0;
  for (std::size_t i = first + 1; i < last && i < history_.size(); ++i)
  {
    const Pose2 d = between(history_[i - 1].reference, history_[i].reference);
    travelled += std::hypot(d.x, d.y);
    turned += std::abs(d.theta);
  }
  const TrackerOptions& o = options_;
  const double xy = o.odom_alpha3 * travelled + o.odom_alpha4 * turned;
  const double theta = o.odom_alpha1 * turned + o.odom_alpha2 * travelled;
  return Eigen::Vector3d(xy * xy, xy * xy, theta * theta).asDiagonal();
}

Eigen::Matrix3d HypothesisTracker::leastCovariance() const
{
  const Eigen::Vector3d floor(options_.box_min_xy / 3.0, options_.box_min_xy / 3.0, options_.box_min_theta / 3.0);
  return floor.cwiseProduct(floor).asDiagonal();
}

Eigen::Matrix3d HypothesisTracker::initialCovariance(const Candidate& candidate) const
{
  // At least the smallest search box (as 3 sigma): a global search's polish may be overconfident.
  const Eigen::Matrix3d least = leastCovariance();
  const Eigen::Matrix3d& polished = candidate.covariance;
  return polished.allFinite() && polished.diagonal().minCoeff() > 0.0 ? Eigen::Matrix3d(polished + least) : least;
}

bool HypothesisTracker::wantsGlobalSearch(bool searching, int since_search, int interval) const
{
  const TrackState now = state();
  const bool stuck = failed_updates_ >= interval && since_search >= interval;
  return awaitingConfirmation() || (searching && (now == TrackState::Empty || now == TrackState::Lost || stuck));
}

HintOutcome HypothesisTracker::seedFromHint(const PoseBox& box, const std::vector<Reading>& readings,
                                            const Pose2& reference)
{
  const int k = static_cast<int>(readings.size());
  LocalSolveSettings settings = solveSettings(k);
  // A hint's box may be metres wide: coarser leaves (at most 64 per axis) and more seeds.
  settings.cell_xy = std::max(settings.cell_xy, std::max(box.x1 - box.x0, box.y1 - box.y0) / 64.0);
  settings.cell_theta = std::max(settings.cell_theta, (box.t1 - box.t0) / 64.0);
  settings.max_seeds = std::max(settings.max_seeds, 2 * options_.max_hypotheses);
  settings.max_boxes = 2000000;
  const BoxOccupancy coarse(*map_, settings.cell_xy);
  const LocalSolveOutcome found = localSolve(*map_, coarse, readings, box, settings);
  HintOutcome outcome;
  outcome.min_consensus = settings.min_consensus;
  outcome.best_consensus = found.best_consensus;
  if (found.fixes.empty())
  {
    return outcome;
  }
  clear();
  failed_updates_ = 0;
  // The user placed the robot: no search needs to confirm the hint's places.
  add(found.fixes, reference, options_.min_support, options_.confirm_searches, Eigen::Matrix3d::Zero());
  prune();
  outcome.accepted = true;
  outcome.hypotheses = static_cast<int>(hypotheses_.size());
  return outcome;
}

}  // namespace core
}  // namespace fdml_localization
