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
