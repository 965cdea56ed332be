#include "parcelscope/generation/ParcelMatching.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <tuple>

namespace parcelscope::generation {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

/// How far `v` is from the chord p-q, as a share of the chord's length;
/// infinite when `v` does not lie between p and q (a spike, not a collinear
/// vertex). A vertex repeating both neighbours is 0.
double straightness(const Point& p, const Point& v, const Point& q) {
  const double cx = q.x - p.x, cy = q.y - p.y, vx = v.x - p.x, vy = v.y - p.y;
  const double chord2 = cx * cx + cy * cy;
  if (chord2 == 0) return vx == 0 && vy == 0 ? 0 : kInfinity;
  const double t = (vx * cx + vy * cy) / chord2;
  if (t < 0 || t > 1) return kInfinity;
  return std::fabs(cx * vy - cy * vx) / chord2;
}

/// `ring` moved to its centre and scaled to `unit`: (p - centre) / unit.
std::vector<Point> framed(const Ring& ring, const Point& centre, double unit) {
  std::vector<Point> out;
  out.reserve(ring.size());
  for (const Point& p : ring) out.push_back({(p.x - centre.x) / unit, (p.y - centre.y) / unit});
  return out;
}

/// Equal counts: the cyclic shift s pairing vertex i of `a` with vertex
/// i + s of `b` that fits best up to a similarity transform (see the header).
std::vector<std::pair<std::size_t, std::size_t>> correspondByShift(const Ring& a, const Ring& b) {
  const std::size_t k = a.size();
  // Centre on the vertex mean and scale to unit sum of squared radii: then the
  // residual of the best rotation is 2 - 2 |z|, z = sum conj(a_i) b_(i+s), and
  // the rotation is arg z (orthogonal Procrustes in complex form).
  auto normalised = [k](const Ring& r) -> std::vector<Point> {
    Point mean;
    for (const Point& p : r) {
      mean.x += p.x / static_cast<double>(k);
      mean.y += p.y / static_cast<double>(k);
    }
    double sum2 = 0;
    for (const Point& p : r) sum2 += (p.x - mean.x) * (p.x - mean.x) + (p.y - mean.y) * (p.y - mean.y);
    if (!(sum2 > 0)) return {};
    return framed(r, mean, std::sqrt(sum2));
  };
  const std::vector<Point> na = normalised(a), nb = normalised(b);
  if (na.empty() || nb.empty()) return {};
  std::vector<double> residual(k), rotation(k);
  for (std::size_t s = 0; s < k; ++s) {
    double re = 0, im = 0;
    for (std::size_t i = 0; i < k; ++i) {
      const Point &p = na[i], &q = nb[(i + s) % k];
      re += p.x * q.x + p.y * q.y;
      im += p.x * q.y - p.y * q.x;
    }
    residual[s] = 2 - 2 * norm(re, im);
    rotation[s] = std::fabs(std::atan2(im, re));
  }
  const double best = *std::min_element(residual.begin(), residual.end());
  std::size_t shift = k;
  for (std::size_t s = 0; s < k; ++s) {
    if (residual[s] <= best + kCorrespondenceBand && (shift == k || rotation[s] < rotation[shift])) shift = s;
  }
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  for (std::size_t i = 0; i < k; ++i) pairs.emplace_back(i, (i + shift) % k);
  return pairs;
}

/// Index of the point of `points` nearest to `p` (ties to the lowest index).
std::size_t nearest(const Point& p, const std::vector<Point>& points) {
  std::size_t best = 0;
  double bestDistance = kInfinity;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double d = norm(points[i].x - p.x, points[i].y - p.y);
    if (d < bestDistance) {
      bestDistance = d;
      best = i;
    }
  }
  return best;
}

/// Different counts: the mutual nearest vertices in the area-normalised frame
/// of each contour (see the header).
std::vector<std::pair<std::size_t, std::size_t>> correspondByNearest(const Ring& a, const Ring& b) {
  auto normalised = [](const Ring& r) -> std::vector<Point> {
    const Polygon p{r, {}};
    const double unit = std::sqrt(std::fabs(signedArea(r)));
    if (!(unit > 0)) return {};
    return framed(r, centroid(p), unit);
  };
  const std::vector<Point> na = normalised(a), nb = normalised(b);
  if (na.empty() || nb.empty()) return {};
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  for (std::size_t i = 0; i < na.size(); ++i) {
    const std::size_t j = nearest(na[i], nb);
    if (nearest(nb[j], na) == i) pairs.emplace_back(i, j);
  }
  if (pairs.size() < 3) return {};
  // The vertices of `b` must come in their cyclic order: going round `a`, the
  // paired indices of `b` fall back exactly once (where they wrap around).
  std::size_t descents = 0;
  for (std::size_t t = 0; t < pairs.size(); ++t) {
    if (pairs[(t + 1) % pairs.size()].second < pairs[t].second) ++descents;
  }
  if (descents != 1) return {};
  return pairs;
}

}  // namespace

Ring matchingContour(const Ring& contour) {
  Ring ring = contour;
  if (signedArea(ring) < 0) std::reverse(ring.begin(), ring.end());
  while (ring.size() > 3) {
    const std::size_t n = ring.size();
    std::size_t straightest = n;
    double least = kInfinity;
    for (std::size_t i = 0; i < n; ++i) {
      const double s = straightness(ring[(i + n - 1) % n], ring[i], ring[(i + 1) % n]);
      // Ties go to the lowest x, then y: independent of where the ring starts.
      if (s < least || (s == least && s <= kCollinearShare &&
                        std::tie(ring[i].x, ring[i].y) < std::tie(ring[straightest].x, ring[straightest].y))) {
        least = s;
        straightest = i;
      }
    }
    if (!(least <= kCollinearShare)) break;
    ring.erase(ring.begin() + static_cast<std::ptrdiff_t>(straightest));
  }
  return ring;
}

std::vector<std::pair<std::size_t, std::size_t>> correspondContours(const Ring& before, const Ring& after) {
  if (before.size() < 3 || after.size() < 3) return {};
  return before.size() == after.size() ? correspondByShift(before, after) : correspondByNearest(before, after);
}

Point parcelCentre(const Polygon& parcel) { return centroid(parcel); }

std::vector<double> relativePosition(const Point& point, const Ring& vertices) {
  std::vector<double> l;
  l.reserve(vertices.size());
  double sum = 0;
  for (const Point& b : vertices) {
    l.push_back(norm(point.x - b.x, point.y - b.y));
    sum += l.back();
  }
  for (double& v : l) v = sum > 0 ? v / sum : 1.0 / static_cast<double>(vertices.size());
  return l;
}

double positionDistance(const std::vector<double>& a, const std::vector<double>& b) {
  double d = 0;
  for (std::size_t k = 0; k < a.size() && k < b.size(); ++k) d += std::fabs(a[k] - b[k]);
  return d;
}

ParcelMatches matchParcels(const Polygon& blockBefore, const std::vector<Polygon>& parcelsBefore,
                           const Polygon& blockAfter, const std::vector<Polygon>& parcelsAfter) {
  ParcelMatches out;
  out.before.assign(parcelsAfter.size(), -1);
  out.distance.assign(parcelsAfter.size(), -1.0);
  const Ring contourBefore = matchingContour(blockBefore.outer), contourAfter = matchingContour(blockAfter.outer);
  const auto pairs = correspondContours(contourBefore, contourAfter);
  // A parcel's position in its block, and the distance between two: the
  // paper's over the corresponded vertices; without a correspondence, the
  // parcel's centre relative to the block's area centroid in units of the
  // square root of the block's area, and their Euclidean distance.
  std::function<std::vector<double>(const Polygon&, bool)> position;
  std::function<double(const std::vector<double>&, const std::vector<double>&)> distance = positionDistance;
  Ring verticesBefore, verticesAfter;
  if (!pairs.empty()) {
    for (const auto& [i, j] : pairs) {
      verticesBefore.push_back(contourBefore[i]);
      verticesAfter.push_back(contourAfter[j]);
    }
    position = [&](const Polygon& p, bool after) {
      return relativePosition(parcelCentre(p), after ? verticesAfter : verticesBefore);
    };
  } else {
    if (!(area(blockBefore) > 0) || !(area(blockAfter) > 0)) return out;  // degenerate: nothing to place parcels in
    const Point centreBefore = centroid(blockBefore), centreAfter = centroid(blockAfter);
    const double unitBefore = std::sqrt(area(blockBefore)), unitAfter = std::sqrt(area(blockAfter));
    position = [=](const Polygon& p, bool after) {
      const Point c = parcelCentre(p), o = after ? centreAfter : centreBefore;
      const double u = after ? unitAfter : unitBefore;
      return std::vector<double>{(c.x - o.x) / u, (c.y - o.y) / u};
    };
    distance = [](const std::vector<double>& a, const std::vector<double>& b) {
      return std::hypot(a[0] - b[0], a[1] - b[1]);
    };
  }
  std::vector<std::vector<double>> positionsBefore;
  positionsBefore.reserve(parcelsBefore.size());
  for (const Polygon& p : parcelsBefore) positionsBefore.push_back(position(p, false));

  // Every pair (distance, after, before), taken by increasing distance, ties
  // to the lower indices; a pair is kept when neither parcel is matched yet.
  std::vector<std::tuple<double, std::size_t, std::size_t>> candidates;
  candidates.reserve(parcelsAfter.size() * parcelsBefore.size());
  for (std::size_t i = 0; i < parcelsAfter.size(); ++i) {
    const std::vector<double> at = position(parcelsAfter[i], true);
    for (std::size_t j = 0; j < parcelsBefore.size(); ++j)
      candidates.emplace_back(distance(at, positionsBefore[j]), i, j);
  }
  std::sort(candidates.begin(), candidates.end());
  std::vector<bool> taken(parcelsBefore.size(), false);
  for (const auto& [d, i, j] : candidates) {
    if (out.before[i] >= 0 || taken[j]) continue;
    out.before[i] = static_cast<int>(j);
    out.distance[i] = d;
    taken[j] = true;
  }
  return out;
}

}  // namespace parcelscope::generation
