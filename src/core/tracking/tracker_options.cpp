// The tracker's options: their one validation, and the state names.
#include "fdml_localization/core/tracking/hypothesis_tracker.h"

#include <cmath>
#include <sstream>

namespace fdml_localization
{
namespace core
{
std::vector<std::string> validate(const TrackerOptions& o, const std::function<std::string(const std::string&)>& name)
{
  std::vector<std::string> errors;
  const auto check = [&](bool ok, const char* option, double value, const std::string& allowed) {
    if (!ok)
    {
      std::ostringstream text;
      text << (name ? name(option) : std::string(option)) << " = " << value << " is out of range; allowed: " << allowed;
      errors.push_back(text.str());
    }
  };
  const auto in = [](double v, double lo, double hi) { return std::isfinite(v) && v >= lo && v <= hi; };
  check(in(o.min_consensus_fraction, 0.0, 1.0) && o.min_consensus_fraction > 0.0, "min_consensus_fraction",
        o.min_consensus_fraction, "(0, 1]");
  check(in(o.odom_alpha1, 0.0, 10.0), "odom_alpha1", o.odom_alpha1, "[0, 10]");
  check(in(o.odom_alpha2, 0.0, 10.0), "odom_alpha2", o.odom_alpha2, "[0, 10]");
  check(in(o.odom_alpha3, 0.0, 10.0), "odom_alpha3", o.odom_alpha3, "[0, 10]");
  check(in(o.odom_alpha4, 0.0, 10.0), "odom_alpha4", o.odom_alpha4, "[0, 10]");
  check(in(o.box_max_xy, 0.0, 100.0) && o.box_max_xy > 0.0, "box_max_xy", o.box_max_xy, "(0, 100] m");
  check(in(o.box_max_theta, 0.0, kPi) && o.box_max_theta > 0.0, "box_max_theta", o.box_max_theta, "(0, pi] rad");
  check(in(o.box_min_xy, 0.0, o.box_max_xy) && o.box_min_xy > 0.0, "box_min_xy", o.box_min_xy, "(0, box_max_xy] m");
  check(in(o.box_min_theta, 0.0, o.box_max_theta) && o.box_min_theta > 0.0, "box_min_theta", o.box_min_theta,
        "(0, box_max_theta] rad");
  check(in(o.cell_xy, 0.0, o.box_min_xy) && o.cell_xy >= 1e-3, "cell_xy", o.cell_xy, "[0.001 m, box_min_xy]");
  check(in(o.cell_theta, 0.0, o.box_min_theta) && o.cell_theta >= 1e-4, "cell_theta", o.cell_theta,
        "[0.0001 rad, box_min_theta]");
  check(in(o.support_decay, 0.0, 1.0) && o.support_decay > 0.0 && o.support_decay < 1.0, "support_decay",
        o.support_decay, "(0, 1)");
  check(in(o.min_support, 0.0, 1e6) && o.min_support > 0.0, "min_support", o.min_support, "(0, 1e6]");
  check(in(o.support_margin, 0.0, 1e6), "support_margin", o.support_margin, "[0, 1e6]");
  check(o.tolerated_misses >= 0 && o.tolerated_misses <= 1000, "tolerated_misses", o.tolerated_misses,
        "an integer in [0, 1000]");
  check(o.max_misses > o.tolerated_misses && o.max_misses <= 1000, "max_misses", o.max_misses,
        "an integer in (tolerated_misses, 1000]");
  check(o.conflict_readings >= 1 && o.conflict_readings <= 1000, "conflict_readings", o.conflict_readings,
        "an integer in [1, 1000]");
  check(in(o.publish_max_xy, 0.0, 100.0) && o.publish_max_xy > 0.0, "publish_max_xy", o.publish_max_xy, "(0, 100] m");
  check(in(o.publish_max_theta, 0.0, kPi) && o.publish_max_theta > 0.0, "publish_max_theta", o.publish_max_theta,
        "(0, pi] rad");
  check(o.lost_updates >= 1 && o.lost_updates <= 1000, "lost_updates", o.lost_updates, "an integer in [1, 1000]");
  check(o.max_hypotheses >= 1 && o.max_hypotheses <= 1000, "max_hypotheses", o.max_hypotheses,
        "an integer in [1, 1000]");
  check(in(o.merge_distance, 0.0, 100.0), "merge_distance", o.merge_distance, "[0, 100] m");
  check(in(o.merge_angle, 0.0, kPi), "merge_angle", o.merge_angle, "[0, pi] rad");
  check(in(o.agreement_tolerance, 0.0, 1e6) && o.agreement_tolerance > 0.0, "agreement_tolerance",
        o.agreement_tolerance, "(0, 1e6] m");
  check(in(o.range_tolerance, 0.0, 10.0), "range_tolerance", o.range_tolerance, "[0, 10] m");
  check(in(o.fix_covariance_scale, 1.0, 1000.0), "fix_covariance_scale", o.fix_covariance_scale, "[1, 1000]");
  check((std::isfinite(o.direction_group) && o.direction_group <= kPi) || o.direction_group < 0.0, "direction_group",
        o.direction_group, "[0, pi] rad, or < 0 (off)");
  check(in(o.fix_gate, 0.0, 1e6), "fix_gate", o.fix_gate, "[0, 1e6]");
  check(o.max_seeds >= 0 && o.max_seeds <= 100, "max_seeds", o.max_seeds, "an integer in [0, 100]");
  check(o.confirm_searches >= 0 && o.confirm_searches <= 100, "confirm_searches", o.confirm_searches,
        "an integer in [0, 100]");
  check(o.history_batches >= 0 && o.history_batches <= 1000, "history_batches", o.history_batches,
        "an integer in [0, 1000]");
  return errors;
}

const char* toString(TrackState state)
{
  switch (state)
  {
    case TrackState::Empty:
      return "empty";
    case TrackState::Tracking:
      return "tracking";
    case TrackState::Ambiguous:
      return "ambiguous";
    case TrackState::Lost:
      return "lost";
  }
  return "unknown";
}

}  // namespace core
}  // namespace fdml_localization
