#include "parcelscope/pipeline/Inspect.h"

#include <cmath>
#include <cstdio>

#include "parcelscope/analysis/Comparison.h"
#include "parcelscope/core/Error.h"
#include "parcelscope/core/Keys.h"

namespace parcelscope::pipeline {

namespace {

bool inside(const Polygon& shape, const Point& p) {
  const Box box = bounds(shape);
  if (p.x < box.minX || p.x > box.maxX || p.y < box.minY || p.y > box.maxY) return false;
  return pointInPolygon(p, shape);
}

NamedValues metricsOf(const analysis::ParcelMetrics& m) {
  NamedValues out;
  for (const analysis::ParcelQuantity& q : analysis::parcelMetrics()) {
    const double v = q.value(m);
    if (q.integer && std::isfinite(v)) {
      out.emplace_back(q.name, static_cast<std::int64_t>(std::llround(v)));
    } else {
      out.emplace_back(q.name, v);
    }
  }
  return out;
}

NamedValues row(const Table& table, std::size_t index) {
  NamedValues out;
  for (std::size_t c = 0; c < table.columns.size(); ++c) out.emplace_back(table.columns[c].name, table.rows[index][c]);
  return out;
}

Json jsonOf(const Value& v) {
  if (const auto* i = std::get_if<std::int64_t>(&v)) return Json(static_cast<long long>(*i));
  if (const auto* d = std::get_if<double>(&v)) return std::isfinite(*d) ? Json(*d) : Json(nullptr);
  return Json(std::get<std::string>(v));
}

Json objectOf(const NamedValues& values) {
  Json out = Json::object();
  for (const auto& [name, v] : values) out.set(name, jsonOf(v));
  return out;
}

}  // namespace

int parcelAt(const ObservedData& data, const Point& p) {
  const auto& parcels = data.layer.parcels;
  for (std::size_t i = 0; i < parcels.size(); ++i) {
    if (inside(parcels[i].shape, p)) return static_cast<int>(i);
  }
  return -1;
}

int generatedParcelAt(const GeneratedParcels& g, const Point& p) {
  for (std::size_t i = 0; i < g.parcels.size(); ++i) {
    if (inside(g.parcels[i], p)) return static_cast<int>(i);
  }
  return -1;
}

ParcelInspection inspectParcel(const ObservedData& data, int parcel) {
  const std::size_t i = static_cast<std::size_t>(parcel);
  ParcelInspection out;
  out.path = data.layer.path;
  // The identity columns of parcels.csv.
  static const char* roles[] = {"lot", "right_of_way_holes", "right_of_way_network"};
  const Parcel& p = data.layer.parcels[i];
  const int blockId = data.analysis.blockOf[i];
  out.attributes = {{"parcel_id", std::int64_t(parcel)},
                    {"parcel_key", keyText(parcelKey(p))},
                    {"source_fid", std::int64_t(p.sourceFid)},
                    {"part", std::int64_t(p.part)},
                    {"block_id", std::int64_t(blockId)},
                    {"block_key", blockId >= 0 ? keyText(data.analysis.blocks[static_cast<std::size_t>(blockId)].key)
                                               : std::string()},
                    {"role", std::string(roles[static_cast<int>(data.analysis.rightOfWay[i])])},
                    {"stack_count", std::int64_t(p.stackCount)},
                    {"repaired", std::int64_t(p.repaired)}};
  out.metrics = metricsOf(data.analysis.metrics[i]);
  if (blockId >= 0) out.block = row(analysis::blockTable(data.analysis), static_cast<std::size_t>(blockId));
  return out;
}

ParcelInspection inspectGeneratedParcel(const GeneratedParcels& g, int parcel) {
  ParcelInspection out;
  out.path = g.source ? g.source->path : std::string();
  std::int64_t entry = -1, index = -1;
  for (std::size_t b = 0; b < g.blocks.size() && entry < 0; ++b) {
    const auto& members = g.blocks[b].parcels;
    for (std::size_t k = 0; k < members.size(); ++k) {
      if (members[k] == parcel) {
        entry = static_cast<std::int64_t>(b);
        index = static_cast<std::int64_t>(k);
        break;
      }
    }
  }
  out.attributes.emplace_back("parcel_id", std::int64_t(parcel));
  if (entry >= 0) {
    const std::size_t e = static_cast<std::size_t>(entry);
    out.attributes.emplace_back("parcel_key", keyText(g.blockKeys[e]) + "-" + std::to_string(index));
    out.attributes.emplace_back("block_id", g.blockIds[e]);
    out.attributes.emplace_back("block_key", keyText(g.blockKeys[e]));
    out.attributes.emplace_back("style", e < g.blockStyles.size() ? g.blockStyles[e] : std::string());
  }
  out.attributes.emplace_back("role",
                              std::string(g.isUnassigned(static_cast<std::size_t>(parcel)) ? "unassigned" : "parcel"));
  out.metrics = metricsOf(g.metrics[static_cast<std::size_t>(parcel)]);
  return out;
}

ParcelInspection inspect(const InspectRequest& request, const ProgressFn& progress) {
  const ObservedData data = loadObserved(request.input, request.parameters, progress);
  const Point p = data.layer.frame.toLocal(request.x, request.y);
  const int parcel = std::isfinite(p.x) && std::isfinite(p.y) ? parcelAt(data, p) : -1;
  if (parcel < 0) {
    char at[96];
    std::snprintf(at, sizeof at, "%.10g,%.10g", request.x, request.y);
    throw inputError(request.input.path + ": no parcel at " + at + " (coordinates of the input's CRS, " +
                     data.layer.crs.name + ")");
  }
  return inspectParcel(data, parcel);
}

std::string valueText(const Value& v) {
  if (const auto* i = std::get_if<std::int64_t>(&v)) return std::to_string(*i);
  if (const auto* d = std::get_if<double>(&v)) {
    if (std::isnan(*d)) return "nan";
    char text[64];
    std::snprintf(text, sizeof text, "%.10g", *d);
    return text;
  }
  return std::get<std::string>(v);
}

std::string inspectionText(const ParcelInspection& inspection) {
  std::string out = "file: " + inspection.path + "\n";
  for (const auto& [name, v] : inspection.attributes) out += name + ": " + valueText(v) + "\n";
  for (const auto& [name, v] : inspection.metrics) out += name + ": " + valueText(v) + "\n";
  for (const auto& [name, v] : inspection.block) out += "block." + name + ": " + valueText(v) + "\n";
  return out;
}

Json inspectionJson(const ParcelInspection& inspection) {
  return Json::object()
      .set("file", inspection.path)
      .set("parcel", objectOf(inspection.attributes))
      .set("metrics", objectOf(inspection.metrics))
      .set("block", inspection.block.empty() ? Json(nullptr) : objectOf(inspection.block));
}

}  // namespace parcelscope::pipeline
