// Tests of the benchmark protocol, scoring, summary and the fdml_bench tool itself.
#include "fdml_localization/benchmark/benchmark_runner.h"
#include "fdml_localization/core/map/map_io.h"
#include "fdml_localization/core/util/text_parsing.h"

#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

namespace core = fdml_localization::core;

namespace
{
/// An L-shaped room (4 x 3 m with a 2 x 1.5 m corner cut away) with a square pillar.
std::shared_ptr<const core::MapRayCaster> lRoom()
{
  std::vector<core::Ring> rings{
    { { 0, 0 }, { 4, 0 }, { 4, 1.5 }, { 2, 1.5 }, { 2, 3 }, { 0, 3 } },
    { { 0.8, 0.8 }, { 0.8, 1.2 }, { 1.2, 1.2 }, { 1.2, 0.8 } },
  };
  return std::make_shared<const core::MapRayCaster>(core::PolygonMap::fromRings(rings, "l_room"));
}

/// Brute force: nearest hit over every map edge and every disc.
double bruteForceRange(const core::MapRayCaster& map, const std::vector<core::Obstacle>& obstacles,
                       const core::Pose2& sensor, bool* static_hit)
{
  const double d_map = map.grid().castBruteForce(sensor.position(), sensor.heading()).distance;
  double best = d_map;
  for (const core::Obstacle& o : obstacles)
  {
    best = std::min(best, core::rayCircleDistance(sensor.position(), sensor.heading(), o.centre, o.radius));
  }
  *static_hit = best == d_map;
  return best;
}

double bruteForceEdgeDistance(const core::PolygonMap& map, const core::Vec2& p)
{
  double best = core::kInf;
  for (const core::Segment& s : map.edges())
  {
    best = std::min(best, std::sqrt(core::pointSegmentDistanceSquared(p, s)));
  }
  return best;
}

std::vector<std::string> split(const std::string& line, char sep)
{
  std::vector<std::string> out;
  std::string item;
  std::stringstream in(line);
  while (std::getline(in, item, sep))
  {
    out.push_back(item);
  }
  if (!line.empty() && line.back() == sep)
  {
    out.push_back("");
  }
  return out;
}

int runTool(const std::string& args)
{
  const std::string cmd = std::string(FDML_BENCH_BINARY) + " " + args + " >/dev/null 2>&1";
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}
}  // namespace

TEST(BenchProtocol, TrialMatchesBruteForce)
{
  const auto map = lRoom();
  core::ProtocolOptions options;
  options.obstacles = 30;
  for (int t = 0; t < 20; ++t)
  {
    const core::Trial trial = core::generateTrial(map, options, core::trialSeed(7, "l_room", 30, t));
    ASSERT_EQ(trial.readings.size(), 10u);
    ASSERT_EQ(trial.obstacles.size(), 30u);
    EXPECT_TRUE(map->map().containsBruteForce(trial.truth.position()));
    for (const core::Obstacle& o : trial.obstacles)
    {
      EXPECT_TRUE(map->map().containsBruteForce(o.centre));
      EXPECT_GT(bruteForceEdgeDistance(map->map(), o.centre), o.radius);
      EXPECT_GT((o.centre - trial.truth.position()).norm(), 2.0 * o.radius);
    }
    int static_hits = 0;
    for (int i = 0; i < 10; ++i)
    {
      const core::Reading& r = trial.readings[static_cast<std::size_t>(i)];
      EXPECT_DOUBLE_EQ(r.offset.x, 0.0);
      EXPECT_DOUBLE_EQ(r.offset.y, 0.0);
      EXPECT_NEAR(core::angleDiff(r.offset.theta, i * core::kTwoPi / 10), 0.0, 1e-12);
      bool static_hit = false;
      const double d = bruteForceRange(*map, trial.obstacles, core::compose(trial.truth, r.offset), &static_hit);
      EXPECT_NEAR(r.range, d, 1e-9);
      EXPECT_EQ(trial.hit_static[static_cast<std::size_t>(i)], static_hit);
      static_hits += static_hit ? 1 : 0;
    }
    EXPECT_EQ(trial.static_hits, static_hits);
  }
}

TEST(BenchProtocol, SameSeedSameTrialOtherSeedOtherTrial)
{
  const auto map = lRoom();
  core::ProtocolOptions options;
  const core::Trial a = core::generateTrial(map, options, core::trialSeed(1, "s", 10, 0));
  const core::Trial b = core::generateTrial(map, options, core::trialSeed(1, "s", 10, 0));
  const core::Trial c = core::generateTrial(map, options, core::trialSeed(1, "s", 10, 1));
  EXPECT_EQ(a.truth.x, b.truth.x);
  EXPECT_EQ(a.readings.back().range, b.readings.back().range);
  EXPECT_NE(a.truth.x, c.truth.x);
  EXPECT_NE(core::trialSeed(1, "s", 10, 0), core::trialSeed(1, "t", 10, 0));
  EXPECT_NE(core::trialSeed(1, "s", 10, 0), core::trialSeed(1, "s", 30, 0));
}

TEST(BenchProtocol, TranslateAndMovingObstacles)
{
  const auto map = lRoom();
  core::ProtocolOptions options;
  options.translate = true;
  options.moving_obstacles = true;
  for (int t = 0; t < 20; ++t)
  {
    const core::Trial trial = core::generateTrial(map, options, 1000 + t);
    double moved = 0.0;
    for (std::size_t i = 0; i < trial.readings.size(); ++i)
    {
      const core::Pose2 sensor = core::compose(trial.truth, trial.readings[i].offset);
      EXPECT_NEAR((sensor.position() - trial.sensor_poses[i].position()).norm(), 0.0, 1e-9);
      EXPECT_NEAR(core::angleDiff(sensor.theta, trial.sensor_poses[i].theta), 0.0, 1e-9);
      EXPECT_TRUE(map->map().containsBruteForce(sensor.position()));
      // Obstacles only ever shorten a reading.
      EXPECT_LE(trial.readings[i].range,
                map->grid().castBruteForce(sensor.position(), sensor.heading()).distance + 1e-9);
      if (i > 0)
      {
        const double step = (trial.sensor_poses[i].position() - trial.sensor_poses[i - 1].position()).norm();
        EXPECT_LE(step, options.step_max + 1e-12);
        moved += step;
      }
    }
    EXPECT_GT(moved, 0.0);
  }
}

TEST(BenchProtocol, RejectsBadOptions)
{
  core::ProtocolOptions options;
  options.readings = 2;
  options.obstacle_radius = -1.0;
  EXPECT_EQ(core::validate(options).size(), 2u);
  EXPECT_THROW(core::generateTrial(lRoom(), options, 1), std::invalid_argument);
  options = core::ProtocolOptions();
  options.obstacle_radius = 5.0;  // no disc of radius 5 fits in the room
  EXPECT_THROW(core::generateTrial(lRoom(), options, 1), std::runtime_error);
}

TEST(BenchScoring, PaperMetricAndCriteria)
{
  EXPECT_NEAR(core::paperResolutionError(100), 2.0 * std::cbrt(900.0 / (4.0 * core::kPi)) / 100.0, 1e-15);
  core::Box2 bounds;
  bounds.extend(core::Vec2(0, 0));
  bounds.extend(core::Vec2(4, 2));
  EXPECT_NEAR(core::normalisedDistance(core::Pose2(0, 0, 3.0), core::Pose2(0.4, 0.2, -3.0), bounds),
              std::sqrt(0.01 + 0.01 + std::pow((2 * core::kPi - 6.0) / core::kTwoPi, 2)), 1e-12);

  core::Trial trial;
  trial.truth = core::Pose2(1, 1, 0.5);
  trial.static_hits = 6;
  core::Result result;
  core::Candidate far, near;
  far.pose = core::Pose2(3, 1.5, 0.5);
  near.pose = core::Pose2(1.03, 1.0, 0.52);
  result.candidates = { far, near };
  core::TrialScore s = core::scoreTrial(trial, result, bounds, 100, 6, 12.5);
  EXPECT_TRUE(s.success_paper);
  EXPECT_TRUE(s.success_strict);
  EXPECT_FALSE(s.success_top1);
  EXPECT_TRUE(s.sparsity_held);
  EXPECT_EQ(s.candidates, 2);
  EXPECT_NEAR(s.err_pos, 0.03, 1e-12);
  EXPECT_NEAR(s.err_theta, 0.02, 1e-12);
  EXPECT_NEAR(s.top_err_pos, std::hypot(2.0, 0.5), 1e-12);  // the best-ranked one: far
  EXPECT_NEAR(s.top_err_theta, 0.0, 1e-12);
  EXPECT_EQ(s.time_ms, 12.5);

  result.candidates = { near };
  s = core::scoreTrial(trial, result, bounds, 100, 7, 1.0);
  EXPECT_TRUE(s.success_top1);
  EXPECT_FALSE(s.sparsity_held);

  result.candidates = { far };
  s = core::scoreTrial(trial, result, bounds, 100, 6, 1.0);
  EXPECT_FALSE(s.success_paper);
  EXPECT_FALSE(s.success_strict);

  result.candidates.clear();
  s = core::scoreTrial(trial, result, bounds, 100, 6, 1.0);
  EXPECT_FALSE(s.has_nearest);
  EXPECT_FALSE(s.success_paper);
  EXPECT_EQ(core::csvRow(core::BenchRow{ "a", 1, 2, "robust", 3, s }), "a,1,2,robust,3,0,0,0,0,1.000,1,,,0,,");
  EXPECT_EQ(core::csvRow(core::BenchRow{ "a", 1, 2, "robust", 3, s, 27.0 }), "a,1,2,robust,3,0,0,0,0,1.000,1,,,27,,");
}

TEST(BenchReport, SummaryCountsAndQuantiles)
{
  std::vector<core::BenchRow> rows;
  for (int t = 0; t < 20; ++t)
  {
    core::BenchRow r{ "room", 10, 50, "robust", t, {} };
    r.score.success_paper = t % 2 == 0;
    r.score.success_strict = t % 4 == 0;
    r.score.success_top1 = t % 5 == 0;
    r.score.sparsity_held = t < 15;
    r.score.candidates = t;
    r.score.time_ms = t + 1;
    rows.push_back(r);
  }
  rows.push_back(core::BenchRow{ "room", 30, 50, "robust", 0, {} });
  const auto summary = core::summarize(rows, { { "room", 50, "robust", 1.5 } });
  ASSERT_EQ(summary.size(), 2u);
  const core::BenchSummary& s = summary[0];
  EXPECT_EQ(s.trials, 20);
  EXPECT_EQ(s.success_paper, 10);
  EXPECT_EQ(s.success_strict, 5);
  EXPECT_EQ(s.success_top1, 4);
  EXPECT_EQ(s.sparsity_held, 15);
  EXPECT_EQ(s.success_held, 8);
  EXPECT_EQ(s.success_not_held, 2);
  EXPECT_DOUBLE_EQ(s.mean_candidates, 9.5);
  EXPECT_DOUBLE_EQ(s.median_ms, 10.5);
  EXPECT_NEAR(s.p95_ms, 19.05, 1e-12);
  EXPECT_DOUBLE_EQ(s.table_s, 1.5);
  EXPECT_EQ(summary[1].m, 30);
  EXPECT_EQ(summary[1].trials, 1);
}

using CellKey = std::tuple<std::string, int, int, std::string>;
using CellSums = std::map<CellKey, std::vector<int>>;  // trials, paper, strict, top1

/// Reads the tool's CSV (its header, then rows of 16 fields, fov_deg = @p fov the 14th), summing
/// the counts per cell; returns the number of rows.
int readCsvSums(const std::string& csv, const std::string& fov, CellSums* sums)
{
  std::ifstream csv_in(csv);
  std::string line;
  EXPECT_TRUE(std::getline(csv_in, line));
  EXPECT_EQ(line, "scene,m,n,method,trial,success_paper,success_strict,success_top1,candidates,time_ms,"
                  "sparsity_held,err_pos,err_theta,fov_deg,top_err_pos,top_err_theta");
  int rows = 0;
  while (std::getline(csv_in, line))
  {
    const std::vector<std::string> f = split(line, ',');
    EXPECT_EQ(f.size(), 16u) << line;
    if (f.size() != 16u)
    {
      return rows;
    }
    auto& s = (*sums)[CellKey(f[0], std::stoi(f[1]), std::stoi(f[2]), f[3])];
    s.resize(4, 0);
    s[0] += 1;
    for (int c = 0; c < 3; ++c)
    {
      EXPECT_TRUE(f[5 + c] == "0" || f[5 + c] == "1") << line;
      s[1 + c] += std::stoi(f[5 + c]);
    }
    EXPECT_TRUE(f[11].empty() == f[12].empty() && f[11].empty() == f[14].empty() && f[14].empty() == f[15].empty());
    EXPECT_EQ(f[11].empty(), f[8] == "0") << line;
    EXPECT_EQ(f[13], fov) << line;
    ++rows;
  }
  return rows;
}

/// The Markdown table: one line per cell whose trials and "paper/strict/top1" counts are the
/// sums; returns the number of cell lines.
int checkMarkdownAgainstSums(const std::string& md, const CellSums& sums)
{
  std::ifstream md_in(md);
  std::string line;
  int table_lines = 0;
  while (std::getline(md_in, line))
  {
    const std::vector<std::string> f = split(line, '|');
    if (f.size() != 18 || core::trim(f[1]) == "scene" || core::trim(f[1]).rfind("---", 0) == 0)
    {
      continue;
    }
    const CellKey key(core::trim(f[1]), std::stoi(core::trim(f[2])), std::stoi(core::trim(f[3])), core::trim(f[4]));
    const auto it = sums.find(key);
    EXPECT_NE(it, sums.end()) << line;
    if (it == sums.end())
    {
      continue;
    }
    const std::vector<int>& s = it->second;
    EXPECT_EQ(std::stoi(core::trim(f[5])), s[0]) << line;
    EXPECT_EQ(core::trim(f[16]), std::to_string(s[1]) + "/" + std::to_string(s[2]) + "/" + std::to_string(s[3]))
        << line;
    ++table_lines;
  }
  return table_lines;
}

TEST(BenchTool, CsvHeaderAndTableCountsMatchRows)
{
  const std::string dir = ::testing::TempDir();
  const std::string poly = dir + "/bench_l_room.poly";
  core::savePolyFile(poly, lRoom()->map());
  const std::string csv = dir + "/bench_rows.csv";
  const std::string md = dir + "/bench_table.md";
  ASSERT_EQ(runTool("--map " + poly +
                    " --random 12:2 --obstacles 0,5 --resolution 32 --trials 2 --seed 3 "
                    "--method robust,baseline --threads 2 --csv " +
                    csv + " --markdown " + md),
            0);
  CellSums sums;
  EXPECT_EQ(readCsvSums(csv, "0", &sums), 2 * 2 * 2 * 2);  // scenes x m x methods x trials
  ASSERT_EQ(sums.size(), 8u);
  EXPECT_EQ(sums.count(CellKey("bench_l_room", 5, 32, "baseline")), 1u);
  EXPECT_EQ(sums.count(CellKey("random12_x2", 0, 32, "robust")), 1u);
  EXPECT_EQ(checkMarkdownAgainstSums(md, sums), 8);
}

TEST(BenchTool, FovFlagGivesEveryRowItsFieldOfView)
{
  const std::string dir = ::testing::TempDir();
  const std::string poly = dir + "/bench_l_room_fov.poly";
  core::savePolyFile(poly, lRoom()->map());
  const std::string csv = dir + "/bench_rows_fov.csv";
  ASSERT_EQ(runTool("--map " + poly + " --obstacles 3 --resolution 32 --trials 2 --threads 2 --fov 27 --csv " + csv),
            0);
  CellSums sums;
  EXPECT_EQ(readCsvSums(csv, "27", &sums), 2);
  EXPECT_EQ(runTool("--help"), 0);
  EXPECT_EQ(runTool("--map " + poly + " --fov 181 --trials 1"), 2);
  EXPECT_EQ(runTool("--map " + poly + " --fov -1 --trials 1"), 2);
  EXPECT_EQ(runTool("--map " + poly + " --fov nan --trials 1"), 2);
  EXPECT_EQ(runTool("--map " + poly + " --fov"), 2);
}

TEST(BenchTool, RejectsBadArguments)
{
  const std::string poly = ::testing::TempDir() + "/bench_l_room_args.poly";
  core::savePolyFile(poly, lRoom()->map());
  EXPECT_EQ(runTool("--map " + poly + " --resolution 8 --trials 1"), 2);
  EXPECT_EQ(runTool("--map " + poly + " --method magic --trials 1"), 2);
  EXPECT_EQ(runTool("--map " + poly + " --min-inliers 11 --trials 1"), 2);
  EXPECT_EQ(runTool("--map /nonexistent/map.poly --trials 1"), 2);
  EXPECT_EQ(runTool("--random 70:-2 --trials 1"), 2);
  EXPECT_EQ(runTool("--trials 1"), 2);
}

TEST(BenchRunner, LocalizerOptionsPerMethod)
{
  core::BenchConfig config;
  config.scenes.push_back({ "l_room", lRoom() });
  config.protocol.noise = 0.03;
  config.min_inliers = 0;
  EXPECT_TRUE(core::validate(config).empty());
  EXPECT_EQ(core::sparsityKPrime(config), 6);
  const core::LocalizerOptions robust = core::benchLocalizerOptions(config, core::Method::Robust, 64);
  EXPECT_EQ(robust.min_inliers, 0);
  EXPECT_EQ(robust.resolution, 64);
  EXPECT_NEAR(robust.range_tolerance, 0.09, 1e-12);
  EXPECT_NEAR(robust.agreement_tolerance, 0.12, 1e-12);
  EXPECT_EQ(core::benchLocalizerOptions(config, core::Method::Paper, 64).min_inliers, 6);
  EXPECT_EQ(core::benchLocalizerOptions(config, core::Method::Baseline, 64).min_inliers, 10);
  config.min_inliers = 7;
  EXPECT_EQ(core::sparsityKPrime(config), 7);
  EXPECT_EQ(core::benchLocalizerOptions(config, core::Method::Paper, 64).min_inliers, 7);
  EXPECT_TRUE(core::validate(core::benchLocalizerOptions(config, core::Method::Baseline, 64)).empty());
  config.resolutions = { 8 };
  config.min_inliers = 2;
  EXPECT_EQ(core::validate(config).size(), 2u);
}
