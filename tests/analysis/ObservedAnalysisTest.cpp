#include "parcelscope/analysis/ObservedAnalysis.h"

#include <gtest/gtest.h>

#include <cmath>

#include "TestUtil.h"

namespace parcelscope::analysis {
namespace {

using test::rect;

std::vector<Parcel> parcelsOf(const std::vector<Polygon>& shapes) {
  std::vector<Parcel> out;
  for (const auto& s : shapes) {
    Parcel p;
    p.shape = s;
    normalise(p.shape);
    out.push_back(p);
  }
  return out;
}

TEST(BlockStatistics, MeansDeviationsAndDerivedBounds) {
  const BlockStatistics s = blockStatistics({100, 200, 300}, {10, 12, 14}, 1.0);
  EXPECT_EQ(s.parcelCount, 3);
  EXPECT_DOUBLE_EQ(s.meanArea, 200);
  EXPECT_DOUBLE_EQ(s.sdArea, 100);
  EXPECT_DOUBLE_EQ(s.meanWidth, 12);
  EXPECT_DOUBLE_EQ(s.sdWidth, 2);
  EXPECT_DOUBLE_EQ(s.aMin, 100);
  EXPECT_DOUBLE_EQ(s.aMax, 300);
  EXPECT_DOUBLE_EQ(s.wMin, 10);
  EXPECT_DOUBLE_EQ(s.wMax, 14);
  EXPECT_FALSE(s.aMinClamped);
}

TEST(BlockStatistics, LowerBoundsAreClampedAndFlagged) {
  const BlockStatistics s = blockStatistics({100, 200, 300}, {10, 12, 14}, 2.0);
  EXPECT_TRUE(s.aMinClamped);
  EXPECT_DOUBLE_EQ(s.aMin, 20);  // 10% of the mean area
  EXPECT_FALSE(s.wMinClamped);   // 12 - 2 * 2 = 8 > 1.2
  EXPECT_DOUBLE_EQ(s.aMax, 400);
  const BlockStatistics one = blockStatistics({50}, {5}, 2.0);
  EXPECT_DOUBLE_EQ(one.sdArea, 0);
  EXPECT_DOUBLE_EQ(one.aMin, 50);
}

// --derive robust: median -/+ k x 1.4826 MAD, which one large lot does not
// pull up; the statistics reported stay the mean and standard deviation.
TEST(BlockStatistics, RobustBoundsComeFromMedianAndMad) {
  const std::vector<double> areas = {100, 200, 300, 400, 10000}, widths = {8, 10, 12, 14, 60};
  const BlockStatistics paper = blockStatistics(areas, widths, BoundsRule(2.0, false));
  const BlockStatistics robust = blockStatistics(areas, widths, BoundsRule(2.0, true));
  // median 300, MAD = median(200, 100, 0, 100, 9700) = 100
  EXPECT_DOUBLE_EQ(robust.aMax, 300 + 2 * 1.4826 * 100);
  EXPECT_DOUBLE_EQ(robust.aMin, 30);  // 300 - 296.5, below 10 % of the median: clamped there
  EXPECT_TRUE(robust.aMinClamped);
  // widths: median 12, MAD = median(4, 2, 0, 2, 48) = 2
  EXPECT_DOUBLE_EQ(robust.wMax, 12 + 2 * 1.4826 * 2);
  EXPECT_GT(paper.aMax, 10000);
  EXPECT_DOUBLE_EQ(robust.meanArea, paper.meanArea);
  EXPECT_DOUBLE_EQ(robust.sdArea, paper.sdArea);
  // An even count takes the mean of the two middle values.
  EXPECT_DOUBLE_EQ(blockStatistics({100, 200, 300, 400}, {1, 2, 3, 4}, BoundsRule(0.0, true)).aMax, 250);
  // The parameter selects it.
  EXPECT_TRUE(analysisOptionsFrom({{"derive", 1}}).bounds().robust);
  EXPECT_FALSE(analysisOptionsFrom({}).bounds().robust);
}

TEST(ObservedAnalysis, TouchingAndNearlyTouchingLotsFormBlocks) {
  // A 2 x 2 block of 10 m lots with a 0.5 m digitising gap, and a lone lot 30 m away.
  const auto parcels = parcelsOf(
      {rect(0, 0, 10, 10), rect(10.5, 0, 20, 10), rect(0, 10, 10, 20), rect(10.5, 10, 20, 20), rect(50, 0, 60, 10)});
  AnalysisOptions o;
  o.blockTolerance = 1.0;
  const ObservedAnalysis a = analyseParcels(parcels, o);
  ASSERT_EQ(a.blocks.size(), 2u);
  EXPECT_EQ(a.blockOf, (std::vector<int>{0, 0, 0, 0, 1}));
  EXPECT_EQ(a.blocks[0].parts.size(), 1u);
  EXPECT_NEAR(a.statistics[0].blockArea, 20 * 20, 1e-6);  // the gap is closed, corners kept
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(a.metrics[i].neighbours, 2) << i;                          // corner contacts do not count
    EXPECT_NEAR(a.metrics[i].frontage, i % 2 ? 19.5 : 20.0, 1e-6) << i;  // two whole sides on the outline
    EXPECT_TRUE(a.metrics[i].streetAccess);
  }
  EXPECT_EQ(a.metrics[4].neighbours, 0);
  EXPECT_NEAR(a.metrics[4].frontage, 40, 1e-6);
  // With no tolerance the gap splits the block in two.
  o.blockTolerance = 0.0;
  EXPECT_EQ(analyseParcels(parcels, o).blocks.size(), 3u);
}

TEST(ObservedAnalysis, LargeToleranceKeepsALoneBlockAndDoesNotInventFrontage) {
  // A lone lot: its block is the lot itself whatever the tolerance.
  AnalysisOptions wide;
  wide.blockTolerance = 30;
  const ObservedAnalysis lone = analyseParcels(parcelsOf({rect(0, 0, 20, 20)}), wide);
  ASSERT_EQ(lone.blocks.size(), 1u);
  ASSERT_EQ(lone.blocks[0].parts.size(), 1u);
  EXPECT_NEAR(lone.statistics[0].blockArea, 400, 1e-6);
  EXPECT_TRUE(lone.metrics[0].streetAccess);
  // 3 rows of 8 m deep lots: the middle row has no frontage, even with a 10 m tolerance.
  std::vector<Polygon> shapes;
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 4; ++col) shapes.push_back(rect(col * 20, row * 8, col * 20 + 20, row * 8 + 8));
  wide.blockTolerance = 10;
  const ObservedAnalysis grid = analyseParcels(parcelsOf(shapes), wide);
  EXPECT_NEAR(grid.metrics[5].frontage, 0, 1e-9);
  EXPECT_NEAR(grid.metrics[6].frontage, 0, 1e-9);
  EXPECT_FALSE(grid.metrics[5].streetAccess);
}

TEST(ObservedAnalysis, InnerLotHasNoStreetAccess) {
  // 3 x 3 grid: the middle lot touches no street.
  std::vector<Polygon> shapes;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) shapes.push_back(rect(i * 10, j * 10, i * 10 + 10, j * 10 + 10));
  const ObservedAnalysis a = analyseParcels(parcelsOf(shapes), {});
  ASSERT_EQ(a.blocks.size(), 1u);
  EXPECT_FALSE(a.metrics[4].streetAccess);
  EXPECT_NEAR(a.metrics[4].frontage, 0, 1e-9);
  EXPECT_EQ(a.metrics[4].neighbours, 4);
  EXPECT_NEAR(a.statistics[0].streetAccessShare, 8.0 / 9.0, 1e-12);
}

TEST(ObservedAnalysis, StreetRingAroundBlocksIsRightOfWay) {
  // A 10 m wide street ring whose hole holds a block of two lots; another block outside.
  Polygon street = rect(0, 0, 100, 100);
  street.holes.push_back({{10, 10}, {10, 90}, {90, 90}, {90, 10}});
  const auto parcels = parcelsOf({street, rect(10, 10, 50, 90), rect(50, 10, 90, 90), rect(100, 0, 140, 40)});
  const ObservedAnalysis a = analyseParcels(parcels, {});
  EXPECT_EQ(a.rightOfWay[0], RightOfWay::HolesHoldParcels);
  EXPECT_EQ(a.rightOfWayCount, 1);
  EXPECT_EQ(a.blockOf[0], -1);
  ASSERT_EQ(a.blocks.size(), 2u);  // without the street, the inner and outer lots are apart
  AnalysisOptions keep;
  keep.detectRightOfWay = false;
  EXPECT_EQ(analyseParcels(parcels, keep).blocks.size(), 1u);
}

TEST(ObservedAnalysis, LotWithEnclaveIsNotRightOfWay) {
  Polygon lot = rect(0, 0, 30, 20);
  lot.holes.push_back({{10, 5}, {10, 15}, {20, 15}, {20, 5}});
  const ObservedAnalysis a = analyseParcels(parcelsOf({lot, rect(10, 5, 20, 15)}), {});
  EXPECT_EQ(a.rightOfWayCount, 0);
  EXPECT_EQ(a.blocks.size(), 1u);
}

TEST(ObservedAnalysis, TablesHaveOneRowPerParcelAndBlock) {
  const auto parcels = parcelsOf({rect(0, 0, 10, 10), rect(10, 0, 20, 10)});
  const ObservedAnalysis a = analyseParcels(parcels, {});
  const Table p = parcelTable(parcels, a);
  const Table b = blockTable(a);
  ASSERT_EQ(p.rows.size(), 2u);
  ASSERT_EQ(b.rows.size(), 1u);
  EXPECT_DOUBLE_EQ(std::get<double>(p.rows[1][p.column("area")]), 100.0);
  EXPECT_EQ(std::get<std::int64_t>(b.rows[0][b.column("parcel_count")]), 2);
}

TEST(MeasureParcels, LargeGridsCountNeighboursAndFrontageExactly) {
  // Four blocks of 60 x 60 squares of 10 m, far apart: enough candidate pairs
  // for contacts to measure them in parallel chunks, and frontage block by
  // block in parallel. Every count is known.
  constexpr int kSide = 60;
  std::vector<Polygon> shapes;
  std::vector<Block> blocks;
  for (int b = 0; b < 4; ++b) {
    Block block;
    block.id = b;
    const double ox = 1000.0 * b;
    block.parts = {rect(ox, 0, ox + 10 * kSide, 10 * kSide)};
    for (int i = 0; i < kSide; ++i) {
      for (int j = 0; j < kSide; ++j) {
        block.parcels.push_back(static_cast<int>(shapes.size()));
        shapes.push_back(rect(ox + 10 * i, 10 * j, ox + 10 * (i + 1), 10 * (j + 1)));
      }
    }
    blocks.push_back(block);
  }
  const auto metrics = measureParcels(shapes, blocks, 0.05, 1.0);
  for (int b = 0; b < 4; ++b) {
    for (int i = 0; i < kSide; ++i) {
      for (int j = 0; j < kSide; ++j) {
        const ParcelMetrics& m = metrics[static_cast<std::size_t>(b * kSide * kSide + i * kSide + j)];
        const int borders = (i == 0) + (i == kSide - 1) + (j == 0) + (j == kSide - 1);
        ASSERT_EQ(m.neighbours, 4 - borders) << b << " " << i << " " << j;
        ASSERT_NEAR(m.frontage, 10.0 * borders, 1e-9) << b << " " << i << " " << j;
        ASSERT_EQ(m.streetAccess, borders > 0);
      }
    }
  }
}

}  // namespace
}  // namespace parcelscope::analysis
