#pragma once
// The local metric plane every analysis works in, and the way back to the
// input's coordinates.
//
// - Geographic input (lon/lat in degrees): a transverse Mercator projection
//   (GeographicLib, on the CRS's ellipsoid) whose central meridian and origin are
//   the centre of the data, so that scale error stays below 1e-6 within ~10 km.
// - Projected input: its own coordinates, converted to metres with the CRS's
//   linear unit and shifted so the centre of the data is the origin.
// Working near the origin keeps exact-arithmetic geometry (CGAL) accurate.
#include <memory>
#include <string>
#include <vector>

#include "parcelscope/core/Geometry.h"

namespace GeographicLib {
class TransverseMercator;
}

namespace parcelscope::io {

class LocalFrame {
public:
  /// Identity frame (metres, origin at 0, 0).
  LocalFrame();
  /// Transverse Mercator centred on (lon0, lat0) in degrees, on the ellipsoid
  /// with semi-major axis `a` (m) and flattening `f`. Input coordinates are in
  /// units of `degreesPerUnit` degrees (0.9 for grads).
  static LocalFrame geographic(double lon0, double lat0, double a = 6378137.0, double f = 1.0 / 298.257223563,
                               double degreesPerUnit = 1.0);
  /// Projected coordinates in a unit of `metresPerUnit` metres, origin moved to (x0, y0).
  static LocalFrame projected(double metresPerUnit, double x0, double y0);

  bool isGeographic() const { return tm_ != nullptr; }
  /// Input coordinates (x = easting or longitude) to local metres.
  Point toLocal(double x, double y) const;
  /// Local metres back to input coordinates.
  Point toSource(const Point& p) const;
  /// Where keys drawn from positions see local point `p`: its input
  /// coordinates in steps of about a centimetre (hundredths of a metre in a
  /// projected CRS, 1e-7 degree in a geographic one), the same whatever the
  /// frame's origin, which follows the data.
  Point keyPlace(const Point& p) const;
  /// The frame as numbers, and back: fromState(state()) converts exactly as
  /// this frame does (frames sent between processes).
  std::vector<double> state() const;
  static LocalFrame fromState(const std::vector<double>& state);
  /// Distance (m) from the frame's centre to input coordinates (x = easting or
  /// longitude): on the sphere of the mean Earth radius for a geographic frame,
  /// in the plane for a projected one.
  double distanceFromCentre(double x, double y) const;
  /// One line for logs and run records, e.g. "transverse Mercator at lon 2.35, lat 48.89".
  std::string describe() const;

private:
  std::shared_ptr<const GeographicLib::TransverseMercator> tm_;
  double lon0_ = 0, lat0_ = 0;  // geographic: centre in degrees
  double x0_ = 0, y0_ = 0;      // geographic: projected centre (m); projected: origin (units)
  double unit_ = 1.0;           // projected: metres per unit; geographic: degrees per unit
};

}  // namespace parcelscope::io
