// The bound windows (bound_windows.h) against their definition, voxel by voxel: the minimum or
// maximum of the cell bounds over 2 x 2 cells and m heading cells (periodic), in range steps.
// Windows up to 16 headings are combined row by row, longer ones column by column.
#include "fdml_localization/core/localization/voxel/bound_windows.h"

#include "localizer_test_utils.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>

namespace fdml_localization
{
namespace core
{
namespace
{
TEST(BoundWindows, EachEntryIsItsWindowsBoundInSteps)
{
  const auto map = test::lRoomMap();
  const GridSpec spec = GridSpec::fromMap(map->map(), 20, 24);
  BoundWindows windows(CellBounds::compute(*map, spec, 2));
  const CellBounds& cells = windows.cells();
  const RangeSteps& steps = windows.steps();
  using Kind = BoundWindows::Kind;
  for (const Kind kind : { Kind::Lower, Kind::UpperMax, Kind::UpperInner })
  {
    for (const int m : { 1, 2, 3, 16, 17, 23, 24, 30 })
    {
      windows.require(kind, m);
      const auto& array = windows.get(kind, m);
      ASSERT_EQ(array.size(), spec.voxelCount());
      for (int jt = 0; jt < spec.nt; ++jt)
      {
        for (int wy = 0; wy < spec.ny; ++wy)
        {
          for (int wx = 0; wx < spec.nx; ++wx)
          {
            // Lower: min over the window; UpperMax: max; UpperInner: max over the 2 x 2 cells of
            // the min over the headings.
            double bound = (kind == Kind::Lower ? 1.0 : -1.0) * std::numeric_limits<double>::infinity();
            for (int jy = wy - 1; jy <= wy; ++jy)
            {
              for (int jx = wx - 1; jx <= wx; ++jx)
              {
                double over_headings = (kind == Kind::UpperMax ? -1.0 : 1.0) * std::numeric_limits<double>::infinity();
                for (int k = 0; k < std::min(m, spec.nt); ++k)
                {
                  const std::size_t c = cells.index(jx, jy, (jt + k) % spec.nt);
                  const double v = kind == Kind::Lower ? cells.lower()[c] : cells.upper()[c];
                  over_headings = kind == Kind::UpperMax ? std::max(over_headings, v) : std::min(over_headings, v);
                }
                bound = kind == Kind::Lower ? std::min(bound, over_headings) : std::max(bound, over_headings);
              }
            }
            const std::uint16_t expected = kind == Kind::Lower ? steps.down(bound) : steps.up(bound);
            ASSERT_EQ(array[spec.index(wx, wy, jt)], expected)
                << "kind " << static_cast<int>(kind) << " m " << m << " voxel " << wx << " " << wy << " " << jt;
          }
        }
      }
    }
  }
  EXPECT_THROW(windows.get(Kind::Lower, 4), std::logic_error);
}

}  // namespace
}  // namespace core
}  // namespace fdml_localization
