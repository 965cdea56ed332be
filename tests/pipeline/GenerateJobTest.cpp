// The generate job given observed data already read (as `compare` does) gives
// exactly the parcels it gives when it reads the input itself.
#include <gtest/gtest.h>

#include "TestUtil.h"
#include "parcelscope/pipeline/GenerateJob.h"

namespace parcelscope::pipeline {
namespace {

using namespace generation;

TEST(GenerateJob, ObservedDataPassedInGivesTheSameParcelsAsReadingTheInput) {
  GenerateRequest request;
  request.input.path = std::string(PARCELSCOPE_SOURCE_DIR) + "/datasets/sample/sample_town.geojson";
  request.input.where = "use <> 'ROW'";
  request.fromParcels = true;
  request.parameters = defaultValues(obbParameterDescriptions());
  for (const auto& [name, value] : defaultValues(analysis::analysisParameters())) {
    request.parameters.emplace(name, value);
  }
  const GeneratedParcels read = generate(request);
  const pipeline::ObservedData observed = pipeline::loadObserved(request.input, request.parameters);
  request.observed = &observed;
  const GeneratedParcels given = generate(request);

  ASSERT_EQ(given.parcels.size(), read.parcels.size());
  ASSERT_GT(given.parcels.size(), 100u);
  for (std::size_t i = 0; i < given.parcels.size(); ++i) {
    EXPECT_TRUE(sameVertices(given.parcels[i], read.parcels[i])) << i;
  }
  EXPECT_EQ(given.blockIds, read.blockIds);
  EXPECT_EQ(given.source->parcels.size(), observed.layer.parcels.size());
  ASSERT_EQ(given.timings.stages().size(), 2u);
  EXPECT_EQ(given.timings.stages()[0].first, "subdivide");
  EXPECT_EQ(given.timings.stages()[1].first, "measure");

  // The parcel table: one row per parcel, in block order, geometries alongside.
  std::vector<std::vector<Polygon>> geometries;
  const Table table = generatedParcelTable(given, &geometries);
  ASSERT_EQ(table.rows.size(), given.parcels.size());
  ASSERT_EQ(geometries.size(), given.parcels.size());
  const std::int64_t first = std::get<std::int64_t>(table.rows[0][table.column("parcel_id")]);
  EXPECT_DOUBLE_EQ(std::get<double>(table.rows[0][table.column("area")]), given.metrics[first].area);
  EXPECT_DOUBLE_EQ(area(geometries[0][0]), area(given.parcels[first]));
}

}  // namespace
}  // namespace parcelscope::pipeline

namespace parcelscope::pipeline {
namespace {

GenerateRequest templateOnTheSample() {
  GenerateRequest request;
  request.input.path = std::string(PARCELSCOPE_SOURCE_DIR) + "/datasets/sample/sample_town.geojson";
  request.input.where = "use <> 'ROW'";
  request.fromParcels = true;
  request.style = "template";
  request.parameters = generation::styleValues(generation::style("template"), {});
  for (const auto& [name, value] : defaultValues(analysis::analysisParameters())) {
    request.parameters.emplace(name, value);
  }
  return request;
}

// Bug: template with bounds of a few square metres ran for minutes on a block
// of the sample (merging each of ~1,200 parcels without street access looked
// at every parcel, pass after pass). It finishes, every block subdivided.
TEST(GenerateJob, TemplateWithTinyBoundsFinishesAndSubdivides) {
  GenerateRequest request = templateOnTheSample();
  const pipeline::ObservedData observed = pipeline::loadObserved(request.input, request.parameters);
  request.observed = &observed;
  request.parameters["a-min"] = 0.001;
  request.parameters["a-max"] = 5;
  request.parameters["w-min"] = 0.001;
  request.parameters["w-max"] = 0.5;
  request.explicitParameters = {"a-min", "a-max", "w-min", "w-max"};
  const GeneratedParcels g = generate(request);
  // Every block subdivided (by template, or by obb where merging went over its budget).
  EXPECT_GT(g.parcels.size(), 10 * g.blocks.size());
  bool budget = false;
  for (const std::string& f : g.failures) {
    budget = budget || f.find("work budget: merging the parcels without street access") != std::string::npos;
    EXPECT_EQ(f.find("failed"), std::string::npos) << f;
  }
  EXPECT_TRUE(budget) << "no block went over the merge budget: the test no longer covers it";
}

// Bug: template with --a-min 0 split nothing (its aim, the bounds' geometric
// mean, was 0): it subdivides.
TEST(GenerateJob, TemplateWithAMinOfZeroSubdivides) {
  // The sample's parcels read as blocks: no observed parcels, so the aim is
  // the bounds' geometric mean.
  GenerateRequest request = templateOnTheSample();
  request.fromParcels = false;
  request.input.where = "use <> 'ROW' AND FID < 12";
  request.parameters["a-min"] = 0;
  request.parameters["w-min"] = 0;
  request.explicitParameters = {"a-min", "w-min"};
  const GeneratedParcels g = generate(request);
  ASSERT_GT(g.blocks.size(), 5u);
  EXPECT_GT(g.parcels.size(), 2 * g.blocks.size());  // it gave one parcel, or two, per block
}

}  // namespace
}  // namespace parcelscope::pipeline
