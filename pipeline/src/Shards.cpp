#include "parcelscope/pipeline/Shards.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <type_traits>

#include "CompareStages.h"
#include "parcelscope/core/Error.h"
#include "parcelscope/core/Parallel.h"
#include "parcelscope/io/OutputDirectory.h"
#include "parcelscope/io/Writers.h"
#include "parcelscope/pipeline/BlockSource.h"
#include "parcelscope/pipeline/CompareSession.h"

namespace parcelscope::pipeline {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int kMaxReads = 64;

// The strip boundaries: strip k is [cut(k), cut(k + 1)).
struct Strips {
  Box extent;
  int count = 1;
  double cut(int k) const {
    if (k <= 0) return -std::numeric_limits<double>::infinity();
    if (k >= count) return std::numeric_limits<double>::infinity();
    return extent.minX + extent.width() * static_cast<double>(k) / static_cast<double>(count);
  }
  bool holds(int k, double x) const { return x >= cut(k) && x < cut(k + 1); }
};

// The box, in the input CRS, of a local box: its corners and edge midpoints.
Box sourceBox(const io::LocalFrame& frame, const Box& b) {
  Box out{std::numeric_limits<double>::max(), std::numeric_limits<double>::max(), std::numeric_limits<double>::lowest(),
          std::numeric_limits<double>::lowest()};
  const double xs[] = {b.minX, 0.5 * (b.minX + b.maxX), b.maxX};
  const double ys[] = {b.minY, 0.5 * (b.minY + b.maxY), b.maxY};
  for (double x : xs) {
    for (double y : ys) {
      const Point p = frame.toSource({x, y});
      out = {std::min(out.minX, p.x), std::min(out.minY, p.y), std::max(out.maxX, p.x), std::max(out.maxY, p.y)};
    }
  }
  return out;
}

bool inside(const Box& inner, const Box& outer) {
  return inner.minX >= outer.minX && inner.maxX <= outer.maxX && inner.minY >= outer.minY && inner.maxY <= outer.maxY;
}

Box unite(const Box& a, const Box& b) {
  return {std::min(a.minX, b.minX), std::min(a.minY, b.minY), std::max(a.maxX, b.maxX), std::max(a.maxY, b.maxY)};
}

// The parcels' box (local metres) and their anchor: the smallest x of their
// features' envelopes in the input CRS, the same number in every shard.
struct Extent {
  double anchor = std::numeric_limits<double>::infinity();
  bool startsInStrip = false;  // one of its parcels' envelopes starts in the shard's strip
  bool mayBeJoined = false;    // holds a parcel that may be a right-of-way (`uncertain` in analyseShard)
  Box box{std::numeric_limits<double>::max(), std::numeric_limits<double>::max(), std::numeric_limits<double>::lowest(),
          std::numeric_limits<double>::lowest()};
  void add(const Polygon& shape, double sourceMinX) {
    anchor = std::min(anchor, sourceMinX);
    for (const Point& p : shape.outer) box = unite(box, {p.x, p.y, p.x, p.y});
  }
};

// ---- bytes ----

class Writer {
public:
  template <class T>
  void pod(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    bytes_.append(reinterpret_cast<const char*>(&v), sizeof v);
  }
  template <class T>
  void pods(const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    pod(static_cast<std::uint64_t>(v.size()));
    bytes_.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  }
  void text(const std::string& s) {
    pod(static_cast<std::uint64_t>(s.size()));
    bytes_ += s;
  }
  void polygon(const Polygon& p) {
    pods(p.outer);
    pod(static_cast<std::uint64_t>(p.holes.size()));
    for (const Ring& h : p.holes) pods(h);
  }
  void timings(const std::vector<std::pair<std::string, double>>& t) {
    pod(static_cast<std::uint64_t>(t.size()));
    for (const auto& [name, s] : t) {
      text(name);
      pod(s);
    }
  }
  void premade(const PremadeBlock& p) {
    pod(static_cast<std::uint8_t>(p.made));
    if (!p.made) return;
    pod(p.plan);
    const Subdivision& d = p.outcome.subdivision;
    pod(static_cast<std::uint64_t>(d.parcels.size()));
    for (const Polygon& parcel : d.parcels) polygon(parcel);
    pod(d.oversize);
    pod(d.withoutAccess);
    pod(static_cast<std::uint8_t>(d.failed));
    text(d.failure);
    pod(static_cast<std::uint8_t>(d.fallback));
    text(d.fallbackReason);
    pod(d.patioParcels);
    pod(d.unassignedParcels);
    pod(d.targetParcels);
    text(d.variant);
    pod(d.blockSimple);
    pod(static_cast<std::uint8_t>(d.skeletonExact));
    pods(p.outcome.metrics);
    geometries(p.outcome.written);
  }
  void geometries(const std::vector<io::FileGeometry>& all) {
    pod(static_cast<std::uint64_t>(all.size()));
    for (const io::FileGeometry& g : all) {
      text(g.wkb);
      pod(static_cast<std::uint8_t>(g.repaired));
      pod(static_cast<std::uint8_t>(g.emptied));
    }
  }
  std::string take() { return std::move(bytes_); }

private:
  std::string bytes_;
};

class Reader {
public:
  Reader(std::string_view bytes, std::string what) : bytes_(bytes), what_(std::move(what)) {}
  template <class T>
  T pod() {
    static_assert(std::is_trivially_copyable_v<T>);
    need(sizeof(T));
    T v;
    std::memcpy(&v, bytes_.data() + at_, sizeof v);
    at_ += sizeof v;
    return v;
  }
  std::uint64_t count(std::size_t each) {
    const auto n = pod<std::uint64_t>();
    if (each > 0 && n > (bytes_.size() - at_) / each) fail();
    return n;
  }
  template <class T>
  std::vector<T> pods() {
    const auto n = count(sizeof(T));
    std::vector<T> v(n);
    std::memcpy(v.data(), bytes_.data() + at_, n * sizeof(T));
    at_ += n * sizeof(T);
    return v;
  }
  bool flag() {
    const auto v = pod<std::uint8_t>();
    if (v > 1) fail();
    return v == 1;
  }
  std::string text() {
    const auto n = count(1);
    std::string s(bytes_.substr(at_, n));
    at_ += n;
    return s;
  }
  Polygon polygon() {
    Polygon p;
    p.outer = pods<Point>();
    p.holes.resize(count(sizeof(std::uint64_t)));
    for (Ring& h : p.holes) h = pods<Point>();
    return p;
  }
  std::vector<std::pair<std::string, double>> timings() {
    std::vector<std::pair<std::string, double>> t(count(sizeof(std::uint64_t) + sizeof(double)));
    for (auto& [name, s] : t) {
      name = text();
      s = pod<double>();
    }
    return t;
  }
  PremadeBlock premade() {
    PremadeBlock p;
    p.made = flag();
    if (!p.made) return p;
    p.plan = pod<Key>();
    Subdivision& d = p.outcome.subdivision;
    d.parcels.resize(count(2 * sizeof(std::uint64_t)));
    for (Polygon& parcel : d.parcels) parcel = polygon();
    d.oversize = pod<int>();
    d.withoutAccess = pod<int>();
    d.failed = flag();
    d.failure = text();
    d.fallback = flag();
    d.fallbackReason = text();
    d.patioParcels = pod<int>();
    d.unassignedParcels = pod<int>();
    d.targetParcels = pod<int>();
    d.variant = text();
    d.blockSimple = pod<signed char>();
    d.skeletonExact = flag();
    p.outcome.metrics = pods<analysis::ParcelMetrics>();
    p.outcome.written = geometries();
    if (p.outcome.metrics.size() != d.parcels.size() ||
        (!p.outcome.written.empty() && p.outcome.written.size() != d.parcels.size())) {
      fail();
    }
    return p;
  }
  std::vector<io::FileGeometry> geometries() {
    std::vector<io::FileGeometry> all(count(sizeof(std::uint64_t) + 2));
    for (io::FileGeometry& g : all) {
      g.wkb = text();
      g.repaired = flag();
      g.emptied = flag();
    }
    return all;
  }
  bool done() const { return at_ == bytes_.size(); }
  [[noreturn]] void fail() const {
    throw inputError(what_ + ": not a shard of parcelscope " + version() + " (truncated or another version)");
  }

private:
  void need(std::size_t n) const {
    if (bytes_.size() - at_ < n) fail();
  }
  std::string_view bytes_;
  std::string what_;
  std::size_t at_ = 0;
};

constexpr char kMagic[] = "parcelscope-shard-2";

// A checksum of `bytes`, eight bytes at a time.
Key checksum(std::string_view bytes) {
  Key h = 0x9e3779b97f4a7c15ull ^ bytes.size();
  std::size_t i = 0;
  for (; i + sizeof(std::uint64_t) <= bytes.size(); i += sizeof(std::uint64_t)) {
    std::uint64_t word = 0;
    std::memcpy(&word, bytes.data() + i, sizeof word);
    h = (h ^ word) * 0xff51afd7ed558ccdull;
    h ^= h >> 32;
  }
  return mixKeys(h, hashBytes(bytes.substr(i)));
}

void addReport(io::CleaningReport& sum, const io::CleaningReport& r) {
  sum.features += r.features;
  sum.nullOrEmpty += r.nullOrEmpty;
  sum.nonPolygonal += r.nonPolygonal;
  sum.nonPolygonalParts += r.nonPolygonalParts;
  sum.nonFiniteSkipped += r.nonFiniteSkipped;
  sum.multipartFeatures += r.multipartFeatures;
  sum.partsFromMultipart += r.partsFromMultipart;
  sum.withHoles += r.withHoles;
  sum.invalidRepaired += r.invalidRepaired;
  sum.invalidSkipped += r.invalidSkipped;
  sum.degenerateSkipped += r.degenerateSkipped;
  sum.duplicatesCollapsed += r.duplicatesCollapsed;
  sum.duplicateStacks += r.duplicateStacks;
  sum.parcels += r.parcels;
}

}  // namespace

std::pair<int, int> parseShard(const std::string& text) {
  const auto slash = text.find('/');
  int i = -1, n = -1;
  try {
    std::size_t used = 0;
    if (slash != std::string::npos) {
      i = std::stoi(text.substr(0, slash), &used);
      if (used != slash) i = -1;
      n = std::stoi(text.substr(slash + 1), &used);
      if (used != text.size() - slash - 1) n = -1;
    }
  } catch (const std::exception&) {
    i = n = -1;
  }
  if (i < 0 || n < 1 || i >= n) throw usageError("--shard " + text + ": expected I/N with 0 <= I < N, e.g. 0/4");
  return {i, n};
}

namespace {

// Subdivides and measures the part's block entries as the merged run would,
// leaving to it those whose style reads street widths (measured from the
// neighbouring blocks, some of them another shard's) and every entry when
// overrides name blocks by id (ids are the merged run's).
void generateInShard(const CompareRequest& request, ShardPart& part) {
  if (!request.overridesById.empty() || part.blocks.empty()) return;
  const auto started = std::chrono::steady_clock::now();
  GenerateRequest g = detail::generateRequest(request, nullptr);
  BlockInputs inputs;
  appendObservedEntries(inputs, part.blocks, part.statistics, part.metrics);
  // Overrides of this part's blocks only; the merged run checks the others.
  std::set<Key> keys;
  for (const Block& b : part.blocks) keys.insert(b.key);
  for (auto it = g.overrides.begin(); it != g.overrides.end();) {
    it = keys.count(it->first) ? std::next(it) : g.overrides.erase(it);
  }
  const std::vector<BlockPlan> plans = planBlocks(g, inputs);
  const double minFrontage = generation::obbParametersFrom(request.parameters).minFrontage;
  const io::LocalFrame frame = io::LocalFrame::fromState(part.frame);
  part.generated.assign(plans.size(), PremadeBlock{});
  std::atomic<std::int64_t> made{0};
  parallelFor(plans.size(), [&](std::size_t k) {
    if (generation::style(plans[k].style).usesStreetWidths()) return;
    PremadeBlock& p = part.generated[k];
    p.outcome = runBlock(inputs, k, plans[k], minFrontage);
    // The parcels as parcels.gpkg holds them, made here rather than by the writer.
    for (const Polygon& parcel : p.outcome.subdivision.parcels) {
      p.outcome.written.push_back(io::fileGeometry({parcel}, frame));
    }
    p.plan = planKey(plans[k]);
    p.made = true;
    ++made;
  });
  part.blocksGenerated = made;
  part.generateSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  part.seconds += part.generateSeconds;
}

}  // namespace

ShardPart analyseShard(const CompareRequest& request, int index, int count, const ShardReading& reading,
                       const ProgressFn& progress) {
  if (request.streets) {
    throw usageError("blocks from street centre lines (--streets) are not split into shards; run in one process");
  }
  if (count < 1 || index < 0 || index >= count)
    throw usageError("shard " + std::to_string(index) + " of " + std::to_string(count) + " does not exist");
  const auto started = std::chrono::steady_clock::now();
  Box extent;
  try {
    extent = io::layerExtent(request.input);
  } catch (const Error&) {
    // No extent: no feature with finite coordinates, or none at all. One
    // process's read names why; failing that, the extent's error stands.
    io::readParcels(request.input);
    throw;
  }
  const Strips strips{extent, count};
  const double halo = 0.1 * std::max(strips.extent.width() / count, 1e-9);
  const analysis::AnalysisOptions options = analysis::analysisOptionsFrom(request.parameters);
  // Metres around a block within which every parcel must have been read: its
  // contacts (the block tolerance) and theirs, with room to spare.
  const double margin = 2.0 * options.blockTolerance + 2.0;

  io::ReadOptions input = request.input;
  io::ShardRead shard;
  shard.tileMinX = strips.cut(index);
  shard.tileMaxX = strips.cut(index + 1);
  shard.spatialFilter = reading.spatialFilter;
  shard.exchange = reading.exchange;
  Box window{index == 0 ? -kInf : shard.tileMinX - halo, -kInf, index == count - 1 ? kInf : shard.tileMaxX + halo,
             kInf};
  ShardPart part;
  part.index = index;
  part.count = count;
  if (index == 0) part.layerFeatures = io::featureCount(request.input);
  for (int read = 1;; ++read) {
    shard.window = window;
    input.shard = shard;
    const ProgressFn step = scaledProgress(progress, read == 1 ? 0.0 : 0.9, 1.0);
    io::ParcelLayer layer = io::readParcels(input, scaledProgress(step, 0.0, 0.4));
    shard.frame = layer.frame;  // later reads take it as it is, and exchange nothing
    shard.exchange = nullptr;
    const analysis::ObservedAnalysis a =
        analysis::analyseParcels(layer.parcels, options, scaledProgress(step, 0.4, 1.0));
    part.parcelsRead += static_cast<std::int64_t>(layer.parcels.size());

    // Blocks, then right-of-way parcels: kept when whole and this shard's;
    // the window grows for those of this shard cut by its edge.
    std::vector<char> keepBlock(a.blocks.size(), 0), keepParcel(layer.parcels.size(), 0);
    bool cut = false;
    Box grow{kInf, kInf, -kInf, -kInf};
    // A parcel of right-of-way shape is one or not by the parcels around it
    // (in its holes, touching it): known here only when its own box, grown by
    // the contact distances, lies inside the window. Seen as a lot without
    // being known, it may join blocks that one process keeps apart.
    auto uncertain = [&](int i) {
      return options.detectRightOfWay && a.rightOfWay[i] == analysis::RightOfWay::No &&
             analysis::hasRightOfWayShape(a.metrics[i]) &&
             !inside(sourceBox(layer.frame, bounds(layer.parcels[i].shape.outer).expanded(margin)), window);
    };
    auto judge = [&](const Extent& e) {
      const Box box = sourceBox(layer.frame, e.box.expanded(margin));
      if (inside(box, window)) return strips.holds(index, e.anchor);
      if (e.mayBeJoined) {
        // Its true blocks are not known: one of them is this shard's when one
        // of its parcels seen starts in this strip (a parcel beyond the
        // window starts beyond the strip).
        if (!e.startsInStrip) return false;
        cut = true;
        grow = unite(grow, box);
        return false;
      }
      // Cut. Its true anchor is at most the one seen: left of this strip, a
      // shard on the left owns it. Not cut on the left (windows span every y),
      // the anchor seen is the true one: it names the owner.
      if (e.anchor < shard.tileMinX) return false;
      if (box.minX >= window.minX && !strips.holds(index, e.anchor)) return false;
      cut = true;
      grow = unite(grow, box);
      return false;
    };
    for (std::size_t b = 0; b < a.blocks.size(); ++b) {
      Extent e;
      for (int i : a.blocks[b].parcels) {
        e.add(layer.parcels[i].shape, layer.sourceMinX[i]);
        e.startsInStrip = e.startsInStrip || strips.holds(index, layer.sourceMinX[i]);
        e.mayBeJoined = e.mayBeJoined || uncertain(i);
      }
      keepBlock[b] = judge(e);
    }
    for (std::size_t i = 0; i < layer.parcels.size(); ++i) {
      if (a.blockOf[i] >= 0) continue;
      Extent e;
      e.add(layer.parcels[i].shape, layer.sourceMinX[i]);
      keepParcel[i] = judge(e);
    }
    if (cut) {
      // Windows span every y: grown in x past the cut items by a halo that
      // doubles with each read, so that a large block takes few reads.
      const double by = std::ldexp(halo, read - 1);
      const Box wider = unite(window, {grow.minX - by, window.minY, grow.maxX + by, window.maxY});
      if (read >= kMaxReads || inside(wider, window)) {
        throw inputError(request.input.path + ": shard " + std::to_string(index) + " of " + std::to_string(count) +
                         " found no window holding its blocks whole after " + std::to_string(read) + " reads");
      }
      window = wider;
      continue;
    }
    part.reads = read;
    // This shard's parcels in input order, and its blocks over them.
    std::vector<int> at(layer.parcels.size(), -1);
    for (std::size_t i = 0; i < layer.parcels.size(); ++i) {
      if (a.blockOf[i] >= 0 ? !keepBlock[a.blockOf[i]] : !keepParcel[i]) continue;
      at[i] = static_cast<int>(part.parcels.size());
      part.parcels.push_back(std::move(layer.parcels[i]));
      if (!layer.fields.empty()) part.fields.push_back(layer.fields[i]);
      part.metrics.push_back(a.metrics[i]);
      part.rightOfWay.push_back(a.rightOfWay[i]);
    }
    for (std::size_t b = 0; b < a.blocks.size(); ++b) {
      if (!keepBlock[b]) continue;
      Block block = a.blocks[b];
      block.id = -1;
      for (int& i : block.parcels) i = at[i];
      part.blocks.push_back(std::move(block));
      part.statistics.push_back(a.statistics[b]);
    }
    // The outlines as blocks.gpkg holds them, made here rather than by the writer.
    part.blockOutlines.resize(part.blocks.size());
    parallelFor(part.blocks.size(),
                [&](std::size_t b) { part.blockOutlines[b] = io::fileGeometry(part.blocks[b].parts, layer.frame); });
    part.path = layer.path;
    part.layerName = layer.layerName;
    part.frame = layer.frame.state();
    part.crs = layer.crs;
    part.report = layer.report;
    part.readTimings = layer.timings.stages();
    part.analysisTimings = a.timings.stages();
    break;
  }
  part.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  generateInShard(request, part);
  return part;
}

ObservedData mergeShards(std::vector<ShardPart> parts, std::vector<PremadeBlock>* generated) {
  if (parts.empty()) throw inputError("merge: no shard given");
  const int count = parts.front().count;
  std::sort(parts.begin(), parts.end(), [](const ShardPart& a, const ShardPart& b) { return a.index < b.index; });
  for (std::size_t k = 0; k < parts.size(); ++k) {
    const ShardPart& p = parts[k];
    const std::string which = "shard " + std::to_string(p.index) + " of " + std::to_string(p.count);
    if (p.count != count || p.path != parts.front().path || p.layerName != parts.front().layerName) {
      throw inputError("merge: " + which + " is not of the run of shard 0 of " + std::to_string(count) + " (" +
                       parts.front().path + ")");
    }
    if (p.frame != parts.front().frame) throw inputError("merge: " + which + " chose another local frame");
    if (k > 0 && p.index == parts[k - 1].index) throw inputError("merge: " + which + " is given twice");
  }
  if (static_cast<int>(parts.size()) != count) {
    std::string missing;
    for (int i = 0, k = 0, listed = 0; i < count; ++i) {
      if (k < static_cast<int>(parts.size()) && parts[k].index == i) {
        ++k;
      } else if (++listed <= 20) {
        missing += (missing.empty() ? "" : ", ") + std::to_string(i);
      } else if (listed == 21) {
        missing += ", ...";
      }
    }
    throw inputError("merge: " + std::to_string(parts.size()) + " of " + std::to_string(count) +
                     " shards given; missing: " + missing);
  }

  // Every parcel, ordered as one process reads them: by feature id, then part.
  struct Ref {
    std::int64_t fid;
    int partIndex;
    int shard;
    int local;
  };
  std::vector<Ref> refs;
  for (std::size_t s = 0; s < parts.size(); ++s) {
    for (std::size_t i = 0; i < parts[s].parcels.size(); ++i) {
      const Parcel& p = parts[s].parcels[i];
      refs.push_back({p.sourceFid, p.part, static_cast<int>(s), static_cast<int>(i)});
    }
  }
  std::sort(refs.begin(), refs.end(),
            [](const Ref& a, const Ref& b) { return a.fid != b.fid ? a.fid < b.fid : a.partIndex < b.partIndex; });
  for (std::size_t g = 1; g < refs.size(); ++g) {
    if (refs[g].fid == refs[g - 1].fid && refs[g].partIndex == refs[g - 1].partIndex) {
      throw inputError("merge: feature " + std::to_string(refs[g].fid) + " is in shards " +
                       std::to_string(parts[refs[g - 1].shard].index) + " and " +
                       std::to_string(parts[refs[g].shard].index));
    }
  }

  ObservedData data;
  io::ParcelLayer& layer = data.layer;
  analysis::ObservedAnalysis& a = data.analysis;
  layer.path = parts.front().path;
  layer.layerName = parts.front().layerName;
  layer.frame = io::LocalFrame::fromState(parts.front().frame);
  layer.crs = parts.front().crs;
  for (const ShardPart& p : parts) addReport(layer.report, p.report);
  // Every feature of the layer is some shard's, once.
  if (const std::int64_t all = parts.front().layerFeatures; all >= 0 && all != layer.report.features) {
    throw inputError("merge: the shards counted " + std::to_string(layer.report.features) + " features of the " +
                     std::to_string(all) + " of " + layer.path + " (was the file changed between the shards?)");
  }
  if (layer.report.parcels != static_cast<std::int64_t>(refs.size())) {
    throw inputError("merge: the shards read " + std::to_string(layer.report.parcels) + " parcels but hold " +
                     std::to_string(refs.size()) + " in their blocks and right-of-way");
  }
  if (refs.size() >= static_cast<std::size_t>(std::numeric_limits<int>::max())) {
    throw inputError("merge: more than 2^31 parcels in one run");
  }
  std::vector<std::vector<int>> global(parts.size());
  for (std::size_t s = 0; s < parts.size(); ++s) global[s].resize(parts[s].parcels.size());
  const bool fields = std::any_of(parts.begin(), parts.end(), [](const ShardPart& p) { return !p.fields.empty(); });
  for (const ShardPart& p : parts) {
    if (fields && p.fields.size() != p.parcels.size()) {
      throw inputError("merge: shard " + std::to_string(p.index) + " carries no field values where others do");
    }
  }
  layer.parcels.reserve(refs.size());
  a.metrics.reserve(refs.size());
  a.rightOfWay.reserve(refs.size());
  for (const Ref& r : refs) {
    ShardPart& p = parts[r.shard];
    global[r.shard][r.local] = static_cast<int>(layer.parcels.size());
    layer.parcels.push_back(std::move(p.parcels[r.local]));
    if (fields) layer.fields.push_back(std::move(p.fields[r.local]));
    a.metrics.push_back(p.metrics[r.local]);
    a.rightOfWay.push_back(p.rightOfWay[r.local]);
  }
  // Blocks numbered in the order of their first parcel.
  struct BlockRef {
    int first;
    int shard;
    std::size_t block;
  };
  std::vector<BlockRef> blockRefs;
  for (std::size_t s = 0; s < parts.size(); ++s) {
    for (std::size_t b = 0; b < parts[s].blocks.size(); ++b) {
      int first = std::numeric_limits<int>::max();
      for (int& i : parts[s].blocks[b].parcels) {
        i = global[s][i];
        first = std::min(first, i);
      }
      blockRefs.push_back({first, static_cast<int>(s), b});
    }
  }
  std::sort(blockRefs.begin(), blockRefs.end(), [](const BlockRef& x, const BlockRef& y) { return x.first < y.first; });
  // Each part's first block entry of each of its blocks (entries are the blocks' parts in turn).
  std::vector<std::vector<std::size_t>> firstEntry(parts.size());
  for (std::size_t s = 0; s < parts.size(); ++s) {
    std::size_t at = 0;
    for (const Block& b : parts[s].blocks) {
      firstEntry[s].push_back(at);
      at += b.parts.size();
    }
  }
  if (generated) generated->clear();
  a.blockOf.assign(layer.parcels.size(), -1);
  for (const BlockRef& r : blockRefs) {
    if (generated) {
      std::vector<PremadeBlock>& made = parts[r.shard].generated;
      for (std::size_t k = 0; k < parts[r.shard].blocks[r.block].parts.size(); ++k) {
        const std::size_t e = firstEntry[r.shard][r.block] + k;
        generated->push_back(e < made.size() ? std::move(made[e]) : PremadeBlock{});
      }
    }
    data.blocksWritten.push_back(std::move(parts[r.shard].blockOutlines[r.block]));
    Block block = std::move(parts[r.shard].blocks[r.block]);
    analysis::BlockStatistics s = parts[r.shard].statistics[r.block];
    block.id = s.blockId = static_cast<int>(a.blocks.size());
    for (int i : block.parcels) a.blockOf[i] = block.id;
    if (block.parts.size() > 1) ++a.multipartBlocks;
    a.clampedAMin += s.aMinClamped;
    a.clampedWMin += s.wMinClamped;
    a.blocks.push_back(std::move(block));
    a.statistics.push_back(s);
  }
  for (auto r : a.rightOfWay) a.rightOfWayCount += r != analysis::RightOfWay::No;
  // Stage times: the slowest shard's.
  auto slowest = [&](auto member) {
    std::map<std::string, double> most;
    std::vector<std::string> order;
    for (const ShardPart& p : parts) {
      for (const auto& [name, s] : p.*member) {
        if (!most.count(name)) order.push_back(name);
        most[name] = std::max(most[name], s);
      }
    }
    Timings t;
    for (const auto& name : order) t.add(name, most[name]);
    return t;
  };
  layer.timings = slowest(&ShardPart::readTimings);
  a.timings = slowest(&ShardPart::analysisTimings);
  return data;
}

std::string encodeShard(const ShardPart& p) {
  Writer w;
  w.text(kMagic);
  w.text(version());
  w.pod(p.index);
  w.pod(p.count);
  w.text(p.path);
  w.text(p.layerName);
  w.pods(p.frame);
  w.text(p.crs.wkt);
  w.text(p.crs.name);
  w.pod(static_cast<std::uint8_t>(p.crs.assumedLonLat));
  w.pod(static_cast<std::uint8_t>(p.crs.overridden));
  w.pod(p.report);
  w.pod(static_cast<std::uint64_t>(p.parcels.size()));
  for (const Parcel& parcel : p.parcels) {
    w.polygon(parcel.shape);
    w.pod(parcel.sourceFid);
    w.pod(parcel.part);
    w.pod(parcel.stackCount);
    w.pod(static_cast<std::uint8_t>(parcel.repaired));
    w.pod(parcel.featureKey);
  }
  w.pod(static_cast<std::uint64_t>(p.fields.size()));
  for (const auto& f : p.fields) w.pods(f);
  w.pods(p.metrics);
  w.pods(p.rightOfWay);
  w.pod(static_cast<std::uint64_t>(p.blocks.size()));
  for (const Block& b : p.blocks) {
    w.pod(static_cast<std::uint64_t>(b.parts.size()));
    for (const Polygon& part : b.parts) w.polygon(part);
    w.pods(b.parcels);
    w.pod(b.key);
  }
  w.pods(p.statistics);
  w.geometries(p.blockOutlines);
  w.pod(static_cast<std::uint64_t>(p.generated.size()));
  for (const PremadeBlock& g : p.generated) w.premade(g);
  w.pod(p.blocksGenerated);
  w.pod(p.generateSeconds);
  w.timings(p.readTimings);
  w.timings(p.analysisTimings);
  w.pod(p.layerFeatures);
  w.pod(p.reads);
  w.pod(p.parcelsRead);
  w.pod(p.seconds);
  std::string bytes = w.take();
  const Key sum = checksum(bytes);
  bytes.append(reinterpret_cast<const char*>(&sum), sizeof sum);
  return bytes;
}

ShardPart decodeShard(std::string_view bytes, const std::string& what) {
  Reader r(bytes.substr(0, bytes.size() - std::min(bytes.size(), sizeof(Key))), what);
  if (r.text() != kMagic || r.text() != version()) r.fail();
  // The last 8 bytes: the checksum of the others (a part damaged on its way
  // or on disk is refused, not merged).
  Key sum = 0;
  std::memcpy(&sum, bytes.data() + bytes.size() - sizeof sum, sizeof sum);
  if (sum != checksum(bytes.substr(0, bytes.size() - sizeof sum))) {
    throw inputError(what + ": a damaged shard (its checksum does not match its contents)");
  }
  ShardPart p;
  p.index = r.pod<int>();
  p.count = r.pod<int>();
  p.path = r.text();
  p.layerName = r.text();
  p.frame = r.pods<double>();
  p.crs.wkt = r.text();
  p.crs.name = r.text();
  p.crs.assumedLonLat = r.flag();
  p.crs.overridden = r.flag();
  p.report = r.pod<io::CleaningReport>();
  constexpr std::size_t kMinParcelBytes = 3 * sizeof(std::uint64_t) + sizeof(std::int64_t) + 2 * sizeof(int) + 1;
  p.parcels.resize(r.count(kMinParcelBytes));
  for (Parcel& parcel : p.parcels) {
    parcel.shape = r.polygon();
    parcel.sourceFid = r.pod<std::int64_t>();
    parcel.part = r.pod<int>();
    parcel.stackCount = r.pod<int>();
    parcel.repaired = r.flag();
    parcel.featureKey = r.pod<Key>();
  }
  p.fields.resize(r.count(sizeof(std::uint64_t)));
  for (auto& f : p.fields) f = r.pods<double>();
  p.metrics = r.pods<analysis::ParcelMetrics>();
  p.rightOfWay = r.pods<analysis::RightOfWay>();
  p.blocks.resize(r.count(3 * sizeof(std::uint64_t)));
  for (Block& b : p.blocks) {
    b.parts.resize(r.count(sizeof(std::uint64_t)));
    for (Polygon& part : b.parts) part = r.polygon();
    b.parcels = r.pods<int>();
    b.key = r.pod<Key>();
  }
  p.statistics = r.pods<analysis::BlockStatistics>();
  p.blockOutlines = r.geometries();
  p.generated.resize(r.count(1));
  for (PremadeBlock& g : p.generated) g = r.premade();
  p.blocksGenerated = r.pod<std::int64_t>();
  p.generateSeconds = r.pod<double>();
  p.readTimings = r.timings();
  p.analysisTimings = r.timings();
  p.layerFeatures = r.pod<std::int64_t>();
  p.reads = r.pod<int>();
  p.parcelsRead = r.pod<std::int64_t>();
  p.seconds = r.pod<double>();
  constexpr int kMaxShards = 1 << 20;
  if (!r.done() || p.count < 1 || p.count > kMaxShards || p.index < 0 || p.index >= p.count ||
      p.metrics.size() != p.parcels.size() || p.rightOfWay.size() != p.parcels.size() ||
      p.statistics.size() != p.blocks.size() || p.blockOutlines.size() != p.blocks.size() ||
      (!p.fields.empty() && p.fields.size() != p.parcels.size()) || (p.frame.size() != 4 && p.frame.size() != 6)) {
    r.fail();
  }
  for (const auto& f : p.fields) {
    if (f.size() != p.fields.front().size()) r.fail();
  }
  std::size_t entries = 0;
  for (const Block& b : p.blocks) entries += b.parts.size();
  if (!p.generated.empty() && p.generated.size() != entries) r.fail();
  // Each lot in exactly one block, each right-of-way parcel in none.
  std::vector<char> inBlock(p.parcels.size(), 0);
  for (const Block& b : p.blocks) {
    if (b.parcels.empty()) r.fail();
    for (int i : b.parcels) {
      if (i < 0 || static_cast<std::size_t>(i) >= p.parcels.size() || inBlock[static_cast<std::size_t>(i)]) r.fail();
      inBlock[static_cast<std::size_t>(i)] = 1;
    }
  }
  for (std::size_t i = 0; i < p.parcels.size(); ++i) {
    const auto role = static_cast<std::uint8_t>(p.rightOfWay[i]);
    if (role > static_cast<std::uint8_t>(analysis::RightOfWay::NetworkShape) || (role == 0) != (inBlock[i] == 1)) {
      r.fail();
    }
  }
  return p;
}

namespace {
// What run.json and shard.json say of a shard.
Json shardRecord(const ShardPart& p) {
  return Json::object()
      .set("shard", p.index)
      .set("blocks", static_cast<std::int64_t>(p.blocks.size()))
      .set("parcels", static_cast<std::int64_t>(p.parcels.size()))
      .set("parcels_read", p.parcelsRead)
      .set("windows_read", p.reads)
      .set("block_entries_generated", p.blocksGenerated)
      .set("seconds", p.seconds);
}
}  // namespace

PreparedObserved prepareMerged(std::vector<ShardPart> parts, int ranks, const io::ReadOptions& input) {
  Json shards = Json::array();
  for (const ShardPart& p : parts) shards.push(shardRecord(p));
  PreparedObserved prepared;
  prepared.premade = std::make_shared<std::vector<PremadeBlock>>();
  prepared.data = std::make_shared<const ObservedData>(mergeShards(std::move(parts), prepared.premade.get()));
  // A shard's window may hold nothing; the whole layer holding nothing usable
  // is told as one process tells it.
  if (prepared.data->layer.parcels.empty()) io::readParcels(input);
  prepared.ranks = ranks;
  prepared.shards = std::move(shards);
  return prepared;
}

JobOutcome runShard(const CompareRequest& request, int index, int count, const std::string& outDir,
                    const ProgressFn& progress) {
  io::OutputDirectory out(outDir, inputPaths(request));
  try {
    const ShardPart part = analyseShard(request, index, count, ShardReading{}, scaledProgress(progress, 0.0, 0.95));
    reportProgress(progress, 0.95, "writing");
    {
      std::ofstream file(out.stage("shard.bin"), std::ios::binary);
      const std::string bytes = encodeShard(part);
      file.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
      if (!file.flush()) throw ioError(outDir + "/shard.bin: cannot be written");
    }
    io::writeJson(out.stage("session.json"), sessionJson(withAbsolutePaths(request)));
    const Json record = shardRecord(part)
                            .set("shards", count)
                            .set("tool", "parcelscope")
                            .set("version", version())
                            .set("command", "compare --shard")
                            .set("input_as_given", request.input.path)
                            .set("metric", request.metric)
                            .set("vector_format", request.vectorFormat)
                            .set("parcels_format", request.parcelsFormat)
                            .set("outputs", Json::array().push("shard.bin").push("session.json").push("shard.json"));
    io::writeJson(out.stage("shard.json"), record);
    out.commit();
    reportProgress(progress, 1.0, "writing");
    return {record, "shard " + std::to_string(index) + " of " + std::to_string(count) + ": " +
                        std::to_string(part.blocks.size()) + " blocks, " + std::to_string(part.parcels.size()) +
                        " parcels (" + std::to_string(part.reads) + " windows read), " +
                        std::to_string(part.blocksGenerated) + " block entries subdivided; merge the shards with " +
                        "'parcelscope merge'"};
  } catch (const Error& e) {
    throw out.explain(e);
  }
}

std::pair<CompareRequest, PreparedObserved> readShards(const std::vector<std::string>& folders) {
  namespace fs = std::filesystem;
  if (folders.empty()) throw usageError("merge: give the folders of every shard");
  auto slurp = [](const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw inputError(file.string() + ": no such file (not a folder of 'compare --shard')");
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
  };
  std::vector<ShardPart> parts;
  std::string session;
  for (const std::string& folder : folders) {
    const std::string text = slurp(fs::path(folder) / "session.json");
    if (session.empty()) {
      session = text;
    } else if (text != session) {
      throw inputError(folder + ": a shard of another request (its session.json differs from " + folders.front() +
                       "'s)");
    }
    parts.push_back(decodeShard(slurp(fs::path(folder) / "shard.bin"), (fs::path(folder) / "shard.bin").string()));
  }
  CompareRequest request = readSession((fs::path(folders.front()) / "session.json").string());
  // The input path as the shards were given it, when it names the same file from here.
  const Json record = io::readJson((fs::path(folders.front()) / "shard.json").string());
  if (const Json* given = record.find("input_as_given"); given && given->isString()) {
    std::error_code ec;
    if (fs::equivalent(given->string(), request.input.path, ec) && !ec) request.input.path = given->string();
  }
  // What the session file does not hold: the outputs' forms.
  for (auto [key, field] : {std::pair<const char*, std::string*>{"metric", &request.metric},
                            {"vector_format", &request.vectorFormat},
                            {"parcels_format", &request.parcelsFormat}}) {
    if (const Json* v = record.find(key); v && v->isString()) *field = v->string();
  }
  request.readFrom = folders;  // --out must not replace a shard
  const int ranks = parts.front().count;
  PreparedObserved prepared = prepareMerged(std::move(parts), ranks, request.input);
  return {std::move(request), std::move(prepared)};
}

}  // namespace parcelscope::pipeline
