#include "parcelscope/io/LocalFrame.h"

#include <GeographicLib/TransverseMercator.hpp>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace parcelscope::io {

LocalFrame::LocalFrame() = default;

LocalFrame LocalFrame::geographic(double lon0, double lat0, double a, double f, double degreesPerUnit) {
  LocalFrame frame;
  frame.unit_ = degreesPerUnit;
  frame.tm_ = std::make_shared<GeographicLib::TransverseMercator>(a, f, 1.0);
  frame.lon0_ = lon0;
  frame.lat0_ = lat0;
  double x = 0, y = 0;
  frame.tm_->Forward(lon0, lat0, lon0, x, y);
  frame.x0_ = x;
  frame.y0_ = y;
  return frame;
}

LocalFrame LocalFrame::projected(double metresPerUnit, double x0, double y0) {
  LocalFrame frame;
  frame.unit_ = metresPerUnit;
  frame.x0_ = x0;
  frame.y0_ = y0;
  return frame;
}

Point LocalFrame::toLocal(double x, double y) const {
  if (tm_) {
    double e = 0, n = 0;
    tm_->Forward(lon0_, y * unit_, x * unit_, e, n);
    return {e - x0_, n - y0_};
  }
  return {(x - x0_) * unit_, (y - y0_) * unit_};
}

Point LocalFrame::toSource(const Point& p) const {
  if (tm_) {
    double lat = 0, lon = 0;
    tm_->Reverse(lon0_, p.x + x0_, p.y + y0_, lat, lon);
    return {lon / unit_, lat / unit_};
  }
  return {p.x / unit_ + x0_, p.y / unit_ + y0_};
}

Point LocalFrame::keyPlace(const Point& p) const {
  const Point s = toSource(p);
  const double scale = tm_ ? unit_ * 1e7 : unit_ * 100;
  return {s.x * scale, s.y * scale};
}

double LocalFrame::distanceFromCentre(double x, double y) const {
  if (tm_) {
    // Haversine: the transverse Mercator is no guide this far (it folds).
    constexpr double kRadian = M_PI / 180, kEarthRadius = 6371008.8;
    const double lat = y * unit_ * kRadian, lat0 = lat0_ * kRadian, dLon = (x * unit_ - lon0_) * kRadian;
    const double h =
        std::pow(std::sin((lat - lat0) / 2), 2) + std::cos(lat) * std::cos(lat0) * std::pow(std::sin(dLon / 2), 2);
    return 2 * kEarthRadius * std::asin(std::min(1.0, std::sqrt(h)));
  }
  return std::hypot((x - x0_) * unit_, (y - y0_) * unit_);
}

std::vector<double> LocalFrame::state() const {
  if (tm_) return {1.0, lon0_, lat0_, tm_->EquatorialRadius(), tm_->Flattening(), unit_};
  return {0.0, x0_, y0_, unit_};
}

LocalFrame LocalFrame::fromState(const std::vector<double>& s) {
  if (s.size() == 6 && s[0] == 1.0) return geographic(s[1], s[2], s[3], s[4], s[5]);
  if (s.size() == 4 && s[0] == 0.0) return projected(s[3], s[1], s[2]);
  throw std::invalid_argument("LocalFrame::fromState: not a frame's state");
}

std::string LocalFrame::describe() const {
  std::ostringstream s;
  s.precision(10);
  if (tm_) {
    s << "transverse Mercator centred on lon " << lon0_ << ", lat " << lat0_;
  } else {
    s << "input CRS, " << unit_ << " m per unit, origin at (" << x0_ << ", " << y0_ << ")";
  }
  return s.str();
}

}  // namespace parcelscope::io
