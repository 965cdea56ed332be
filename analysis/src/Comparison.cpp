#include "parcelscope/analysis/Comparison.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "parcelscope/core/Error.h"

namespace parcelscope::analysis {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The finite values, sorted; a sample already sorted (as compareSets passes
// them) is only copied.
std::vector<double> finiteSorted(const std::vector<double>& v) {
  std::vector<double> out;
  out.reserve(v.size());
  for (double x : v) {
    if (std::isfinite(x)) out.push_back(x);
  }
  if (!std::is_sorted(out.begin(), out.end())) std::sort(out.begin(), out.end());
  return out;
}

struct CdfDistances {
  double ks = kNaN;
  double wasserstein = kNaN;
};

// One walk over the pooled sorted values: between consecutive distinct values
// both empirical distribution functions are constant, so the supremum of their
// difference (KS) and the integral of its absolute value (W1) are exact sums.
// `a` and `b` are sorted and finite.
CdfDistances cdfDistancesOfSorted(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.empty() || b.empty()) return {};
  const double na = static_cast<double>(a.size()), nb = static_cast<double>(b.size());
  std::size_t i = 0, j = 0;
  double fa = 0, fb = 0, previous = 0;
  CdfDistances d{0, 0};
  while (i < a.size() || j < b.size()) {
    const double x = (j >= b.size() || (i < a.size() && a[i] <= b[j])) ? a[i] : b[j];
    if (i > 0 || j > 0) d.wasserstein += std::fabs(fa - fb) * (x - previous);
    while (i < a.size() && a[i] <= x) ++i;
    while (j < b.size() && b[j] <= x) ++j;
    fa = static_cast<double>(i) / na;
    fb = static_cast<double>(j) / nb;
    d.ks = std::max(d.ks, std::fabs(fa - fb));
    previous = x;
  }
  return d;
}

CdfDistances cdfDistances(const std::vector<double>& a, const std::vector<double>& b) {
  return cdfDistancesOfSorted(finiteSorted(a), finiteSorted(b));
}

// The k-th smallest (0-based) of two sorted samples together; k < a.size() + b.size().
double pooledAt(const std::vector<double>& a, const std::vector<double>& b, std::size_t k) {
  std::size_t i = 0, j = 0;
  for (;;) {
    const bool fromA = j >= b.size() || (i < a.size() && a[i] <= b[j]);
    const double x = fromA ? a[i] : b[j];
    if (i + j == k) return x;
    (fromA ? i : j)++;
  }
}

// sharedHistogram of two sorted, finite samples.
SharedHistogram sharedHistogramOfSorted(const std::vector<double>& a, const std::vector<double>& b, int bins,
                                        double upperQuantile) {
  if (bins < 1) throw usageError("histogram: at least one bin is needed (got " + std::to_string(bins) + ")");
  if (!(upperQuantile > 0 && upperQuantile <= 1)) {
    throw usageError("histogram: the upper quantile must lie in (0, 1] (got " + std::to_string(upperQuantile) + ")");
  }
  SharedHistogram h;
  const std::size_t pooled = a.size() + b.size();
  if (pooled == 0) return h;
  const double lo = a.empty() ? b.front() : b.empty() ? a.front() : std::min(a.front(), b.front());
  const double top = a.empty() ? b.back() : b.empty() ? a.back() : std::max(a.back(), b.back());
  // Nearest-rank quantile; when it equals the minimum, fall back to the maximum.
  const auto rank = static_cast<std::size_t>(std::ceil(upperQuantile * static_cast<double>(pooled)));
  double hi = pooledAt(a, b, std::min(pooled, std::max<std::size_t>(rank, 1)) - 1);
  if (hi <= lo) hi = top;
  if (hi <= lo) {
    bins = 1;
    hi = lo + 1;
  }
  const double width = (hi - lo) / bins;
  h.edges.resize(static_cast<std::size_t>(bins) + 1);
  for (int k = 0; k <= bins; ++k) h.edges[k] = lo + width * k;
  h.edges.back() = hi;
  h.a.assign(bins, 0);
  h.b.assign(bins, 0);
  auto count = [&](const std::vector<double>& values, std::vector<int>& counts, int& overflow) {
    for (double x : values) {
      if (x > hi) ++overflow;
      const int k = std::min(bins - 1, static_cast<int>(std::floor((x - lo) / width)));
      ++counts[std::max(0, k)];
    }
  };
  count(a, h.a, h.aOverflow);
  count(b, h.b, h.bOverflow);
  return h;
}

double share(std::int64_t count, std::size_t total) {
  return total == 0 ? kNaN : static_cast<double>(count) / static_cast<double>(total);
}

}  // namespace

double ksStatistic(const std::vector<double>& a, const std::vector<double>& b) { return cdfDistances(a, b).ks; }

double wasserstein1(const std::vector<double>& a, const std::vector<double>& b) {
  return cdfDistances(a, b).wasserstein;
}

SharedHistogram sharedHistogram(const std::vector<double>& a, const std::vector<double>& b, int bins,
                                double upperQuantile) {
  return sharedHistogramOfSorted(finiteSorted(a), finiteSorted(b), bins, upperQuantile);
}

double histogramIntersection(const SharedHistogram& h) {
  long na = 0, nb = 0;
  for (int c : h.a) na += c;
  for (int c : h.b) nb += c;
  if (na == 0 || nb == 0) return kNaN;
  double sum = 0;
  for (std::size_t k = 0; k < h.a.size(); ++k) {
    sum += std::min(static_cast<double>(h.a[k]) / static_cast<double>(na),
                    static_cast<double>(h.b[k]) / static_cast<double>(nb));
  }
  return std::min(sum, 1.0);
}

bool isUndesirable(const ShapeMetrics& m) { return m.pAngle > 15.0 || m.pArea > 1.2; }

const char* metricName(ComparedMetric m) {
  switch (m) {
    case ComparedMetric::Area:
      return "area";
    case ComparedMetric::Width:
      return "width";
    case ComparedMetric::AspectRatio:
      return "aspect_ratio";
  }
  return "";
}

const char* metricUnit(ComparedMetric m) { return parcelQuantity(metricName(m)).unit.c_str(); }

const std::vector<ParcelQuantity>& parcelMetrics() {
  using M = ParcelMetrics;
  static const std::vector<ParcelQuantity> q = {
      {"area", "area (m\xc2\xb2)", [](const M& m) { return m.area; }, false, "m2", false,
       "|outer ring| - sum of |holes| (shoelace)", "> 0", "Vanegas et al. 2012, section 6 (A)"},
      {"perimeter", "perimeter (m)", [](const M& m) { return m.perimeter; }, false, "m", false,
       "length of the outer ring plus the holes", "> 0", ""},
      {"width", "width, short side of the minimum bounding rectangle (m)", [](const M& m) { return m.width; }, false,
       "m", false, "short side of the minimum-area bounding rectangle (MBR)", ">= 0",
       "Vanegas et al. 2012, section 6 (minimum width W)"},
      {"length", "length, long side of the minimum bounding rectangle (m)", [](const M& m) { return m.length; }, false,
       "m", false, "long side of the MBR", ">= width", ""},
      {"aspect_ratio", "aspect ratio (length / width)", [](const M& m) { return m.aspectRatio; }, false, "", false,
       "length / width", "[1, inf)", "Vanegas et al. 2012, Figure 1 (the colour maps)"},
      {"elongation", "elongation (MBR width / length)", [](const M& m) { return m.elongation; }, false, "", false,
       "width / length of the MBR; 1 is a square", "(0, 1]", "momepy.elongation (Gil et al. 2012)"},
      {"rectangularity", "rectangularity (area / MBR area)", [](const M& m) { return m.rectangularity; }, false, "",
       false, "area / MBR area; 1 is a rectangle", "(0, 1]", "momepy.rectangularity (Dibble et al. 2019)"},
      {"p_angle", "p_angle, mean corner deviation from 90\xc2\xb0 (degrees)", [](const M& m) { return m.pAngle; },
       false, "deg", false,
       "mean over the outer ring's corners (turns above 10 degrees) of | |turn| - 90 |; 0 without corners", "[0, 90)",
       "Yang et al. 2013, section 6"},
      {"p_area", "p_area, bounding rectangle area / area", [](const M& m) { return m.pArea; }, false, "", false,
       "MBR area / area", "[1, inf)", "Yang et al. 2013, section 6 (undesirable: p_angle > 15 or p_area > 1.2)"},
      {"neighbours", "neighbours (parcels sharing at least 1 m of boundary)",
       [](const M& m) { return static_cast<double>(m.neighbours); }, true, "", true,
       "parcels of the same block sharing at least 1 m of boundary (edges parallel within 10 degrees and within "
       "min(block tolerance, 1 m))",
       ">= 0", ""},
      {"frontage", "frontage, boundary on the block's outer contour (m)", [](const M& m) { return m.frontage; }, true,
       "m", false,
       "boundary length on the block's outer outline (facing a street), edges within half the block tolerance "
       "(5 cm to 0.5 m)",
       ">= 0", "Vanegas et al. 2012, section 4 (street access)"},
      {"street_access", "street access (1: at least min-frontage on the block contour)",
       [](const M& m) { return m.streetAccess ? 1.0 : 0.0; }, true, "", true,
       "1 when frontage >= --min-frontage (default 1 m)", "0 or 1", "Vanegas et al. 2012, section 4"},
  };
  return q;
}

const std::vector<ParcelQuantity>& parcelQuantities() {
  static const std::vector<ParcelQuantity> q = [] {
    std::vector<ParcelQuantity> out;
    for (const ParcelQuantity& m : parcelMetrics()) {
      if (m.name == "aspect_ratio")
        out.insert(out.begin(), m);
      else
        out.push_back(m);
    }
    return out;
  }();
  return q;
}

const ParcelQuantity& parcelQuantity(const std::string& name) {
  std::string names;
  for (const ParcelQuantity& q : parcelQuantities()) {
    if (q.name == name) return q;
    names += (names.empty() ? "" : ", ") + q.name;
  }
  throw usageError("no parcel quantity '" + name + "' (quantities: " + names + ")");
}

std::vector<double> quantitySample(const std::vector<ParcelMetrics>& metrics, const ParcelQuantity& q) {
  std::vector<double> out;
  out.reserve(metrics.size());
  for (const ParcelMetrics& m : metrics) {
    const double v = q.value(m);
    if (std::isfinite(v)) out.push_back(v);
  }
  return out;
}

std::vector<double> metricSample(const std::vector<ParcelMetrics>& metrics, ComparedMetric m) {
  return quantitySample(metrics, parcelQuantity(metricName(m)));
}

SetSummary summarizeSet(const std::vector<ParcelMetrics>& metrics) {
  SetSummary s;
  s.parcels = static_cast<std::int64_t>(metrics.size());
  if (metrics.empty()) {
    s.meanArea = s.sdArea = s.meanWidth = s.sdWidth = s.meanAspectRatio = kNaN;
    s.streetAccessShare = s.meanPAngle = s.meanPArea = s.undesirableShare = kNaN;
    return s;
  }
  // Means and sample SDs exactly as the per-block statistics compute them.
  const BlockStatistics st =
      blockStatistics(metricSample(metrics, ComparedMetric::Area), metricSample(metrics, ComparedMetric::Width), 0.0);
  s.meanArea = st.meanArea;
  s.sdArea = st.sdArea;
  s.meanWidth = st.meanWidth;
  s.sdWidth = st.sdWidth;
  const std::vector<double> aspect = metricSample(metrics, ComparedMetric::AspectRatio);
  double aspectSum = 0, pAngleSum = 0, pAreaSum = 0;
  std::int64_t access = 0, undesirable = 0;
  for (double x : aspect) aspectSum += x;
  for (const ParcelMetrics& m : metrics) {
    pAngleSum += m.pAngle;
    pAreaSum += m.pArea;
    access += m.streetAccess;
    undesirable += isUndesirable(m);
  }
  s.meanAspectRatio = aspect.empty() ? kNaN : aspectSum / static_cast<double>(aspect.size());
  s.streetAccessShare = share(access, metrics.size());
  s.meanPAngle = pAngleSum / static_cast<double>(metrics.size());
  s.meanPArea = pAreaSum / static_cast<double>(metrics.size());
  s.undesirableShare = share(undesirable, metrics.size());
  return s;
}

const Distances& Comparison::distances(ComparedMetric m) const {
  return m == ComparedMetric::Area ? area : m == ComparedMetric::Width ? width : aspectRatio;
}

Distances& Comparison::distances(ComparedMetric m) {
  return const_cast<Distances&>(static_cast<const Comparison&>(*this).distances(m));
}

PreparedSet prepareSet(const std::vector<ParcelMetrics>& metrics) {
  PreparedSet p;
  p.summary = summarizeSet(metrics);
  for (std::size_t k = 0; k < std::size(kComparedMetrics); ++k) {
    p.sorted[k] = metricSample(metrics, kComparedMetrics[k]);  // finite values only
    std::sort(p.sorted[k].begin(), p.sorted[k].end());
  }
  return p;
}

Comparison compareSets(const PreparedSet& observed, const PreparedSet& generated, int bins, double upperQuantile,
                       std::vector<SharedHistogram>* histograms) {
  Comparison c;
  if (histograms) histograms->clear();
  c.observed = observed.summary;
  c.generated = generated.summary;
  for (std::size_t k = 0; k < std::size(kComparedMetrics); ++k) {
    const std::vector<double>&a = observed.sorted[k], &b = generated.sorted[k];
    const CdfDistances d = cdfDistancesOfSorted(a, b);
    Distances& out = c.distances(kComparedMetrics[k]);
    out.ks = d.ks;
    out.wasserstein = d.wasserstein;
    SharedHistogram h = sharedHistogramOfSorted(a, b, bins, upperQuantile);
    out.intersection = histogramIntersection(h);
    if (histograms) histograms->push_back(std::move(h));
  }
  return c;
}

Comparison compareSets(const std::vector<ParcelMetrics>& observed, const std::vector<ParcelMetrics>& generated,
                       int bins, double upperQuantile, std::vector<SharedHistogram>* histograms) {
  return compareSets(prepareSet(observed), prepareSet(generated), bins, upperQuantile, histograms);
}

Table blockComparisonTable(const std::vector<BlockComparison>& blocks) {
  using T = Column::Type;
  Table t;
  t.columns = {{"block_id", T::Integer, ""}, {"block_key", T::String, ""}, {"block_area", T::Real, "m2"}};
  // Observed and generated side by side, in the order of the paper's table.
  const std::pair<const char*, const char*> pairs[] = {
      {"parcels", ""},     {"mean_area", "m2"},       {"sd_area", "m2"},           {"mean_width", "m"},
      {"sd_width", "m"},   {"mean_aspect_ratio", ""}, {"street_access_share", ""}, {"mean_p_angle", "deg"},
      {"mean_p_area", ""}, {"undesirable_share", ""}};
  for (const auto& [name, unit] : pairs) {
    for (const char* side : {"observed_", "generated_"}) {
      t.columns.push_back({side + std::string(name), name == std::string("parcels") ? T::Integer : T::Real, unit});
    }
  }
  for (ComparedMetric m : kComparedMetrics) {
    t.columns.push_back({std::string("ks_") + metricName(m), T::Real, ""});
    t.columns.push_back({std::string("wasserstein_") + metricName(m), T::Real, metricUnit(m)});
    t.columns.push_back({std::string("intersection_") + metricName(m), T::Real, ""});
  }
  for (const BlockComparison& b : blocks) {
    const SetSummary& o = b.comparison.observed;
    const SetSummary& g = b.comparison.generated;
    std::vector<Value> row = {b.blockId, keyText(b.blockKey), b.blockArea, o.parcels, g.parcels};
    for (const auto& [ov, gv] : {std::pair{o.meanArea, g.meanArea},
                                 {o.sdArea, g.sdArea},
                                 {o.meanWidth, g.meanWidth},
                                 {o.sdWidth, g.sdWidth},
                                 {o.meanAspectRatio, g.meanAspectRatio},
                                 {o.streetAccessShare, g.streetAccessShare},
                                 {o.meanPAngle, g.meanPAngle},
                                 {o.meanPArea, g.meanPArea},
                                 {o.undesirableShare, g.undesirableShare}}) {
      row.emplace_back(std::in_place_type<double>, ov);
      row.emplace_back(std::in_place_type<double>, gv);
    }
    for (ComparedMetric m : kComparedMetrics) {
      const Distances& d = b.comparison.distances(m);
      for (double v : {d.ks, d.wasserstein, d.intersection}) row.emplace_back(std::in_place_type<double>, v);
    }
    t.rows.push_back(std::move(row));
  }
  return t;
}

Table summaryTable(const Comparison& city) {
  using T = Column::Type;
  Table t;
  t.columns = {
      {"quantity", T::String, ""}, {"unit", T::String, ""}, {"observed", T::Real, ""}, {"generated", T::Real, ""}};
  const SetSummary& o = city.observed;
  const SetSummary& g = city.generated;
  auto add = [&](const char* name, const char* unit, double ov, double gv) {
    t.rows.push_back({std::string(name), std::string(unit), ov, gv});
  };
  add("parcels", "", static_cast<double>(o.parcels), static_cast<double>(g.parcels));
  add("mean_area", "m2", o.meanArea, g.meanArea);
  add("sd_area", "m2", o.sdArea, g.sdArea);
  add("mean_width", "m", o.meanWidth, g.meanWidth);
  add("sd_width", "m", o.sdWidth, g.sdWidth);
  add("mean_aspect_ratio", "", o.meanAspectRatio, g.meanAspectRatio);
  add("street_access_share", "", o.streetAccessShare, g.streetAccessShare);
  add("mean_p_angle", "deg", o.meanPAngle, g.meanPAngle);
  add("mean_p_area", "", o.meanPArea, g.meanPArea);
  add("undesirable_share", "", o.undesirableShare, g.undesirableShare);
  return t;
}

Table distanceTable(const Comparison& city) {
  using T = Column::Type;
  Table t;
  t.columns = {{"metric", T::String, ""},
               {"unit", T::String, ""},
               {"ks", T::Real, ""},
               {"wasserstein_1", T::Real, ""},
               {"histogram_intersection", T::Real, ""}};
  for (ComparedMetric m : kComparedMetrics) {
    const Distances& d = city.distances(m);
    t.rows.push_back({std::string(metricName(m)), std::string(metricUnit(m)), d.ks, d.wasserstein, d.intersection});
  }
  return t;
}

}  // namespace parcelscope::analysis
