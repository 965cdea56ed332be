#pragma once
// Randomised block shapes for the subdivision property tests: convex, star,
// L, U, comb, holes and near-degenerate, at random orientations, every fifth
// far from the origin.
#include <cmath>
#include <random>

#include "TestUtil.h"
#include "parcelscope/core/Geometry.h"
#include "parcelscope/generation/ObbSubdivision.h"

namespace parcelscope::test {

constexpr int kShapeKinds = 7;

inline Polygon rotateShift(Polygon p, double angle, double dx, double dy) {
  const double c = std::cos(angle), s = std::sin(angle);
  auto f = [&](Point q) { return Point{dx + q.x * c - q.y * s, dy + q.x * s + q.y * c}; };
  for (Point& q : p.outer) q = f(q);
  for (Ring& h : p.holes)
    for (Point& q : h) q = f(q);
  return p;
}

inline Polygon randomShape(std::mt19937_64& rng, int kind) {
  std::uniform_real_distribution<double> u(0, 1);
  const double w = 60 + 200 * u(rng), h = 40 + 120 * u(rng);
  Polygon p;
  switch (kind) {
    case 0: {  // convex
      std::vector<Point> pts;
      for (int i = 0; i < 12; ++i) pts.push_back({w * u(rng), h * u(rng)});
      p.outer = convexHull(pts);
      break;
    }
    case 1: {  // star-shaped concave
      const int n = 7 + static_cast<int>(u(rng) * 10);
      for (int i = 0; i < n; ++i) {
        const double a = 2 * M_PI * i / n, r = 0.5 + 0.5 * u(rng);
        p.outer.push_back({w * r * std::cos(a), h * r * std::sin(a)});
      }
      break;
    }
    case 2: {  // L
      const double a = w * (0.3 + 0.4 * u(rng)), b = h * (0.3 + 0.4 * u(rng));
      p = poly({{0, 0}, {w, 0}, {w, b}, {a, b}, {a, h}, {0, h}});
      break;
    }
    case 3: {  // U
      const double t = w * (0.2 + 0.1 * u(rng)), b = h * (0.2 + 0.3 * u(rng));
      p = poly({{0, 0}, {w, 0}, {w, h}, {w - t, h}, {w - t, b}, {t, b}, {t, h}, {0, h}});
      break;
    }
    case 4: {  // comb
      const int teeth = 3 + static_cast<int>(u(rng) * 3);
      const double tw = w / (2 * teeth - 1), base = h * 0.3;
      p.outer = {{0, 0}, {w, 0}};
      for (int i = teeth - 1; i >= 0; --i) {
        const double x0 = 2 * i * tw, x1 = x0 + tw;
        p.outer.push_back({x1, base});
        p.outer.push_back({x1, h});
        p.outer.push_back({x0, h});
        p.outer.push_back({x0, base});
      }
      p.outer.erase(p.outer.begin() + 2);  // (w, base) duplicates the last tooth's corner
      p.outer.pop_back();                  // (0, base) lies on the first edge back to (0, 0)
      break;
    }
    case 5: {  // holes
      p = rect(0, 0, w, h);
      p.holes.push_back({{0.2 * w, 0.3 * h}, {0.2 * w, 0.7 * h}, {0.45 * w, 0.7 * h}, {0.45 * w, 0.3 * h}});
      if (u(rng) < 0.5)
        p.holes.push_back({{0.6 * w, 0.4 * h}, {0.6 * w, 0.6 * h}, {0.8 * w, 0.6 * h}, {0.8 * w, 0.4 * h}});
      break;
    }
    default: {  // near-degenerate: a rectangle with micro-edges and almost collinear vertices
      p.outer = {{0, 0}, {w * 0.5, 1e-7}, {w * 0.5 + 1e-6, 0}, {w, 0}, {w, h}, {w * 0.3, h + 1e-5}, {0, h}};
      break;
    }
  }
  normalise(p);
  // Random orientation; every fifth shape far from the origin.
  const double far = (kind + static_cast<int>(u(rng) * 5)) % 5 == 0 ? 3e6 : 0.0;
  return rotateShift(p, 2 * M_PI * u(rng), far + 500 * u(rng), far - 500 * u(rng));
}

// Size bounds scaled to a block of area `a`: 3 to 23 parcels' worth of A_max,
// random omega; street-access preference left at its default.
inline generation::ObbParameters randomBounds(std::mt19937_64& rng, double a) {
  std::uniform_real_distribution<double> u(0, 1);
  generation::ObbParameters p;
  p.aMax = a / (3 + 20 * u(rng));
  p.aMin = p.aMax * (0.15 + 0.3 * u(rng));
  p.wMin = std::sqrt(p.aMin) * 0.3;
  p.wMax = std::sqrt(p.aMax) * (1.0 + u(rng));
  p.omega = u(rng);
  return p;
}

/// Sanitizer builds run exact arithmetic about 20x slower: the property tests
/// use a fifth of their shapes there.
#if defined(__SANITIZE_ADDRESS__)
constexpr int kSanitizerDivisor = 5;
#else
constexpr int kSanitizerDivisor = 1;
#endif

}  // namespace parcelscope::test
