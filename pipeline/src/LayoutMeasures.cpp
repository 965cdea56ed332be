#include "parcelscope/pipeline/LayoutMeasures.h"

#include <algorithm>

#include "parcelscope/analysis/RoadGraph.h"
#include "parcelscope/pipeline/StreetsJob.h"

namespace parcelscope::pipeline {

LayoutContext layoutContext(const ObservedData& observed) {
  LayoutContext c;
  const analysis::ObservedAnalysis& a = observed.analysis;
  std::vector<double> boundaries;
  for (const Block& block : a.blocks) {
    double length = 0;
    for (const Polygon& part : block.parts) {
      c.blockArea += area(part);
      length += ringLength(part.outer);
    }
    boundaries.push_back(length);
  }
  c.blocks = static_cast<std::int64_t>(a.blocks.size());
  if (!boundaries.empty()) {
    c.boundaryMin = *std::min_element(boundaries.begin(), boundaries.end());
    c.boundaryMax = *std::max_element(boundaries.begin(), boundaries.end());
    for (double b : boundaries) c.boundaryAvg += b / static_cast<double>(boundaries.size());
  }
  c.studyArea = c.blockArea;
  if (observed.streets) {
    const analysis::RoadGraph& g = observed.streets->graph;
    c.streetArea = 0;
    for (const Polygon& p : analysis::streetSurface(g)) c.streetArea += area(p);
    c.studyArea += c.streetArea;
    c.streetLength = 0;
    for (const analysis::RoadEdge& e : g.edges) {
      if (e.boundary) continue;
      for (std::size_t i = 0; i + 1 < e.line.size(); ++i) {
        c.streetLength += norm(e.line[i + 1].x - e.line[i].x, e.line[i + 1].y - e.line[i].y);
      }
    }
    // Nodes only the study area's boundary lines reach are no streets' ends.
    std::vector<int> degree(g.nodes.size(), 0);
    for (const analysis::RoadEdge& e : g.edges) {
      if (e.boundary) continue;
      ++degree[static_cast<std::size_t>(e.from)];
      ++degree[static_cast<std::size_t>(e.to)];
    }
    for (int d : degree) {
      c.intersections += d >= 3;
      c.deadEnds += d == 1;
    }
  }
  return c;
}

namespace {

LayoutMeasures shared(const LayoutContext& c, const std::string& layout) {
  LayoutMeasures m;
  m.layout = layout;
  const double km2 = c.studyArea / 1e6;
  if (std::isfinite(c.streetArea) && c.studyArea > 0) m.streetShare = 100 * c.streetArea / c.studyArea;
  m.blocksPerKm2 = km2 > 0 ? static_cast<double>(c.blocks) / km2 : NAN;
  m.boundaryMin = c.boundaryMin;
  m.boundaryAvg = c.boundaryAvg;
  m.boundaryMax = c.boundaryMax;
  if (std::isfinite(c.streetLength) && km2 > 0) {
    m.streetLengthPerKm2 = c.streetLength / 1e3 / km2;
    m.intersectionsPerKm2 = static_cast<double>(c.intersections) / km2;
    m.deadEndsPerKm2 = static_cast<double>(c.deadEnds) / km2;
  }
  return m;
}

// The parcel part of a row from the parcels' metrics.
void addParcels(LayoutMeasures& m, const LayoutContext& c, const std::vector<const analysis::ParcelMetrics*>& parcels) {
  double inParcels = 0;
  for (const analysis::ParcelMetrics* p : parcels) {
    inParcels += p->area;
    m.meanPAngle += p->pAngle / static_cast<double>(parcels.size());
    m.meanPArea += p->pArea / static_cast<double>(parcels.size());
  }
  if (c.studyArea > 0) {
    m.parcelShare = 100 * inParcels / c.studyArea;
    m.otherShare = 100 * std::max(0.0, c.blockArea - inParcels) / c.studyArea;
    m.parcelsPerKm2 = static_cast<double>(parcels.size()) / (c.studyArea / 1e6);
  }
}

}  // namespace

LayoutMeasures observedLayout(const LayoutContext& context, const ObservedData& observed) {
  LayoutMeasures m = shared(context, "observed");
  std::vector<const analysis::ParcelMetrics*> lots;
  for (std::size_t i = 0; i < observed.analysis.blockOf.size(); ++i) {
    if (observed.analysis.blockOf[i] >= 0) lots.push_back(&observed.analysis.metrics[i]);
  }
  addParcels(m, context, lots);
  return m;
}

LayoutMeasures generatedLayout(const LayoutContext& context, const GeneratedParcels& generated,
                               const std::string& style) {
  LayoutMeasures m = shared(context, style);
  std::vector<const analysis::ParcelMetrics*> parcels;
  for (std::size_t i = 0; i < generated.metrics.size(); ++i) {
    if (!generated.isUnassigned(i)) parcels.push_back(&generated.metrics[i]);
  }
  addParcels(m, context, parcels);
  return m;
}

Table layoutTable(const std::vector<LayoutMeasures>& rows) {
  Table t;
  using T = Column::Type;
  t.columns = {{"layout", T::String, ""},
               {"streets_pct", T::Real, "%"},
               {"parcels_pct", T::Real, "%"},
               {"other_pct", T::Real, "%"},
               {"blocks_per_km2", T::Real, "1/km2"},
               {"block_boundary_max", T::Real, "m"},
               {"block_boundary_avg", T::Real, "m"},
               {"block_boundary_min", T::Real, "m"},
               {"street_length_per_km2", T::Real, "km/km2"},
               {"intersections_per_km2", T::Real, "1/km2"},
               {"dead_ends_per_km2", T::Real, "1/km2"},
               {"parcels_per_km2", T::Real, "1/km2"},
               {"mean_p_angle", T::Real, "deg"},
               {"mean_p_area", T::Real, ""}};
  for (const LayoutMeasures& m : rows) {
    t.rows.push_back({m.layout, m.streetShare, m.parcelShare, m.otherShare, m.blocksPerKm2, m.boundaryMax,
                      m.boundaryAvg, m.boundaryMin, m.streetLengthPerKm2, m.intersectionsPerKm2, m.deadEndsPerKm2,
                      m.parcelsPerKm2, m.meanPAngle, m.meanPArea});
  }
  return t;
}

}  // namespace parcelscope::pipeline
