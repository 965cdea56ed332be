// Controller: the request the application edits and the bookkeeping of its
// updates, without a window or a thread. Reports are built here as the update
// worker builds them; the two tests of failures also run the real
// CompareSession on the bundled sample.
#include "parcelscope/pipeline/Controller.h"

#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "TestUtil.h"
#include "parcelscope/core/Error.h"
#include "parcelscope/pipeline/CompareSession.h"

namespace parcelscope::pipeline {
namespace {

using test::TempDir;

const std::string kSample = std::string(PARCELSCOPE_SOURCE_DIR) + "/datasets/sample/sample_town.geojson";

io::ReadOptions sampleInput() {
  io::ReadOptions input;
  input.path = kSample;
  input.where = "use <> 'ROW'";
  return input;
}

// A result whose neighbours and street access are measured, or still pending.
std::shared_ptr<const CompareResult> fakeResult(bool contextPending = false) {
  auto r = std::make_shared<CompareResult>();
  if (contextPending) r->generated.contextPending = {0};
  return r;
}

// The report the worker makes for the update `serial` of `controller`'s request.
UpdateReport reportOf(const Controller& controller, std::int64_t serial, bool contextPending = false) {
  UpdateReport report;
  report.result = fakeResult(contextPending);
  report.request = controller.request();
  report.serial = serial;
  report.contextPending = contextPending;
  return report;
}

Block blockWith(int id, Key key) {
  Block b;
  b.id = id;
  b.key = key;
  return b;
}

// Runs `controller`'s request through `session` as the worker does, and hands
// the report or the failure back to the controller. Returns the error message
// ("" when the update succeeded).
std::string runUpdate(Controller& controller, CompareSession& session, std::int64_t serial) {
  controller.submitted(serial);
  const CompareRequest request = controller.request();
  try {
    const CompareSession::Update u = session.update(request);
    UpdateReport report;
    report.result = u.result;
    report.request = request;
    report.serial = serial;
    report.reloaded = u.reloaded;
    controller.receive(report);
    return "";
  } catch (const Error& e) {
    EXPECT_TRUE(controller.failed(serial));
    return e.what();
  }
}

TEST(Controller, StartsWithDefaultsFiguresOffOnlyTheSeedExplicitAndNothingOpen) {
  const Controller c;
  EXPECT_FALSE(c.loaded());
  EXPECT_FALSE(c.busy());
  EXPECT_EQ(c.request().parameters.at("figures"), 0.0);
  EXPECT_EQ(c.request().parameters.at("omega"), defaultValues(compareParameters()).at("omega"));
  EXPECT_EQ(c.request().explicitParameters, std::set<std::string>{"seed"});
  EXPECT_TRUE(c.perBlockBounds());
}

TEST(Controller, SetParameterMarksItExplicitAndABoundMakesAllFourExplicit) {
  Controller c;
  c.setParameter("omega", 0.45);
  EXPECT_EQ(c.request().parameters.at("omega"), 0.45);
  EXPECT_TRUE(c.request().explicitParameters.count("omega"));
  EXPECT_TRUE(c.perBlockBounds());  // omega is no bound

  c.setParameter("w-max", 18);
  EXPECT_EQ(c.request().parameters.at("w-max"), 18.0);
  for (const char* bound : {"a-min", "a-max", "w-min", "w-max"}) {
    EXPECT_TRUE(c.request().explicitParameters.count(bound)) << bound;
  }
  EXPECT_FALSE(c.perBlockBounds());

  c.setPerBlockBounds(true);
  for (const char* bound : {"a-min", "a-max", "w-min", "w-max"}) {
    EXPECT_FALSE(c.request().explicitParameters.count(bound)) << bound;
  }
  EXPECT_TRUE(c.request().explicitParameters.count("omega"));
  EXPECT_EQ(c.request().parameters.at("w-max"), 18.0);  // the value stays, unused per block
}

TEST(Controller, OverridesAreKeyedByBlockKeyAndReplaceAVersionOneOverrideById) {
  TempDir dir;
  const std::string session = dir.write("v1.json", R"({"parcelscope_session": 1, "input": {"path": "town.geojson"},
      "style": "obb", "overrides": [{"block_id": 4, "style": "skeleton", "parameters": {"a-max": 400}},
                                    {"block_id": 5, "style": "obb", "parameters": {}}]})");
  Controller c;
  c.openSession(session);
  ASSERT_EQ(c.request().overridesById.size(), 2u);
  const Block four = blockWith(4, 0xabcdef0123456789ULL), five = blockWith(5, 0x1111);
  EXPECT_TRUE(c.overridden(four));

  BlockOverride o;
  o.style = "skeleton";
  o.parameters = {{"w-max", 14.0}};
  c.overrideBlock(four, o);
  ASSERT_EQ(c.request().overrides.count(four.key), 1u);
  EXPECT_EQ(c.request().overrides.at(four.key).parameters.at("w-max"), 14.0);
  EXPECT_EQ(c.request().overridesById.count(4), 0u);  // the same block, by id: replaced
  EXPECT_EQ(c.request().overridesById.count(5), 1u);
  EXPECT_TRUE(c.overridden(four));

  // An override follows the block's key, not its id (which moves with the order of features).
  EXPECT_FALSE(c.overridden(blockWith(7, 0x2222)));
  EXPECT_TRUE(c.overridden(blockWith(9, four.key)));

  c.clearOverride(five);
  EXPECT_FALSE(c.overridden(five));
  c.clearOverride(four);
  EXPECT_FALSE(c.overridden(four));
  EXPECT_TRUE(c.request().overrides.empty());
  EXPECT_TRUE(c.request().overridesById.empty());
}

TEST(Controller, OpeningAnInputDropsTheFormerOverridesAndKeepsTheRest) {
  Controller c;
  c.setStyle("skeleton");
  c.setParameter("seed", 4);
  c.openInput(sampleInput());
  EXPECT_TRUE(c.loaded());
  c.overrideBlock(blockWith(1, 0x42), BlockOverride{"obb", {}});
  io::ReadOptions other;
  other.path = "/elsewhere/other.gpkg";
  other.layer = "lots";
  c.openInput(other);
  EXPECT_EQ(c.request().input.path, other.path);
  EXPECT_EQ(c.request().input.layer, "lots");
  EXPECT_EQ(c.request().input.where, "");
  EXPECT_TRUE(c.request().overrides.empty());
  EXPECT_EQ(c.request().style, "skeleton");
  EXPECT_EQ(c.request().parameters.at("seed"), 4.0);
}

TEST(Controller, SessionsRoundTripAndFiguresStayOff) {
  TempDir dir;
  Controller a;
  a.openInput(sampleInput());
  a.setStyle("skeleton");
  a.setMetric("p_area");
  a.setParameter("w-max", 21.5);
  a.overrideBlock(blockWith(3, 0x77), BlockOverride{"obb", {{"a-max", 420.0}}});
  a.saveSession(dir.file("s.json"));

  Controller b;
  b.openSession(dir.file("s.json"));
  EXPECT_TRUE(b.loaded());
  EXPECT_EQ(b.request().input.path, kSample);
  EXPECT_EQ(b.request().input.where, "use <> 'ROW'");
  EXPECT_EQ(b.request().style, "skeleton");
  EXPECT_EQ(b.request().metric, "p_area");
  EXPECT_EQ(b.request().parameters.at("w-max"), 21.5);
  EXPECT_EQ(b.request().explicitParameters, a.request().explicitParameters);
  EXPECT_EQ(b.request().overrides.at(0x77).parameters.at("a-max"), 420.0);
  EXPECT_EQ(b.request().parameters.at("figures"), 0.0);

  // A file that cannot be read leaves the request as it was.
  const CompareRequest before = b.request();
  EXPECT_THROW(b.openSession(dir.write("bad.json", "{not json")), Error);
  EXPECT_EQ(b.request().style, before.style);
  EXPECT_EQ(b.request().input.path, before.input.path);
}

TEST(Controller, AReportOfAnOlderSerialIsNotShown) {
  Controller c;
  c.openInput(sampleInput());
  c.submitted(1);
  const UpdateReport first = reportOf(c, 1);
  EXPECT_EQ(c.receive(first).action, Controller::Action::Draw);
  c.setParameter("seed", 2);
  c.submitted(2);
  c.setParameter("seed", 3);
  c.submitted(3);
  // A result in between of update 2, which 3 supersedes: not drawn.
  UpdateReport partial = reportOf(c, 2);
  partial.partial = true;
  EXPECT_EQ(c.receive(partial).action, Controller::Action::Ignore);
  EXPECT_EQ(c.shownResult(), first.result);
  EXPECT_TRUE(c.busy());

  // Update 3 drawn; a late report of 2 may not replace it.
  const UpdateReport third = reportOf(c, 3);
  EXPECT_EQ(c.receive(third).action, Controller::Action::Draw);
  const UpdateReport late = reportOf(c, 2);
  EXPECT_EQ(c.receive(late).action, Controller::Action::Ignore);
  EXPECT_EQ(c.shownResult(), third.result);
  EXPECT_EQ(c.finalResult(), third.result);
  EXPECT_EQ(c.drawnSerial(), 3);
  EXPECT_FALSE(c.busy());
}

TEST(Controller, APartialReportIsShownThenTheFinalOneCompletesTheUpdate) {
  Controller c;
  c.openInput(sampleInput());
  c.submitted(1);
  const UpdateReport first = reportOf(c, 1);
  EXPECT_TRUE(c.receive(first).newInput);  // nothing was shown: fit the views

  c.setParameter("omega", 0.5);
  c.submitted(2);
  EXPECT_TRUE(c.awaitingViews(2));
  UpdateReport partial = reportOf(c, 2);
  partial.partial = true;
  partial.blocksRegenerated = 3;
  partial.blocksTotal = 10;
  const Controller::Decision d = c.receive(partial);
  EXPECT_EQ(d.action, Controller::Action::Draw);
  EXPECT_FALSE(d.newInput);
  EXPECT_EQ(c.shownResult(), partial.result);
  EXPECT_EQ(c.shownRequest().parameters.at("omega"), 0.5);
  EXPECT_EQ(c.finalResult(), first.result);  // exports keep the last complete result
  EXPECT_TRUE(c.busy());
  EXPECT_FALSE(c.awaitingViews(2));  // the result in between says how far it is
  EXPECT_EQ(c.drawnSerial(), 1);

  UpdateReport last = reportOf(c, 2);
  EXPECT_EQ(c.receive(last).action, Controller::Action::Draw);
  EXPECT_EQ(c.shownResult(), last.result);
  EXPECT_EQ(c.finalResult(), last.result);
  EXPECT_EQ(c.finalRequest().parameters.at("omega"), 0.5);
  EXPECT_EQ(c.completeSerial(), 2);
  EXPECT_FALSE(c.busy());
}

TEST(Controller, AContextCompletionChangesTheNumbersOnlyUnlessTheViewsNeedIt) {
  Controller c;
  c.openInput(sampleInput());
  c.submitted(1);
  c.receive(reportOf(c, 1));

  // Shapes first: drawn, but not complete (exports keep the former result).
  c.setParameter("omega", 0.45);
  c.submitted(2);
  const UpdateReport shapes = reportOf(c, 2, /*contextPending=*/true);
  EXPECT_EQ(c.receive(shapes).action, Controller::Action::Draw);
  EXPECT_EQ(c.drawnSerial(), 2);
  EXPECT_NE(c.finalResult(), shapes.result);
  EXPECT_TRUE(c.busy());
  UpdateReport completed = reportOf(c, 2);
  completed.completesContext = true;
  EXPECT_EQ(c.receive(completed).action, Controller::Action::Numbers);
  EXPECT_EQ(c.shownResult(), completed.result);
  EXPECT_EQ(c.finalResult(), completed.result);
  EXPECT_EQ(c.completeSerial(), 2);
  EXPECT_FALSE(c.busy());

  // Coloured by street access, the views wait for the completed result.
  c.setMetric("street_access");
  c.setParameter("omega", 0.5);
  c.submitted(3);
  const UpdateReport pending = reportOf(c, 3, /*contextPending=*/true);
  EXPECT_EQ(c.receive(pending).action, Controller::Action::Ignore);
  EXPECT_EQ(c.shownResult(), completed.result);
  EXPECT_TRUE(c.busy());
  UpdateReport full = reportOf(c, 3);
  full.completesContext = true;
  full.reloaded = true;  // as its first report said; that one was not drawn
  const Controller::Decision d = c.receive(full);
  EXPECT_EQ(d.action, Controller::Action::Draw);
  EXPECT_TRUE(d.newInput);
  EXPECT_EQ(c.shownRequest().metric, "street_access");
  EXPECT_FALSE(c.busy());
}

TEST(Controller, AFailedOrCancelledUpdateOfAnOlderSerialChangesNothing) {
  Controller c;
  c.openInput(sampleInput());
  c.submitted(1);
  c.setParameter("seed", 8);
  c.submitted(2);
  EXPECT_FALSE(c.failed(1));
  EXPECT_FALSE(c.cancelled(1));
  EXPECT_TRUE(c.busy());
  EXPECT_EQ(c.request().parameters.at("seed"), 8.0);
  EXPECT_EQ(c.failedRequest(), nullptr);

  // Cancelling the newest keeps its edits: they were not wrong, only stopped.
  EXPECT_TRUE(c.cancelled(2));
  EXPECT_FALSE(c.busy());
  EXPECT_EQ(c.request().parameters.at("seed"), 8.0);
  EXPECT_EQ(c.failedRequest(), nullptr);
}

TEST(Controller, AFailedUpdateKeepsTheLastGoodRequestAndTheNextEditBuildsOnIt) {
  Controller c;
  c.openInput(sampleInput());
  c.submitted(1);
  const UpdateReport good = reportOf(c, 1);
  c.receive(good);

  c.setParameter("a-min", 5000);  // above a-max: the update fails
  c.setStyle("skeleton");
  c.submitted(2);
  c.setMetric("area");  // colouring needs no update: it stays
  ASSERT_TRUE(c.failed(2));
  EXPECT_FALSE(c.busy());
  ASSERT_NE(c.failedRequest(), nullptr);
  EXPECT_EQ(c.failedRequest()->parameters.at("a-min"), 5000.0);
  EXPECT_EQ(c.request().parameters.at("a-min"), good.request.parameters.at("a-min"));
  EXPECT_EQ(c.request().style, "obb");
  EXPECT_TRUE(c.perBlockBounds());
  EXPECT_EQ(c.request().metric, "area");
  EXPECT_EQ(c.shownResult(), good.result);
  EXPECT_EQ(c.finalResult(), good.result);

  c.setParameter("seed", 6);
  EXPECT_EQ(c.request().parameters.at("a-min"), good.request.parameters.at("a-min"));
  EXPECT_EQ(c.request().parameters.at("seed"), 6.0);
  c.submitted(3);
  EXPECT_EQ(c.failedRequest(), nullptr);
  EXPECT_EQ(c.submittedRequest().parameters.at("seed"), 6.0);
  EXPECT_TRUE(c.busy());
  // A result in between is no success: should update 3 fail after it, the request is 1's again.
  UpdateReport partial = reportOf(c, 3);
  partial.partial = true;
  EXPECT_EQ(c.receive(partial).action, Controller::Action::Draw);
  ASSERT_TRUE(c.failed(3));
  EXPECT_EQ(c.request().parameters.at("seed"), good.request.parameters.at("seed"));
  EXPECT_EQ(c.lastGoodRequest().parameters.at("seed"), good.request.parameters.at("seed"));
  EXPECT_EQ(c.finalResult(), good.result);
}

// The bug the controller fixed: after a file that cannot be read, every later
// slider change read that file again and failed again.
TEST(Controller, AFailedOpenDoesNotPoisonLaterEdits) {
  TempDir dir;
  const std::string broken = dir.write("broken.geojson", "{ this is not geojson");
  Controller c;
  CompareSession session;
  c.openInput(sampleInput());
  ASSERT_EQ(runUpdate(c, session, 1), "");
  const auto sample = c.shownResult();
  ASSERT_TRUE(sample);

  io::ReadOptions bad;
  bad.path = broken;
  c.openInput(bad);
  EXPECT_NE(runUpdate(c, session, 2).find("broken.geojson"), std::string::npos);
  EXPECT_EQ(c.request().input.path, kSample);
  EXPECT_EQ(c.request().input.where, "use <> 'ROW'");
  ASSERT_NE(c.failedRequest(), nullptr);
  EXPECT_EQ(c.failedRequest()->input.path, broken);  // to read it again with another CRS

  c.setParameter("seed", 5);
  EXPECT_EQ(runUpdate(c, session, 3), "");
  EXPECT_NE(c.shownResult(), sample);
  EXPECT_EQ(c.shownResult()->observed->analysis.blocks.size(), sample->observed->analysis.blocks.size());
  EXPECT_EQ(c.finalRequest().parameters.at("seed"), 5.0);
  EXPECT_FALSE(c.busy());
}

// A first open that fails leaves nothing open: later edits are not updates
// (nothing to read), and the edits made before the open stay.
TEST(Controller, AFailedFirstOpenLeavesNothingOpen) {
  Controller c;
  c.setParameter("omega", 0.4);
  io::ReadOptions missing;
  missing.path = "/nonexistent/parcels.gpkg";
  c.openInput(missing);
  ASSERT_TRUE(c.loaded());
  CompareSession session;
  EXPECT_NE(runUpdate(c, session, 1), "");
  EXPECT_FALSE(c.loaded());
  EXPECT_EQ(c.request().input.path, "");
  EXPECT_EQ(c.request().parameters.at("omega"), 0.4);
  c.setParameter("seed", 2);
  EXPECT_FALSE(c.loaded());
  c.openInput(sampleInput());
  EXPECT_EQ(runUpdate(c, session, 2), "");
  EXPECT_EQ(c.finalRequest().parameters.at("omega"), 0.4);
  EXPECT_EQ(c.finalRequest().parameters.at("seed"), 2.0);
}

}  // namespace
}  // namespace parcelscope::pipeline
