/**
 * @file benchmark_report.h
 * @brief Per-trial rows of the benchmark, their CSV form, and the per-(scene, m, n, method)
 *        summary printed as a table (plain text or Markdown).
 */
#pragma once

#include "fdml_localization/benchmark/benchmark_protocol.h"

#include <iosfwd>
#include <string>
#include <vector>

namespace fdml_localization
{
namespace core
{
/// One localization of the benchmark: one CSV row.
struct BenchRow
{
  std::string scene;
  int m = 0;
  int n = 0;
  std::string method;
  int trial = 0;
  TrialScore score;
  double fov_deg = 0.0;  ///< the readings' full field of view [deg]; 0 = rays
};

/// The table build (or load) time of one localizer, per (scene, n, method).
struct TableBuild
{
  std::string scene;
  int n = 0;
  std::string method;
  double seconds = 0.0;  ///< [s]
};

/// The summary of one (scene, m, n, method) cell.
struct BenchSummary
{
  std::string scene;
  int m = 0;
  int n = 0;
  std::string method;
  int trials = 0;
  int success_paper = 0;  ///< counts, not rates
  int success_strict = 0;
  int success_top1 = 0;
  double mean_candidates = 0.0;
  double median_ms = 0.0;    ///< per localization [ms]
  double p95_ms = 0.0;       ///< [ms]
  double table_s = 0.0;      ///< table build [s] (0 when unknown)
  int sparsity_held = 0;     ///< trials where (k, k') sparsity held
  int success_held = 0;      ///< success_paper among those
  int success_not_held = 0;  ///< success_paper among the others
};

/// The CSV header: scene,m,n,method,trial,success_paper,...,err_theta,fov_deg (no newline).
std::string csvHeader();
/// One CSV row (no newline); err_* are empty when there is no candidate.
std::string csvRow(const BenchRow& row);

/// Groups rows by (scene, m, n, method) in first-seen order and summarises each group.
std::vector<BenchSummary> summarize(const std::vector<BenchRow>& rows, const std::vector<TableBuild>& tables);

/// q-quantile (0..1) of the values by linear interpolation; 0 for an empty list.
double quantile(std::vector<double> values, double q);

/// The detailed table, one line per cell, aligned columns for a terminal.
std::string formatTable(const std::vector<BenchSummary>& summary);
/// The same table in Markdown.
std::string formatMarkdownTable(const std::vector<BenchSummary>& summary);
/// The paper's Table 1 layout: success (paper criterion) averaged over n, per method and
/// scene x m, in Markdown; also strict and top-1 and the mean candidate count.
std::string formatPaperTable(const std::vector<BenchSummary>& summary);

}  // namespace core
}  // namespace fdml_localization
