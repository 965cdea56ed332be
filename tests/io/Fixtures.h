#pragma once
// Small GeoJSON/TopoJSON documents written inline, in lon/lat near Paris.
#include <sstream>
#include <string>

namespace parcelscope::test {

/// A closed square ring [[lon, lat], ...] of side `d` degrees at (lon, lat).
inline std::string squareRing(double lon, double lat, double d, bool clockwise = false) {
  std::ostringstream s;
  s.precision(12);
  if (!clockwise) {
    s << "[[" << lon << "," << lat << "],[" << lon + d << "," << lat << "],[" << lon + d << "," << lat + d << "],["
      << lon << "," << lat + d << "],[" << lon << "," << lat << "]]";
  } else {
    s << "[[" << lon << "," << lat << "],[" << lon << "," << lat + d << "],[" << lon + d << "," << lat + d << "],["
      << lon + d << "," << lat << "],[" << lon << "," << lat << "]]";
  }
  return s.str();
}

inline std::string feature(const std::string& geometry, int id) {
  return R"({"type":"Feature","properties":{"pid":)" + std::to_string(id) + R"(,"use":")" + (id % 2 ? "lot" : "road") +
         R"("},"geometry":)" + geometry + "}";
}

inline std::string collection(const std::string& features) {
  return R"({"type":"FeatureCollection","features":[)" + features + "]}";
}

/// Seven features exercising every cleaning rule (see ParcelReaderTest).
inline std::string quirksGeoJson() {
  const double lon = 2.35, lat = 48.85, d = 0.0001;
  const std::string a = R"({"type":"Polygon","coordinates":[)" + squareRing(lon, lat, d) + "]}";
  std::string f;
  f += feature(a, 1) + ",";                                              // plain lot
  f += R"({"type":"Feature","properties":{"pid":2},"geometry":null},)";  // null
  f += feature(R"({"type":"MultiPolygon","coordinates":[[)" + squareRing(lon + 2 * d, lat, d) + "],[" +
                   squareRing(lon + 4 * d, lat, d) + "]]}",
               3) +
       ",";  // two parts
  f +=
      feature(
          R"({"type":"Polygon","coordinates":[[[2.351,48.85],[2.3511,48.8501],[2.3511,48.85],[2.351,48.8501],[2.351,48.85]]]})",
          5) +
      ",";                   // bow-tie
  f += feature(a, 7) + ",";  // exact copy of the first
  f += feature(R"({"type":"Polygon","coordinates":[)" + squareRing(lon, lat + 2 * d, 3 * d) + "," +
                   squareRing(lon + d, lat + 3 * d, 0.5 * d, true) + "]}",
               9) +
       ",";                                                            // lot with a hole
  f += feature(R"({"type":"Point","coordinates":[2.35,48.85]})", 11);  // not a polygon
  return collection(f);
}

}  // namespace parcelscope::test
