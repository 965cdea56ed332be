#include "parcelscope/io/LocalFrame.h"

#include <gtest/gtest.h>

#include <GeographicLib/Geodesic.hpp>
#include <cmath>

namespace parcelscope::io {
namespace {

TEST(LocalFrame, GeographicRoundTripIsExactToMicrodegrees) {
  const LocalFrame f = LocalFrame::geographic(-71.1, 42.37);
  for (auto [lon, lat] : {std::pair{-71.1, 42.37}, {-71.16, 42.35}, {-71.06, 42.41}}) {
    const Point local = f.toLocal(lon, lat);
    const Point back = f.toSource(local);
    EXPECT_NEAR(back.x, lon, 1e-11);
    EXPECT_NEAR(back.y, lat, 1e-11);
  }
  const Point origin = f.toLocal(-71.1, 42.37);
  EXPECT_NEAR(origin.x, 0, 1e-9);
  EXPECT_NEAR(origin.y, 0, 1e-9);
}

TEST(LocalFrame, GeographicDistancesMatchGeodesicsWithinTenKilometres) {
  const LocalFrame f = LocalFrame::geographic(2.35, 48.85);
  const auto& g = GeographicLib::Geodesic::WGS84();
  for (auto [lon, lat] : {std::pair{2.40, 48.88}, {2.30, 48.80}, {2.45, 48.85}}) {
    double s12 = 0;
    g.Inverse(48.85, 2.35, lat, lon, s12);
    const Point p = f.toLocal(lon, lat);
    EXPECT_NEAR(std::hypot(p.x, p.y) / s12, 1.0, 2e-6);
  }
}

TEST(LocalFrame, ProjectedConvertsUnitsAndShiftsOrigin) {
  const LocalFrame f = LocalFrame::projected(0.3048006096, 1195000, 565000);
  const Point p = f.toLocal(1195100, 565000);
  EXPECT_NEAR(p.x, 30.48006096, 1e-9);
  EXPECT_NEAR(p.y, 0, 1e-12);
  const Point back = f.toSource(p);
  EXPECT_NEAR(back.x, 1195100, 1e-6);
}

}  // namespace
}  // namespace parcelscope::io
