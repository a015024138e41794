// The continuous polish: Levenberg-Marquardt on (x, y, theta) over the exact ray cast (analytic
// derivative) or the exact cone cast (analytic derivative too), with a covariance estimate.
#include "fdml_localization/core/localization/robust_search.h"

#include "fdml_localization/core/geometry/cone_cast.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <limits>

namespace fdml_localization
{
namespace core
{
namespace
{
/// Residual [m] charged to a ray that leaves free space or misses, during the polish.
constexpr double kPenaltyResidual = 1.0;
/// A step shorter than this [m], [rad] ends the polish: the pose has converged. A damping (LM
/// lambda) beyond kStartDamping ends it, and beyond kCrawlDamping once a step is taken: a tenth of
/// Gauss-Newton's step still fails, so the pose is pressed against a depth discontinuity (a ray
/// about to reach another wall) the model cannot see, where descent crawls micrometres a step.
constexpr double kConvergedStep = 1e-8;
constexpr double kConvergedTurn = 1e-9;
constexpr double kCrawlDamping = 10.0;
constexpr double kStartDamping = 1e8;

/// One reading's residual and its derivative with respect to (x, y, theta).
struct ResidualRow
{
  double r = 0.0;
  Eigen::RowVector3d jacobian = Eigen::RowVector3d::Zero();
  bool valid = false;
};

/// cos and sin of the robot's heading and of a reading's mounting angle.
struct Rotation
{
  double c = 1.0;
  double s = 0.0;
  explicit Rotation(double angle) : c(std::cos(angle)), s(std::sin(angle))
  {}
};

/// A ray reading: the hit edge's normal gives the derivative of the range.
ResidualRow rayRow(const MapRayCaster& map, const Pose2& q, const Rotation& rq, const Reading& reading,
                   const Rotation& rg)
{
  ResidualRow row;
  const double c = rq.c;
  const double s = rq.s;
  const Vec2 origin(q.x + c * reading.offset.x - s * reading.offset.y,
                    q.y + s * reading.offset.x + c * reading.offset.y);
  if (!map.isFree(origin))
  {
    return row;
  }
  const Vec2 u(c * rg.c - s * rg.s, s * rg.c + c * rg.s);
  const RayHit hit = map.cast(origin, u);
  if (!hit.hit() || !std::isfinite(hit.distance))
  {
    return row;
  }
  row.valid = true;
  row.r = hit.distance - reading.range;
  const Segment& seg = map.grid().segments()[static_cast<std::size_t>(hit.segment)];
  const Vec2 edge = seg.b - seg.a;
  const double len = edge.norm();
  if (len <= 0.0)
  {
    return row;
  }
  const Vec2 n(-edge.y() / len, edge.x() / len);
  const double nu = n.dot(u);
  if (std::abs(nu) < 1e-6)
  {
    return row;
  }
  // t = (c - n.p) / (n.u): dt/dp = -n / (n.u), dt/dphi = -t (n.u_perp) / (n.u).
  const Vec2 dp_dtheta(-s * reading.offset.x - c * reading.offset.y, c * reading.offset.x - s * reading.offset.y);
  const Vec2 u_perp(-u.y(), u.x());
  row.jacobian(0) = -n.x() / nu;
  row.jacobian(1) = -n.y() / nu;
  row.jacobian(2) = -n.dot(dp_dtheta) / nu - hit.distance * n.dot(u_perp) / nu;
  return row;
}

/// A cone reading: the exact cone cast and its analytic derivative (cone_cast.h). Where the
/// nearest point lies strictly inside the sector the heading enters only through the sensor's
/// mounting offset (the reading does not fix it). @p hint: the reading's last hit point (NaN
/// before the first), which bounds the cast near the last pose; updated.
ResidualRow coneRow(const MapRayCaster& map, const Pose2& q, const Rotation& rq, const Reading& reading, Vec2& hint)
{
  ResidualRow row;
  const Pose2 sensor = compose(q, reading.offset);
  if (!map.isFree(sensor.position()))
  {
    return row;
  }
  const ConeHit hit = coneCast(map, sensor, reading.half_angle, kInf, hint);
  if (!std::isfinite(hit.distance))
  {
    return row;
  }
  hint = hit.point;
  row.valid = true;
  row.r = hit.distance - reading.range;
  const Eigen::RowVector3d d = coneRangeDerivative(map, sensor, reading.half_angle, hit);
  const Vec2 dp_dtheta(-rq.s * reading.offset.x - rq.c * reading.offset.y,
                       rq.c * reading.offset.x - rq.s * reading.offset.y);
  row.jacobian << d(0), d(1), d(2) + d(0) * dp_dtheta.x() + d(1) * dp_dtheta.y();
  return row;
}

struct System
{
  double cost = 0.0;
  Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
  Eigen::Vector3d g = Eigen::Vector3d::Zero();
  Eigen::Matrix3d jtj = Eigen::Matrix3d::Zero();
  double sum_sq = 0.0;
  int used = 0;
};

/// One reading's row: the cone cast for a cone reading (updating @p hint), else the ray cast.
ResidualRow readingRow(const MapRayCaster& map, const Pose2& q, const Rotation& rq, const Reading& reading,
                       const Rotation& mount, Vec2& hint)
{
  return reading.half_angle > 0.0 ? coneRow(map, q, rq, reading, hint) : rayRow(map, q, rq, reading, mount);
}

/// The one-sided row of a no-return reading (free up to its max range): the range the map
/// gives short of max_range (r < 0) where a wall lies within it, else inactive (not valid).
ResidualRow noReturnRow(const MapRayCaster& map, const Pose2& q, const Rotation& rq, const Reading& reading,
                        const Rotation& mount, Vec2& hint)
{
  if (!(reading.max_range < kInf))
  {
    return ResidualRow();
  }
  Reading bound = reading;
  bound.range = reading.max_range;
  ResidualRow row = readingRow(map, q, rq, bound, mount, hint);
  row.valid = row.valid && row.r < 0.0;
  return row;
}

/// Adds @p row's cost (Cauchy loss of @p scale [m], 0 = squares) and gradient to @p sys; its
/// information too when @p informs (a range; not a no-return's one-sided bound).
void addRow(System& sys, const ResidualRow& row, double scale, bool informs)
{
  double w = 1.0;
  if (scale > 0.0)
  {
    const double z = (row.r / scale) * (row.r / scale);
    sys.cost += scale * scale * std::log1p(z);
    w = 1.0 / (1.0 + z);
  }
  else
  {
    sys.cost += row.r * row.r;
  }
  sys.h += w * row.jacobian.transpose() * row.jacobian;
  sys.g += w * row.jacobian.transpose() * row.r;
  if (informs)
  {
    sys.jtj += row.jacobian.transpose() * row.jacobian;
    sys.sum_sq += row.r * row.r;
  }
}

/// The normal equations at @p q; @p hints: each cone reading's last hit point (see coneRow).
System buildSystem(const MapRayCaster& map, const Pose2& q, const std::vector<Reading>& readings,
                   const std::vector<Rotation>& mounts, const std::vector<bool>& use, double scale,
                   std::vector<Vec2>& hints)
{
  System sys;
  const Rotation rq(q.theta);
  for (std::size_t i = 0; i < readings.size(); ++i)
  {
    if (!use[i])
    {
      continue;
    }
    if (!std::isfinite(readings[i].range))
    {
      const ResidualRow bound = noReturnRow(map, q, rq, readings[i], mounts[i], hints[i]);
      if (bound.valid)
      {
        addRow(sys, bound, scale, false);
      }
      continue;
    }
    const ResidualRow row = readingRow(map, q, rq, readings[i], mounts[i], hints[i]);
    ++sys.used;
    if (!row.valid)
    {
      const double p = kPenaltyResidual;
      sys.cost += scale > 0.0 ? scale * scale * std::log1p((p / scale) * (p / scale)) : p * p;
      continue;
    }
    addRow(sys, row, scale, true);
  }
  return sys;
}

/// Adds @p prior's term, weighted by @p weight (noise_sigma^2, the readings' cost unit), to @p sys.
void addPrior(System& sys, const Pose2& q, const PosePrior& prior, double weight)
{
  if (prior.information.isZero())
  {
    return;
  }
  const Eigen::Vector3d d = poseDifference(q, prior.mean);
  const Eigen::Matrix3d w = weight * prior.information;
  sys.cost += d.dot(w * d);
  sys.h += w;
  sys.g += w * d;
}

Pose2 step(const Pose2& q, const Eigen::Vector3d& delta)
{
  return Pose2(q.x + delta(0), q.y + delta(1), wrapAngle(q.theta + delta(2)));
}

/**
 * The covariance of (x, y, theta): sigma^2 (J^T J)^-1 where the readings determine the pose, with
 * a weak prior (a standard deviation of the map's diagonal in x, y and of pi in theta) so that a
 * direction the readings leave undetermined (a corridor, a cone facing a flat wall) gets about
 * the prior's large variance along it instead of a false precision or an arbitrary constant.
 */
Eigen::Matrix3d poseCovariance(const MapRayCaster& map, const System& sys, double noise_sigma)
{
  const int dof = sys.used - 3;
  double sigma2 = noise_sigma * noise_sigma;
  if (dof > 0)
  {
    sigma2 = std::max(sigma2, sys.sum_sq / dof);
  }
  const double extent = std::max(map.map().bounds().size().norm(), 1.0);
  Eigen::Matrix3d information = sys.jtj / sigma2;
  information.diagonal() += Eigen::Vector3d(1.0 / (extent * extent), 1.0 / (extent * extent), 1.0 / (kPi * kPi));
  Eigen::Matrix3d covariance = information.inverse();
  covariance = 0.5 * (covariance + covariance.transpose());
  return covariance.allFinite() ? covariance : Eigen::Matrix3d::Identity() * 1e6;
}
/// Each used finite reading's own J^T J in @p jtj (one cast each; @p used marks them) and their
/// sum: the accounting of buildSystem() without the robust loss.
System informationPerReading(const MapRayCaster& map, const Pose2& pose, const std::vector<Reading>& readings,
                             const std::vector<bool>& use, std::vector<Eigen::Matrix3d>& jtj, std::vector<char>& used)
{
  System all;
  const Rotation rq(pose.theta);
  for (std::size_t i = 0; i < readings.size(); ++i)
  {
    if (!use[i] || !std::isfinite(readings[i].range))
    {
      continue;
    }
    Vec2 hint = Vec2::Constant(std::numeric_limits<double>::quiet_NaN());
    const ResidualRow row = readingRow(map, pose, rq, readings[i], Rotation(readings[i].offset.theta), hint);
    used[i] = 1;
    ++all.used;
    if (row.valid)
    {
      jtj[i] = row.jacobian.transpose() * row.jacobian;
      all.jtj += jtj[i];
      all.sum_sq += row.r * row.r;
    }
  }
  return all;
}

/// The positive part of @p without / 2 - @p with_all: two groups fixing a direction equally
/// (without either, twice the covariance; half of it is what they give together) add nothing.
Eigen::Matrix3d excessOver(const Eigen::Matrix3d& without, const Eigen::Matrix3d& with_all)
{
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> excess(0.5 * without - with_all);
  const Eigen::Vector3d kept = excess.eigenvalues().cwiseMax(0.0);
  return excess.eigenvectors() * kept.asDiagonal() * excess.eigenvectors().transpose();
}

}  // namespace

PolishOutcome polishPose(const MapRayCaster& map, const Pose2& start, const std::vector<Reading>& readings,
                         const std::vector<bool>& use, double robust_scale, int max_iterations, double noise_sigma,
                         const PosePrior& prior)
{
  PolishOutcome out;
  out.pose = start;
  std::vector<Rotation> mounts;
  mounts.reserve(readings.size());
  for (const Reading& r : readings)
  {
    mounts.emplace_back(r.offset.theta);
  }
  std::vector<Vec2> hints(readings.size(), Vec2::Constant(std::numeric_limits<double>::quiet_NaN()));
  const double prior_weight = noise_sigma * noise_sigma;
  System sys = buildSystem(map, out.pose, readings, mounts, use, robust_scale, hints);
  addPrior(sys, out.pose, prior, prior_weight);
  double lambda = 1e-3;
  bool moved = false;
  for (int iter = 0; iter < max_iterations && lambda <= (moved ? kCrawlDamping : kStartDamping); ++iter)
  {
    out.iterations = iter + 1;
    Eigen::Matrix3d a = sys.h;
    a.diagonal() += lambda * sys.h.diagonal() + Eigen::Vector3d::Constant(1e-12);
    Eigen::Vector3d delta = -a.ldlt().solve(sys.g);
    if (!delta.allFinite())
    {
      break;
    }
    // Keep each step local: the model only holds near the current pose (0.5 m, 0.3 rad).
    delta /= std::max({ 1.0, delta.head<2>().norm() / 0.5, std::abs(delta(2)) / 0.3 });
    const Pose2 trial = step(out.pose, delta);
    System next = buildSystem(map, trial, readings, mounts, use, robust_scale, hints);
    addPrior(next, trial, prior, prior_weight);
    const bool converged = delta.head<2>().norm() < kConvergedStep && std::abs(delta(2)) < kConvergedTurn;
    const bool better = next.cost < sys.cost;
    if (better)
    {
      out.pose = trial;
      sys = next;
      moved = true;
    }
    lambda = better ? std::max(lambda / 3.0, 1e-9) : 4.0 * lambda;
    if (converged)
    {
      break;
    }
  }
  // sys is the system at out.pose: its information and residuals do not depend on the loss.
  out.covariance = poseCovariance(map, sys, noise_sigma);
  return out;
}

void ensureCovariance(const MapRayCaster& map, const std::vector<Reading>& readings, double noise_sigma,
                      Candidate& candidate)
{
  if (candidate.covariance.isZero())
  {
    candidate.covariance =
        polishPose(map, candidate.pose, readings, candidate.inlier_mask, 0.0, 0, noise_sigma).covariance;
  }
}

Eigen::Matrix3d oneDirectionLostCovariance(const MapRayCaster& map, const Pose2& pose,
                                           const std::vector<Reading>& readings, const std::vector<bool>& use,
                                           double noise_sigma, double group_angle)
{
  std::vector<Eigen::Matrix3d> jtj(readings.size(), Eigen::Matrix3d::Zero());
  std::vector<char> used(readings.size(), 0);
  const System all = informationPerReading(map, pose, readings, use, jtj, used);
  const Eigen::Matrix3d with_all = poseCovariance(map, all, noise_sigma);
  // The group (around each used reading) whose loss leaves the largest covariance
  // (determinant); and, over groups that do not overlap, the excess of every other group some of
  // whose finite readings disagree (spoilt: shortened by a person who may also be read as a
  // wall at a slant by the rest).
  Eigen::Matrix3d worst = with_all;
  Eigen::Matrix3d spoilt_excess = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d worst_spoilt = Eigen::Matrix3d::Zero();
  std::vector<char> covered(readings.size(), 0);
  for (std::size_t i = 0; i < readings.size(); ++i)
  {
    if (!used[i])
    {
      continue;
    }
    const bool first = !covered[i];
    System rest = all;  // the noise estimated from every reading
    bool spoilt = false;
    for (std::size_t j = 0; j < readings.size(); ++j)
    {
      if (std::abs(angleDiff(readings[j].offset.theta, readings[i].offset.theta)) <= group_angle)
      {
        rest.jtj -= jtj[j];
        covered[j] = covered[j] || first;
        spoilt = spoilt || (!use[j] && std::isfinite(readings[j].range));
      }
    }
    const Eigen::Matrix3d without = poseCovariance(map, rest, noise_sigma);
    const Eigen::Matrix3d excess = first && spoilt ? excessOver(without, with_all) : Eigen::Matrix3d::Zero();
    spoilt_excess += excess;
    if (without.determinant() > worst.determinant())
    {
      worst = without;
      worst_spoilt = excess;
    }
  }
  return excessOver(worst, with_all) + spoilt_excess - worst_spoilt;
}

}  // namespace core
}  // namespace fdml_localization
