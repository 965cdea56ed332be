#include "TemplateWarp.h"

#include <algorithm>
#include <cmath>

#include "LotSplit.h"

namespace parcelscope::generation::detail {

namespace {
constexpr double kMaxMergedTurn = 2 * kPi / 3;
}  // namespace

std::vector<Corner> cornersOf(const Ring& ring, double minTurn, std::size_t maxCorners, double shortShare) {
  const std::vector<Side> sides = sidesOf(ring);
  std::vector<Corner> corners;
  if (sides.size() < 3) return corners;
  std::vector<double> signedTurn;  // per corner
  std::vector<double> cumulative{0};
  for (std::size_t i = 0; i < ring.size(); ++i) {
    const Point &a = ring[i], &b = ring[(i + 1) % ring.size()];
    cumulative.push_back(cumulative.back() + norm(b.x - a.x, b.y - a.y));
  }
  std::vector<std::size_t> index;
  for (std::size_t k = 0; k < sides.size(); ++k) {
    const Point& u = sides[(k + sides.size() - 1) % sides.size()].dir;
    const Point& v = sides[k].dir;
    const double turn = std::atan2(u.x * v.y - u.y * v.x, u.x * v.x + u.y * v.y);
    if (std::fabs(turn) < minTurn) continue;
    index.push_back(sides[k].first);
    signedTurn.push_back(turn);
  }
  const double perimeter = cumulative.back();
  auto arcAfter = [&](std::size_t k) {  // from corner k to the next
    const std::size_t n = index.size();
    const double d = cumulative[index[(k + 1) % n]] - cumulative[index[k]];
    return d > 0 ? d : d + perimeter;
  };
  for (bool merged = shortShare > 0; merged && index.size() > 3;) {
    merged = false;
    const std::size_t n = index.size();
    for (std::size_t k = 0; k < n && !merged; ++k) {
      const double between = arcAfter(k);
      if (!(between < shortShare * arcAfter((k + n - 1) % n) && between < shortShare * arcAfter((k + 1) % n))) continue;
      const std::size_t next = (k + 1) % n;
      const double sum = signedTurn[k] + signedTurn[next];
      if (std::fabs(sum) > kMaxMergedTurn) continue;  // the two ends of a narrow strip, not one corner
      const std::size_t keep = std::fabs(signedTurn[k]) >= std::fabs(signedTurn[next]) ? k : next;
      const std::size_t drop = keep == k ? next : k;
      signedTurn[keep] = sum;
      std::vector<std::size_t> gone{drop};
      if (std::fabs(sum) < minTurn) gone.push_back(keep);
      std::sort(gone.rbegin(), gone.rend());
      for (std::size_t g : gone) {
        index.erase(index.begin() + static_cast<long>(g));
        signedTurn.erase(signedTurn.begin() + static_cast<long>(g));
      }
      merged = true;
    }
  }
  for (std::size_t k = 0; k < index.size(); ++k) {
    corners.push_back({index[k], static_cast<signed char>(signedTurn[k] > 0 ? 1 : -1), std::fabs(signedTurn[k])});
  }
  if (corners.size() > maxCorners) {
    std::vector<Corner> sharpest = corners;
    std::stable_sort(sharpest.begin(), sharpest.end(),
                     [](const Corner& a, const Corner& b) { return a.turn > b.turn; });
    const double least = sharpest[maxCorners - 1].turn;
    std::size_t ties = 0;  // corners turning by exactly `least` kept, first in ring order
    for (std::size_t k = 0; k < maxCorners; ++k) ties += sharpest[k].turn == least;
    std::vector<Corner> kept;
    for (const Corner& c : corners) {
      if (c.turn > least || (c.turn == least && ties-- > 0)) kept.push_back(c);
    }
    corners = std::move(kept);
  }
  std::sort(corners.begin(), corners.end(), [](const Corner& a, const Corner& b) { return a.index < b.index; });
  return corners;
}

namespace {

double distance(const Point& a, const Point& b) { return norm(b.x - a.x, b.y - a.y); }

// The ring's vertices from matched[k] to matched[k + 1] (both included).
std::vector<std::vector<Point>> ringArcPolylines(const Ring& ring, const std::vector<std::size_t>& matched) {
  std::vector<std::vector<Point>> arcs;
  const std::size_t n = ring.size();
  for (std::size_t k = 0; k < matched.size(); ++k) {
    const std::size_t from = matched[k], to = matched[(k + 1) % matched.size()];
    std::vector<Point> arc{ring[from]};
    for (std::size_t i = (from + 1) % n;; i = (i + 1) % n) {
      arc.push_back(ring[i]);
      if (i == to) break;
    }
    arcs.push_back(std::move(arc));
  }
  return arcs;
}

double polylineLength(const std::vector<Point>& line) {
  double l = 0;
  for (std::size_t i = 1; i < line.size(); ++i) l += distance(line[i - 1], line[i]);
  return l;
}

Point alongPolyline(const std::vector<Point>& line, double fraction) {
  double left = std::clamp(fraction, 0.0, 1.0) * polylineLength(line);
  for (std::size_t i = 1; i < line.size(); ++i) {
    const double l = distance(line[i - 1], line[i]);
    if (left <= l && l > 0) {
      const double f = left / l;
      return {line[i - 1].x + f * (line[i].x - line[i - 1].x), line[i - 1].y + f * (line[i].y - line[i - 1].y)};
    }
    left -= l;
  }
  return line.back();
}

Point closestOnPolyline(const std::vector<Point>& line, const Point& p) {
  Point best = line.front();
  double bestD = distance(p, best);
  for (std::size_t i = 1; i < line.size(); ++i) {
    const Point &a = line[i - 1], &b = line[i];
    const double dx = b.x - a.x, dy = b.y - a.y, l2 = dx * dx + dy * dy;
    const double f = l2 > 0 ? std::clamp(((p.x - a.x) * dx + (p.y - a.y) * dy) / l2, 0.0, 1.0) : 0.0;
    const Point c{a.x + f * dx, a.y + f * dy};
    const double d = distance(p, c);
    if (d < bestD) {
      bestD = d;
      best = c;
    }
  }
  return best;
}

}  // namespace

std::vector<double> templateArcs(const Template& t) {
  std::vector<double> arcs;
  const std::size_t n = t.boundary.size();
  std::size_t first = 0;
  while (first < n && t.corners[first] == 0) ++first;
  if (first == n) return arcs;
  double run = 0;
  for (std::size_t k = 1; k <= n; ++k) {
    const std::size_t i = (first + k) % n;
    run += distance(t.vertices[t.boundary[(i + n - 1) % n]], t.vertices[t.boundary[i]]);
    if (t.corners[i] != 0) {
      arcs.push_back(run);
      run = 0;
    }
  }
  return arcs;
}

std::vector<double> ringArcs(const Ring& ring, const std::vector<std::size_t>& matched) {
  std::vector<double> arcs;
  for (const auto& arc : ringArcPolylines(ring, matched)) arcs.push_back(polylineLength(arc));
  return arcs;
}

double boundaryDistortion(const std::vector<double>& templateArcs, const std::vector<double>& blockArcs) {
  if (templateArcs.empty() || templateArcs.size() != blockArcs.size()) return std::numeric_limits<double>::infinity();
  double sum = 0;
  for (std::size_t k = 0; k < templateArcs.size(); ++k) {
    if (!(templateArcs[k] > 0) || !(blockArcs[k] > 0)) return std::numeric_limits<double>::infinity();
    const double r = std::log(blockArcs[k] / templateArcs[k]);
    sum += r * r;
  }
  return std::sqrt(sum / static_cast<double>(templateArcs.size()));
}

AffineMap registerPart(const std::vector<Point>& from, const std::vector<Point>& to, const TemplatePart& part) {
  const std::size_t n = from.size();
  Point pc, qc;
  for (std::size_t i = 0; i < n; ++i) {
    pc.x += from[i].x / static_cast<double>(n);
    pc.y += from[i].y / static_cast<double>(n);
    qc.x += to[i].x / static_cast<double>(n);
    qc.y += to[i].y / static_cast<double>(n);
  }
  // The similarity's c = a11 = a22 and s = a21 = -a12 (section 4.1).
  double pp = 0, c = 0, s = 0, xx = 0, yy = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Point p{from[i].x - pc.x, from[i].y - pc.y}, q{to[i].x - qc.x, to[i].y - qc.y};
    pp += p.x * p.x + p.y * p.y;
    xx += p.x * p.x;
    yy += p.y * p.y;
    c += p.x * q.x + p.y * q.y;
    s += p.x * q.y - p.y * q.x;
  }
  const double r = std::sqrt(c * c + s * s);
  const double cosA = r > 0 ? c / r : 1, sinA = r > 0 ? s / r : 0;
  double sx = 1, sy = 1;
  switch (part.kind) {
    case PartClass::Rigid:
      break;
    case PartClass::Similarity:
      sx = sy = std::clamp(pp > 0 ? r / pp : 1.0, part.scaleMin, part.scaleMax);
      break;
    case PartClass::Affine: {
      // Then the scales along the template's axes: with the rotation fixed, a
      // quadratic program in two unknowns with box constraints, separable.
      double ux = 0, uy = 0;
      for (std::size_t i = 0; i < n; ++i) {
        const Point p{from[i].x - pc.x, from[i].y - pc.y}, q{to[i].x - qc.x, to[i].y - qc.y};
        const Point u{cosA * q.x + sinA * q.y, -sinA * q.x + cosA * q.y};  // rotated back
        ux += p.x * u.x;
        uy += p.y * u.y;
      }
      sx = std::clamp(xx > 0 ? ux / xx : 1.0, part.scaleMin, part.scaleMax);
      sy = std::clamp(yy > 0 ? uy / yy : 1.0, part.scaleMinY, part.scaleMaxY);
      break;
    }
  }
  AffineMap m{cosA * sx, -sinA * sy, sinA * sx, cosA * sy, {}};
  const Point moved = m(pc);
  m.t = {qc.x - moved.x, qc.y - moved.y};
  return m;
}

std::vector<double> meanValueCoordinates(const Point& x, const std::vector<Point>& polygon) {
  const std::size_t n = polygon.size();
  std::vector<double> w(n, 0.0);
  std::vector<double> r(n), tanHalf(n);
  for (std::size_t i = 0; i < n; ++i) {
    r[i] = distance(x, polygon[i]);
    if (r[i] == 0) {
      w[i] = 1;
      return w;
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    const Point a{polygon[i].x - x.x, polygon[i].y - x.y};
    const Point b{polygon[(i + 1) % n].x - x.x, polygon[(i + 1) % n].y - x.y};
    const double cross = a.x * b.y - a.y * b.x, dot = a.x * b.x + a.y * b.y;
    const double angle = std::atan2(cross, dot);
    tanHalf[i] = std::tan(0.5 * angle);
  }
  double sum = 0;
  for (std::size_t i = 0; i < n; ++i) {
    w[i] = (tanHalf[(i + n - 1) % n] + tanHalf[i]) / r[i];
    sum += w[i];
  }
  if (sum != 0 && std::isfinite(sum)) {
    for (double& v : w) v /= sum;
  }
  return w;
}

Warp warpTemplate(const Template& t, const Ring& ring, const std::vector<std::size_t>& matched, int iterations) {
  const std::size_t nv = t.vertices.size(), nb = t.boundary.size();
  const std::vector<std::vector<Point>> arcs = ringArcPolylines(ring, matched);
  // Each boundary vertex's arc and its arc-length fraction along the template's arc.
  std::vector<int> arcOf(nv, -1);
  std::vector<double> fractionOf(nv, 0.0);
  std::vector<char> isCorner(nv, 0);
  std::size_t first = 0;
  while (first < nb && t.corners[first] == 0) ++first;
  const std::vector<double> lengths = templateArcs(t);
  {
    int arc = -1;
    double run = 0;
    for (std::size_t k = 0; k < nb; ++k) {
      const std::size_t i = (first + k) % nb;
      if (k > 0) run += distance(t.vertices[t.boundary[(i + nb - 1) % nb]], t.vertices[t.boundary[i]]);
      if (t.corners[i] != 0) {
        ++arc;
        run = 0;
        isCorner[t.boundary[i]] = 1;
      }
      arcOf[t.boundary[i]] = arc;
      fractionOf[t.boundary[i]] = lengths[arc] > 0 ? run / lengths[arc] : 0;
    }
  }
  // Initialisation: the boundary by arc-length scaling, the interior by mean
  // value coordinates with respect to the template's boundary.
  Warp w;
  w.positions.assign(nv, Point{});
  std::vector<Point> boundaryFrom, boundaryTo;
  for (std::size_t k = 0; k < nb; ++k) {
    const int v = t.boundary[k];
    w.positions[v] = alongPolyline(arcs[arcOf[v]], fractionOf[v]);
    boundaryFrom.push_back(t.vertices[v]);
    boundaryTo.push_back(w.positions[v]);
  }
  for (std::size_t v = 0; v < nv; ++v) {
    if (arcOf[v] >= 0) continue;
    const std::vector<double> mvc = meanValueCoordinates(t.vertices[v], boundaryFrom);
    Point p;
    for (std::size_t k = 0; k < nb; ++k) {
      p.x += mvc[k] * boundaryTo[k].x;
      p.y += mvc[k] * boundaryTo[k].y;
    }
    w.positions[v] = p;
  }
  // Alternating registration and regression.
  std::vector<Point> from, to;
  std::vector<Point> sum(nv);
  std::vector<double> weight(nv);
  auto registration = [&](bool accumulate) {
    double squared = 0;
    std::size_t count = 0;
    std::fill(sum.begin(), sum.end(), Point{});
    std::fill(weight.begin(), weight.end(), 0.0);
    for (const TemplatePart& part : t.parts) {
      from.clear();
      to.clear();
      for (int v : part.ring) {
        from.push_back(t.vertices[v]);
        to.push_back(w.positions[v]);
      }
      const AffineMap m = registerPart(from, to, part);
      const double wt = 1.0 / std::max(part.tolerance, 1e-6);
      for (std::size_t i = 0; i < part.ring.size(); ++i) {
        const Point q = m(from[i]);
        squared += (q.x - to[i].x) * (q.x - to[i].x) + (q.y - to[i].y) * (q.y - to[i].y);
        ++count;
        if (!accumulate) continue;
        sum[part.ring[i]].x += wt * q.x;
        sum[part.ring[i]].y += wt * q.y;
        weight[part.ring[i]] += wt;
      }
    }
    return count > 0 ? std::sqrt(squared / static_cast<double>(count)) : 0.0;
  };
  w.initialResidual = w.residual = registration(false);
  for (int it = 0; it < iterations; ++it) {
    registration(true);
    for (std::size_t v = 0; v < nv; ++v) {
      if (isCorner[v] || weight[v] == 0) continue;  // corners stay on the block's corners
      const Point p{sum[v].x / weight[v], sum[v].y / weight[v]};
      w.positions[v] = arcOf[v] >= 0 ? closestOnPolyline(arcs[arcOf[v]], p) : p;
    }
    w.iterations = it + 1;
    w.residual = registration(false);
  }
  return w;
}

}  // namespace parcelscope::generation::detail
