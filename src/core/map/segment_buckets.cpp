#include "fdml_localization/core/map/segment_buckets.h"

#include <utility>

namespace fdml_localization
{
namespace core
{
SegmentBuckets::SegmentBuckets(const std::vector<Segment>& segments) : segments_(segments), stamp_(segments.size(), 0)
{
  Box2 box;
  double length = 0.0;
  for (const Segment& s : segments)
  {
    box.extend(s.a);
    box.extend(s.b);
    length += (s.b - s.a).norm();
  }
  if (box.empty())
  {
    box.extend(Vec2(0.0, 0.0));
  }
  origin_ = box.min;
  const double extent = std::max(box.max.x() - box.min.x(), box.max.y() - box.min.y());
  cell_ = std::max(length / static_cast<double>(std::max<std::size_t>(segments.size(), 1)), extent / kMaxCells);
  if (!(cell_ > 0.0))
  {
    cell_ = 1.0;
  }
  std::vector<std::pair<std::uint64_t, std::uint32_t>> entries;
  for (std::size_t i = 0; i < segments.size(); ++i)
  {
    forEachRowSpan(segments[i], [&](std::uint64_t first, std::uint64_t last) {
      for (std::uint64_t key = first; key <= last; ++key)
      {
        entries.emplace_back(key, static_cast<std::uint32_t>(i));
      }
    });
  }
  std::sort(entries.begin(), entries.end());
  items_.reserve(entries.size());
  for (const auto& entry : entries)
  {
    if (keys_.empty() || keys_.back() != entry.first)
    {
      keys_.push_back(entry.first);
      start_.push_back(static_cast<std::uint32_t>(items_.size()));
    }
    items_.push_back(entry.second);
  }
  start_.push_back(static_cast<std::uint32_t>(items_.size()));
}

}  // namespace core
}  // namespace fdml_localization
