#pragma once
// ParcelScope polygons as OGR geometries, for tests that compare results with
// GDAL/GEOS directly (the library's own conversion is private to io/), and
// written layers read back with GDAL.
#include <gdal_priv.h>
#include <gtest/gtest.h>
#include <ogr_geometry.h>
#include <ogrsf_frmts.h>

#include <cstdint>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "parcelscope/core/Geometry.h"

namespace parcelscope::test {

inline std::unique_ptr<OGRPolygon> toOgr(const Polygon& p) {
  auto ring = [](const Ring& r) {
    auto o = std::make_unique<OGRLinearRing>();
    for (const Point& v : r) o->addPoint(v.x, v.y);
    o->addPoint(r.front().x, r.front().y);
    return o;
  };
  auto polygon = std::make_unique<OGRPolygon>();
  polygon->addRingDirectly(ring(p.outer).release());
  for (const Ring& h : p.holes) polygon->addRingDirectly(ring(h).release());
  return polygon;
}

inline std::unique_ptr<OGRMultiPolygon> toOgr(const std::vector<Polygon>& parts) {
  auto multi = std::make_unique<OGRMultiPolygon>();
  for (const Polygon& p : parts) multi->addGeometryDirectly(toOgr(p).release());
  return multi;
}

/// The polygons of an OGR polygon or multipolygon, rings as written (the
/// closing vertex left out, nothing reordered or cleaned), for comparing
/// written geometries vertex for vertex (sameVertices).
inline std::vector<Polygon> fromOgr(const OGRGeometry* g) {
  std::vector<Polygon> parts;
  if (!g) return parts;
  auto ring = [](const OGRLinearRing* r) {
    Ring out;
    const int n = r->getNumPoints();
    for (int i = 0; i + 1 < n; ++i) out.push_back({r->getX(i), r->getY(i)});
    return out;
  };
  auto polygon = [&](const OGRPolygon* p) {
    Polygon out;
    if (p->getExteriorRing()) out.outer = ring(p->getExteriorRing());
    for (int h = 0; h < p->getNumInteriorRings(); ++h) out.holes.push_back(ring(p->getInteriorRing(h)));
    parts.push_back(std::move(out));
  };
  const OGRwkbGeometryType type = wkbFlatten(g->getGeometryType());
  if (type == wkbPolygon) {
    polygon(g->toPolygon());
  } else if (type == wkbMultiPolygon) {
    for (const OGRPolygon* p : *g->toMultiPolygon()) polygon(p);
  }
  return parts;
}

/// A vector file opened read-only with GDAL (null when it cannot be opened).
inline GDALDatasetUniquePtr openVectorFile(const std::string& path) {
  GDALAllRegister();
  return GDALDatasetUniquePtr(GDALDataset::Open(path.c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY));
}

/// What a written polygon layer must hold besides valid polygons.
struct LayerExpectation {
  std::string layer;                         ///< the layer's name; "" for the file's first layer
  std::vector<std::string> fields;           ///< fields that must be present
  const OGRSpatialReference* crs = nullptr;  ///< the layer's CRS must be this one; nullptr: not checked
};

/// A written layer read back with GDAL: the features, in the file's order, and
/// each one's polygons as written.
struct ReadLayer {
  std::vector<OGRFeatureUniquePtr> features;
  std::vector<std::vector<Polygon>> geometries;
};

/// Reads a written polygon layer back with GDAL and checks it as a user's GIS
/// would see it: `expectedCount` features, each with a non-empty polygon or
/// multipolygon geometry that GEOS finds valid (OGRGeometry::IsValid) and of
/// positive area (the whole and each polygon), the expected fields present, and
/// the expected CRS. Returns what it read (empty when the file cannot be read).
inline ReadLayer expectValidPolygonLayer(const std::string& path, std::int64_t expectedCount,
                                         const LayerExpectation& expect = {}) {
  ReadLayer read;
  EXPECT_TRUE(OGRGeometryFactory::haveGEOS()) << "GDAL without GEOS cannot check validity";
  auto ds = openVectorFile(path);
  if (!ds) {
    ADD_FAILURE() << path << " cannot be opened with GDAL";
    return read;
  }
  OGRLayer* layer = expect.layer.empty() ? ds->GetLayer(0) : ds->GetLayerByName(expect.layer.c_str());
  if (!layer) {
    ADD_FAILURE() << path << " has no layer '" << expect.layer << "'";
    return read;
  }
  EXPECT_EQ(layer->GetFeatureCount(), expectedCount) << path;
  for (const std::string& field : expect.fields) {
    EXPECT_GE(layer->GetLayerDefn()->GetFieldIndex(field.c_str()), 0) << path << " has no field " << field;
  }
  if (expect.crs) {
    const OGRSpatialReference* crs = layer->GetSpatialRef();
    EXPECT_TRUE(crs && crs->IsSame(expect.crs))
        << path << ": CRS " << (crs ? crs->GetName() : "(none)") << ", expected " << expect.crs->GetName();
  }
  int bad = 0;
  std::ostringstream first;  // the first few bad features, named
  auto reject = [&](const OGRFeature& f, const std::string& why) {
    if (++bad <= 5) first << "\n  feature " << f.GetFID() << ": " << why;
  };
  layer->ResetReading();
  for (OGRFeatureUniquePtr f(layer->GetNextFeature()); f; f.reset(layer->GetNextFeature())) {
    const OGRGeometry* g = f->GetGeometryRef();
    read.geometries.push_back(fromOgr(g));
    if (!g || g->IsEmpty()) {
      reject(*f, "no geometry");
    } else if (wkbFlatten(g->getGeometryType()) != wkbPolygon && wkbFlatten(g->getGeometryType()) != wkbMultiPolygon) {
      reject(*f, std::string("a ") + g->getGeometryName() + ", not a polygon");
    } else if (!g->IsValid()) {
      reject(*f, "invalid (OGRGeometry::IsValid)");
    } else {
      bool positive = true;
      for (const Polygon& part : read.geometries.back()) {
        positive = positive && !part.outer.empty() && toOgr(part)->get_Area() > 0;
      }
      const double a =
          wkbFlatten(g->getGeometryType()) == wkbPolygon ? g->toPolygon()->get_Area() : g->toMultiPolygon()->get_Area();
      if (!(a > 0) || !positive) {
        std::ostringstream why;
        why << "area " << a << (positive ? "" : " (a polygon of no area)");
        reject(*f, why.str());
      }
    }
    read.features.push_back(OGRFeatureUniquePtr(f.release()));
  }
  EXPECT_EQ(static_cast<std::int64_t>(read.features.size()), expectedCount) << path << ": features read";
  EXPECT_EQ(bad, 0) << path << ": " << bad << " of " << read.features.size()
                    << " features are not valid polygons of positive area" << first.str();
  return read;
}

/// The CRS of a file's first layer (empty when it has none or cannot be read).
inline OGRSpatialReference layerCrs(const std::string& path) {
  OGRSpatialReference crs;
  auto ds = openVectorFile(path);
  if (ds && ds->GetLayerCount() > 0 && ds->GetLayer(0)->GetSpatialRef()) crs = *ds->GetLayer(0)->GetSpatialRef();
  return crs;
}

/// Two written layers hold the same geometries, feature for feature, vertex
/// for vertex (exact comparison).
inline ::testing::AssertionResult sameGeometries(const ReadLayer& a, const ReadLayer& b) {
  if (a.geometries.size() != b.geometries.size()) {
    return ::testing::AssertionFailure() << a.geometries.size() << " features against " << b.geometries.size();
  }
  for (std::size_t i = 0; i < a.geometries.size(); ++i) {
    const auto& x = a.geometries[i];
    const auto& y = b.geometries[i];
    if (x.size() != y.size()) return ::testing::AssertionFailure() << "feature " << i << ": parts differ";
    for (std::size_t k = 0; k < x.size(); ++k) {
      if (!sameVertices(x[k], y[k])) return ::testing::AssertionFailure() << "feature " << i << ": vertices differ";
    }
  }
  return ::testing::AssertionSuccess();
}

}  // namespace parcelscope::test
