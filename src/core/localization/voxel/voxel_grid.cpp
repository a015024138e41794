#include "fdml_localization/core/localization/voxel/voxel_grid.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

namespace fdml_localization
{
namespace core
{
namespace
{
std::uint64_t mixHash(std::uint64_t h, std::uint64_t value)
{
  h ^= value + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2);
  h *= 0xff51afd7ed558ccdULL;
  return h ^ (h >> 33);
}

/// Each row of @p wpr words dilated by one bit both ways (no carry between rows).
void dilateAlongX(const std::uint64_t* words, std::uint64_t* result, std::size_t rows, int wpr, std::uint64_t tail_mask)
{
  for (std::size_t r = 0; r < rows; ++r)
  {
    const std::uint64_t* in = words + r * wpr;
    std::uint64_t* out = result + r * wpr;
    for (int k = 0; k < wpr; ++k)
    {
      const std::uint64_t w = in[k];
      std::uint64_t d = w | (w << 1) | (w >> 1);
      if (k > 0)
      {
        d |= in[k - 1] >> 63;
      }
      if (k + 1 < wpr)
      {
        d |= in[k + 1] << 63;
      }
      out[k] = d;
    }
    out[wpr - 1] &= tail_mask;
  }
}

/// One heading slice (@p ny rows of @p wpr words) dilated along x and y into @p out (@p along_x:
/// scratch of the slice's size).
void dilateSliceInPlane(const std::uint64_t* in, std::uint64_t* along_x, std::uint64_t* out, int ny, int wpr,
                        std::uint64_t tail_mask)
{
  dilateAlongX(in, along_x, static_cast<std::size_t>(ny), wpr, tail_mask);
  for (int iy = 0; iy < ny; ++iy)
  {
    const std::uint64_t* mid = along_x + static_cast<std::size_t>(iy) * wpr;
    const std::uint64_t* lo = iy > 0 ? mid - wpr : nullptr;
    const std::uint64_t* hi = iy + 1 < ny ? mid + wpr : nullptr;
    std::uint64_t* o = out + static_cast<std::size_t>(iy) * wpr;
    for (int k = 0; k < wpr; ++k)
    {
      o[k] = mid[k] | (lo ? lo[k] : 0) | (hi ? hi[k] : 0);
    }
  }
}

std::uint64_t doubleBits(double value)
{
  std::uint64_t bits = 0;
  static_assert(sizeof(bits) == sizeof(value), "double is 64 bits");
  std::memcpy(&bits, &value, sizeof(bits));
  return bits;
}
}  // namespace

GridSpec GridSpec::fromMap(const PolygonMap& map, int resolution, int theta_resolution)
{
  if (map.empty() || !(map.area() > 0.0))
  {
    throw std::invalid_argument("the map has no area");
  }
  return fromBounds(map.bounds(), resolution, theta_resolution);
}

GridSpec GridSpec::fromBounds(const Box2& b, int resolution, int theta_resolution)
{
  if (resolution < 16 || resolution > 1024)
  {
    throw std::invalid_argument("resolution " + std::to_string(resolution) + " is outside [16, 1024]");
  }
  if (theta_resolution != 0 && (theta_resolution < 16 || theta_resolution > 1024))
  {
    throw std::invalid_argument("theta_resolution " + std::to_string(theta_resolution) +
                                " is outside [16, 1024] (or 0 = resolution)");
  }
  const double width = b.max.x() - b.min.x();
  const double height = b.max.y() - b.min.y();
  if (!(std::max(width, height) > 0.0) || !std::isfinite(width) || !std::isfinite(height))
  {
    throw std::invalid_argument("the grid's bounds have no extent");
  }
  GridSpec spec;
  spec.cell = std::max(width, height) / resolution;
  spec.nx = static_cast<int>(std::ceil(width / spec.cell - 1e-9)) + 2;
  spec.ny = static_cast<int>(std::ceil(height / spec.cell - 1e-9)) + 2;
  spec.nt = theta_resolution > 0 ? theta_resolution : resolution;
  spec.origin_x = b.min.x() - 0.5 * (spec.nx * spec.cell - width);
  spec.origin_y = b.min.y() - 0.5 * (spec.ny * spec.cell - height);
  return spec;
}

double GridSpec::thetaStep() const
{
  return kTwoPi / nt;
}

void GridSpec::unindex(std::size_t v, int& ix, int& iy, int& it) const
{
  ix = static_cast<int>(v % nx);
  const std::size_t rest = v / nx;
  iy = static_cast<int>(rest % ny);
  it = static_cast<int>(rest / ny);
}

double GridSpec::centreTheta(int it) const
{
  return -kPi + (it + 0.5) * thetaStep();
}

Pose2 GridSpec::centre(std::size_t v) const
{
  int ix = 0;
  int iy = 0;
  int it = 0;
  unindex(v, ix, iy, it);
  return Pose2(centreX(ix), centreY(iy), centreTheta(it));
}

bool GridSpec::locate(const Pose2& pose, int& ix, int& iy, int& it) const
{
  int fx = 0;
  int fy = 0;
  int ft = 0;
  if (!floorIndex((pose.x - origin_x) / cell, 2.0 * nx + 2.0, fx) ||
      !floorIndex((pose.y - origin_y) / cell, 2.0 * ny + 2.0, fy) || fx < 0 || fx >= nx || fy < 0 || fy >= ny ||
      !floorIndex((wrapAngle(pose.theta) + kPi) / thetaStep(), 2.0 * nt + 2.0, ft))
  {
    return false;
  }
  ix = fx;
  iy = fy;
  it = ((ft % nt) + nt) % nt;
  return true;
}

std::uint64_t GridSpec::hash() const
{
  std::uint64_t h = 0x5f1d3a7c2b9e8d41ULL;
  h = mixHash(h, doubleBits(origin_x));
  h = mixHash(h, doubleBits(origin_y));
  h = mixHash(h, doubleBits(cell));
  h = mixHash(h, static_cast<std::uint64_t>(nx));
  h = mixHash(h, static_cast<std::uint64_t>(ny));
  h = mixHash(h, static_cast<std::uint64_t>(nt));
  return h;
}

bool GridSpec::operator==(const GridSpec& other) const
{
  return origin_x == other.origin_x && origin_y == other.origin_y && cell == other.cell && nx == other.nx &&
         ny == other.ny && nt == other.nt;
}

VoxelSet::VoxelSet(const GridSpec& spec) : nx_(spec.nx), ny_(spec.ny), nt_(spec.nt), words_per_row_((spec.nx + 63) / 64)
{
  words_.assign(static_cast<std::size_t>(words_per_row_) * ny_ * nt_, 0);
}

std::size_t VoxelSet::count() const
{
  std::size_t total = 0;
  for (std::uint64_t w : words_)
  {
    total += static_cast<std::size_t>(__builtin_popcountll(w));
  }
  return total;
}

void VoxelSet::clear()
{
  std::fill(words_.begin(), words_.end(), 0);
}

void VoxelSet::clearSlice(int it)
{
  const std::size_t slice = static_cast<std::size_t>(ny_) * words_per_row_;
  std::fill_n(words_.begin() + static_cast<std::ptrdiff_t>(it * slice), slice, 0);
}

void VoxelSet::reshape(const GridSpec& spec)
{
  nx_ = spec.nx;
  ny_ = spec.ny;
  nt_ = spec.nt;
  words_per_row_ = (spec.nx + 63) / 64;
  words_.resize(static_cast<std::size_t>(words_per_row_) * ny_ * nt_);
}

VoxelSet VoxelSet::dilated() const
{
  VoxelSet result;
  dilateInto(result);
  return result;
}

void VoxelSet::dilateInto(VoxelSet& out) const
{
  if (&out == this)
  {
    out = dilated();  // the input cannot be overwritten while it is read
    return;
  }
  out.nx_ = nx_;
  out.ny_ = ny_;
  out.nt_ = nt_;
  out.words_per_row_ = words_per_row_;
  out.words_.resize(words_.size());
  const int wpr = words_per_row_;
  const int tail_bits = nx_ - (wpr - 1) * 64;
  const std::uint64_t tail_mask = tail_bits >= 64 ? ~std::uint64_t(0) : (std::uint64_t(1) << tail_bits) - 1;
  const std::size_t slice = static_cast<std::size_t>(ny_) * wpr;
  if (slice == 0 || nt_ <= 0)
  {
    return;
  }
  // A slice dilated along x (inside each row) and then y: three of them (the slices before, at
  // and after the one written) at a time, so every word is read and written once.
  std::vector<std::uint64_t> along_x(slice);
  std::vector<std::uint64_t> ring(3 * slice);
  auto planar = [&](int it, std::uint64_t* dst) {
    dilateSliceInPlane(words_.data() + static_cast<std::size_t>(it) * slice, along_x.data(), dst, ny_, wpr, tail_mask);
  };
  std::uint64_t* prev = ring.data();
  std::uint64_t* mid = prev + slice;
  std::uint64_t* next = mid + slice;
  planar(nt_ - 1, prev);
  planar(0, mid);
  planar(1 % nt_, next);
  // Along theta, periodic.
  for (int it = 0; it < nt_; ++it)
  {
    std::uint64_t* o = out.words_.data() + static_cast<std::size_t>(it) * slice;
    for (std::size_t k = 0; k < slice; ++k)
    {
      o[k] = prev[k] | mid[k] | next[k];
    }
    std::swap(prev, mid);  // the slice at it becomes the one before it + 1 ...
    std::swap(mid, next);  // ... and the one after it the one at it + 1
    if (it + 1 < nt_)
    {
      planar((it + 2) % nt_, next);
    }
  }
}

VoxelSet& VoxelSet::operator&=(const VoxelSet& other)
{
  if (other.words_.size() != words_.size())
  {
    throw std::invalid_argument("VoxelSet: grids differ");
  }
  for (std::size_t k = 0; k < words_.size(); ++k)
  {
    words_[k] &= other.words_[k];
  }
  return *this;
}

VoxelSet& VoxelSet::operator|=(const VoxelSet& other)
{
  if (other.words_.size() != words_.size())
  {
    throw std::invalid_argument("VoxelSet: grids differ");
  }
  for (std::size_t k = 0; k < words_.size(); ++k)
  {
    words_[k] |= other.words_[k];
  }
  return *this;
}

bool VoxelSet::operator==(const VoxelSet& other) const
{
  return nx_ == other.nx_ && ny_ == other.ny_ && nt_ == other.nt_ && words_ == other.words_;
}

}  // namespace core
}  // namespace fdml_localization
