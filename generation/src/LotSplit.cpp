#include "LotSplit.h"

#include <algorithm>
#include <cmath>
#include <iterator>

#include "PolygonSplit.h"
#include "parcelscope/core/GeosOps.h"

namespace parcelscope::generation::detail {

Point unitFrom(const Point& a, const Point& b) {
  const double n = norm(b.x - a.x, b.y - a.y);
  return n > 0 ? Point{(b.x - a.x) / n, (b.y - a.y) / n} : Point{1, 0};
}

double angleBetween(const Point& u, const Point& v) {
  return std::atan2(std::fabs(u.x * v.y - u.y * v.x), u.x * v.x + u.y * v.y);
}

std::vector<Side> sidesOf(const Ring& ring) {
  const std::size_t n = ring.size();
  std::vector<Side> sides;
  if (n < 3) return sides;
  auto edgeDir = [&](std::size_t i) { return unitFrom(ring[i], ring[(i + 1) % n]); };
  std::size_t start = 0;
  double sharpest = -1;
  for (std::size_t i = 0; i < n; ++i) {
    const double turn = angleBetween(edgeDir((i + n - 1) % n), edgeDir(i));
    if (turn > sharpest) {
      sharpest = turn;
      start = i;
    }
  }
  auto begin = [&](std::size_t i) {
    Side s{ring[i], ring[(i + 1) % n], 0, edgeDir(i), i, 1};
    s.length = norm(s.b.x - s.a.x, s.b.y - s.a.y);
    return s;
  };
  Side run = begin(start);
  for (std::size_t k = 1; k <= n; ++k) {
    const std::size_t i = (start + k) % n;
    if (k < n && angleBetween(run.dir, edgeDir(i)) < kSideTurn) {
      run.b = ring[(i + 1) % n];
      run.dir = unitFrom(run.a, run.b);
      run.length = norm(run.b.x - run.a.x, run.b.y - run.a.y);
      ++run.edges;
      continue;
    }
    sides.push_back(run);
    if (k < n) run = begin(i);
  }
  return sides;
}

namespace {
bool validPiece(const Polygon& p) { return (p.holes.empty() && isClearlySimple(p.outer)) || geos::isValid(p); }

std::vector<Polygon> joined(SplitPieces&& split) {
  std::vector<Polygon> parts = std::move(split.left);
  parts.insert(parts.end(), std::make_move_iterator(split.right.begin()), std::make_move_iterator(split.right.end()));
  return parts;
}
}  // namespace

std::vector<Polygon> splitLot(const Polygon& lot, double lotArea, const SplitLine& line, bool exact,
                              const std::function<bool(const std::vector<Polygon>&)>& admissible) {
  SplitPieces split;
  if (splitByLineFast(lot, line.through, line.dir, split) && !split.pinched) {
    std::vector<Polygon> pieces = joined(std::move(split));
    double sum = 0;
    for (const Polygon& q : pieces) sum += area(q);
    if (std::fabs(sum - lotArea) <= 1e-9 * lotArea) {
      if (pieces.size() < 2 || (admissible && !admissible(pieces))) return {};
      if (std::all_of(pieces.begin(), pieces.end(), validPiece)) return pieces;
    }
  }
  if (!exact) return {};
  std::vector<Polygon> pieces = joined(splitByLine(lot, line.through, line.dir));
  if (pieces.size() < 2 || (admissible && !admissible(pieces))) return {};
  if (!std::all_of(pieces.begin(), pieces.end(), validPiece)) return {};
  return pieces;
}

}  // namespace parcelscope::generation::detail
