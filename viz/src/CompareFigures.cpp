#include "parcelscope/viz/CompareFigures.h"

#include <sstream>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iterator>
#include <numeric>
#include <optional>

#include "parcelscope/core/Error.h"
#include "parcelscope/io/OutputDirectory.h"

namespace parcelscope::viz {

namespace {

double value(const CompareRequest& request, const std::string& name) { return pipeline::compareValue(request, name); }

std::string generatedName(const CompareRequest& request, const CompareResult& r) {
  std::string name = "procedural (" + request.style + ", seed " + std::to_string(r.generated.seed);
  if (!request.overrides.empty()) name += ", " + std::to_string(request.overrides.size()) + " blocks overridden";
  return name + ")";
}

// The generated parcels on a map: land a style left unassigned has no value
// (drawn in the no-value grey), the others their value of `q`.
void fillGenerated(MapPanel& panel, const pipeline::GeneratedParcels& g, const analysis::ParcelQuantity& q) {
  for (std::size_t i = 0; i < g.parcels.size(); ++i) {
    panel.shapes.push_back(&g.parcels[i]);
    panel.values.push_back(g.isUnassigned(i) ? std::nan("") : q.value(g.metrics[i]));
  }
}

// "N parcels", with the unassigned land counted apart.
std::string generatedCount(const pipeline::GeneratedParcels& g) {
  const std::size_t unassigned = static_cast<std::size_t>(g.unassignedParcels);
  return std::to_string(g.parcels.size() - unassigned) + " parcels" +
         (unassigned > 0 ? ", " + std::to_string(unassigned) + " unassigned (grey)" : std::string());
}

// The values of `q` of the generated parcels, unassigned land left out.
std::vector<double> generatedSample(const pipeline::GeneratedParcels& g, const analysis::ParcelQuantity& q) {
  if (g.unassigned.empty()) return analysis::quantitySample(g.metrics, q);
  std::vector<analysis::ParcelMetrics> assigned;
  for (std::size_t i = 0; i < g.metrics.size(); ++i) {
    if (!g.unassigned[i]) assigned.push_back(g.metrics[i]);
  }
  return analysis::quantitySample(assigned, q);
}

std::string inputName(const CompareRequest& request) {
  return std::filesystem::path(request.input.path).filename().string();
}

// Histograms, figures and extra files drawn by compare, by quantity name.
bool drawnAnyway(const std::string& quantity, bool histogram) {
  if (histogram) return quantity == "area" || quantity == "width" || quantity == "aspect_ratio";
  return quantity == "aspect_ratio";
}

}  // namespace

ColourScale quantityScale(const CompareResult& r, const CompareRequest& request, const std::string& quantity) {
  const analysis::ParcelQuantity& q = analysis::parcelQuantity(quantity);
  ColourScale scale;
  char title[160];
  if (q.name == "aspect_ratio") {
    scale.kind = ColourScale::Kind::RedToGreen;
    scale.minimum = 1;
    scale.maximum = value(request, "map-aspect-ratio-max");
    std::snprintf(title, sizeof title, "Aspect ratio (length / width; %g and above drawn green)", scale.maximum);
    scale.title = title;
    return scale;
  }
  scale.kind = ColourScale::Kind::Sequential;
  scale.title = q.title;
  scale.title[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(scale.title[0])));
  if (q.name == "street_access") {
    scale.minimum = 0;
    scale.maximum = 1;
    return scale;
  }
  // The observed parcels set the range, so that a change to the generated
  // parcels (a slider) leaves the scale, and the observed view, as they were;
  // the generated parcels set it only when no observed parcel has a value.
  std::vector<double> sample = analysis::quantitySample(r.observedLots, q);
  if (sample.empty()) sample = generatedSample(r.generated, q);
  if (sample.empty()) {
    scale.minimum = 0;
    scale.maximum = 1;
    return scale;
  }
  std::sort(sample.begin(), sample.end());
  const double quantile = value(request, "histogram-quantile");
  scale.minimum = sample.front();
  // The nearest-rank quantile, as the histograms' bins (analysis::sharedHistogram).
  const auto rank = static_cast<std::size_t>(std::ceil(quantile * static_cast<double>(sample.size())));
  scale.maximum = sample[std::min(sample.size(), std::max<std::size_t>(rank, 1)) - 1];
  if (!(scale.maximum > scale.minimum)) scale.maximum = scale.minimum + 1;
  std::snprintf(title, sizeof title, "; %.4g and above drawn darkest", scale.maximum);
  scale.title += title;
  return scale;
}

void renderQuantityMap(const CompareResult& r, const CompareRequest& request, const std::string& quantity,
                       const FigureOutput& output) {
  const analysis::ParcelQuantity& q = analysis::parcelQuantity(quantity);
  MapPanel observed, generated;
  const auto& parcels = r.observed->layer.parcels;
  for (std::size_t i = 0; i < parcels.size(); ++i) {
    if (r.observed->analysis.blockOf[i] < 0) continue;
    observed.shapes.push_back(&parcels[i].shape);
    observed.values.push_back(q.value(r.observed->analysis.metrics[i]));
  }
  fillGenerated(generated, r.generated, q);
  observed.title = "Observed: " + std::to_string(observed.shapes.size()) + " parcels";
  generated.title = "Procedural (" + request.style + "): " + generatedCount(r.generated);
  std::string what = q.title.substr(0, q.title.find(" ("));
  what[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(what[0])));
  renderMaps("Parcel " + (q.name == "aspect_ratio" ? std::string("aspect ratio") : q.name) + ", observed and " +
                 generatedName(request, r) + ": " + inputName(request),
             {observed, generated}, quantityScale(r, request, quantity), output);
}

QuantityHistogram quantityHistogram(const CompareResult& r, const CompareRequest& request, const std::string& quantity,
                                    HistogramTexts texts) {
  const bool numbers = texts == HistogramTexts::WithNumbers;
  const analysis::ParcelQuantity& q = analysis::parcelQuantity(quantity);
  const int bins = static_cast<int>(value(request, "bins"));
  const double quantile = value(request, "histogram-quantile");
  // The compared metrics' histograms were made with the comparison, on the same bins.
  const analysis::SharedHistogram* made = nullptr;
  for (std::size_t k = 0; k < std::size(analysis::kComparedMetrics); ++k) {
    if (q.name == analysis::metricName(analysis::kComparedMetrics[k]) && r.histograms.size() > k &&
        r.histogramBins == bins && r.histogramQuantile == quantile) {
      made = &r.histograms[k];
      break;
    }
  }
  const analysis::SharedHistogram h = made ? *made
                                           : analysis::sharedHistogram(analysis::quantitySample(r.observedLots, q),
                                                                       generatedSample(r.generated, q), bins, quantile);
  QuantityHistogram out;
  out.edges = h.edges;
  out.xTitle = q.title;
  if (h.aOverflow + h.bOverflow > 0) {
    char note[96];
    std::snprintf(note, sizeof note, "; the last bin holds every value above %.4g", h.edges.back());
    out.xTitle += numbers ? note : "; the last bin holds every higher value";
  }
  out.yTitle = "parcels (count)";
  auto counts = [&](const std::vector<int>& c) {
    return numbers ? " (n = " + std::to_string(std::accumulate(c.begin(), c.end(), 0)) + ")" : std::string();
  };
  out.series = {{"observed" + counts(h.a), h.a, {0.84, 0.15, 0.16}},
                {"procedural, " + request.style + counts(h.b), h.b, {0.12, 0.38, 0.75}}};
  const std::string what = q.name == "aspect_ratio" ? std::string("Parcel aspect ratio") : "Parcel " + q.name;
  out.title = what + ": observed and " + generatedName(request, r) + ", " + inputName(request);
  return out;
}

void renderQuantityHistogram(const CompareResult& r, const CompareRequest& request, const std::string& quantity,
                             const FigureOutput& output) {
  const QuantityHistogram h = quantityHistogram(r, request, quantity);
  if (h.edges.empty()) throw usageError(output.png + ": no finite " + quantity + " value on either side to draw");
  renderHistogram(h.title, h.xTitle, h.yTitle, h.edges, h.series, output);
}

void renderBlocksMap(const CompareResult& r, const CompareRequest& request, const FigureOutput& output) {
  MapPanel blocks;
  int withValue = 0;
  const analysis::ObservedAnalysis& a = r.observed->analysis;
  for (std::size_t b = 0; b < a.blocks.size(); ++b) {
    const double ks = r.blocks[b].comparison.area.ks;
    withValue += !std::isnan(ks);
    for (const Polygon& part : a.blocks[b].parts) {
      blocks.shapes.push_back(&part);
      blocks.values.push_back(ks);
    }
  }
  blocks.title =
      std::to_string(a.blocks.size()) + " blocks (" + std::to_string(withValue) + " with parcels on both sides)";
  ColourScale scale;
  scale.kind = ColourScale::Kind::Sequential;
  scale.minimum = 0;
  scale.maximum = 1;
  scale.title = "KS statistic of parcel area (0: same distribution, 1: disjoint)";
  renderMaps(
      "Per-block difference in parcel area, observed and " + generatedName(request, r) + ": " + inputName(request),
      {blocks}, scale, output);
}

std::vector<std::string> figureNames() {
  std::vector<std::string> names;
  for (const auto& q : analysis::parcelQuantities()) names.push_back("map_" + q.name);
  for (const auto& q : analysis::parcelQuantities()) names.push_back("hist_" + q.name);
  names.push_back("map_blocks");
  return names;
}

void exportFigure(const CompareResult& r, const CompareRequest& request, const std::string& name,
                  const std::string& path, int width, int height) {
  const auto names = figureNames();
  if (std::find(names.begin(), names.end(), name) == names.end()) {
    throw usageError("no figure named '" + name + "'");
  }
  const std::string extension = std::filesystem::path(path).extension().string();
  const bool histogram = name.rfind("hist_", 0) == 0;
  if (extension != ".png" && extension != ".svg" && extension != ".pdf") {
    throw usageError(path + ": " + name + " is written as .png, .svg or .pdf");
  }
  const std::vector<std::string> inputs = {request.input.path};
  io::StagedFile file(path, inputs);
  std::optional<io::StagedFile> bitmap;  // the PNG every render writes, thrown away for a vector export
  FigureOutput o;
  o.width = width;
  o.height = height;
  if (extension == ".png") {
    o.png = file.path();
  } else {
    bitmap.emplace(path + ".png", inputs);
    o.png = bitmap->path();
    if (histogram) {
      o.vector = file.path();
    } else {
      o.mapVectors.push_back(file.path());
    }
  }
  if (name == "map_blocks") {
    renderBlocksMap(r, request, o);
  } else if (histogram) {
    renderQuantityHistogram(r, request, name.substr(5), o);
  } else {
    renderQuantityMap(r, request, name.substr(4), o);
  }
  file.commit();
}

namespace {

// The figures of one run of compare, staged in its output folder.
struct FigureSet {
  const CompareRequest& request;
  const std::function<std::string(const std::string&)>& stage;
  std::vector<std::string> written;

  FigureOutput output(const std::string& name) {
    // Charts also go to SVG (or PDF) through VTK; maps to both SVG and PDF,
    // written as paths by writeVectorMaps (VTK 9.1's GL2PS export would
    // rasterise their polygons).
    FigureOutput o;
    written.push_back("figures/" + name + ".png");
    o.png = stage(written.back());
    if (name.rfind("map_", 0) != 0) {
      written.push_back("figures/" + name + "." + request.vectorFormat);
      o.vector = stage(written.back());
    } else {
      for (const char* extension : {".svg", ".pdf"}) {
        written.push_back("figures/" + name + extension);
        o.mapVectors.push_back(stage(written.back()));
      }
    }
    o.width = static_cast<int>(value(request, "figure-width"));
    o.height = static_cast<int>(value(request, "figure-height"));
    return o;
  }
};

std::vector<std::string> drawCompareFigures(const CompareResult& r, const CompareRequest& request,
                                            const std::function<std::string(const std::string&)>& stage,
                                            const ProgressFn& progress) {
  FigureSet f{request, stage, {}};
  renderQuantityMap(r, request, "aspect_ratio", f.output("map_aspect_ratio"));
  reportProgress(progress, 0.4, "figures");
  std::size_t index = 0;
  for (analysis::ComparedMetric m : analysis::kComparedMetrics) {
    // Nothing to draw when neither side has a finite value.
    if (!r.histograms[index++].edges.empty()) {
      renderQuantityHistogram(r, request, analysis::metricName(m),
                              f.output(std::string("hist_") + analysis::metricName(m)));
    }
  }
  reportProgress(progress, 0.7, "figures");
  renderBlocksMap(r, request, f.output("map_blocks"));
  if (!drawnAnyway(request.metric, false)) {
    renderQuantityMap(r, request, request.metric, f.output("map_" + request.metric));
  }
  if (!drawnAnyway(request.metric, true)) {
    renderQuantityHistogram(r, request, request.metric, f.output("hist_" + request.metric));
  }
  return f.written;
}

}  // namespace

const pipeline::FigureRenderer& compareFigureRenderer() {
  static const pipeline::FigureRenderer renderer{requireDisplay, drawCompareFigures, vtkVersionString()};
  return renderer;
}

std::vector<std::string> drawLeaderboard(const pipeline::Leaderboard& board, const CompareRequest& request,
                                         const std::function<std::string(const std::string&)>& stage) {
  if (board.entries.empty()) return {};
  requireDisplay();
  const analysis::ParcelQuantity& q = analysis::parcelQuantity("aspect_ratio");
  const CompareResult& first = board.entries.front().result;
  std::vector<MapPanel> panels(1 + board.entries.size());
  const auto& parcels = board.observed->layer.parcels;
  for (std::size_t i = 0; i < parcels.size(); ++i) {
    if (board.observed->analysis.blockOf[i] < 0) continue;
    panels[0].shapes.push_back(&parcels[i].shape);
    panels[0].values.push_back(q.value(board.observed->analysis.metrics[i]));
  }
  panels[0].title = "Observed: " + std::to_string(panels[0].shapes.size());
  for (std::size_t e = 0; e < board.entries.size(); ++e) {
    const auto& g = board.entries[e].result.generated;
    MapPanel& p = panels[e + 1];
    fillGenerated(p, g, q);
    std::ostringstream t;
    t.precision(2);
    t << board.entries[e].style << ": " << g.parcels.size() - static_cast<std::size_t>(g.unassignedParcels)
      << (g.unassignedParcels > 0 ? " + " + std::to_string(g.unassignedParcels) + " unassigned" : std::string())
      << ", fit " << pipeline::fitScore(board.entries[e].result.city);
    p.title = t.str();
  }
  const std::string title = "Parcel aspect ratio, observed and every style: " + inputName(request);
  const int width = 600 * static_cast<int>(panels.size()), height = 700;
  FigureOutput out;
  out.png = stage("leaderboard.png");
  out.width = width;
  out.height = height;
  const ColourScale scale = quantityScale(first, request, "aspect_ratio");
  renderMaps(title, panels, scale, out);
  writeVectorMaps(title, panels, scale, width, height, stage("leaderboard.svg"));
  return {"leaderboard.png", "leaderboard.svg"};
}

std::vector<std::string> drawCalibration(const pipeline::Calibration& c, const CompareRequest& request,
                                         const std::function<std::string(const std::string&)>& stage) {
  requireDisplay();
  const analysis::ObservedAnalysis& a = c.board.observed->analysis;
  std::vector<std::string> written;
  // The blocks by their distance, before and after, on one scale.
  std::vector<MapPanel> panels(2);
  double top = 0;
  for (std::size_t b = 0; b < c.blocks.size() && b < a.blocks.size(); ++b) {
    for (const Polygon& part : a.blocks[b].parts) {
      panels[0].shapes.push_back(&part);
      panels[0].values.push_back(c.blocks[b].distanceBefore);
      panels[1].shapes.push_back(&part);
      panels[1].values.push_back(c.blocks[b].distanceAfter);
    }
    top = std::max(top, c.blocks[b].distanceBefore);
  }
  char title[160];
  std::snprintf(title, sizeof title, "Before (the paper's rule, access): city KS area %.3f, width %.3f, aspect %.3f",
                c.before.ksArea, c.before.ksWidth, c.before.ksAspectRatio);
  panels[0].title = title;
  std::snprintf(title, sizeof title, "Calibrated: city KS area %.3f, width %.3f, aspect %.3f", c.after.ksArea,
                c.after.ksWidth, c.after.ksAspectRatio);
  panels[1].title = title;
  ColourScale scale;
  scale.kind = ColourScale::Kind::Sequential;
  scale.minimum = 0;
  scale.maximum = std::max(top, 1e-9);
  scale.title = "Block distance to its observed parcels (KS area + width + aspect ratio + count error)";
  const std::string mapTitle = "Per-block fit before and after calibration: " + inputName(request);
  FigureOutput map;
  map.png = stage("figures/map_fit.png");
  renderMaps(mapTitle, panels, scale, map);
  writeVectorMaps(mapTitle, panels, scale, map.width, map.height, stage("figures/map_fit.svg"));
  written.insert(written.end(), {"figures/map_fit.png", "figures/map_fit.svg"});

  // Observed, before and after, on the bins of observed and before.
  std::vector<analysis::ParcelMetrics> observed;
  for (std::size_t i = 0; i < a.metrics.size(); ++i) {
    if (a.blockOf[i] >= 0) observed.push_back(a.metrics[i]);
  }
  const auto before = pipeline::generatedMetrics(c.board, c.entryBefore);
  const auto after = pipeline::generatedMetrics(c.board, c.entryAfter);
  const int bins = static_cast<int>(value(request, "bins"));
  const double quantile = value(request, "histogram-quantile");
  for (const char* name : {"area", "width", "aspect_ratio"}) {
    const analysis::ParcelQuantity& q = analysis::parcelQuantity(name);
    const std::vector<double> o = analysis::quantitySample(observed, q), b = analysis::quantitySample(before, q),
                              f = analysis::quantitySample(after, q);
    const analysis::SharedHistogram h = analysis::sharedHistogram(o, b, bins, quantile);
    if (h.edges.size() < 2) continue;
    std::vector<int> counts(h.edges.size() - 1, 0);
    for (double v : f) {
      const auto bin = std::upper_bound(h.edges.begin(), h.edges.end(), v) - h.edges.begin() - 1;
      ++counts[static_cast<std::size_t>(std::clamp<long>(bin, 0, static_cast<long>(counts.size()) - 1))];
    }
    const std::vector<HistogramSeries> series = {{"observed", h.a, {0.84, 0.19, 0.15}},
                                                 {"before (access)", h.b, {0.55, 0.55, 0.55}},
                                                 {"calibrated", counts, {0.17, 0.40, 0.75}}};
    const std::string file = std::string("figures/hist_calibration_") + name;
    FigureOutput out;
    out.png = stage(file + ".png");
    out.vector = stage(file + ".svg");
    renderHistogram("Parcel " + std::string(name == std::string("aspect_ratio") ? "aspect ratio" : name) +
                        ": observed, before and after calibration (last bin: every value above)",
                    q.title, "parcels", h.edges, series, out);
    written.insert(written.end(), {file + ".png", file + ".svg"});
  }
  return written;
}

pipeline::JobOutcome runCalibrate(const CompareRequest& request, const std::string& outDir,
                                  const ProgressFn& progress) {
  return pipeline::runCalibrate(request, outDir, progress, drawCalibration);
}

pipeline::JobOutcome runLeaderboard(const CompareRequest& request, const std::string& outDir,
                                    const ProgressFn& progress) {
  return pipeline::runLeaderboard(request, outDir, progress, drawLeaderboard);
}

pipeline::JobOutcome runCompare(const CompareRequest& request, const std::string& outDir, const ProgressFn& progress,
                                const pipeline::PreparedObserved* prepared) {
  return pipeline::runCompare(request, outDir, progress, &compareFigureRenderer(), prepared);
}

}  // namespace parcelscope::viz
