// MainWindow's street editing mode (see MainWindow.h, "Street editing").
#include <QAction>
#include <QFileDialog>
#include <QInputDialog>
#include <QLabel>
#include <QLineEdit>
#include <QMenuBar>
#include <QMessageBox>
#include <QScrollArea>
#include <QStatusBar>
#include <QTextBrowser>
#include <QThreadPool>

#include <algorithm>
#include <cmath>
#include <limits>

#include "Laps.h"
#include "MainWindow.h"
#include "MapView.h"
#include "parcelscope/core/Error.h"
#include "parcelscope/pipeline/Inspect.h"
#include "parcelscope/viz/Scenes.h"

namespace parcelscope::gui {

namespace {

constexpr double kPickPixels = 8;       // a node or control point this close to the cursor is picked
constexpr double kStreetPixels = 6;     // a street this close is picked
constexpr double kNewStreetWidth = 10;  // m, a drawn street's width

double distanceToSegment(const Point& p, const Point& a, const Point& b) {
  const double dx = b.x - a.x, dy = b.y - a.y, length2 = dx * dx + dy * dy;
  double t = length2 > 0 ? ((p.x - a.x) * dx + (p.y - a.y) * dy) / length2 : 0;
  t = std::clamp(t, 0.0, 1.0);
  return std::hypot(p.x - (a.x + t * dx), p.y - (a.y + t * dy));
}

// Where a street's control points are: its curve's, else at the thirds of the segment between its nodes.
std::array<Point, 2> controlsOf(const analysis::RoadGraph& g, const analysis::RoadEdge& e) {
  if (e.controls) return *e.controls;
  const Point a = g.nodes[static_cast<std::size_t>(e.from)].at, b = g.nodes[static_cast<std::size_t>(e.to)].at;
  return {Point{a.x + (b.x - a.x) / 3, a.y + (b.y - a.y) / 3},
          Point{a.x + 2 * (b.x - a.x) / 3, a.y + 2 * (b.y - a.y) / 3}};
}

// Per node of `g`, 1 where a street ends (the study area's boundary is not edited).
std::vector<char> streetNodes(const analysis::RoadGraph& g) {
  std::vector<char> onStreet(g.nodes.size(), 0);
  for (const auto& e : g.edges) {
    if (!e.boundary) onStreet[static_cast<std::size_t>(e.from)] = onStreet[static_cast<std::size_t>(e.to)] = 1;
  }
  return onStreet;
}

int indexOfKey(const std::vector<Key>& keys, Key key) {
  const auto it = std::find(keys.begin(), keys.end(), key);
  return it == keys.end() ? -1 : static_cast<int>(it - keys.begin());
}

}  // namespace

std::vector<std::vector<Point>> MainWindow::centreLines(const analysis::RoadGraph& graph) {
  std::vector<std::vector<Point>> lines;
  for (const analysis::RoadEdge& e : graph.edges) {
    if (!e.boundary) lines.push_back(e.line);
  }
  return lines;
}

void MainWindow::buildEditMenu() {
  QMenu* edit = menuBar()->addMenu("&Edit");
  edit->setToolTipsVisible(true);
  editAction_ = edit->addAction("Edit &streets");
  editAction_->setObjectName("editStreetsAction");
  editAction_->setCheckable(true);
  editAction_->setShortcut(QKeySequence("Ctrl+E"));
  editAction_->setToolTip(
      "Edit the street network of the comparison in the procedural view: drag nodes, draw and delete streets, "
      "change widths and curves; the parcels follow (the command line's 'parcelscope edit')");
  connect(editAction_, &QAction::triggered, this, [this](bool on) { setEditing(on); });
  edit->addSeparator();
  undoAction_ = edit->addAction(
      "&Undo", this, [this] { undoEdit(); }, QKeySequence::Undo);
  redoAction_ = edit->addAction(
      "&Redo", this, [this] { redoEdit(); }, QKeySequence("Ctrl+Shift+Z"));
  edit->addSeparator();
  drawStreetAction_ = edit->addAction("&Draw street");
  drawStreetAction_->setCheckable(true);
  drawStreetAction_->setShortcut(QKeySequence("Ctrl+D"));
  drawStreetAction_->setToolTip("Click the new street's two ends (on a node to join it there)");
  connect(drawStreetAction_, &QAction::triggered, this, [this](bool on) { setDrawingStreet(on); });
  deleteStreetAction_ = edit->addAction(
      "De&lete street", this, [this] { deleteSelectedStreet(); }, QKeySequence::Delete);
  widthAction_ = edit->addAction("Street &width...", this, [this] {
    if (!editState_ || selectedStreet_ == 0) return;
    double current = kNewStreetWidth;
    for (const auto& e : editState_->snapshot->network().graph.edges) {
      if (e.key == selectedStreet_ && std::isfinite(e.width)) current = e.width;
    }
    bool ok = false;
    const double width = QInputDialog::getDouble(this, "Street width", "Width (m):", current, 0.5, 200, 1, &ok);
    if (ok) setSelectedStreetWidth(width);
  });
  curveAction_ = edit->addAction("&Curved street");
  curveAction_->setCheckable(true);
  curveAction_->setToolTip("Curve the selected street (then drag its two control points) or straighten it");
  connect(curveAction_, &QAction::triggered, this, [this](bool on) { setSelectedStreetCurved(on); });
  edit->addSeparator();
  labelAction_ = edit->addAction("&Label parcel...", this, [this] {
    if (!editState_ || selectedEditParcel_ == 0) return;
    const auto& labels = editState_->snapshot->labels();
    const auto it = labels.find(selectedEditParcel_);
    bool ok = false;
    const QString label =
        QInputDialog::getText(this, "Label parcel", "Label (empty: none):", QLineEdit::Normal,
                              it == labels.end() ? QString() : QString::fromStdString(it->second), &ok);
    if (ok) labelSelectedParcel(label);
  });
  lockAction_ = edit->addAction("L&ock parcel");
  lockAction_->setCheckable(true);
  lockAction_->setToolTip("A locked parcel keeps its shape when its block is subdivided again (while it fits)");
  connect(lockAction_, &QAction::triggered, this, [this](bool on) { lockSelectedParcel(on); });
  edit->addSeparator();
  saveEditsAction_ = edit->addAction("Sa&ve edits...", this, [this] {
    const QString path = QFileDialog::getSaveFileName(this, "Save edits", "edits.json", "ParcelScope edits (*.json)");
    if (!path.isEmpty()) saveEdits(path);
  });
  saveEditsAction_->setToolTip("The edits as a file for 'parcelscope edit SESSION --edits FILE'");
  for (QAction* a : {undoAction_, redoAction_, drawStreetAction_, deleteStreetAction_, widthAction_, curveAction_,
                     labelAction_, lockAction_, saveEditsAction_}) {
    addAction(a);  // shortcuts work wherever the focus is in the window
  }
  updateEditActions();
}

bool MainWindow::setEditing(bool on) {
  if (on == editing_) return true;
  if (on) {
    const auto shown = controller_.finalResult();
    if (!shown || !shown->observed->streets) {
      showError("Edit streets needs a comparison with a street network: File > Open streets first.");
      editAction_->setChecked(false);
      return false;
    }
    editing_ = true;
    editState_.reset();
    selectedNode_ = selectedStreet_ = selectedEditParcel_ = 0;
    streetStart_.reset();
    editStarted_.clear();
    editStarted_[0].start();
    editWorker_->start(controller_.shownRequest(), shown->observed);
    controlsScroll_->setEnabled(false);
    proceduralView_->setTitle("Edited streets: building the editor...");
    status_->setText("street editing: drag a node, click a street or a parcel; Ctrl+Z undoes");
  } else {
    editing_ = false;
    editWorker_->stop();
    editState_.reset();
    drawingStreet_ = false;
    streetStart_.reset();
    controlsScroll_->setEnabled(true);
    proceduralView_->handles().setVisible(false);
    if (const auto shown = controller_.shownResult()) {
      // The comparison's parcels and streets again.
      drawProceduralLayer(shown->generated);
      proceduralView_->streets().setStreets(comparisonLines_, comparisonSurface_);
      recolour(false);
      showParcel();
    }
    proceduralView_->render();
  }
  editAction_->setChecked(editing_);
  updateEditActions();
  return true;
}

qint64 MainWindow::submitEdit(const StreetEditWorker::Command& command) {
  const qint64 serial = editWorker_->submit(command);
  editStarted_[serial].start();
  return serial;
}

void MainWindow::drawEditState(const StreetEditState& state) {
  if (!editing_) return;
  Laps lap;
  EditTimings timings;
  if (const auto it = editStarted_.find(state.serial); it != editStarted_.end()) {
    timings.library = static_cast<double>(it->second.nsecsElapsed()) / 1e6;
  }
  timings.editor = 1e3 * state.seconds;
  // The state shown until now is often the last hold on a whole city's
  // parcels (a drag's move before): it is let go on a pool thread, after the
  // new one is drawn, not here before it.
  auto shownBefore = std::make_shared<std::optional<StreetEditState>>(std::move(editState_));
  editState_ = state;
  const pipeline::StreetEditor::Snapshot& s = *state.snapshot;
  drawProceduralLayer(s.parcels());
  timings.parcels = lap();
  // The edited network: centre lines, and the blocks' outlines as kerbs (the
  // street surface's rings that face a block; the union of the whole
  // surface would take about a second per edit on a city).
  std::vector<Polygon> kerbs;
  for (const analysis::StreetBlock& b : s.network().blocks.blocks) kerbs.push_back(b.shape);
  proceduralView_->streets().setStreets(centreLines(s.network().graph), kerbs);
  timings.streets = lap();
  recolour(false);
  // Selections follow their keys; what is gone is no longer selected.
  const auto& g = s.network().graph;
  if (selectedNode_ &&
      std::none_of(g.nodes.begin(), g.nodes.end(), [&](const auto& n) { return n.key == selectedNode_; }))
    selectedNode_ = 0;
  if (selectedStreet_ &&
      std::none_of(g.edges.begin(), g.edges.end(), [&](const auto& e) { return e.key == selectedStreet_; }))
    selectedStreet_ = 0;
  if (selectedEditParcel_ && indexOfKey(s.parcelKeys(), selectedEditParcel_) < 0) selectedEditParcel_ = 0;
  drawHandles();
  showEditParcel();
  timings.handles = lap();
  proceduralView_->render();
  timings.views = lap();
  QThreadPool::globalInstance()->start([before = std::move(shownBefore)]() mutable { before.reset(); });
  if (const auto it = editStarted_.find(state.serial); it != editStarted_.end()) {
    lastEditLatencyMs_ = static_cast<double>(it->second.nsecsElapsed()) / 1e6;
    editStarted_.erase(editStarted_.begin(), std::next(it));
  }
  lastEditTimings_ = timings;
  const std::size_t unassigned = static_cast<std::size_t>(s.parcels().unassignedParcels);
  proceduralView_->setTitle(QString("Edited streets (%1, seed %2): %3 parcels; %4 edits")
                                .arg(QString::fromStdString(controller_.shownRequest().style))
                                .arg(s.parcels().seed)
                                .arg(s.parcels().parcels.size() - unassigned)
                                .arg(state.undo));
  if (state.report && !state.report->blocksAffected.empty()) {
    const pipeline::EditReport& r = *state.report;
    status_->setText(QString("%1: %2 blocks subdivided again; %3 of %4 of their parcels kept their keys; %5 ms")
                         .arg(QString::fromStdString(r.op))
                         .arg(r.blocksAffected.size())
                         .arg(r.matched)
                         .arg(r.parcelsBefore)
                         .arg(lastEditLatencyMs_, 0, 'f', 0));
  } else if (state.serial == 0) {
    status_->setText(QString("street editing: %1 blocks, %2 parcels; drag a node, click a street or a parcel")
                         .arg(s.parcels().blocks.size())
                         .arg(s.parcels().parcels.size()));
  }
  updateEditActions();
  emit editShown(state.serial);
}

void MainWindow::drawHandles() {
  viz::HandleLayer& h = proceduralView_->handles();
  if (!editing_ || !editState_) {
    h.setVisible(false);
    return;
  }
  const analysis::RoadGraph& g = editState_->snapshot->network().graph;
  const std::vector<char> onStreet = streetNodes(g);
  std::vector<Point> nodes;
  for (std::size_t i = 0; i < g.nodes.size(); ++i) {
    if (onStreet[i]) nodes.push_back(g.nodes[i].at);
  }
  h.setNodes(nodes);
  std::vector<Point> street, points;
  std::vector<std::vector<Point>> arms;
  for (const auto& e : g.edges) {
    if (e.key != selectedStreet_) continue;
    street = e.line;
    if (e.controls) {
      const Point a = g.nodes[static_cast<std::size_t>(e.from)].at, b = g.nodes[static_cast<std::size_t>(e.to)].at;
      arms = {{a, (*e.controls)[0]}, {b, (*e.controls)[1]}};
      points = {(*e.controls)[0], (*e.controls)[1]};
    }
  }
  for (const auto& n : g.nodes) {
    if (n.key == selectedNode_) points.push_back(n.at);
  }
  h.setSelection(street, arms, points);
  h.setVisible(true);
}

int MainWindow::nodeNear(double x, double y, double pixels) const {
  if (!editState_) return -1;
  const double reach = pixels * proceduralView_->metresPerPixel();
  const analysis::RoadGraph& g = editState_->snapshot->network().graph;
  const std::vector<char> onStreet = streetNodes(g);
  int best = -1;
  double nearest = reach;
  for (std::size_t i = 0; i < g.nodes.size(); ++i) {
    const double d = std::hypot(g.nodes[i].at.x - x, g.nodes[i].at.y - y);
    if (onStreet[i] && d <= nearest) {
      nearest = d;
      best = static_cast<int>(i);
    }
  }
  return best;
}

int MainWindow::streetNear(double x, double y, double pixels) const {
  if (!editState_) return -1;
  const double reach = pixels * proceduralView_->metresPerPixel();
  const analysis::RoadGraph& g = editState_->snapshot->network().graph;
  int best = -1;
  double nearest = reach;
  for (std::size_t i = 0; i < g.edges.size(); ++i) {
    if (g.edges[i].boundary) continue;
    const auto& line = g.edges[i].line;
    for (std::size_t k = 1; k < line.size(); ++k) {
      const double d = distanceToSegment({x, y}, line[k - 1], line[k]);
      if (d <= nearest) {
        nearest = d;
        best = static_cast<int>(i);
      }
    }
  }
  return best;
}

int MainWindow::controlNear(double x, double y, double pixels) const {
  if (!editState_ || selectedStreet_ == 0) return -1;
  const double reach = pixels * proceduralView_->metresPerPixel();
  for (const auto& e : editState_->snapshot->network().graph.edges) {
    if (e.key != selectedStreet_ || !e.controls) continue;
    for (int c = 0; c < 2; ++c) {
      const Point& p = (*e.controls)[static_cast<std::size_t>(c)];
      if (std::hypot(p.x - x, p.y - y) <= reach) return c;
    }
  }
  return -1;
}

bool MainWindow::pressAt(double x, double y) {
  if (!editing_ || !editState_ || drawingStreet_) return false;
  dragNode_ = 0;
  dragControl_ = controlNear(x, y, kPickPixels);
  if (dragControl_ < 0) {
    const int node = nodeNear(x, y, kPickPixels);
    if (node < 0) return false;
    dragNode_ = editState_->snapshot->network().graph.nodes[static_cast<std::size_t>(node)].key;
  }
  gesture_ = ++gestures_;
  dragMoved_ = false;
  return true;
}

void MainWindow::dragTo(double x, double y) {
  if (!editing_ || gesture_ == 0 || !editState_) return;
  dragMoved_ = true;
  StreetEditWorker::Command c;
  c.gesture = gesture_;
  if (dragNode_ != 0) {
    c.edit.op = pipeline::StreetEdit::Op::MoveNode;
    c.edit.node = dragNode_;
    c.edit.to = {x, y};
  } else {
    // The control point follows the cursor; the other stays where it was when the drag began.
    const analysis::RoadGraph& g = editState_->snapshot->network().graph;
    for (const auto& e : g.edges) {
      if (e.key != selectedStreet_) continue;
      if (!dragControls_) dragControls_ = controlsOf(g, e);
      std::array<Point, 2> controls = *dragControls_;
      controls[static_cast<std::size_t>(dragControl_)] = {x, y};
      c.edit.op = pipeline::StreetEdit::Op::SetCurve;
      c.edit.edge = e.key;
      c.edit.controls = controls;
    }
    if (c.edit.edge == 0) return;
  }
  submitEdit(c);
}

void MainWindow::dropAt(double, double) {
  // The drag's last move was applied by dragTo; a press on a node without a move selects it.
  if (gesture_ == 0) return;
  gesture_ = 0;
  dragControls_.reset();
  if (dragMoved_ || dragNode_ == 0) return;
  selectedNode_ = dragNode_;
  selectedStreet_ = 0;
  drawHandles();
  updateEditActions();
  proceduralView_->render();
}

void MainWindow::editClickAt(double x, double y) {
  if (!editing_ || !editState_) return;
  const pipeline::StreetEditor::Snapshot& s = *editState_->snapshot;
  if (drawingStreet_) {
    const int node = nodeNear(x, y, kPickPixels);
    const Key key = node >= 0 ? s.network().graph.nodes[static_cast<std::size_t>(node)].key : 0;
    const Point at = node >= 0 ? s.network().graph.nodes[static_cast<std::size_t>(node)].at : Point{x, y};
    if (!streetStart_) {
      streetStart_ = at;
      streetStartNode_ = key;
      proceduralView_->handles().setSelection({}, {}, {at});
      proceduralView_->render();
      status_->setText("draw street: click its other end");
      return;
    }
    StreetEditWorker::Command c;
    c.edit.op = pipeline::StreetEdit::Op::AddStreet;
    c.edit.from = *streetStart_;
    c.edit.node = streetStartNode_;
    c.edit.to = at;
    c.edit.node2 = key;
    c.edit.width = kNewStreetWidth;
    c.edit.name = "new street";
    streetStart_.reset();
    setDrawingStreet(false);
    submitEdit(c);
    return;
  }
  selectedNode_ = selectedStreet_ = selectedEditParcel_ = 0;
  if (const int node = nodeNear(x, y, kPickPixels); node >= 0) {
    selectedNode_ = s.network().graph.nodes[static_cast<std::size_t>(node)].key;
  } else if (const int street = streetNear(x, y, kStreetPixels); street >= 0) {
    selectedStreet_ = s.network().graph.edges[static_cast<std::size_t>(street)].key;
  } else if (const int parcel = pipeline::generatedParcelAt(s.parcels(), {x, y}); parcel >= 0) {
    selectedEditParcel_ = s.parcelKeys()[static_cast<std::size_t>(parcel)];
  }
  drawHandles();
  showEditParcel();
  updateEditActions();
  proceduralView_->render();
}

void MainWindow::showEditParcel() {
  if (!editing_ || !editState_) return;
  const pipeline::StreetEditor::Snapshot& s = *editState_->snapshot;
  QString html;
  const int i = selectedEditParcel_ ? indexOfKey(s.parcelKeys(), selectedEditParcel_) : -1;
  if (i < 0) {
    html = "No parcel selected (click one in the procedural view).";
  } else {
    const auto label = s.labels().find(selectedEditParcel_);
    html = QString("<b>Edited parcel %1</b><table cellspacing=2>")
               .arg(QString::fromStdString(keyText(selectedEditParcel_)));
    html +=
        QString("<tr><td>label</td><td>%1</td></tr>")
            .arg(label == s.labels().end() ? QString("(none)") : QString::fromStdString(label->second).toHtmlEscaped());
    html += QString("<tr><td>locked</td><td>%1</td></tr>").arg(s.locked().count(selectedEditParcel_) ? "yes" : "no");
    const pipeline::ParcelInspection p = pipeline::inspectGeneratedParcel(s.parcels(), i);
    for (const auto* values : {&p.attributes, &p.metrics}) {
      for (const auto& [name, v] : *values) {
        if (name == "parcel_key") continue;  // the editor's key is above
        html += QString("<tr><td>%1</td><td>%2</td></tr>")
                    .arg(QString::fromStdString(name), QString::fromStdString(pipeline::valueText(v)).toHtmlEscaped());
      }
    }
    html += "</table>";
  }
  if (html == parcelInfoHtml_) return;
  parcelInfoHtml_ = html;
  parcelInfo_->setHtml(html);
}

void MainWindow::undoEdit() {
  if (!editing_ || !editState_ || editState_->undo == 0) return;
  StreetEditWorker::Command c;
  c.kind = StreetEditWorker::Command::Kind::Undo;
  submitEdit(c);
}

void MainWindow::redoEdit() {
  if (!editing_ || !editState_ || editState_->redo == 0) return;
  StreetEditWorker::Command c;
  c.kind = StreetEditWorker::Command::Kind::Redo;
  submitEdit(c);
}

void MainWindow::setDrawingStreet(bool on) {
  drawingStreet_ = on && editing_;
  streetStart_.reset();
  if (drawStreetAction_) drawStreetAction_->setChecked(drawingStreet_);
  if (drawingStreet_) status_->setText("draw street: click its first end (on a node to join it there)");
}

void MainWindow::deleteSelectedStreet() {
  if (!editing_ || selectedStreet_ == 0) return;
  StreetEditWorker::Command c;
  c.edit.op = pipeline::StreetEdit::Op::DeleteStreet;
  c.edit.edge = selectedStreet_;
  selectedStreet_ = 0;
  submitEdit(c);
}

void MainWindow::setSelectedStreetWidth(double width) {
  if (!editing_ || selectedStreet_ == 0) return;
  StreetEditWorker::Command c;
  c.edit.op = pipeline::StreetEdit::Op::SetWidth;
  c.edit.edge = selectedStreet_;
  c.edit.width = width;
  submitEdit(c);
}

void MainWindow::setSelectedStreetCurved(bool curved) {
  if (!editing_ || !editState_ || selectedStreet_ == 0) return;
  const analysis::RoadGraph& g = editState_->snapshot->network().graph;
  for (const auto& e : g.edges) {
    if (e.key != selectedStreet_ || e.controls.has_value() == curved) continue;
    StreetEditWorker::Command c;
    c.edit.op = pipeline::StreetEdit::Op::SetCurve;
    c.edit.edge = e.key;
    if (curved) c.edit.controls = controlsOf(g, e);
    submitEdit(c);
  }
}

void MainWindow::labelSelectedParcel(const QString& label) {
  if (!editing_ || selectedEditParcel_ == 0) return;
  StreetEditWorker::Command c;
  c.edit.op = pipeline::StreetEdit::Op::SetLabel;
  c.edit.parcel = selectedEditParcel_;
  c.edit.label = label.toStdString();
  submitEdit(c);
}

void MainWindow::lockSelectedParcel(bool locked) {
  if (!editing_ || selectedEditParcel_ == 0) return;
  StreetEditWorker::Command c;
  c.edit.op = pipeline::StreetEdit::Op::SetLock;
  c.edit.parcel = selectedEditParcel_;
  c.edit.locked = locked;
  submitEdit(c);
}

void MainWindow::saveEdits(const QString& path) {
  if (!editState_) return;
  try {
    pipeline::writeEdits(path.toStdString(), editState_->history, editState_->snapshot->network().layer.frame,
                         pipeline::inputPaths(controller_.shownRequest()));
    status_->setText(QString("%1 edits saved to %2").arg(editState_->history.size()).arg(path));
  } catch (const std::exception& e) {
    showError(QString::fromStdString(e.what()));
  }
}

void MainWindow::updateEditActions() {
  if (!editAction_) return;
  const bool ready = editing_ && editState_.has_value();
  editAction_->setEnabled(editing_ || (controller_.finalResult() && controller_.finalResult()->observed->streets));
  undoAction_->setEnabled(ready && editState_->undo > 0);
  redoAction_->setEnabled(ready && editState_->redo > 0);
  drawStreetAction_->setEnabled(ready);
  deleteStreetAction_->setEnabled(ready && selectedStreet_ != 0);
  widthAction_->setEnabled(ready && selectedStreet_ != 0);
  bool curved = false;
  if (ready && selectedStreet_ != 0) {
    for (const auto& e : editState_->snapshot->network().graph.edges) {
      if (e.key == selectedStreet_) curved = e.controls.has_value();
    }
  }
  curveAction_->setEnabled(ready && selectedStreet_ != 0);
  curveAction_->setChecked(curved);
  labelAction_->setEnabled(ready && selectedEditParcel_ != 0);
  lockAction_->setEnabled(ready && selectedEditParcel_ != 0);
  lockAction_->setChecked(ready && selectedEditParcel_ != 0 &&
                          editState_->snapshot->locked().count(selectedEditParcel_));
  saveEditsAction_->setEnabled(ready && !editState_->history.empty());
}

}  // namespace parcelscope::gui
