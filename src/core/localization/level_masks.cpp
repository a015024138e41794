#include "fdml_localization/core/localization/level_runs.h"

#include "fdml_localization/core/localization/count_scan.h"

#include <algorithm>
#include <cstring>
#include <utility>

namespace fdml_localization
{
namespace core
{
LevelRuns::LevelRuns(const GridSpec& spec, const std::vector<std::uint8_t>& count, int level)
  : spec_(spec)
  , count_(count)
  , level_(level)
  , runs_(static_cast<std::size_t>(spec.ny) * spec.nt)
  , built_(runs_.size(), 0)
  , labels_(runs_.size())
{}

const std::vector<LevelRuns::Run>& LevelRuns::runsOf(std::size_t row)
{
  std::vector<Run>& runs = runs_[row];
  if (built_[row])
  {
    return runs;
  }
  built_[row] = 1;
  const std::uint8_t* c = count_.data() + row * static_cast<std::size_t>(spec_.nx);
  const int nx = spec_.nx;
  const bool words = level_ >= 1 && level_ <= 128;
  for (int x = 0; x < nx;)
  {
    std::uint64_t word = 0;
    if (words && x + 8 <= nx && (std::memcpy(&word, c + x, 8), !anyByteAtLeast(word, static_cast<unsigned>(level_))))
    {
      x += 8;  // eight voxels below the level
      continue;
    }
    if (c[x] < level_)
    {
      ++x;
      continue;
    }
    const int x0 = x;
    while (x < nx && c[x] >= level_)
    {
      ++x;
    }
    runs.push_back(Run{ x0, x });
  }
  labels_[row].assign(runs.size(), -1);
  return runs;
}

long LevelRuns::runAt(std::size_t row, int x)
{
  const std::vector<Run>& runs = runsOf(row);
  const auto it = std::upper_bound(runs.begin(), runs.end(), x, [](int v, const Run& r) { return v < r.x0; });
  if (it == runs.begin() || (it - 1)->x1 <= x)
  {
    return -1;
  }
  return static_cast<long>(it - runs.begin()) - 1;
}

std::size_t LevelRuns::walk(std::size_t row, std::size_t run, int label)
{
  const std::size_t ny = static_cast<std::size_t>(spec_.ny);
  const int nt = spec_.nt;
  std::size_t voxels = 0;
  std::vector<std::pair<std::size_t, std::size_t>> stack{ { row, run } };
  labels_[row][run] = label;
  while (!stack.empty())
  {
    const auto [r, i] = stack.back();
    stack.pop_back();
    const Run here = runs_[r][i];
    voxels += static_cast<std::size_t>(here.x1 - here.x0);
    const int iy = static_cast<int>(r % ny);
    const int it = static_cast<int>(r / ny);
    for (int dt = -1; dt <= 1; ++dt)
    {
      const int t = (it + dt + nt) % nt;
      for (int dy = -1; dy <= 1; ++dy)
      {
        const int y = iy + dy;
        const std::size_t next = static_cast<std::size_t>(t) * ny + static_cast<std::size_t>(y);
        if (y < 0 || y >= spec_.ny || next == r)
        {
          continue;  // a row's own runs never touch (a gap lies between them)
        }
        // Runs meeting [x0 - 1, x1 + 1): x and the neighbours along it.
        const std::vector<Run>& runs = runsOf(next);
        auto j = std::lower_bound(runs.begin(), runs.end(), here.x0, [](const Run& a, int v) { return a.x1 < v; });
        for (; j != runs.end() && j->x0 <= here.x1; ++j)
        {
          int& l = labels_[next][static_cast<std::size_t>(j - runs.begin())];
          if (l < 0)
          {
            l = label;
            stack.emplace_back(next, static_cast<std::size_t>(j - runs.begin()));
          }
        }
      }
    }
  }
  return voxels;
}

std::vector<std::size_t> LevelRuns::componentSizes(const std::vector<std::size_t>& voxels)
{
  std::vector<std::size_t> sizes(voxels.size(), 0);
  std::vector<std::size_t> by_label;
  const std::size_t nx = static_cast<std::size_t>(spec_.nx);
  for (std::size_t k = 0; k < voxels.size(); ++k)
  {
    if (voxels[k] >= count_.size())
    {
      continue;
    }
    const std::size_t row = voxels[k] / nx;
    const long run = runAt(row, static_cast<int>(voxels[k] % nx));
    if (run < 0)
    {
      continue;
    }
    int& label = labels_[row][static_cast<std::size_t>(run)];
    if (label < 0)
    {
      const int fresh = static_cast<int>(by_label.size());
      by_label.push_back(walk(row, static_cast<std::size_t>(run), fresh));
    }
    sizes[k] = by_label[static_cast<std::size_t>(label)];
  }
  return sizes;
}

}  // namespace core
}  // namespace fdml_localization
