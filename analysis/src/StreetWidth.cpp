#include "parcelscope/analysis/StreetWidth.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

namespace parcelscope::analysis {

namespace {

struct Segment {
  Point a, b;
  std::size_t block;
};

// Segments bucketed in square cells, each segment in every cell its bounding
// box touches.
class SegmentGrid {
public:
  SegmentGrid(std::vector<Segment> segments, double cell) : segments_(std::move(segments)), cell_(cell) {
    for (std::size_t s = 0; s < segments_.size(); ++s) {
      const Segment& g = segments_[s];
      forCells(std::min(g.a.x, g.b.x), std::min(g.a.y, g.b.y), std::max(g.a.x, g.b.x), std::max(g.a.y, g.b.y),
               [&](long long key) { cells_[key].push_back(s); });
    }
  }

  template <class F>
  void forCells(double x0, double y0, double x1, double y1, F f) const {
    const long long i0 = cellOf(x0), i1 = cellOf(x1), j0 = cellOf(y0), j1 = cellOf(y1);
    for (long long i = i0; i <= i1; ++i) {
      for (long long j = j0; j <= j1; ++j) f(key(i, j));
    }
  }

  const std::vector<std::size_t>* cell(long long k) const {
    auto it = cells_.find(k);
    return it == cells_.end() ? nullptr : &it->second;
  }
  const Segment& segment(std::size_t s) const { return segments_[s]; }

private:
  long long cellOf(double v) const { return static_cast<long long>(std::floor(v / cell_)); }
  static long long key(long long i, long long j) { return i * 0x1000003LL ^ j; }

  std::vector<Segment> segments_;
  double cell_;
  std::unordered_map<long long, std::vector<std::size_t>> cells_;
};

// Distance along the ray from o in unit direction d to segment s, or infinity.
double rayHit(const Point& o, const Point& d, const Segment& s) {
  const double ex = s.b.x - s.a.x, ey = s.b.y - s.a.y;
  const double denom = d.x * ey - d.y * ex;
  if (std::fabs(denom) < 1e-12 * norm(ex, ey)) return std::numeric_limits<double>::infinity();
  const double wx = s.a.x - o.x, wy = s.a.y - o.y;
  const double t = (wx * ey - wy * ex) / denom;    // along the ray
  const double u = (wx * d.y - wy * d.x) / denom;  // along the segment
  if (t <= 0 || u < 0 || u > 1) return std::numeric_limits<double>::infinity();
  return t;
}

}  // namespace

std::vector<std::vector<std::vector<double>>> streetWidths(const std::vector<const Polygon*>& blocks, double maxWidth) {
  std::vector<Segment> segments;
  auto rings = [](const Polygon& p) {
    std::vector<const Ring*> r{&p.outer};
    for (const Ring& h : p.holes) r.push_back(&h);
    return r;
  };
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    for (const Ring* ring : rings(*blocks[b])) {
      for (std::size_t i = 0, n = ring->size(); i < n; ++i) segments.push_back({(*ring)[i], (*ring)[(i + 1) % n], b});
    }
  }
  const SegmentGrid grid(std::move(segments), std::max(1.0, maxWidth / 2));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<std::vector<std::vector<double>>> out(blocks.size());
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    for (const Ring* ring : rings(*blocks[b])) {
      std::vector<double> widths(ring->size(), nan);
      for (std::size_t i = 0, n = ring->size(); i < n; ++i) {
        const Point &a = (*ring)[i], &c = (*ring)[(i + 1) % n];
        const double len = norm(c.x - a.x, c.y - a.y);
        if (len < 1e-3) continue;
        // Normalised rings have the block on their left: out is to the right.
        const Point d{(c.y - a.y) / len, -(c.x - a.x) / len};
        const Point o{0.5 * (a.x + c.x), 0.5 * (a.y + c.y)};
        const Point e{o.x + d.x * maxWidth, o.y + d.y * maxWidth};
        double best = std::numeric_limits<double>::infinity();
        grid.forCells(std::min(o.x, e.x), std::min(o.y, e.y), std::max(o.x, e.x), std::max(o.y, e.y), [&](long long k) {
          const auto* cell = grid.cell(k);
          if (!cell) return;
          for (std::size_t s : *cell) {
            if (grid.segment(s).block == b) continue;
            best = std::min(best, rayHit(o, d, grid.segment(s)));
          }
        });
        if (best <= maxWidth) widths[i] = best;
      }
      out[b].push_back(std::move(widths));
    }
  }
  return out;
}

}  // namespace parcelscope::analysis
