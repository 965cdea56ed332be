#include "parcelscope/io/StreetReader.h"

#include <cpl_error.h>
#include <ogr_spatialref.h>

#include <cmath>
#include <cstdlib>
#include <memory>
#include <set>

#include "OgrConvert.h"
#include "VectorInput.h"
#include "parcelscope/core/Error.h"

namespace parcelscope::io {

namespace {

using detail::lastGdalMessage;

// Appends the line strings of `g` (lines, multilines, collections of them;
// curves linearised). Returns false when `g` holds something else.
bool collectLines(const OGRGeometry& g, std::vector<std::unique_ptr<OGRLineString>>& out) {
  switch (wkbFlatten(g.getGeometryType())) {
    case wkbLineString:
      out.emplace_back(g.toLineString()->clone());
      return true;
    case wkbCircularString:
    case wkbCompoundCurve: {
      std::unique_ptr<OGRGeometry> linear(g.getLinearGeometry());
      return linear && collectLines(*linear, out);
    }
    case wkbMultiLineString:
    case wkbMultiCurve:
    case wkbGeometryCollection: {
      bool ok = true;
      for (const OGRGeometry* part : *g.toGeometryCollection()) ok = collectLines(*part, out) && ok;
      return ok;
    }
    default:
      return false;
  }
}

int fieldIndex(OGRLayer* layer, const std::string& name, const std::string& path, const std::string& flag) {
  if (name.empty()) return -1;
  const int i = layer->GetLayerDefn()->GetFieldIndex(name.c_str());
  if (i < 0) {
    throw inputError(path + ": layer " + layer->GetName() + " has no field '" + name + "' (" + flag + ")");
  }
  return i;
}

}  // namespace

StreetLayer readStreets(const StreetReadOptions& options, const LocalFrame* frame, const CrsInfo* targetCrs) {
  const std::string& path = options.path;
  auto ds = detail::openVector(path);
  detail::QuietErrors quiet;
  OGRLayer* layer = options.layer.empty() ? ds->GetLayer(0) : ds->GetLayerByName(options.layer.c_str());
  if (!layer) throw inputError(path + ": no layer named '" + options.layer + "'");
  StreetLayer result;
  result.path = path;
  result.layerName = layer->GetName();
  StreetReport& report = result.report;

  // Lines kept apart: their feature ids, under the main filter.
  std::set<GIntBig> apart;
  auto setFilter = [&](const std::string& filter, const std::string& flag) {
    CPLErrorReset();
    if (layer->SetAttributeFilter(filter.empty() ? nullptr : filter.c_str()) != OGRERR_NONE) {
      throw inputError(path + ": " + flag + " \"" + filter + "\" is not a valid filter on layer " + result.layerName +
                       " (" + lastGdalMessage() + ")");
    }
  };
  if (!options.noNodeWhere.empty()) {
    setFilter(options.where.empty() ? options.noNodeWhere : "(" + options.where + ") AND (" + options.noNodeWhere + ")",
              "--no-node-where");
    for (auto& f : *layer) apart.insert(f->GetFID());
  }
  setFilter(options.where, "--where");

  OGRSpatialReference overrideSrs;
  const OGRSpatialReference* srs =
      detail::layerCrs(path, *layer, options.crsOverride, overrideSrs, result.crs.overridden);
  // A street layer that declares no CRS, read with parcels, is taken to be in
  // theirs (its extent is checked against it below).
  OGRSpatialReference targetSrs;
  if (!srs && frame && targetCrs && !targetCrs->wkt.empty() &&
      targetSrs.importFromWkt(targetCrs->wkt.c_str()) == OGRERR_NONE) {
    targetSrs.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
    srs = &targetSrs;
  }
  // Widths in a projected CRS's unit become metres.
  const double widthUnit = srs && srs->IsProjected() && srs->GetLinearUnits() > 0 ? srs->GetLinearUnits() : 1.0;
  const int widthIndex = fieldIndex(layer, options.widthField, path, "--width-field");
  const int classIndex = fieldIndex(layer, options.classField, path, "--class-field");
  const int nameIndex = fieldIndex(layer, options.nameField, path, "--name-field");

  struct Read {
    std::unique_ptr<OGRGeometry> geometry;
    StreetFeature attributes;
  };
  std::vector<Read> read;
  detail::Envelope env;
  std::string wkb;
  CPLErrorReset();
  layer->ResetReading();
  for (auto& feature : *layer) {
    if (CPLGetLastErrorType() == CE_Failure || CPLGetLastErrorType() == CE_Fatal) break;
    ++report.features;
    OGRGeometry* g = feature->GetGeometryRef();
    if (!g || g->IsEmpty()) {
      ++report.nullOrEmpty;
      continue;
    }
    OGREnvelope e;
    g->getEnvelope(&e);
    if (!detail::coordinatesFinite(*g) || std::fabs(e.MinX) > 1e12 || std::fabs(e.MaxX) > 1e12 ||
        std::fabs(e.MinY) > 1e12 || std::fabs(e.MaxY) > 1e12) {
      ++report.nonFiniteSkipped;
      continue;
    }
    StreetFeature a;
    a.fid = feature->GetFID();
    a.noNode = apart.count(feature->GetFID()) > 0;
    if (widthIndex >= 0 && feature->IsFieldSetAndNotNull(widthIndex)) {
      // A text field is read as a number too: empty is no width, anything
      // else but a whole decimal number is an error (never a silent 0).
      const std::string text = feature->GetFieldAsString(widthIndex);
      const bool numeric = layer->GetLayerDefn()->GetFieldDefn(widthIndex)->GetType() != OFTString;
      double w = NAN;
      if (numeric) {
        w = feature->GetFieldAsDouble(widthIndex);
      } else if (text.find_first_not_of(" \t") != std::string::npos) {
        char* end = nullptr;
        w = std::strtod(text.c_str(), &end);
        while (end && (*end == ' ' || *end == '\t')) ++end;
        if (!end || *end != '\0') w = -1;
      }
      if ((numeric || !std::isnan(w)) && (!std::isfinite(w) || w < 0 || w * widthUnit > kMaxStreetWidth)) {
        throw inputError(path + ": feature " + std::to_string(a.fid) + " has width '" + text + "' in field '" +
                         options.widthField + "' (a width is a number of 0 or more, at most " +
                         std::to_string(static_cast<int>(kMaxStreetWidth)) + " m)");
      }
      if (!std::isnan(w)) a.width = w * widthUnit;
    }
    if (std::isnan(a.width) && classIndex >= 0 && feature->IsFieldSetAndNotNull(classIndex)) {
      const auto it = options.classWidths.find(feature->GetFieldAsString(classIndex));
      if (it != options.classWidths.end()) a.width = it->second;
    }
    if (nameIndex >= 0 && feature->IsFieldSetAndNotNull(nameIndex)) a.name = feature->GetFieldAsString(nameIndex);
    wkb.resize(static_cast<std::size_t>(g->WkbSize()));
    g->exportToWkb(wkbNDR, reinterpret_cast<unsigned char*>(wkb.data()), wkbVariantIso);
    a.key = hashBytes(wkb);
    env.merge(e);
    read.push_back({std::unique_ptr<OGRGeometry>(feature->StealGeometry()), std::move(a)});
  }
  if (CPLGetLastErrorType() == CE_Failure || CPLGetLastErrorType() == CE_Fatal) {
    throw inputError(path + ": reading layer " + result.layerName + " failed after " + std::to_string(report.features) +
                     " features (" + lastGdalMessage() + ")");
  }
  if (read.empty()) {
    throw inputError(path + ": layer " + result.layerName + " holds no line geometry (" +
                     std::to_string(report.features) + " features read)");
  }

  // The plane: the parcels' when given (the lines taken to their CRS first),
  // else the layer's own.
  std::unique_ptr<OGRCoordinateTransformation> toTarget;
  OGRSpatialReference target;
  if (frame) {
    result.frame = *frame;
    result.crs = targetCrs ? *targetCrs : CrsInfo{};
    // Coordinates that cannot be the parcels' (degrees against a projected
    // CRS, or the other way round) are refused, not drawn kilometres away.
    const bool degrees = env.looksLikeDegrees();
    if (frame->isGeographic() && !degrees && !(srs && srs->IsProjected())) {
      throw inputError(path + ": the street coordinates (x " + std::to_string(env.minX) + " to " +
                       std::to_string(env.maxX) +
                       ") cannot be degrees, the parcels' CRS; give the streets' CRS "
                       "in the file");
    }
    if (targetCrs && !targetCrs->wkt.empty() && srs) {
      target.importFromWkt(targetCrs->wkt.c_str());
      target.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
      if (!srs->IsSame(&target)) {
        toTarget.reset(OGRCreateCoordinateTransformation(srs, &target));
        if (!toTarget) {
          throw inputError(path + ": its CRS cannot be transformed to the parcels' CRS (" + lastGdalMessage() + ")");
        }
      }
    }
  } else {
    result.frame = detail::chooseFrame(path, srs, env, result.crs);
    if (srs) {
      char* wkt = nullptr;
      const char* wktOptions[] = {"FORMAT=WKT2_2018", nullptr};
      if (srs->exportToWkt(&wkt, wktOptions) == OGRERR_NONE && wkt) result.crs.wkt = wkt;
      CPLFree(wkt);
    }
  }

  for (Read& r : read) {
    if (toTarget && r.geometry->transform(toTarget.get()) != OGRERR_NONE) {
      throw inputError(path + ": feature " + std::to_string(r.attributes.fid) +
                       " cannot be transformed to the parcels' CRS");
    }
    std::vector<std::unique_ptr<OGRLineString>> parts;
    if (!collectLines(*r.geometry, parts)) {
      ++report.nonLinear;
      continue;
    }
    for (std::size_t p = 0; p < parts.size(); ++p) {
      StreetFeature s = r.attributes;
      s.key = partKey(r.attributes.key, static_cast<int>(p));
      for (int i = 0; i < parts[p]->getNumPoints(); ++i) {
        const double x = parts[p]->getX(i), y = parts[p]->getY(i);
        // In the parcels' frame: a line this far from them is another place
        // (a CRS wrong on one side), and the frame's projection folds there.
        if (const double d = frame ? frame->distanceFromCentre(x, y) : 0; !(d <= kMaxStreetReach)) {
          throw inputError(path + ": feature " + std::to_string(r.attributes.fid) + " lies " +
                           std::to_string(static_cast<long long>(std::isfinite(d) ? d / 1000 : -1)) +
                           " km from the parcels' centre, more than " +
                           std::to_string(static_cast<long long>(kMaxStreetReach / 1000)) +
                           " km: the streets are not where the parcels are (is each file's CRS right?)");
        }
        s.line.push_back(result.frame.toLocal(x, y));
      }
      if (s.line.size() < 2) continue;
      report.withWidth += !std::isnan(s.width);
      report.noNode += s.noNode;
      result.streets.push_back(std::move(s));
    }
  }
  report.lines = static_cast<std::int64_t>(result.streets.size());
  if (result.streets.empty()) {
    throw inputError(path + ": layer " + result.layerName + " holds no line (" + std::to_string(report.features) +
                     " features read, " + std::to_string(report.nonLinear) + " of them not lines)");
  }
  return result;
}

}  // namespace parcelscope::io
