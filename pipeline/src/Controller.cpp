#include "parcelscope/pipeline/Controller.h"

#include <utility>

#include "parcelscope/analysis/Comparison.h"
#include "parcelscope/core/Parallel.h"
#include "parcelscope/pipeline/CompareSession.h"

namespace parcelscope::pipeline {

namespace {

// The generator bounds that are per block unless explicit.
const char* const kBounds[] = {"a-min", "a-max", "w-min", "w-max"};

bool isBound(const std::string& name) {
  for (const char* b : kBounds) {
    if (name == b) return true;
  }
  return false;
}

}  // namespace

Controller::Controller() {
  request_.parameters = defaultValues(compareParameters());
  request_.parameters["figures"] = 0;
  request_.explicitParameters = {"seed"};
  good_ = {request_, loaded_};
}

void Controller::edited() {
  if (!loaded_) good_ = {request_, false};
}

void Controller::openInput(const io::ReadOptions& input) {
  request_.input = input;
  request_.overrides.clear();
  request_.overridesById.clear();
  loaded_ = true;
  edited();
}

void Controller::setStreets(std::optional<io::StreetReadOptions> streets) {
  request_.streets = std::move(streets);
  request_.overrides.clear();
  request_.overridesById.clear();
  edited();
}

void Controller::openSession(const std::string& path) {
  CompareRequest next = readSession(path);
  next.parameters["figures"] = 0;
  request_ = std::move(next);
  loaded_ = true;
  edited();
}

void Controller::saveSession(const std::string& path) const { exportSession(request_, path); }

void Controller::setParameter(const std::string& name, double value) {
  const bool perBlock = perBlockBounds();
  request_.parameters[name] = value;
  request_.explicitParameters.insert(name);
  if (isBound(name) && perBlock) {
    for (const char* b : kBounds) request_.explicitParameters.insert(b);
  }
  edited();
}

void Controller::setPerBlockBounds(bool perBlock) {
  for (const char* b : kBounds) {
    if (perBlock) {
      request_.explicitParameters.erase(b);
    } else {
      request_.explicitParameters.insert(b);
    }
  }
  edited();
}

bool Controller::perBlockBounds() const {
  for (const char* b : kBounds) {
    if (request_.explicitParameters.count(b)) return false;
  }
  return true;
}

void Controller::setStyle(const std::string& style) {
  request_.style = style;
  edited();
}

void Controller::setMetric(const std::string& metric) {
  request_.metric = metric;
  edited();
}

void Controller::overrideBlock(const Block& block, const BlockOverride& blockOverride) {
  request_.overridesById.erase(block.id);  // a version 1 session's override of the same block
  request_.overrides[block.key] = blockOverride;
  edited();
}

void Controller::setOverrides(const BlockOverrides& overrides) {
  request_.overrides = overrides;
  request_.overridesById.clear();
  edited();
}

void Controller::clearOverride(const Block& block) {
  request_.overrides.erase(block.key);
  request_.overridesById.erase(block.id);
  edited();
}

bool Controller::overridden(const Block& block) const {
  return request_.overrides.count(block.key) > 0 || request_.overridesById.count(block.id) > 0;
}

void Controller::submitted(std::int64_t serial) {
  pendingSerial_ = serial;
  submitted_ = request_;
  failedOrCancelled_ = false;
  failed_ = false;
}

Controller::Decision Controller::receive(const UpdateReport& report) {
  // The worker reports in the order of serials; nothing older than the views
  // drawn may replace them.
  if (report.serial < drawnSerial_) return {};
  if (report.partial && report.serial != pendingSerial_) return {};  // superseded already
  if (!report.partial && report.serial >= goodSerial_) {
    // Its update succeeded: a later failure comes back to this request.
    good_ = {report.request, true};
    goodSerial_ = report.serial;
  }
  const bool contextPending = !report.result->generated.contextPending.empty();
  const bool colouredByContext = analysis::parcelQuantity(request_.metric).context;
  // Coloured by a quantity not measured yet: the completed result follows.
  if (contextPending && colouredByContext) return {};
  if (report.completesContext && report.serial == drawnSerial_ && shown_ && !colouredByContext) {
    // Views and histogram show this result's shapes already: only the numbers change.
    releaseInBackground(std::exchange(shown_, report.result));
    releaseInBackground(std::exchange(final_, report.result));
    shownRequest_ = finalRequest_ = report.request;
    completeSerial_ = report.serial;
    return {Action::Numbers, false};
  }
  // (A completion drawn in full, as the colouring changed to what it brings,
  // is not a new input when its first report was drawn.)
  const bool newInput = !shown_ || (report.reloaded && report.serial != drawnSerial_);
  // The result replaced is freed in the background, not before drawing.
  releaseInBackground(std::exchange(shown_, report.result));
  shownRequest_ = report.request;
  if (report.partial) {
    partialSerial_ = report.serial;
  } else {
    if (!contextPending) {
      releaseInBackground(std::exchange(final_, report.result));
      finalRequest_ = report.request;
      completeSerial_ = report.serial;
    }
    drawnSerial_ = report.serial;
  }
  return {Action::Draw, newInput};
}

bool Controller::failed(std::int64_t serial) {
  if (serial != pendingSerial_) return false;
  failedOrCancelled_ = true;
  failed_ = true;
  // Back to the last good request; the colouring needs no update, so it stays.
  std::string metric = std::move(request_.metric);
  request_ = good_.request;
  request_.metric = std::move(metric);
  loaded_ = good_.loaded;
  return true;
}

bool Controller::cancelled(std::int64_t serial) {
  if (serial != pendingSerial_) return false;
  failedOrCancelled_ = true;
  return true;
}

bool Controller::awaitingViews(std::int64_t serial) const {
  return serial == pendingSerial_ && !failedOrCancelled_ && serial != completeSerial_ && serial != drawnSerial_ &&
         serial != partialSerial_;
}

CompareRequest Controller::shownRequest() const {
  CompareRequest r = shownRequest_;
  r.metric = request_.metric;
  return r;
}

}  // namespace parcelscope::pipeline
