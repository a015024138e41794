#include "fdml_localization/benchmark/benchmark_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>
#include <tuple>

namespace fdml_localization
{
namespace core
{
namespace
{
std::string format(const char* fmt, double value)
{
  char buf[64];
  std::snprintf(buf, sizeof(buf), fmt, value);
  return buf;
}

std::string percent(int count, int total)
{
  return total > 0 ? format("%.1f", 100.0 * count / total) : std::string("-");
}

using CellKey = std::tuple<std::string, int, int, std::string>;

/// The cells of one line of either table, in print order.
std::vector<std::string> cells(const BenchSummary& s)
{
  const int not_held = s.trials - s.sparsity_held;
  return { s.scene,
           std::to_string(s.m),
           std::to_string(s.n),
           s.method,
           std::to_string(s.trials),
           percent(s.success_paper, s.trials),
           percent(s.success_strict, s.trials),
           percent(s.success_top1, s.trials),
           format("%.2f", s.mean_candidates),
           format("%.1f", s.median_ms),
           format("%.1f", s.p95_ms),
           format("%.2f", s.table_s),
           percent(s.sparsity_held, s.trials),
           percent(s.success_held, s.sparsity_held),
           percent(s.success_not_held, not_held),
           std::to_string(s.success_paper) + "/" + std::to_string(s.success_strict) + "/" +
               std::to_string(s.success_top1) };
}

const std::vector<std::string>& headers()
{
  static const std::vector<std::string> h = { "scene",   "m",          "n",         "method",      "trials", "success%",
                                              "strict%", "top1%",      "cand",      "med_ms",      "p95_ms", "table_s",
                                              "sparse%", "succ_held%", "succ_not%", "counts p/s/t" };
  return h;
}
}  // namespace

std::string csvHeader()
{
  return "scene,m,n,method,trial,success_paper,success_strict,success_top1,candidates,time_ms,"
         "sparsity_held,err_pos,err_theta,fov_deg,top_err_pos,top_err_theta";
}

std::string csvRow(const BenchRow& r)
{
  const TrialScore& s = r.score;
  std::ostringstream out;
  out << r.scene << ',' << r.m << ',' << r.n << ',' << r.method << ',' << r.trial << ',' << int(s.success_paper) << ','
      << int(s.success_strict) << ',' << int(s.success_top1) << ',' << s.candidates << ',' << format("%.3f", s.time_ms)
      << ',' << int(s.sparsity_held) << ',';
  if (s.has_nearest)
  {
    out << format("%.6f", s.err_pos) << ',' << format("%.6f", s.err_theta);
  }
  else
  {
    out << ',';
  }
  out << ',' << format("%g", r.fov_deg) << ',';
  if (s.has_nearest)
  {
    out << format("%.6f", s.top_err_pos) << ',' << format("%.6f", s.top_err_theta);
  }
  else
  {
    out << ',';
  }
  return out.str();
}

double quantile(std::vector<double> values, double q)
{
  if (values.empty())
  {
    return 0.0;
  }
  std::sort(values.begin(), values.end());
  const double pos = std::clamp(q, 0.0, 1.0) * static_cast<double>(values.size() - 1);
  const std::size_t lo = static_cast<std::size_t>(std::floor(pos));
  const std::size_t hi = std::min(lo + 1, values.size() - 1);
  return values[lo] + (pos - static_cast<double>(lo)) * (values[hi] - values[lo]);
}

std::vector<BenchSummary> summarize(const std::vector<BenchRow>& rows, const std::vector<TableBuild>& tables)
{
  std::vector<BenchSummary> out;
  std::map<CellKey, std::size_t> index;
  std::vector<std::vector<double>> times;
  for (const BenchRow& r : rows)
  {
    const CellKey key(r.scene, r.m, r.n, r.method);
    auto it = index.find(key);
    if (it == index.end())
    {
      it = index.emplace(key, out.size()).first;
      BenchSummary s;
      s.scene = r.scene;
      s.m = r.m;
      s.n = r.n;
      s.method = r.method;
      for (const TableBuild& t : tables)
      {
        if (t.scene == r.scene && t.n == r.n && t.method == r.method)
        {
          s.table_s = t.seconds;
        }
      }
      out.push_back(s);
      times.emplace_back();
    }
    BenchSummary& s = out[it->second];
    const TrialScore& t = r.score;
    ++s.trials;
    s.success_paper += t.success_paper ? 1 : 0;
    s.success_strict += t.success_strict ? 1 : 0;
    s.success_top1 += t.success_top1 ? 1 : 0;
    s.mean_candidates += t.candidates;
    s.sparsity_held += t.sparsity_held ? 1 : 0;
    s.success_held += (t.sparsity_held && t.success_paper) ? 1 : 0;
    s.success_not_held += (!t.sparsity_held && t.success_paper) ? 1 : 0;
    times[it->second].push_back(t.time_ms);
  }
  for (std::size_t i = 0; i < out.size(); ++i)
  {
    out[i].mean_candidates /= std::max(1, out[i].trials);
    out[i].median_ms = quantile(times[i], 0.5);
    out[i].p95_ms = quantile(times[i], 0.95);
  }
  return out;
}

std::string formatTable(const std::vector<BenchSummary>& summary)
{
  std::vector<std::vector<std::string>> lines{ headers() };
  for (const BenchSummary& s : summary)
  {
    lines.push_back(cells(s));
  }
  std::vector<std::size_t> width(headers().size(), 0);
  for (const auto& line : lines)
  {
    for (std::size_t c = 0; c < line.size(); ++c)
    {
      width[c] = std::max(width[c], line[c].size());
    }
  }
  std::ostringstream out;
  for (const auto& line : lines)
  {
    for (std::size_t c = 0; c < line.size(); ++c)
    {
      const std::string pad(width[c] - line[c].size(), ' ');
      // Text columns left-aligned, numbers right-aligned.
      out << (c == 0 || c == 3 ? line[c] + pad : pad + line[c]) << (c + 1 < line.size() ? "  " : "\n");
    }
  }
  return out.str();
}

std::string formatMarkdownTable(const std::vector<BenchSummary>& summary)
{
  std::ostringstream out;
  out << '|';
  for (const std::string& h : headers())
  {
    out << ' ' << h << " |";
  }
  out << "\n|";
  for (std::size_t c = 0; c < headers().size(); ++c)
  {
    out << (c == 0 || c == 3 ? "---|" : "---:|");
  }
  out << '\n';
  for (const BenchSummary& s : summary)
  {
    out << '|';
    for (const std::string& cell : cells(s))
    {
      out << ' ' << cell << " |";
    }
    out << '\n';
  }
  return out.str();
}

namespace
{
/// The counts of one (method, scene, m) pooled over n.
struct Pool
{
  int trials = 0, paper = 0, strict = 0, top1 = 0;
  double candidates = 0.0;
};

/// The paper table's pools, its columns (scene, m) and its methods, in first-seen order.
struct PaperPools
{
  std::vector<std::pair<std::string, int>> columns;
  std::vector<std::string> methods;
  std::map<std::tuple<std::string, std::string, int>, Pool> pools;
};

PaperPools poolOverResolutions(const std::vector<BenchSummary>& summary)
{
  PaperPools out;
  for (const BenchSummary& s : summary)
  {
    const std::pair<std::string, int> col(s.scene, s.m);
    if (std::find(out.columns.begin(), out.columns.end(), col) == out.columns.end())
    {
      out.columns.push_back(col);
    }
    if (std::find(out.methods.begin(), out.methods.end(), s.method) == out.methods.end())
    {
      out.methods.push_back(s.method);
    }
    Pool& p = out.pools[std::make_tuple(s.method, s.scene, s.m)];
    p.trials += s.trials;
    p.paper += s.success_paper;
    p.strict += s.success_strict;
    p.top1 += s.success_top1;
    p.candidates += s.mean_candidates * s.trials;
  }
  return out;
}
}  // namespace

std::string formatPaperTable(const std::vector<BenchSummary>& summary)
{
  // Columns: (scene, m) in first-seen order; rows: method x metric. Counts pooled over n.
  const PaperPools pooled = poolOverResolutions(summary);
  std::ostringstream out;
  out << "| method | metric |";
  for (const auto& c : pooled.columns)
  {
    out << ' ' << c.first << " m=" << c.second << " |";
  }
  out << "\n|---|---|";
  for (std::size_t i = 0; i < pooled.columns.size(); ++i)
  {
    out << "---:|";
  }
  out << '\n';
  const char* metrics[] = { "success %", "strict %", "top-1 %", "candidates" };
  for (const std::string& method : pooled.methods)
  {
    for (int k = 0; k < 4; ++k)
    {
      out << "| " << method << " | " << metrics[k] << " |";
      for (const auto& c : pooled.columns)
      {
        const auto it = pooled.pools.find(std::make_tuple(method, c.first, c.second));
        std::string cell = "-";
        if (it != pooled.pools.end() && it->second.trials > 0)
        {
          const Pool& p = it->second;
          const int counts[] = { p.paper, p.strict, p.top1 };
          cell = k < 3 ? percent(counts[k], p.trials) : format("%.2f", p.candidates / p.trials);
        }
        out << ' ' << cell << " |";
      }
      out << '\n';
    }
  }
  return out.str();
}

}  // namespace core
}  // namespace fdml_localization
