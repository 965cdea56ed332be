#include "parcelscope/pipeline/BlockSource.h"

#include "parcelscope/pipeline/StreetsJob.h"

#include <cmath>
#include <utility>

namespace parcelscope::pipeline {

std::shared_ptr<generation::ObservedSample> observedSample(const std::vector<analysis::ParcelMetrics>& metrics,
                                                           const Block& block) {
  auto sample = std::make_shared<generation::ObservedSample>();
  double with = 0;
  for (int i : block.parcels) {
    const analysis::ParcelMetrics& m = metrics[static_cast<std::size_t>(i)];
    sample->areas.push_back(m.area);
    sample->widths.push_back(m.width);
    sample->aspectRatios.push_back(m.aspectRatio);
    sample->access.push_back(m.streetAccess ? 1 : 0);
    sample->frontages.push_back(m.frontage);
    with += m.streetAccess;
  }
  if (!sample->areas.empty()) sample->accessShare = with / static_cast<double>(sample->areas.size());
  return sample;
}

std::shared_ptr<generation::ObservedSample> observedSample(const analysis::ObservedAnalysis& analysis,
                                                           std::size_t block) {
  return observedSample(analysis.metrics, analysis.blocks[block]);
}

void appendObservedEntries(BlockInputs& in, const std::vector<Block>& blocks,
                           const std::vector<analysis::BlockStatistics>& statistics,
                           const std::vector<analysis::ParcelMetrics>& metrics) {
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    const auto& s = statistics[b];
    const Block& block = blocks[b];
    std::shared_ptr<const generation::ObservedSample> sample = observedSample(metrics, block);
    double blockArea = 0;
    for (const Polygon& part : block.parts) blockArea += area(part);
    for (std::size_t part = 0; part < block.parts.size(); ++part) {
      in.entries.push_back({block.id, block.parts[part], s.aMin, s.aMax, s.wMin, s.wMax, s.streetAccessShare, block.key,
                            static_cast<int>(part), sample, blockArea > 0 ? area(block.parts[part]) / blockArea : 1.0});
    }
  }
}

namespace {

class ObservedParcelBlocks : public BlockSource {
public:
  ObservedParcelBlocks(io::ReadOptions input, ParameterValues parameters, const ObservedData* observed)
      : input_(std::move(input)), parameters_(std::move(parameters)), observed_(observed) {}

  std::string kind() const override { return "observed-parcels"; }

  BlockInputs blocks(const ProgressFn& progress) const override {
    BlockInputs in;
    ObservedData loaded;
    if (!observed_) loaded = loadObserved(input_, parameters_, progress);
    const ObservedData& observed = observed_ ? *observed_ : loaded;
    appendObservedEntries(in, observed.analysis.blocks, observed.analysis.statistics, observed.analysis.metrics);
    if (observed.streets) {
      // Street blocks know the width of each street they face.
      for (const analysis::StreetBlock& b : observed.streets->blocks.blocks) {
        in.widths.push_back(analysis::facedWidths(observed.streets->graph, b));
      }
      in.streets = observed.streets;
    }
    if (observed_) {
      in.source = std::make_shared<const io::ParcelLayer>(observed_->layer);
    } else {
      in.source = std::make_shared<const io::ParcelLayer>(std::move(loaded.layer));
    }
    return in;
  }

private:
  io::ReadOptions input_;
  ParameterValues parameters_;
  const ObservedData* observed_;
};

class BlockLayer : public BlockSource {
public:
  explicit BlockLayer(io::ReadOptions input) : input_(std::move(input)) {}

  std::string kind() const override { return "block-layer"; }

  BlockInputs blocks(const ProgressFn& progress) const override {
    io::ReadOptions options = input_;
    options.numericFields = {"block_id", "a_min", "a_max", "w_min", "w_max", "street_access_share"};
    if (options.keyField.empty()) {
      options.keyField = "block_key";  // as `stats` writes it; absent: keys from the geometries
      options.keyFieldOptional = true;
    }
    auto layer = std::make_shared<io::ParcelLayer>(io::readParcels(options, progress));
    BlockInputs in;
    for (std::size_t i = 0; i < layer->parcels.size(); ++i) {
      const auto& f = layer->fields[i];
      const Parcel& p = layer->parcels[i];
      const std::int64_t id = std::isfinite(f[0]) ? static_cast<std::int64_t>(f[0]) : p.sourceFid;
      in.entries.push_back({id, p.shape, f[1], f[2], f[3], f[4], f[5], p.featureKey, p.part});
    }
    in.source = std::move(layer);
    return in;
  }

private:
  io::ReadOptions input_;
};

}  // namespace

BlockInputs streetNetworkInputs(std::shared_ptr<const StreetNetwork> network) {
  BlockInputs in;
  for (std::size_t b = 0; b < network->blocks.blocks.size(); ++b) {
    const analysis::StreetBlock& block = network->blocks.blocks[b];
    in.entries.push_back({static_cast<std::int64_t>(b), block.shape, NAN, NAN, NAN, NAN, NAN, block.key, 0, {}, 1.0});
    in.widths.push_back(analysis::facedWidths(network->graph, block));
  }
  auto layer = std::make_shared<io::ParcelLayer>();
  layer->path = network->layer.path;
  layer->layerName = network->layer.layerName;
  layer->frame = network->layer.frame;
  layer->crs = network->layer.crs;
  in.source = std::move(layer);
  in.streets = std::move(network);
  return in;
}

std::unique_ptr<BlockSource> observedParcelBlocks(const io::ReadOptions& input, const ParameterValues& parameters,
                                                  const ObservedData* observed) {
  return std::make_unique<ObservedParcelBlocks>(input, parameters, observed);
}

std::unique_ptr<BlockSource> blockLayer(const io::ReadOptions& input) { return std::make_unique<BlockLayer>(input); }

namespace {

// Blocks of a street network. With observed parcels, those are read and
// assigned to the street blocks (observed-parcel blocks regrouped); without,
// every block has no bounds of its own.
class StreetNetworkBlocks : public BlockSource {
public:
  StreetNetworkBlocks(io::StreetReadOptions streets, io::ReadOptions parcels, bool withParcels,
                      ParameterValues parameters)
      : streets_(std::move(streets)),
        parcels_(std::move(parcels)),
        withParcels_(withParcels),
        parameters_(std::move(parameters)) {}

  std::string kind() const override { return withParcels_ ? "street-network-with-parcels" : "street-network"; }

  BlockInputs blocks(const ProgressFn& progress) const override {
    if (withParcels_) {
      const ObservedData observed = loadObservedInStreetBlocks(parcels_, &streets_, parameters_, progress);
      return ObservedParcelBlocks(parcels_, parameters_, &observed).blocks({});
    }
    return streetNetworkInputs(
        std::make_shared<StreetNetwork>(buildStreetNetwork(streets_, parameters_, nullptr, progress)));
  }

private:
  io::StreetReadOptions streets_;
  io::ReadOptions parcels_;
  bool withParcels_;
  ParameterValues parameters_;
};

}  // namespace

std::unique_ptr<BlockSource> blockSourceOf(const GenerateRequest& request) {
  if (request.streets && !(request.fromParcels && request.observed)) {
    return std::make_unique<StreetNetworkBlocks>(*request.streets, request.input, request.fromParcels,
                                                 request.parameters);
  }
  if (request.fromParcels) return observedParcelBlocks(request.input, request.parameters, request.observed);
  return blockLayer(request.input);
}

}  // namespace parcelscope::pipeline
