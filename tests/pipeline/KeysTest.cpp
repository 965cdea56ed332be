// Stable keys: blocks and generated parcels keep their keys, seeds and
// overrides whatever the order of the input's features.
#include <gdal_priv.h>
#include <gtest/gtest.h>
#include <ogrsf_frmts.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "CompareStages.h"
#include "TestUtil.h"
#include "parcelscope/core/Error.h"
#include "parcelscope/io/Writers.h"
#include "parcelscope/pipeline/CompareJob.h"
#include "parcelscope/pipeline/CompareSession.h"

namespace parcelscope::pipeline {
namespace {

using test::TempDir;

const std::string kSample = std::string(PARCELSCOPE_SOURCE_DIR) + "/datasets/sample/sample_town.geojson";

// Copies the features of `from` into a new GeoPackage `to`, in input order or
// reversed; the feature of FID `edited` (if any) gets a vertex inserted in the
// middle of its first edge: the same shape and extent, another geometry.
void copyFeatures(const std::string& from, const std::string& to, bool reversed, GIntBig edited = -1) {
  GDALAllRegister();
  GDALDatasetUniquePtr in(GDALDataset::Open(from.c_str(), GDAL_OF_VECTOR));
  ASSERT_TRUE(in);
  OGRLayer* source = in->GetLayer(0);
  GDALDriver* driver = GetGDALDriverManager()->GetDriverByName("GPKG");
  GDALDatasetUniquePtr out(driver->Create(to.c_str(), 0, 0, 0, GDT_Unknown, nullptr));
  ASSERT_TRUE(out);
  OGRLayer* target = out->CreateLayer("parcels", source->GetSpatialRef(), wkbUnknown, nullptr);
  ASSERT_NE(target, nullptr);
  for (int i = 0; i < source->GetLayerDefn()->GetFieldCount(); ++i) {
    ASSERT_EQ(target->CreateField(source->GetLayerDefn()->GetFieldDefn(i)), OGRERR_NONE);
  }
  std::vector<OGRFeatureUniquePtr> features;
  for (auto& f : *source) features.emplace_back(f.release());
  if (reversed) std::reverse(features.begin(), features.end());
  for (auto& f : features) {
    OGRFeatureUniquePtr copy(OGRFeature::CreateFeature(target->GetLayerDefn()));
    copy->SetFrom(f.get());
    if (f->GetFID() == edited) {
      OGRGeometry* g = copy->GetGeometryRef();
      OGRPolygon* polygon =
          wkbFlatten(g->getGeometryType()) == wkbPolygon ? g->toPolygon() : g->toMultiPolygon()->getGeometryRef(0);
      OGRLinearRing* ring = polygon->getExteriorRing();
      OGRLinearRing longer;
      longer.addPoint(ring->getX(0), ring->getY(0));
      longer.addPoint(0.5 * (ring->getX(0) + ring->getX(1)), 0.5 * (ring->getY(0) + ring->getY(1)));
      for (int i = 1; i < ring->getNumPoints(); ++i) longer.addPoint(ring->getX(i), ring->getY(i));
      *ring = longer;
    }
    ASSERT_EQ(target->CreateFeature(copy.get()), OGRERR_NONE);
  }
}

CompareRequest request(const std::string& path) {
  CompareRequest r;
  r.input.path = path;
  r.input.where = "use <> 'ROW'";
  r.style = "auto";
  r.parameters = defaultValues(compareParameters());
  r.parameters["figures"] = 0;
  r.parameters["seed"] = 5;
  return r;
}

// Generated parcels by block key, each as its exact coordinates in block order.
std::map<Key, std::vector<std::vector<double>>> parcelsByBlockKey(const CompareResult& r) {
  std::map<Key, std::vector<std::vector<double>>> out;
  for (std::size_t b = 0; b < r.generated.blocks.size(); ++b) {
    for (int i : r.generated.blocks[b].parcels) {
      std::vector<double> xy;
      for (const Point& p : r.generated.parcels[i].outer) xy.insert(xy.end(), {p.x, p.y});
      out[r.generated.blockKeys[b]].push_back(std::move(xy));
    }
  }
  return out;
}

std::set<Key> blockKeys(const CompareResult& r) {
  std::set<Key> keys;
  for (const Block& b : r.observed->analysis.blocks) keys.insert(b.key);
  return keys;
}

TEST(StableKeys, ReversedFeatureOrderGivesTheSameBlockKeysAndParcelsPerBlock) {
  TempDir dir;
  copyFeatures(kSample, dir.file("forward.gpkg"), false);
  copyFeatures(kSample, dir.file("reversed.gpkg"), true);
  const CompareResult forward = compare(request(dir.file("forward.gpkg")));
  const CompareResult reversed = compare(request(dir.file("reversed.gpkg")));
  const std::set<Key> keys = blockKeys(forward);
  EXPECT_EQ(keys.size(), forward.observed->analysis.blocks.size());  // no two blocks share a key
  EXPECT_EQ(keys, blockKeys(reversed));
  // Block ids follow the feature order: the reversed input numbers its blocks differently.
  bool renumbered = false;
  for (std::size_t b = 0; b < forward.observed->analysis.blocks.size(); ++b) {
    renumbered = renumbered || forward.observed->analysis.blocks[b].key != reversed.observed->analysis.blocks[b].key;
  }
  EXPECT_TRUE(renumbered) << "the test should exercise a renumbering";
  EXPECT_EQ(parcelsByBlockKey(forward), parcelsByBlockKey(reversed));
}

TEST(StableKeys, OverridesByKeyFollowTheirBlockWhenFeaturesAreReordered) {
  TempDir dir;
  copyFeatures(kSample, dir.file("forward.gpkg"), false);
  copyFeatures(kSample, dir.file("reversed.gpkg"), true);
  CompareRequest f = request(dir.file("forward.gpkg"));
  const CompareResult plain = compare(f);
  const Key target = plain.observed->analysis.blocks[3].key;
  // obb, whose parcels follow the bounds (auto may pick a style that follows the observed count).
  f.overrides[target].style = "obb";
  f.overrides[target].parameters = {{"a-max", 150.0}, {"a-min", 50.0}, {"w-min", 2.0}, {"w-max", 6.0}};
  CompareRequest r = f;
  r.input.path = dir.file("reversed.gpkg");
  const auto forward = parcelsByBlockKey(compare(f));
  const auto reversed = parcelsByBlockKey(compare(r));
  EXPECT_EQ(forward, reversed);
  EXPECT_GT(forward.at(target).size(), parcelsByBlockKey(plain).at(target).size());
  const auto before = parcelsByBlockKey(plain);
  for (const auto& [key, parcels] : forward) {
    if (key != target) {
      EXPECT_EQ(parcels, before.at(key)) << keyText(key);
    }
  }
}

TEST(StableKeys, SessionFilesWriteKeysAndStillReadBlockIds) {
  TempDir dir;
  CompareRequest r = request(kSample);
  const CompareResult plain = compare(r);
  const Block& block = plain.observed->analysis.blocks[2];
  r.overrides[block.key].style = "obb";
  io::writeJson(dir.file("v2.json"), sessionJson(r));
  EXPECT_NE(test::slurpFile(dir.file("v2.json")).find("\"block_key\": \"" + keyText(block.key) + "\""),
            std::string::npos);
  const CompareRequest back = readSession(dir.file("v2.json"));
  ASSERT_EQ(back.overrides.count(block.key), 1u);
  EXPECT_EQ(back.overrides.at(block.key).style, "obb");

  // A version 1 file names the block by id; it lands on the block of that id.
  std::ofstream(dir.file("v1.json")) << R"({"parcelscope_session": 1, "input": {"path": ")" << kSample
                                     << R"(", "where": "use <> 'ROW'"}, "style": "auto", "overrides": [{"block_id": )"
                                     << block.id << R"(, "style": "obb", "parameters": {"w-max": 9}}]})";
  CompareRequest old = readSession(dir.file("v1.json"));
  EXPECT_TRUE(old.overrides.empty());
  ASSERT_EQ(old.overridesById.count(block.id), 1u);
  old.parameters["figures"] = 0;
  const CompareResult viaId = compare(old);
  CompareRequest byKey = old;
  byKey.overridesById.clear();
  byKey.overrides[block.key] = old.overridesById.at(block.id);
  EXPECT_EQ(parcelsByBlockKey(viaId), parcelsByBlockKey(compare(byKey)));

  r.overrides.clear();
  r.overrides[0x0123456789abcdefull].style = "obb";
  EXPECT_THROW(compare(r), Error);
}

// A session that reads another input keeps the blocks it already made when
// they are the same blocks (key and shape): none for the same features in
// another order; all but the edited block when one parcel is left out.
TEST(StableKeys, ASessionReloadRegeneratesOnlyBlocksWhoseKeyOrShapeChanged) {
  TempDir dir;
  copyFeatures(kSample, dir.file("forward.gpkg"), false);
  copyFeatures(kSample, dir.file("reversed.gpkg"), true);
  CompareSession session;
  const auto first = session.update(request(dir.file("forward.gpkg")));
  EXPECT_EQ(first.blocksRegenerated, first.blocksTotal);
  const auto reordered = session.update(request(dir.file("reversed.gpkg")));
  EXPECT_TRUE(reordered.reloaded);
  EXPECT_EQ(reordered.blocksRegenerated, 0u);
  EXPECT_EQ(parcelsByBlockKey(*reordered.result), parcelsByBlockKey(compare(request(dir.file("reversed.gpkg")))));

  // One parcel of one block edited (a vertex inserted on an edge: its extent,
  // and so the local frame, stay): that block gets a new key, the others are
  // kept. Style obb: the skeleton styles also regenerate the neighbours whose
  // street widths, measured across to that block, change.
  const Block& victim = first.result->observed->analysis.blocks[4];
  const std::int64_t fid = first.result->observed->layer.parcels[victim.parcels.front()].sourceFid;
  copyFeatures(kSample, dir.file("edited.gpkg"), false, fid);
  CompareRequest obb = request(dir.file("forward.gpkg"));
  obb.style = "obb";
  session.update(obb);
  CompareRequest edited = obb;
  edited.input.path = dir.file("edited.gpkg");
  const auto edit = session.update(edited);
  EXPECT_TRUE(edit.reloaded);
  EXPECT_EQ(edit.blocksRegenerated, victim.parts.size());
  EXPECT_EQ(parcelsByBlockKey(*edit.result), parcelsByBlockKey(compare(edited)));
  EXPECT_EQ(edit.result->observed->analysis.blocks.size(), first.result->observed->analysis.blocks.size());
  EXPECT_EQ(blockKeys(*edit.result).count(victim.key), 0u);
}

TEST(StableKeys, ABlockLayerFromStatsKeepsTheKeysAndSeedsOfItsParcels) {
  TempDir dir;
  const ParameterValues values = defaultValues(analysis::analysisParameters());
  io::ReadOptions input;
  input.path = kSample;
  input.where = "use <> 'ROW'";
  runStats(input, values, dir.file("stats"));
  GenerateRequest fromParcels;
  fromParcels.input = input;
  fromParcels.fromParcels = true;
  fromParcels.parameters = defaultValues(generation::generationParameterDescriptions());
  GenerateRequest fromBlocks = fromParcels;
  fromBlocks.fromParcels = false;
  fromBlocks.input = {};
  fromBlocks.input.path = dir.file("stats") + "/blocks.gpkg";
  const BlockInputs a = prepareBlocks(fromParcels), b = prepareBlocks(fromBlocks);
  const auto pa = planBlocks(fromParcels, a), pb = planBlocks(fromBlocks, b);
  std::map<std::pair<Key, int>, std::uint64_t> seeds;
  for (std::size_t k = 0; k < a.entries.size(); ++k) seeds[{a.entries[k].blockKey, a.entries[k].part}] = pa[k].seed;
  ASSERT_EQ(a.entries.size(), b.entries.size());
  for (std::size_t k = 0; k < b.entries.size(); ++k) {
    const auto it = seeds.find({b.entries[k].blockKey, b.entries[k].part});
    ASSERT_NE(it, seeds.end()) << "block layer entry " << k << " has a key no observed block has";
    EXPECT_EQ(it->second, pb[k].seed);
  }
}

}  // namespace
}  // namespace parcelscope::pipeline

namespace parcelscope::pipeline {
namespace {

// A block of the generation that no observed block matches (as a block source
// other than the observed parcels can give) is compared with an empty
// observed side, after the observed blocks; nothing throws.
TEST(CompareStage, ABlockWithoutObservedParcelsIsComparedAsSuch) {
  CompareRequest r = request(kSample);
  r.style = "access";  // no unassigned land: every generated parcel is compared
  CompareResult result = compare(r);
  const std::size_t observedBlocks = result.observed->analysis.blocks.size();
  ASSERT_EQ(result.blocks.size(), observedBlocks);
  const std::size_t moved = result.generated.blocks[0].parcels.size();
  const std::int64_t formerBlock = result.generated.blockIds[0];
  const std::int64_t formerCount = result.blocks[formerBlock].comparison.generated.parcels;
  result.generated.blockIds[0] = 9999;
  result.generated.blockKeys[0] = 0x0123456789abcdefull;
  result.blocks.clear();
  detail::compareStage(result, r);
  ASSERT_EQ(result.blocks.size(), observedBlocks + 1);
  const analysis::BlockComparison& extra = result.blocks.back();
  EXPECT_EQ(extra.blockId, 9999);
  EXPECT_EQ(extra.blockKey, 0x0123456789abcdefull);
  EXPECT_EQ(extra.comparison.observed.parcels, 0);
  EXPECT_EQ(extra.comparison.generated.parcels, static_cast<std::int64_t>(moved));
  EXPECT_NEAR(extra.blockArea, area(result.generated.blocks[0].parts[0]), 1e-9);
  EXPECT_EQ(result.blocks[formerBlock].comparison.generated.parcels, formerCount - static_cast<std::int64_t>(moved));
  // The tables hold it too.
  EXPECT_EQ(analysis::blockComparisonTable(result.blocks).rows.size(), observedBlocks + 1);
}

}  // namespace
}  // namespace parcelscope::pipeline
