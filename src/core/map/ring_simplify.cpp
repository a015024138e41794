#include "fdml_localization/core/map/ring_simplify.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace fdml_localization {
namespace core {
namespace {
/// Distance from p to the segment ab [m].
double distanceToSegment(const Vec2 &p, const Vec2 &a, const Vec2 &b) {
  const Vec2 ab = b - a;
  const double len2 = ab.squaredNorm();
  if (len2 <= 0.0) {
    return (p - a).norm();
  }
  const double t = std::clamp((p - a).dot(ab) / len2, 0.0, 1.0);
  return (p - (a + t * ab)).norm();
}

/// Removes vertices lying exactly on the line through their neighbours.
Ring dropCollinear(const Ring &ring) {
  if (ring.size() <= 3) {
    return ring;
  }
  Ring out;
  out.reserve(ring.size());
  const std::size_t n = ring.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 &prev = ring[(i + n - 1) % n];
    const Vec2 &next = ring[(i + 1) % n];
    const Vec2 d1 = ring[i] - prev;
    const Vec2 d2 = next - ring[i];
    if (cross(d1, d2) != 0.0 || d1.dot(d2) < 0.0) {
      out.push_back(ring[i]);
    }
  }
  return out.size() >= 3 ? out : ring;
}

/// Orientation sign of (a, b, c): +1 left turn, -1 right turn, 0 when c lies
/// within @p eps [m] of the line through a and b.
int orient(const Vec2 &a, const Vec2 &b, const Vec2 &c, double eps) {
  const Vec2 ab = b - a;
  const double v = cross(ab, c - a);
  const double band = eps * ab.norm();
  return v > band ? 1 : (v < -band ? -1 : 0);
}

/// True when the closed segments pq and rs come within @p eps [m] of each
/// other.
bool closedSegmentsMeet(const Vec2 &p, const Vec2 &q, const Vec2 &r,
                        const Vec2 &s, double eps) {
  const int o1 = orient(p, q, r, 0.0);
  const int o2 = orient(p, q, s, 0.0);
  const int o3 = orient(r, s, p, 0.0);
  const int o4 = orient(r, s, q, 0.0);
  if (o1 * o2 < 0 && o3 * o4 < 0) {
    return true; // a proper crossing
  }
  return distanceToSegment(r, p, q) <= eps ||
         distanceToSegment(s, p, q) <= eps ||
         distanceToSegment(p, r, s) <= eps || distanceToSegment(q, r, s) <= eps;
}

Box2 ringBounds(const Ring &ring) {
  Box2 box;
  for (const Vec2 &p : ring) {
    box.extend(p);
  }
  return box;
}

struct EdgeRef {
  int ring;
  int index; ///< edge from vertex index to index + 1 (cyclic)
};

/// The Douglas-Peucker anchors: the lowest-leftmost vertex (a true corner of
/// the hull) and the vertex farthest from it.
std::pair<std::size_t, std::size_t> anchors(const Ring &ring) {
  const std::size_t n = ring.size();
  std::size_t a = 0;
  for (std::size_t i = 1; i < n; ++i) {
    if (ring[i].y() < ring[a].y() ||
        (ring[i].y() == ring[a].y() && ring[i].x() < ring[a].x())) {
      a = i;
    }
  }
  std::size_t b = a;
  double best = -1.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double d = (ring[i] - ring[a]).squaredNorm();
    if (d > best) {
      best = d;
      b = i;
    }
  }
  return {a, b};
}

/// Douglas-Peucker on the two chains between the anchors: which vertices to
/// keep.
std::vector<char> douglasPeucker(const Ring &ring, double tolerance) {
  const std::size_t n = ring.size();
  const auto [a, b] = anchors(ring);
  const std::size_t bu = b > a ? b : b + n; // unwrapped index of b after a
  std::vector<char> keep(n, 0);
  keep[a] = 1;
  keep[b] = 1;
  std::vector<std::pair<std::size_t, std::size_t>> stack{{a, bu}, {bu, a + n}};
  while (!stack.empty()) {
    const auto [lo, hi] = stack.back();
    stack.pop_back();
    if (hi <= lo + 1) {
      continue;
    }
    const Vec2 &p0 = ring[lo % n];
    const Vec2 &p1 = ring[hi % n];
    std::size_t far = lo;
    double far_d = -1.0;
    for (std::size_t k = lo + 1; k < hi; ++k) {
      const double d = distanceToSegment(ring[k % n], p0, p1);
      if (d > far_d) {
        far_d = d;
        far = k;
      }
    }
    if (far_d > tolerance) {
      keep[far % n] = 1;
      stack.emplace_back(lo, far);
      stack.emplace_back(far, hi);
    }
  }
  return keep;
}

/// The edges of every usable ring; rings too small, flat or non-finite are
/// marked bad.
std::vector<EdgeRef> collectEdges(const std::vector<Ring> &rings,
                                  std::vector<bool> &bad,
                                  std::vector<Box2> &boxes, Box2 &all) {
  std::vector<EdgeRef> edges;
  for (int r = 0; r < static_cast<int>(rings.size()); ++r) {
    const Ring &ring = rings[r];
    const double area = ring.size() >= 3 ? signedArea(ring) : 0.0;
    if (ring.size() < 3 || area == 0.0 || !std::isfinite(area)) {
      bad[r] = true;
      continue;
    }
    boxes[r] = ringBounds(ring);
    all.extend(boxes[r]);
    for (int i = 0; i < static_cast<int>(ring.size()); ++i) {
      edges.push_back({r, i});
    }
  }
  return edges;
}

/// A bucket grid over every edge's bounding box (grown by @p eps).
std::vector<std::vector<int>> bucketEdges(const std::vector<Ring> &rings,
                                          const std::vector<EdgeRef> &edges,
                                          const Box2 &all, double eps) {
  const Vec2 size = all.size();
  const double extent = std::max({size.x(), size.y(), 1e-9});
  const int cells_per_side = std::clamp(
      static_cast<int>(std::sqrt(static_cast<double>(edges.size()))), 1, 1024);
  const double cell = extent / cells_per_side * (1.0 + 1e-9);
  const int nx = std::max(1, static_cast<int>(size.x() / cell) + 1);
  const int ny = std::max(1, static_cast<int>(size.y() / cell) + 1);
  std::vector<std::vector<int>> buckets(static_cast<std::size_t>(nx) *
                                        static_cast<std::size_t>(ny));
  auto clampCell = [](double v, int n) {
    return static_cast<int>(std::clamp(v, 0.0, n - 1.0));
  };
  for (int e = 0; e < static_cast<int>(edges.size()); ++e) {
    const Ring &ring = rings[edges[e].ring];
    const Vec2 &p = ring[edges[e].index];
    const Vec2 &q = ring[(edges[e].index + 1) % ring.size()];
    const int x0 =
        clampCell((std::min(p.x(), q.x()) - eps - all.min.x()) / cell, nx);
    const int x1 =
        clampCell((std::max(p.x(), q.x()) + eps - all.min.x()) / cell, nx);
    const int y0 =
        clampCell((std::min(p.y(), q.y()) - eps - all.min.y()) / cell, ny);
    const int y1 =
        clampCell((std::max(p.y(), q.y()) + eps - all.min.y()) / cell, ny);
    for (int cy = y0; cy <= y1; ++cy) {
      for (int cx = x0; cx <= x1; ++cx) {
        buckets[static_cast<std::size_t>(cy) * nx + cx].push_back(e);
      }
    }
  }
  return buckets;
}

/// True when edges @p e and @p f meet where they should not (within @p eps
/// [m]): adjacent edges folding back onto each other, other edges touching or
/// crossing.
bool edgesMeet(const std::vector<Ring> &rings, const EdgeRef &e,
               const EdgeRef &f, double eps) {
  const Ring &re = rings[e.ring];
  const int ne = static_cast<int>(re.size());
  const Vec2 &p = re[e.index];
  const Vec2 &q = re[(e.index + 1) % ne];
  const Ring &rf = rings[f.ring];
  const Vec2 &r = rf[f.index];
  const Vec2 &s = rf[(f.index + 1) % rf.size()];
  if (e.ring == f.ring &&
      (f.index == (e.index + 1) % ne || e.index == (f.index + 1) % ne)) {
    // Adjacent edges share one vertex; they must not fold back onto each other.
    const bool e_first = f.index == (e.index + 1) % ne;
    const Vec2 &shared = e_first ? q : p;
    const Vec2 &u = e_first ? p : q;
    const Vec2 &w = e_first ? s : r;
    return orient(u, shared, w, eps) == 0 && (u - shared).dot(w - shared) > 0.0;
  }
  return closedSegmentsMeet(p, q, r, s, eps);
}

/// Containment: every hole inside the outer ring and outside every other hole
/// (no edges cross at this point for good rings, so one vertex decides).
void markContainment(const std::vector<Ring> &rings,
                     const std::vector<Box2> &boxes, std::vector<bool> &bad) {
  const int ring_count = static_cast<int>(rings.size());
  if (!rings.empty() && !bad[0]) {
    for (int r = 1; r < ring_count; ++r) {
      if (!bad[r] && !pointInRing(rings[r].front(), rings[0])) {
        bad[0] = true; // either ring may have moved: tighten both
        bad[r] = true;
      }
    }
  }
  for (int r = 1; r < ring_count; ++r) {
    for (int t = r + 1; t < ring_count; ++t) {
      if (bad[r] || bad[t] || !boxes[r].intersects(boxes[t])) {
        continue;
      }
      if (pointInRing(rings[r].front(), rings[t]) ||
          pointInRing(rings[t].front(), rings[r])) {
        bad[r] = true;
        bad[t] = true;
      }
    }
  }
}
} // namespace

Ring simplifyRing(const Ring &input, double tolerance) {
  const Ring ring = dropCollinear(input);
  if (ring.size() <= 3 || !(tolerance > 0.0)) {
    return ring;
  }
  const std::vector<char> keep = douglasPeucker(ring, tolerance);
  Ring out;
  for (std::size_t i = 0; i < ring.size(); ++i) {
    if (keep[i]) {
      out.push_back(ring[i]);
    }
  }
  return out.size() >= 3 ? out : ring;
}

std::vector<bool> findInvalidRings(const std::vector<Ring> &rings) {
  std::vector<bool> bad(rings.size(), false);
  std::vector<Box2> boxes(rings.size());
  Box2 all;
  const std::vector<EdgeRef> edges = collectEdges(rings, bad, boxes, all);
  if (edges.empty()) {
    return bad;
  }
  // Closer than this counts as touching: well above rounding, far below any map
  // feature.
  const double eps =
      1e-9 * std::max({all.size().x(), all.size().y(), 1e-9,
                       std::abs(all.min.x()), std::abs(all.min.y()),
                       std::abs(all.max.x()), std::abs(all.max.y())});
  for (const std::vector<int> &bucket : bucketEdges(rings, edges, all, eps)) {
    for (std::size_t i = 0; i < bucket.size(); ++i) {
      for (std::size_t j = i + 1; j < bucket.size(); ++j) {
        const EdgeRef &e = edges[bucket[i]];
        const EdgeRef &f = edges[bucket[j]];
        if (!(bad[e.ring] && bad[f.ring]) && edgesMeet(rings, e, f, eps)) {
          bad[e.ring] = true;
          bad[f.ring] = true;
        }
      }
    }
  }
  markContainment(rings, boxes, bad);
  return bad;
}

std::vector<Ring> simplifyRings(const std::vector<Ring> &rings,
                                double tolerance, SimplifyStats *stats) {
  constexpr int kHalvings = 6;
  std::vector<double> tol(rings.size(), tolerance);
  std::vector<bool> tightened(rings.size(), false);
  std::vector<Ring> out(rings.size());
  for (std::size_t r = 0; r < rings.size(); ++r) {
    out[r] = simplifyRing(rings[r], tol[r]);
  }
  bool valid = false;
  while (true) {
    const std::vector<bool> bad = findInvalidRings(out);
    if (std::none_of(bad.begin(), bad.end(), [](bool b) { return b; })) {
      valid = true;
      break;
    }
    bool changed = false;
    for (std::size_t r = 0; r < rings.size(); ++r) {
      if (bad[r] && tol[r] > 0.0) {
        tol[r] = tol[r] <= tolerance / (1 << kHalvings) ? 0.0 : 0.5 * tol[r];
        tightened[r] = true;
        changed = true;
        out[r] = simplifyRing(rings[r], tol[r]);
      }
    }
    if (!changed) {
      break; // the input itself is invalid
    }
  }
  if (stats != nullptr) {
    stats->rings_tightened =
        static_cast<int>(std::count(tightened.begin(), tightened.end(), true));
    stats->valid = valid;
  }
  return out;
}

} // namespace core
} // namespace fdml_localization
