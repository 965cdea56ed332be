#include "MainWindow.h"

#include <QVTKOpenGLStereoWidget.h>
#include <QAction>
#include <QApplication>
#include <QCheckBox>
#include <QCloseEvent>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QDragEnterEvent>
#include <QDropEvent>
#include <QFileDialog>
#include <QFileInfo>
#include <QFormLayout>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QInputDialog>
#include <QLabel>
#include <QMenuBar>
#include <QMessageBox>
#include <QMimeData>
#include <QPainter>
#include <QProgressBar>
#include <QProgressDialog>
#include <QPushButton>
#include <QRegularExpression>
#include <QScreen>
#include <QScrollArea>
#include <QScrollBar>
#include <QSettings>
#include <QSplitter>
#include <QStandardPaths>
#include <QStatusBar>
#include <QSurfaceFormat>
#include <QTableWidget>
#include <QTextBrowser>
#include <QTimer>
#include <QToolBar>
#include <QVBoxLayout>

#include <vtkAxis.h>
#include <vtkChartXY.h>
#include <vtkContextInteractorStyle.h>
#include <vtkContextScene.h>
#include <vtkContextView.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkObjectFactory.h>
#include <vtkPlot.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderer.h>
#include <vtkVersionMacros.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <tuple>
#include <utility>

#include "BackgroundTask.h"
#include "Laps.h"
#include "LeaderboardDialog.h"
#include "MapView.h"
#include "ParameterPanel.h"
#include "parcelscope/analysis/Comparison.h"
#include "parcelscope/core/Error.h"
#include "parcelscope/core/Parallel.h"
#include "parcelscope/io/ParcelReader.h"
#include "parcelscope/pipeline/Calibrate.h"
#include "parcelscope/pipeline/GenerateJob.h"
#include "parcelscope/pipeline/Inspect.h"
#include "parcelscope/pipeline/StreetsJob.h"
#include "parcelscope/viz/CompareFigures.h"
#include "parcelscope/viz/Scenes.h"

namespace parcelscope::gui {

// The histogram's interactor style: the chart's own, which redraws a modified
// chart 40 ms later on a timer, plus a way to draw now and cancel that timer.
class ChartStyle : public vtkContextInteractorStyle {
public:
  static ChartStyle* New();
  vtkTypeMacro(ChartStyle, vtkContextInteractorStyle) void drawNow() { RenderNow(); }
  // VTK's own keys ('3' stereo, 'r' reset the camera, 'e'/'q' quit, ...) do
  // nothing; the chart still receives key presses (OnKeyPress).
  void OnChar() override {}
};
vtkStandardNewMacro(ChartStyle);

namespace {

// The parameters a block override offers.
const char* kBlockParameters[] = {"a-min", "a-max", "w-min", "w-max", "omega", "offset", "seed"};

// Every parameter of compare, in its groups, but the settings of written files
// (outputOnly: figures and their size, the layers' index), which exports take
// from their dialogs.
std::vector<ParameterDescription> panelParameters() {
  std::vector<ParameterDescription> out;
  for (const auto& d : pipeline::compareParameters()) {
    if (!d.outputOnly) out.push_back(d);
  }
  return out;
}

const ParameterDescription& describe(const std::string& name) {
  static const auto all = pipeline::compareParameters();
  for (const auto& d : all) {
    if (d.name == name) return d;
  }
  throw std::logic_error("no parameter " + name);
}

QString number(double v) {
  if (std::isnan(v)) return QStringLiteral("-");
  return QString::number(v, 'g', 5);
}

QString sampleDirectory() { return QStringLiteral(PARCELSCOPE_SAMPLE_DIR); }

// A message of the libraries, worded for the command line ("--crs", "--w-min"),
// in the window's words: its menus and the names of its controls. The
// libraries' messages stay as they are (the command line shows them).
QString windowWording(QString message) {
  // Before a flag: the start, a space or punctuation, not a letter (file names keep their dashes).
  const QString before = QStringLiteral(R"((^|[\s(\[;:,"'=]))");
  message.replace(QRegularExpression(R"(give the (real )?CRS with --crs EPSG:N)"),
                  QStringLiteral("set the input CRS (File > Set input CRS...)"));
  message.replace(QRegularExpression(before + R"(--crs\b)"), QStringLiteral("\\1the input CRS"));
  message.replace(QRegularExpression(before + R"(--where\b)"), QStringLiteral("\\1the filter"));
  // A parameter as the parameter panel and the block override name it.
  static const std::set<QString> names = [] {
    std::set<QString> out{QStringLiteral("style"), QStringLiteral("subdivision-style"), QStringLiteral("key-field")};
    for (const auto& d : pipeline::compareParameters()) out.insert(QString::fromStdString(d.name));
    return out;
  }();
  static const QRegularExpression flag(before + R"(--([a-z][a-z0-9]*(?:-[a-z0-9]+)*))");
  QString out;
  int last = 0;
  for (auto it = flag.globalMatch(message); it.hasNext();) {
    const QRegularExpressionMatch m = it.next();
    if (!names.count(m.captured(2))) continue;
    out += message.mid(last, m.capturedStart(2) - 2 - last) + m.captured(2);
    last = m.capturedEnd(2);
  }
  return out + message.mid(last);
}

// File > Open recent: each file with the layer, filter and CRS it opened with.
struct RecentFile {
  QString path, layer, where, crs;
};

const char* kSettingsOrganisation = "ParcelScope";
const char* kSettingsApplication = "parcelscope-gui";

std::vector<RecentFile> readRecentFiles() {
  QSettings settings(kSettingsOrganisation, kSettingsApplication);
  std::vector<RecentFile> files;
  const int n = settings.beginReadArray("recentFiles");
  for (int i = 0; i < n; ++i) {
    settings.setArrayIndex(i);
    files.push_back({settings.value("path").toString(), settings.value("layer").toString(),
                     settings.value("where").toString(), settings.value("crs").toString()});
  }
  settings.endArray();
  // Written by an earlier version: paths only.
  if (n == 0) {
    for (const QString& path : settings.value("recent").toStringList()) files.push_back({path, {}, {}, {}});
  }
  return files;
}

void writeRecentFiles(const std::vector<RecentFile>& files) {
  QSettings settings(kSettingsOrganisation, kSettingsApplication);
  settings.remove("recent");
  settings.remove("recentFiles");
  settings.beginWriteArray("recentFiles", static_cast<int>(files.size()));
  for (int i = 0; i < static_cast<int>(files.size()); ++i) {
    const RecentFile& f = files[static_cast<std::size_t>(i)];
    settings.setArrayIndex(i);
    settings.setValue("path", f.path);
    settings.setValue("layer", f.layer);
    settings.setValue("where", f.where);
    settings.setValue("crs", f.crs);
  }
  settings.endArray();
}

bool sameInput(const io::ReadOptions& a, const io::ReadOptions& b) {
  return a.path == b.path && a.layer == b.layer && a.where == b.where && a.crsOverride == b.crsOverride;
}

}  // namespace

void MainWindow::prepareApplication() {
  QSurfaceFormat::setDefaultFormat(QVTKOpenGLStereoWidget::defaultFormat());
  if (!qEnvironmentVariableIsSet("QT_QPA_UPDATE_IDLE_TIME")) qputenv("QT_QPA_UPDATE_IDLE_TIME", "0");
}

MainWindow::MainWindow(QWidget* parent) : QMainWindow(parent), worker_(new SessionWorker) {
  setWindowTitle("ParcelScope");
  setAcceptDrops(true);

  worker_->moveToThread(&thread_);
  connect(&thread_, &QThread::finished, worker_, &QObject::deleteLater);
  connect(worker_, &SessionWorker::updated, this, &MainWindow::showReport);
  connect(worker_, &SessionWorker::failed, this, [this](const QString& message, qint64 serial) {
    // The newest request failed: the controls show the last good one, which later edits build on.
    const bool newest = controller_.failed(serial);
    if (newest) {
      showRequest();
      openedInput_.reset();  // it did not open: not a recent file
    }
    progress_->setVisible(false);
    cancel_->setVisible(false);
    updateActions();
    // A CRS the reader cannot use: say so, and offer to give one.
    const bool crsProblem = message.contains("CRS");
    QString shown = windowWording(message);
    if (crsProblem && !shown.contains("File > Set input CRS")) {
      shown += "  (File > Set input CRS... gives the input another CRS)";
    }
    showError(shown);
    if (crsProblem && newest && !QStandardPaths::isTestModeEnabled()) {
      QTimer::singleShot(0, this, [this, input = controller_.failedRequest()->input] { askForCrs(input); });
    }
  });
  connect(worker_, &SessionWorker::cancelled, this, [this](qint64 serial) {
    if (controller_.cancelled(serial)) {
      progress_->setVisible(false);
      cancel_->setVisible(false);
      status_->setText("cancelled");
      // A result in between stays on screen: say what it holds, and that
      // what it did not measure will not come.
      if (shownPartial_ && controller_.shownResult()) {
        partialCancelled_ = true;
        titleProcedural();
        fillNumbers();
        status_->setText(QString("cancelled: %1 of %2 block parts were updated, the others are shown as before")
                             .arg(partialDone_)
                             .arg(partialTotal_));
      }
    }
  });
  connect(worker_, &SessionWorker::progress, this, [this](double fraction, const QString& stage) {
    // Only long updates show progress: showing the bar relays the window out
    // and redraws every view, which would slow the short ones down.
    const auto it = started_.find(controller_.pendingSerial());
    if (it != started_.end() && it->second.elapsed() < 250 && !progress_->isVisible()) return;
    progress_->setVisible(true);
    cancel_->setVisible(true);
    progress_->setValue(static_cast<int>(fraction * 100));
    progress_->setFormat(stage + " %p%");
  });
  thread_.start();

  // Views: observed and procedural side by side, one camera.
  observedView_ = new MapView("Observed", false);
  proceduralView_ = new MapView("Procedural", true);
  proceduralView_->useCamera(observedView_->camera());
  auto* maps = new QSplitter(Qt::Horizontal);
  maps->addWidget(observedView_);
  maps->addWidget(proceduralView_);
  for (MapView* v : {observedView_, proceduralView_}) {
    const bool procedural = v == proceduralView_;
    connect(v, &MapView::clicked, this, [this, procedural](double x, double y) {
      if (procedural && editing_) return editClickAt(x, y);
      inspectAt(procedural, x, y);
    });
    connect(v, &MapView::pointerMoved, this, [this](double x, double y) {
      const QString text = coordinateText(x, y);
      observedView_->setReadout(text);
      proceduralView_->setReadout(text);
    });
  }

  // Street editing in the procedural view: a press on a node or a control point drags it.
  proceduralView_->setGrab([this](double x, double y) { return pressAt(x, y); });
  connect(proceduralView_, &MapView::dragged, this, [this](double x, double y) { dragTo(x, y); });
  connect(proceduralView_, &MapView::dropped, this, [this](double x, double y) { dropAt(x, y); });
  editWorker_ = new StreetEditWorker;
  editWorker_->moveToThread(&editThread_);
  connect(&editThread_, &QThread::finished, editWorker_, &QObject::deleteLater);
  connect(editWorker_, &StreetEditWorker::updated, this,
          [this](const StreetEditState& state) { drawEditState(state); });
  connect(editWorker_, &StreetEditWorker::failed, this, [this](const QString& message, qint64 serial) {
    editStarted_.erase(serial);
    if (!editing_) return;
    if (!editState_) {
      // The editor could not be built.
      showError("Edit streets: " + message);
      setEditing(false);
      return;
    }
    showError("Edit: " + message);
  });
  editThread_.start();

  // Histogram and numbers.
  histogramWidget_ = new QVTKOpenGLStereoWidget;
  // No multisampled buffer: with software OpenGL it made each redraw of the
  // chart several milliseconds longer (its text is drawn from textures anyway).
  histogramWindow_->SetMultiSamples(0);
  histogramWidget_->setRenderWindow(histogramWindow_);
  histogramWidget_->setMinimumSize(160, 100);
  histogramView_->SetRenderWindow(histogramWindow_);
  histogramView_->SetInteractor(histogramWidget_->interactor());
  histogramView_->GetRenderer()->SetBackground(1, 1, 1);
  histogramView_->GetScene()->AddItem(chart_);
  {
    // The chart's own interactor style, replaced by one that can draw now.
    vtkRenderWindowInteractor* iren = histogramWidget_->interactor();
    if (auto* own = vtkContextInteractorStyle::SafeDownCast(iren->GetInteractorStyle())) own->SetScene(nullptr);
    histogramStyle_ = vtkSmartPointer<ChartStyle>::New();
    histogramStyle_->SetScene(histogramView_->GetScene());
    iren->SetInteractorStyle(histogramStyle_);
  }
  numbers_ = new QTableWidget;
  numbers_->setEditTriggers(QAbstractItemView::NoEditTriggers);
  numbers_->verticalHeader()->setVisible(false);
  numbers_->setMinimumWidth(160);
  auto* lower = new QSplitter(Qt::Horizontal);
  lower->addWidget(histogramWidget_);
  lower->addWidget(numbers_);
  lower->setStretchFactor(0, 3);
  lower->setStretchFactor(1, 2);
  lower->setSizes({650, 350});  // a view's container has no size hint of its own

  auto* central = new QWidget;
  auto* layout = new QVBoxLayout(central);
  layout->setContentsMargins(4, 4, 4, 4);
  errorBar_ = new QLabel;
  errorBar_->setObjectName("errorBar");
  errorBar_->setWordWrap(true);
  errorBar_->setStyleSheet("QLabel { background: #fde2e1; color: #8a1414; padding: 6px; border: 1px solid #e0a0a0; }");
  errorBar_->setVisible(false);
  errorBar_->setTextInteractionFlags(Qt::TextSelectableByMouse);
  layout->addWidget(errorBar_);
  noticeBar_ = new QLabel;
  noticeBar_->setObjectName("noticeBar");
  noticeBar_->setWordWrap(true);
  noticeBar_->setStyleSheet("QLabel { background: #e3eefc; color: #123a6b; padding: 6px; border: 1px solid #9dbbe3; }");
  noticeBar_->setVisible(false);
  noticeBar_->setTextInteractionFlags(Qt::TextSelectableByMouse);
  layout->addWidget(noticeBar_);
  auto* vertical = new QSplitter(Qt::Vertical);
  vertical->addWidget(maps);
  vertical->addWidget(lower);
  vertical->setStretchFactor(0, 3);
  vertical->setStretchFactor(1, 2);
  layout->addWidget(vertical, 1);

  auto* outer = new QSplitter(Qt::Horizontal);
  outer->addWidget(central);
  // Every control reachable on small screens and at 1.5x or 2x scaling: the
  // whole column scrolls, and the splitter gives the views or the controls room.
  controlsScroll_ = new QScrollArea;
  controlsScroll_->setObjectName("controlsScroll");
  controlsScroll_->setWidget(buildControls());
  controlsScroll_->setWidgetResizable(true);
  // As wide as the controls need, so that nothing is cut at the side; the rest goes to the views.
  controlsScroll_->setHorizontalScrollBarPolicy(Qt::ScrollBarAlwaysOff);
  controlsScroll_->setMinimumWidth(controlsScroll_->widget()->minimumSizeHint().width() +
                                   controlsScroll_->verticalScrollBar()->sizeHint().width() +
                                   2 * controlsScroll_->frameWidth());
  outer->addWidget(controlsScroll_);
  outer->setStretchFactor(0, 1);
  outer->setStretchFactor(1, 0);
  setCentralWidget(outer);
  outer->setCollapsible(0, false);
  outer->setCollapsible(1, false);
  // The controls at about 420 px where there is room (longer sliders), the views the rest.
  outer->setSizes({1180, 420});

  status_ = new QLabel("Open a parcel dataset (File > Open, drag and drop, or File > Open sample)");
  progress_ = new QProgressBar;
  progress_->setMaximumWidth(260);
  progress_->setVisible(false);
  cancel_ = new QPushButton("Cancel");
  cancel_->setObjectName("cancelButton");
  cancel_->setVisible(false);
  connect(cancel_, &QPushButton::clicked, this, [this] { worker_->cancel(); });
  statusBar()->addWidget(status_, 1);
  statusBar()->addPermanentWidget(progress_);
  statusBar()->addPermanentWidget(cancel_);
  buildMenus();
  updateActions();
  markOverridesSaved();
  // At most the screen's free area (1280 x 720 at 1.5x scaling is 853 x 480).
  QSize size(1600, 1000);
  if (const QScreen* screen = QGuiApplication::primaryScreen()) size = size.boundedTo(screen->availableSize());
  resize(size);
}

MainWindow::~MainWindow() {
  worker_->cancel();
  thread_.quit();
  thread_.wait();
  editWorker_->stop();
  editThread_.quit();
  editThread_.wait();
}

QWidget* MainWindow::buildControls() {
  auto* controls = new QWidget;
  auto* v = new QVBoxLayout(controls);

  auto* run = new QGroupBox("Generator");
  auto* form = new QFormLayout(run);
  style_ = new QComboBox;
  style_->setObjectName("style");
  for (const auto& [name, help] : generation::generationStyles()) {
    style_->addItem(QString::fromStdString(name));
    style_->setItemData(style_->count() - 1, QString::fromStdString(help), Qt::ToolTipRole);
  }
  connect(style_, &QComboBox::currentTextChanged, this, [this](const QString& s) { setStyle(s); });
  form->addRow("style", style_);
  colourBy_ = new QComboBox;
  colourBy_->setObjectName("colourBy");
  for (const auto& q : analysis::parcelQuantities()) {
    colourBy_->addItem(QString::fromStdString(q.name));
    colourBy_->setItemData(colourBy_->count() - 1, QString::fromStdString(q.title), Qt::ToolTipRole);
  }
  connect(colourBy_, &QComboBox::currentTextChanged, this, [this](const QString& q) { setColourBy(q); });
  form->addRow("colour by", colourBy_);
  perBlockBounds_ = new QCheckBox("per-block bounds");
  perBlockBounds_->setObjectName("perBlockBounds");
  perBlockBounds_->setChecked(true);
  perBlockBounds_->setToolTip(
      "Each block's A_min, A_max, W_min, W_max come from its observed parcels (A-bar -/+ k s_A, "
      "W-bar -/+ k s_W); "
      "moving one of those sliders sets it for every block instead");
  connect(perBlockBounds_, &QCheckBox::toggled, this, [this](bool on) {
    controller_.setPerBlockBounds(on);
    if (on) {
      boundsNoticeBefore_.reset();
      showNotice({});
    }
    submit();
  });
  form->addRow(perBlockBounds_);
  v->addWidget(run);

  panel_ = new ParameterPanel(panelParameters());
  panel_->setValues(controller_.request().parameters);
  connect(panel_, &ParameterPanel::changed, this,
          [this](const QString& name, double value) { setParameter(name.toStdString(), value); });
  v->addWidget(panel_);

  auto* block = new QGroupBox("Parcel and block");
  auto* b = new QVBoxLayout(block);
  // A text view of a fixed height, not a label: a label whose text changes
  // makes Qt lay out the whole window again (each label's rich text several
  // times) before the views reach the screen, after every update.
  blockInfo_ = new QTextBrowser;
  blockInfo_->setObjectName("blockInfo");
  blockInfo_->setFrameShape(QFrame::NoFrame);
  blockInfo_->viewport()->setAutoFillBackground(false);
  blockInfo_->setFixedHeight(blockInfo_->fontMetrics().lineSpacing() * 10);
  blockInfo_->setPlainText("Click a parcel or a block in either view.");
  // The inspector: the parcel clicked, its attributes and metrics (its block is below).
  parcelInfo_ = new QTextBrowser;
  parcelInfo_->setObjectName("parcelInfo");
  parcelInfo_->setFrameShape(QFrame::NoFrame);
  parcelInfo_->viewport()->setAutoFillBackground(false);
  parcelInfo_->setFixedHeight(parcelInfo_->fontMetrics().lineSpacing() * 9);
  parcelInfo_->setPlainText("No parcel selected.");
  b->addWidget(parcelInfo_);
  b->addWidget(blockInfo_);
  auto* overrides = new QFormLayout;
  blockStyle_ = new QComboBox;
  blockStyle_->addItem("(run's style)");
  for (const auto& [name, help] : generation::generationStyles()) blockStyle_->addItem(QString::fromStdString(name));
  overrides->addRow("style", blockStyle_);
  for (const char* name : kBlockParameters) {
    const ParameterDescription& d = describe(name);
    auto* check = new QCheckBox(QString::fromStdString(d.name));
    auto* spin = new QDoubleSpinBox;
    spin->setRange(d.minimum, d.maximum);
    spin->setDecimals(d.integer() ? 0 : 2);
    spin->setValue(d.defaultValue);
    spin->setEnabled(false);
    connect(check, &QCheckBox::toggled, spin, &QWidget::setEnabled);
    check->setObjectName(QString("block-check-") + name);
    spin->setObjectName(QString("block-spin-") + name);
    overrides->addRow(check, spin);
    blockParameters_[name] = {check, spin};
  }
  b->addLayout(overrides);
  auto* buttons = new QHBoxLayout;
  auto* apply = overrideBlock_ = new QPushButton("Override block");
  apply->setObjectName("overrideBlock");
  auto* clear = clearOverride_ = new QPushButton("Clear override");
  connect(apply, &QPushButton::clicked, this, [this] {
    ParameterValues values;
    for (const auto& [name, widgets] : blockParameters_) {
      if (widgets.first->isChecked()) values[name] = widgets.second->value();
    }
    // A bound given below the block's other bound would silently move that one.
    if (controller_.shownResult() && selected_ >= 0) {
      auto value = [&](const std::string& name) {
        const auto it = values.find(name);
        return it != values.end() ? it->second : blockValue(*controller_.shownResult(), selected_, name);
      };
      for (const auto& [low, high, unit] :
           {std::tuple{"a-min", "a-max", "m\u00b2"}, std::tuple{"w-min", "w-max", "m"}}) {
        if ((values.count(low) || values.count(high)) && value(high) < value(low)) {
          return showError(QString("%1 (%2 %3) is below the block's %4 (%5 %3): give both, or a larger %1")
                               .arg(high)
                               .arg(value(high))
                               .arg(QString::fromUtf8(unit))
                               .arg(low)
                               .arg(value(low)));
        }
      }
    }
    overrideSelectedBlock(blockStyle_->currentIndex() == 0 ? QString() : blockStyle_->currentText(), values);
  });
  connect(clear, &QPushButton::clicked, this, [this] { clearSelectedOverride(); });
  buttons->addWidget(apply);
  buttons->addWidget(clear);
  b->addLayout(buttons);
  v->addWidget(block);
  return controls;
}

void MainWindow::buildMenus() {
  QMenu* file = menuBar()->addMenu("&File");
  file->addAction(
      "&Open...", this,
      [this] {
        const QString path = QFileDialog::getOpenFileName(
            this, "Open parcels", {}, "Parcel data (*.gpkg *.geojson *.json *.topojson *.shp *.fgb);;All files (*)");
        if (!path.isEmpty()) openFile(path);
      },
      QKeySequence::Open);
  file->addAction("Open &sample", this, [this] { openSample(); });
  recentMenu_ = file->addMenu("Open &recent");
  recentMenu_->setObjectName("recentMenu");
  recentMenu_->setToolTipsVisible(true);
  refreshRecent();
  setCrsAction_ = file->addAction("Set input &CRS...", this, [this] { askForCrs(); });
  filterAction_ = file->addAction("&Filter features...", this, [this] { askForFilter(); });
  filterAction_->setObjectName("filterAction");
  filterAction_->setToolTip("Keep only the features whose attributes match a filter (the command line's --where)");
  streetsAction_ = file->addAction("Open s&treets...", this, [this] { askForStreets(); });
  streetsAction_->setObjectName("streetsAction");
  streetsAction_->setToolTip(
      "Blocks from street centre lines: the parcels are grouped into the blocks of the street network "
      "(the command line's --streets)");
  removeStreetsAction_ = file->addAction("Remove streets", this, [this] { removeStreets(); });
  removeStreetsAction_->setObjectName("removeStreetsAction");
  file->addSeparator();
  file->addAction("Open session...", this, [this] {
    const QString path = QFileDialog::getOpenFileName(this, "Open session", {}, "ParcelScope session (*.json)");
    if (!path.isEmpty()) openSession(path);
  });
  saveSessionAction_ = file->addAction("Save session...", this, [this] {
    const QString path =
        QFileDialog::getSaveFileName(this, "Save session", "session.json", "ParcelScope session (*.json)");
    if (!path.isEmpty()) saveSession(path);
  });
  saveSessionAction_->setObjectName("saveSessionAction");
  file->addSeparator();
  // Disabled until there is a result to export (updateActions).
  QMenu* exports = exportMenu_ = file->addMenu("&Export");
  exports->addAction("Figure...", this, [this] { exportFigureDialog(); });
  exports->addAction("Tables (CSV)...", this, [this] {
    const QString folder = QFileDialog::getExistingDirectory(this, "Export tables into folder");
    if (!folder.isEmpty()) exportTables(folder);
  });
  exports->addAction("Generated parcels...", this, [this] {
    const QString path = QFileDialog::getSaveFileName(this, "Export generated parcels", "parcels.gpkg",
                                                      "GeoPackage (*.gpkg);;GeoJSON (*.geojson)");
    if (!path.isEmpty()) exportParcels(path);
  });
  file->addSeparator();
  file->addAction("&Quit", this, &QWidget::close, QKeySequence::Quit);
  buildEditMenu();
  QMenu* analysis = menuBar()->addMenu("&Analysis");
  leaderboardAction_ = analysis->addAction("Compare every &style...", this, [this] { showLeaderboard(); });
  leaderboardAction_->setEnabled(false);
  fitAction_ = analysis->addAction("&Fit to observed", this, [this] { fitToObserved(); });
  fitAction_->setEnabled(false);
  QMenu* view = menuBar()->addMenu("&View");
  view->setToolTipsVisible(true);
  QAction* outlines = view->addAction("Parcel &outlines");
  outlines->setCheckable(true);
  outlines->setChecked(true);
  outlines->setToolTip(QString("Grey outlines around parcels at least %1 pixels across at the current zoom "
                               "(zoom in to see more of them)")
                           .arg(viz::kMinOutlinedPixels));
  connect(outlines, &QAction::toggled, this, [this](bool on) { setOutlinesVisible(on); });
  zoomToExtentAction_ = view->addAction(
      "Zoom to &extent", this, [this] { zoomToExtent(); }, Qt::Key_Home);
  zoomToExtentAction_->setToolTip("Fit both views to the data");
  QMenu* help = menuBar()->addMenu("&Help");
  help->addAction("&About ParcelScope...", this, [this] {
    auto* box = new QMessageBox(QMessageBox::Information, "About ParcelScope", aboutText(), QMessageBox::Ok, this);
    box->setObjectName("aboutBox");
    box->setTextFormat(Qt::RichText);
    box->setAttribute(Qt::WA_DeleteOnClose);
    box->open();
  });
  QToolBar* bar = addToolBar("Main");
  bar->setObjectName("mainToolBar");
  bar->addAction("Open sample", this, [this] { openSample(); });
}

void MainWindow::askForCrs() {
  if (const pipeline::CompareRequest* failed = controller_.failedRequest()) return askForCrs(failed->input);
  if (!controller_.loaded()) return showError("open a dataset first");
  askForCrs(controller_.request().input);
}

void MainWindow::askForFilter() {
  if (!controller_.loaded()) return showError("open a dataset first");
  bool ok = false;
  const QString where = QInputDialog::getText(
      this, "Filter features",
      "Keep the features whose attributes match (OGR SQL, e.g. use <> 'ROW'); empty: every feature", QLineEdit::Normal,
      QString::fromStdString(controller_.request().input.where), &ok);
  if (ok) setFilter(where.trimmed());
}

void MainWindow::setFilter(const QString& where) {
  setEditing(false);  // the network edited is no longer the one shown
  if (!controller_.loaded()) return showError("open a dataset first");
  const io::ReadOptions& input = controller_.request().input;
  openFile(QString::fromStdString(input.path), QString::fromStdString(input.layer), where,
           QString::fromStdString(input.crsOverride));
}

void MainWindow::askForStreets() {
  if (!controller_.loaded()) return showError("open a dataset first");
  const QString path = QFileDialog::getOpenFileName(this, "Open street centre lines", {},
                                                    "Vector data (*.geojson *.json *.gpkg *.shp *.fgb *.gml *.kml);;"
                                                    "All files (*)");
  if (path.isEmpty()) return;
  // The width and the name from fields the user picks among the layer's.
  QStringList numeric{"(none: measured from the parcels)"}, text{"(none)"};
  try {
    for (const auto& f : io::layerFields(path.toStdString())) {
      (f.numeric ? numeric : text) << QString::fromStdString(f.name);
    }
  } catch (const std::exception& e) {
    return showError(e.what());
  }
  bool ok = false;
  const QString width = QInputDialog::getItem(this, "Street width",
                                              "Field holding each street's width (metres, or the unit of a projected "
                                              "CRS):",
                                              numeric, 0, false, &ok);
  if (!ok) return;
  const QString name =
      QInputDialog::getItem(this, "Street name", "Field holding each street's name:", text, 0, false, &ok);
  if (!ok) return;
  openStreets(path, width == numeric.front() ? QString() : width, name == text.front() ? QString() : name);
}

void MainWindow::openStreets(const QString& path, const QString& widthField, const QString& nameField) {
  setEditing(false);  // the network edited is no longer the one shown
  if (!controller_.loaded()) return showError("open a dataset first");
  if (path.isEmpty()) return removeStreets();
  io::StreetReadOptions streets;
  streets.path = path.toStdString();
  streets.widthField = widthField.toStdString();
  streets.nameField = nameField.toStdString();
  controller_.setStreets(streets);
  markOverridesSaved();
  selected_ = -1;
  selectedParcel_ = -1;
  updateActions();
  submit();
}

void MainWindow::removeStreets() {
  setEditing(false);  // the network edited is no longer the one shown
  if (!controller_.loaded() || !controller_.request().streets) return;
  controller_.setStreets(std::nullopt);
  selected_ = -1;
  selectedParcel_ = -1;
  updateActions();
  submit();
}

void MainWindow::askForCrs(const io::ReadOptions& input) {
  bool ok = false;
  const QString crs =
      QInputDialog::getText(this, "Input CRS", "CRS of the input (e.g. EPSG:2249); empty: as the file declares it",
                            QLineEdit::Normal, QString::fromStdString(input.crsOverride), &ok);
  if (ok) {
    openFile(QString::fromStdString(input.path), QString::fromStdString(input.layer),
             QString::fromStdString(input.where), crs.trimmed());
  }
}

void MainWindow::openFile(const QString& path, const QString& layer, const QString& where, const QString& crs) {
  setEditing(false);  // the network edited is no longer the one shown
  io::ReadOptions input;
  input.path = path.toStdString();
  input.where = where.toStdString();
  input.crsOverride = crs.toStdString();
  input.layer = layer.toStdString();
  if (layer.isEmpty()) {
    try {
      const auto names = io::layerNames(input.path);
      if (names.size() > 1) {
        QStringList items;
        for (const auto& n : names) items << QString::fromStdString(n);
        bool ok = false;
        const QString chosen = QInputDialog::getItem(
            this, "Layer", QFileInfo(path).fileName() + " holds several layers:", items, 0, false, &ok);
        if (!ok) return;
        input.layer = chosen.toStdString();
      }
    } catch (const std::exception& e) {
      showError(e.what());
      return;
    }
  }
  controller_.openInput(input);
  markOverridesSaved();
  selected_ = -1;
  selectedParcel_ = -1;
  // A recent file once a result of it is drawn (drawReport).
  openedInput_ = input;
  updateActions();
  setWindowTitle("ParcelScope - " + QFileInfo(path).fileName());
  submit();
}

void MainWindow::openSample() { openFile(sampleDirectory() + "/sample_town.geojson", {}, "use <> 'ROW'"); }

void MainWindow::openSession(const QString& path) {
  setEditing(false);  // the network edited is no longer the one shown
  try {
    controller_.openSession(path.toStdString());
  } catch (const std::exception& e) {
    showError(e.what());
    return;
  }
  selected_ = -1;
  selectedParcel_ = -1;
  markOverridesSaved();
  openedInput_.reset();  // a session's input is not a recent file
  showRequest();
  updateActions();
  submit();
}

void MainWindow::showRequest() {
  const pipeline::CompareRequest& request = controller_.request();
  {
    const QSignalBlocker a(style_), b(colourBy_), c(perBlockBounds_);
    style_->setCurrentText(QString::fromStdString(request.style));
    colourBy_->setCurrentText(QString::fromStdString(request.metric));
    perBlockBounds_->setChecked(controller_.perBlockBounds());
  }
  panel_->setValues(request.parameters);
  setWindowTitle(controller_.loaded()
                     ? "ParcelScope - " + QFileInfo(QString::fromStdString(request.input.path)).fileName()
                     : QString("ParcelScope"));
}

void MainWindow::saveSession(const QString& path) {
  try {
    controller_.saveSession(path.toStdString());
    markOverridesSaved();
    status_->setText("session saved to " + path);
  } catch (const std::exception& e) {
    showError(e.what());
  }
}

void MainWindow::exportFigure(const QString& name, const QString& path, int width, int height) {
  // Rendering a figure of a whole city takes a few seconds; say so.
  QApplication::setOverrideCursor(Qt::WaitCursor);
  struct RestoreCursor {
    ~RestoreCursor() { QApplication::restoreOverrideCursor(); }
  } restore;
  exportWith(name + " exported to " + path, [&] {
    viz::exportFigure(*controller_.finalResult(), controller_.finalRequest(), name.toStdString(), path.toStdString(),
                      width, height);
  });
}

void MainWindow::exportTables(const QString& folder) {
  exportWith("tables exported to " + folder, [&] {
    pipeline::exportTables(*controller_.finalResult(), folder.toStdString(), {controller_.finalRequest().input.path});
  });
}

void MainWindow::exportParcels(const QString& path) {
  exportWith("generated parcels exported to " + path, [&] {
    pipeline::exportParcels(*controller_.finalResult(), path.toStdString(), {controller_.finalRequest().input.path});
  });
}

LeaderboardDialog* MainWindow::showLeaderboard() {
  if (!controller_.finalResult()) {
    showError("nothing to compare yet: open a dataset first");
    return nullptr;
  }
  if (leaderboard_) leaderboard_->close();  // one at a time; a closed one stops and goes
  leaderboard_ = new LeaderboardDialog(controller_.finalRequest(), this);
  leaderboard_->setAttribute(Qt::WA_DeleteOnClose);
  leaderboard_->show();
  return leaderboard_;
}

void MainWindow::fitToObserved() {
  if (!controller_.finalResult()) return showError("nothing to fit yet: open a dataset first");
  if (fitTask_) return;
  const pipeline::CompareRequest request = controller_.finalRequest();
  auto made = std::make_shared<pipeline::Calibration>();
  fitSummary_.clear();
  fitTask_ = new BackgroundTask(
      [request, made](const ProgressFn& progress) { *made = pipeline::calibrate(request, progress); }, this);
  auto* dialog = new QProgressDialog("Fitting each block's style to its observed parcels...", "Cancel", 0, 1000, this);
  dialog->setAttribute(Qt::WA_DeleteOnClose);
  dialog->setMinimumDuration(300);
  connect(dialog, &QProgressDialog::canceled, this, [this] { cancelFit(); });
  connect(fitTask_, &BackgroundTask::progress, dialog, [dialog](double fraction, const QString& stage) {
    dialog->setValue(static_cast<int>(1000 * fraction));
    dialog->setLabelText("Fitting each block's style to its observed parcels: " + stage);
  });
  connect(fitTask_, &BackgroundTask::finished, this, [this, made, dialog](const QString& error) {
    dialog->close();
    fitTask_->deleteLater();
    fitTask_ = nullptr;
    updateActions();
    if (error == "cancelled") {
      status_->setText("fit to observed cancelled");
      return;
    }
    if (!error.isEmpty()) return showError(error);
    controller_.setOverrides(made->session.overrides);
    auto text = [](const pipeline::FitMeasures& f) {
      return QString("KS area %1, width %2, aspect ratio %3, total count error %4")
          .arg(f.ksArea, 0, 'f', 3)
          .arg(f.ksWidth, 0, 'f', 3)
          .arg(f.ksAspectRatio, 0, 'f', 3)
          .arg(f.totalCountError, 0, 'f', 3);
    };
    QStringList chosen;
    for (const auto& [style, blocks] : made->stylesChosen)
      chosen << QString("%1 %2").arg(QString::fromStdString(style)).arg(blocks);
    fitSummary_ =
        QString(
            "Fitted each block's style to its observed parcels (%1). Before (the paper's rule): %2. After: %3. "
            "Cross-validated: %4. Each block's style is now its override.")
            .arg(chosen.join(", "), text(made->before), text(made->after), text(made->crossFitted));
    showNotice(fitSummary_);
    submit();
  });
  updateActions();
}

void MainWindow::cancelFit() {
  if (fitTask_) fitTask_->cancel();
}

void MainWindow::exportWith(const QString& done, const std::function<void()>& write) {
  if (!controller_.finalResult()) return showError("nothing to export yet: open a dataset first");
  try {
    write();
    status_->setText(done);
  } catch (const std::exception& e) {
    showError(e.what());
  }
}

void MainWindow::exportFigureDialog() {
  const QString metric = QString::fromStdString(controller_.request().metric);
  const QStringList items = {"map_" + metric, "hist_" + metric, "map_blocks"};
  bool ok = false;
  const QString name = QInputDialog::getItem(this, "Export figure", "Figure:", items, 0, false, &ok);
  if (!ok) return;
  const QString filter = name.startsWith("hist_") ? "PNG (*.png);;SVG (*.svg);;PDF (*.pdf)" : "PNG (*.png)";
  const QString path = QFileDialog::getSaveFileName(this, "Export figure", name + ".png", filter);
  if (!path.isEmpty()) exportFigure(name, path);
}

void MainWindow::setParameter(const std::string& name, double value) {
  const bool wasPerBlock = controller_.perBlockBounds();
  controller_.setParameter(name, value);
  if (wasPerBlock && !controller_.perBlockBounds()) {
    // Every block leaves its own bounds for the four shown: say so, with what it does to the count.
    const ParameterValues& p = controller_.request().parameters;
    boundsNotice_ =
        QString(
            "Per-block bounds are off: %1 now holds for every block, with A_min %2, A_max %3 "
            "m\u00b2, W_min %4, W_max %5 m (each block had its own, from its observed parcels). "
            "Tick \"per-block bounds\" to go back.")
            .arg(QString::fromStdString(name))
            .arg(number(p.at("a-min")), number(p.at("a-max")), number(p.at("w-min")), number(p.at("w-max")));
    boundsNoticeBefore_.reset();
    if (controller_.shownResult()) boundsNoticeBefore_ = controller_.shownResult()->generated.parcels.size();
    showNotice(boundsNotice_ + (boundsNoticeBefore_
                                    ? QString(" Procedural parcels before: %1.").arg(*boundsNoticeBefore_)
                                    : QString()));
  }
  if (perBlockBounds_->isChecked() != controller_.perBlockBounds()) {
    const QSignalBlocker block(perBlockBounds_);
    perBlockBounds_->setChecked(controller_.perBlockBounds());
  }
  {
    ParameterValues shown;
    shown[name] = value;
    panel_->setValues(shown);
  }
  submit();
}

void MainWindow::setStyle(const QString& style) {
  controller_.setStyle(style.toStdString());
  if (style_->currentText() != style) {
    const QSignalBlocker block(style_);
    style_->setCurrentText(style);
  }
  submit();
}

void MainWindow::setColourBy(const QString& quantity) {
  controller_.setMetric(quantity.toStdString());
  if (colourBy_->currentText() != quantity) {
    const QSignalBlocker block(colourBy_);
    colourBy_->setCurrentText(quantity);
  }
  const auto& shown = controller_.shownResult();
  if (!shown) return;
  // Not measured yet: the views are coloured when the completed result arrives.
  const bool context = analysis::parcelQuantity(controller_.request().metric).context;
  if (context && !shown->generated.contextPending.empty()) return;
  Laps lap;
  UpdateTimings timings;
  recolour(false);
  timings.layers = lap();
  drawHistogram();
  timings.histogram = lap();
  observedView_->render();
  proceduralView_->render();
  timings.views = lap();
  lastTimings_ = timings;
  lastLatencyMs_ = lap.total();
  lastFirstViewMs_ = lastLatencyMs_;
  emit viewsUpdated(controller_.completeSerial());
}

void MainWindow::zoomToExtent() {
  if (!extent_) return;
  observedView_->fit(*extent_);  // the procedural view shares its camera
  observedView_->render();
  proceduralView_->render();
}

void MainWindow::setOutlinesVisible(bool visible) {
  observedView_->layer().setOutlinesVisible(visible);
  proceduralView_->layer().setOutlinesVisible(visible);
  observedView_->render();
  proceduralView_->render();
}

void MainWindow::inspectAt(bool procedural, double x, double y) {
  if (!controller_.shownResult()) return;
  const pipeline::CompareResult& r = *controller_.shownResult();
  selectedProcedural_ = procedural;
  selectedParcel_ =
      procedural ? pipeline::generatedParcelAt(r.generated, {x, y}) : pipeline::parcelAt(*r.observed, {x, y});
  int block = pipeline::blockAt(r, {x, y});
  if (block < 0 && selectedParcel_ >= 0 && !procedural) block = r.observed->analysis.blockOf[selectedParcel_];
  selectBlock(block);
}

QString MainWindow::parcelInfoText() const { return parcelInfo_->toPlainText(); }

void MainWindow::showParcel() {
  if (editing_) return showEditParcel();
  QString html;
  const auto& shown = controller_.shownResult();
  if (!shown || selectedParcel_ < 0) {
    html = "No parcel selected.";
  } else {
    const pipeline::ParcelInspection p = selectedProcedural_
                                             ? pipeline::inspectGeneratedParcel(shown->generated, selectedParcel_)
                                             : pipeline::inspectParcel(*shown->observed, selectedParcel_);
    html = QString("<b>%1 parcel %2</b><table cellspacing=2>")
               .arg(selectedProcedural_ ? "Procedural" : "Observed")
               .arg(selectedParcel_);
    const auto add = [&html](const pipeline::NamedValues& values) {
      for (const auto& [name, v] : values) {
        html += QString("<tr><td>%1</td><td>%2</td></tr>")
                    .arg(QString::fromStdString(name), QString::fromStdString(pipeline::valueText(v)).toHtmlEscaped());
      }
    };
    add(p.attributes);
    add(p.metrics);
    html += "</table>";
  }
  if (html == parcelInfoHtml_) return;
  parcelInfoHtml_ = html;
  parcelInfo_->setHtml(html);
}

QString MainWindow::coordinateText(double x, double y) const {
  const auto& shown = controller_.shownResult();
  if (!shown) return {};
  const io::ParcelLayer& layer = shown->observed->layer;
  const Point p = layer.frame.toSource({x, y});
  if (layer.frame.isGeographic()) return QString("lon %1, lat %2").arg(p.x, 0, 'f', 6).arg(p.y, 0, 'f', 6);
  return QString("x %1, y %2 (%3)").arg(p.x, 0, 'f', 2).arg(p.y, 0, 'f', 2).arg(QString::fromStdString(layer.crs.name));
}

QString MainWindow::aboutText() {
  return QString(
             "<h3>ParcelScope %1</h3>"
             "<p>Observed and procedural parcels, measured side by side (Vanegas et al. 2012; parcel "
             "metrics after Yang et al. 2013). The command line <tt>parcelscope</tt> does to data what this "
             "window does.</p>"
             "<p><b>Libraries</b>: Qt %2 (LGPL 3), VTK %3 (BSD 3-clause), GDAL (MIT), CGAL (GPL 3 and LGPL 3), "
             "GEOS (LGPL 2.1), GeographicLib (MIT), OpenSSL (Apache 2.0).</p>"
             "<p><b>Data</b>: the bundled sample <tt>datasets/sample/sample_town.geojson</tt> is synthetic, "
             "public domain (CC0 1.0). The real datasets of the tests and benchmarks, kept outside the "
             "project: Cambridge MA (PDDL 1.0); Paris and Rh\u00f4ne cadastre (Licence Ouverte 2.0); Malibu, "
             "Eatonville, Seoul (no licence stated).</p>")
      .arg(QString::fromStdString(pipeline::version()), QString::fromLatin1(qVersion()),
           QString::fromLatin1(VTK_VERSION));
}

std::string MainWindow::overridesText() const {
  const Json session = pipeline::sessionJson(controller_.request());
  const Json* overrides = session.find("overrides");
  return overrides ? overrides->dump(0) : std::string();
}

void MainWindow::markOverridesSaved() { savedOverrides_ = overridesText(); }

bool MainWindow::unsavedOverrides() const { return overridesText() != savedOverrides_; }

QString MainWindow::notice() const { return noticeBar_->isVisible() ? noticeBar_->text() : QString(); }

void MainWindow::showNotice(const QString& text) {
  noticeBar_->setText(text);
  noticeBar_->setVisible(!text.isEmpty());
}

void MainWindow::closeEvent(QCloseEvent* event) {
  if (!unsavedOverrides()) return event->accept();
  QMessageBox box(QMessageBox::Question, "Unsaved block overrides",
                  "The block overrides have changed since they were last saved. Save them in a session file?",
                  QMessageBox::Save | QMessageBox::Discard | QMessageBox::Cancel, this);
  box.setObjectName("quitPrompt");
  box.setDefaultButton(QMessageBox::Save);
  const int answer = box.exec();
  if (answer == QMessageBox::Discard) return event->accept();
  if (answer == QMessageBox::Save) {
    const QString path =
        QFileDialog::getSaveFileName(this, "Save session", "session.json", "ParcelScope session (*.json)");
    if (!path.isEmpty()) {
      saveSession(path);
      if (!unsavedOverrides()) return event->accept();
    }
  }
  event->ignore();
}

void MainWindow::selectBlock(int block) {
  selected_ = block;
  selectionChanged_ = true;
  showBlock();
  observedView_->render();
  proceduralView_->render();
}

void MainWindow::overrideSelectedBlock(const QString& style, const ParameterValues& parameters) {
  if (!controller_.shownResult() || selected_ < 0) return showError("select a block first (click it in either view)");
  pipeline::BlockOverride o;
  o.style = style.toStdString();
  o.parameters = parameters;
  controller_.overrideBlock(controller_.shownResult()->observed->analysis.blocks[selected_], o);
  submit();
}

void MainWindow::clearSelectedOverride() {
  if (!controller_.shownResult() || selected_ < 0) return;
  controller_.clearOverride(controller_.shownResult()->observed->analysis.blocks[selected_]);
  submit();
}

void MainWindow::submit() {
  if (!controller_.loaded()) return;
  errorBar_->setVisible(false);
  const qint64 serial = worker_->submit(controller_.request());
  controller_.submitted(serial);
  started_[serial].start();
  firstViewMs_ = -1;
  // Said only when the update takes a while: any change of a label makes Qt
  // compose the whole window again (it holds OpenGL widgets), which would
  // delay drawing a quick result.
  QTimer::singleShot(250, this, [this, serial] {
    // A result in between already says how far the update is.
    if (controller_.awaitingViews(serial)) status_->setText("updating...");
  });
}

void MainWindow::showReport(const UpdateReport& report) {
  // A slot: nothing may escape into Qt's event loop.
  try {
    drawReport(report);
  } catch (const std::exception& e) {
    showError(QString("cannot show the result: ") + e.what());
  }
}

void MainWindow::drawReport(const UpdateReport& report) {
  const pipeline::Controller::Decision decision = controller_.receive(report);
  if (decision.action == pipeline::Controller::Action::Ignore) return;
  if (decision.action == pipeline::Controller::Action::Numbers) {
    fillNumbers();
    showBlock();
    updateActions();
    noteContextCompleted(report.serial);
    return;
  }
  const bool first = decision.newInput;
  const bool contextPending = !report.result->generated.contextPending.empty();
  Laps lap;
  UpdateTimings timings;
  if (const auto it = started_.find(report.serial); it != started_.end()) {
    timings.library = static_cast<double>(it->second.nsecsElapsed()) / 1e6;
  }
  timings.update = 1e3 * report.seconds;
  for (const auto& [stage, seconds] : report.result->seconds) {
    if (stage == "generate") timings.generate = 1e3 * seconds;
    if (stage == "metrics") timings.metrics = 1e3 * seconds;
  }
  if (!report.partial) {
    progress_->setVisible(false);
    cancel_->setVisible(false);
  }
  const pipeline::CompareResult& r = *controller_.shownResult();
  if (first) {
    selected_ = -1;
    selectedParcel_ = -1;
  }
  shownPartial_ = report.partial;
  partialCancelled_ = false;
  partialDone_ = report.blocksRegenerated;
  partialTotal_ = report.blocksTotal;
  if (selectedProcedural_ && selectedParcel_ >= static_cast<int>(r.generated.parcels.size())) selectedParcel_ = -1;

  // Geometry: the observed parcels only when the input was read again.
  const analysis::ObservedAnalysis& a = r.observed->analysis;
  const analysis::ParcelQuantity& q = analysis::parcelQuantity(controller_.request().metric);
  if (first) {
    std::vector<const Polygon*> shapes;
    std::vector<double> values;
    std::vector<int> blocks;
    for (std::size_t i = 0; i < r.observed->layer.parcels.size(); ++i) {
      if (a.blockOf[i] < 0) continue;
      shapes.push_back(&r.observed->layer.parcels[i].shape);
      values.push_back(q.value(a.metrics[i]));
      blocks.push_back(a.blockOf[i]);
    }
    observedView_->layer().setShapes(shapes, values, blocks);
    // The street network the blocks come from, over both views.
    comparisonLines_.clear();
    comparisonSurface_.clear();
    if (const auto& network = r.observed->streets) {
      comparisonLines_ = centreLines(network->graph);
      comparisonSurface_ = analysis::streetSurface(network->graph);
    }
    observedView_->streets().setStreets(comparisonLines_, comparisonSurface_);
    if (!editing_) proceduralView_->streets().setStreets(comparisonLines_, comparisonSurface_);
  }
  if (first && editing_) setEditing(false);  // another input: its network is not the one edited
  if (!editing_) {
    drawProceduralLayer(r.generated);
    // The layer reads these shapes again when the zoom changes.
    releaseInBackground(std::exchange(layerResult_, controller_.shownResult()));
  }
  const bool observedChanged = recolour(first || selectionChanged_);
  selectionChanged_ = false;
  timings.layers = lap();
  if (first) {
    Box extent{1e300, 1e300, -1e300, -1e300};
    for (const Block& b : a.blocks) {
      for (const Polygon& part : b.parts) {
        const Box x = bounds(part);
        extent = {std::min(extent.minX, x.minX), std::min(extent.minY, x.minY), std::max(extent.maxX, x.maxX),
                  std::max(extent.maxY, x.maxY)};
      }
    }
    extent_ = extent;
    observedView_->fit(extent);
  }
  drawHistogram();
  timings.histogram = lap();
  fillNumbers();
  showBlock();
  timings.text = lap();
  if (observedChanged || first) observedView_->render();
  proceduralView_->render();
  timings.views = lap();
  lastTimings_ = timings;
  updateActions();
  // The input opened: it goes to the recent files, as it was opened.
  if (openedInput_ && sameInput(report.request.input, *openedInput_)) {
    rememberRecent(*openedInput_);
    openedInput_.reset();
  }

  const auto it = started_.find(report.serial);
  if (report.partial) {
    if (it != started_.end() && firstViewMs_ < 0) firstViewMs_ = static_cast<double>(it->second.nsecsElapsed()) / 1e6;
    status_->setText(QString("regenerating: %1 of %2 block parts done, the others shown as before")
                         .arg(report.blocksRegenerated)
                         .arg(report.blocksTotal));
    emit partialShown(report.serial);
    return;
  }
  if (it != started_.end()) {
    lastLatencyMs_ = static_cast<double>(it->second.nsecsElapsed()) / 1e6;
    lastFirstViewMs_ = firstViewMs_ < 0 ? lastLatencyMs_ : firstViewMs_;
    if (contextPending) {
      completeStarted_[report.serial] = it->second;
    } else {
      lastCompleteMs_ = lastLatencyMs_;
    }
    started_.erase(started_.begin(), std::next(it));
  }
  if (report.completesContext) noteContextCompleted(report.serial);
  firstViewMs_ = -1;
  if (boundsNoticeBefore_ && !controller_.perBlockBounds()) {
    showNotice(
        boundsNotice_ +
        QString(" Procedural parcels: %1 before, %2 now.").arg(*boundsNoticeBefore_).arg(r.generated.parcels.size()));
    boundsNoticeBefore_.reset();
  }
  status_->setText(QString("%1 blocks, %2 observed and %3 procedural parcels; %4 of %5 block parts regenerated; %6 ms")
                       .arg(a.blocks.size())
                       .arg(r.observedLots.size())
                       .arg(r.generated.parcels.size())
                       .arg(report.blocksRegenerated)
                       .arg(report.blocksTotal)
                       .arg(lastLatencyMs_, 0, 'f', 0));
  if (!r.generated.failures.empty()) {
    status_->setToolTip(QString::fromStdString(std::to_string(r.generated.failures.size()) +
                                               " blocks fell back or "
                                               "were refused; first: " +
                                               r.generated.failures.front()));
  }
  emit viewsUpdated(report.serial);
}

void MainWindow::drawProceduralLayer(const pipeline::GeneratedParcels& generated) {
  // Grouped by block, so that only the layer parts holding changed blocks are built again.
  const analysis::ParcelQuantity& q = analysis::parcelQuantity(controller_.request().metric);
  std::vector<const Polygon*> shapes;
  std::vector<double> values;
  std::vector<int> blocks(generated.parcels.size(), -1);
  for (std::size_t b = 0; b < generated.blocks.size(); ++b) {
    for (int p : generated.blocks[b].parcels) blocks[static_cast<std::size_t>(p)] = static_cast<int>(b);
  }
  for (std::size_t i = 0; i < generated.parcels.size(); ++i) {
    shapes.push_back(&generated.parcels[i]);
    values.push_back(generated.isUnassigned(i) ? std::nan("") : q.value(generated.metrics[i]));
  }
  proceduralView_->layer().setShapes(shapes, values, blocks);
}

void MainWindow::noteContextCompleted(qint64 serial) {
  if (const auto it = completeStarted_.find(serial); it != completeStarted_.end()) {
    lastCompleteMs_ = static_cast<double>(it->second.nsecsElapsed()) / 1e6;
    completeStarted_.erase(completeStarted_.begin(), std::next(it));
  }
  emit contextCompleted(serial);
}

bool MainWindow::recolour(bool observedChanged) {
  if (!controller_.shownResult()) return false;
  const pipeline::CompareResult& r = *controller_.shownResult();
  const std::string& metric = controller_.request().metric;
  const analysis::ParcelQuantity& q = analysis::parcelQuantity(metric);
  // The observed view changes only with its data, the quantity or the scale.
  observedChanged = observedChanged || q.name != shownQuantity_;
  if (observedChanged) {
    std::vector<double> observed;
    for (std::size_t i = 0; i < r.observed->layer.parcels.size(); ++i) {
      if (r.observed->analysis.blockOf[i] >= 0) observed.push_back(q.value(r.observed->analysis.metrics[i]));
    }
    observedView_->layer().setValues(observed);
    shownQuantity_ = q.name;
  }
  // The procedural view shows the comparison's parcels, or the edited network's.
  const pipeline::GeneratedParcels& shownParcels =
      editing_ && editState_ ? editState_->snapshot->parcels() : r.generated;
  std::vector<double> generated;
  generated.reserve(shownParcels.metrics.size());
  for (std::size_t i = 0; i < shownParcels.metrics.size(); ++i) {
    generated.push_back(shownParcels.isUnassigned(i) ? std::nan("") : q.value(shownParcels.metrics[i]));  // grey
  }
  proceduralView_->layer().setValues(generated);
  const pipeline::CompareRequest shown = controller_.shownRequest();
  const viz::ColourScale scale = viz::quantityScale(r, shown, metric);
  if (observedChanged || scale.minimum != shownScale_.minimum || scale.maximum != shownScale_.maximum ||
      scale.kind != shownScale_.kind || scale.title != shownScale_.title) {
    observedView_->layer().setScale(scale);
    proceduralView_->layer().setScale(scale);
    shownScale_ = scale;
    observedChanged = true;
  }
  observedView_->setTitle(QString("Observed: %1 parcels").arg(r.observedLots.size()));
  titleProcedural();
  return observedChanged;
}

void MainWindow::titleProcedural() {
  if (!controller_.shownResult() || editing_) return;
  const pipeline::CompareResult& r = *controller_.shownResult();
  if (!partialCancelled_) {
    const auto unassigned = static_cast<std::size_t>(r.generated.unassignedParcels);
    proceduralView_->setTitle(QString("Procedural (%1, seed %2): %3 parcels%4")
                                  .arg(QString::fromStdString(controller_.shownRequest().style))
                                  .arg(r.generated.seed)
                                  .arg(r.generated.parcels.size() - unassigned)
                                  .arg(unassigned > 0 ? QString(", %1 unassigned (grey)").arg(unassigned) : QString()));
    return;
  }
  // A cancelled update left a result in between: some blocks new, the others as before.
  QStringList styles;
  for (const std::string& s : r.generated.blockStyles) {
    if (!styles.contains(QString::fromStdString(s))) styles << QString::fromStdString(s);
  }
  styles.sort();
  proceduralView_->setTitle(QString("Procedural, partly updated (cancelled: %1 of %2 block parts new), styles shown: "
                                    "%3: %4 parcels")
                                .arg(partialDone_)
                                .arg(partialTotal_)
                                .arg(styles.join(", "))
                                .arg(r.generated.parcels.size()));
}

void MainWindow::drawHistogram() {
  // Texts without this result's numbers (the numbers table has the counts).
  const viz::QuantityHistogram h = viz::quantityHistogram(*controller_.shownResult(), controller_.shownRequest(),
                                                          controller_.request().metric, viz::HistogramTexts::Steady);
  histogramCounts_.clear();
  if (h.edges.empty()) {
    chart_->ClearPlots();
    chart_->SetTitle("no finite value to draw");
  } else {
    viz::fillHistogramChart(chart_, h.title, h.xTitle, h.yTitle, h.edges, h.series,
                            std::max(360, histogramWidget_->height()));
    for (const auto& s : h.series) histogramCounts_.push_back(s.counts);
  }
  histogramStyle_->drawNow();
  if (histogramView_->GetScene()->GetDirty()) histogramWindow_->Render();
}

QImage MainWindow::screenshot() {
  QPixmap shot = grab();
  QPainter painter(&shot);
  for (QVTKOpenGLStereoWidget* view : findChildren<QVTKOpenGLStereoWidget*>()) {
    if (view->isVisible())
      painter.drawImage(QRect(view->mapTo(this, QPoint(0, 0)), view->size()), view->grabFramebuffer());
  }
  painter.end();
  return shot.toImage();
}

QString MainWindow::histogramTitle() const { return QString::fromStdString(chart_->GetTitle()); }

QStringList MainWindow::histogramTexts() const {
  QStringList texts{QString::fromStdString(chart_->GetTitle()),
                    QString::fromStdString(chart_->GetAxis(vtkAxis::BOTTOM)->GetTitle()),
                    QString::fromStdString(chart_->GetAxis(vtkAxis::LEFT)->GetTitle())};
  for (vtkIdType i = 0; i < chart_->GetNumberOfPlots(); ++i) {
    texts << QString::fromStdString(chart_->GetPlot(i)->GetLabel());
  }
  return texts;
}

void MainWindow::fillNumbers() {
  const pipeline::CompareResult& shown = *controller_.shownResult();
  const Table summary = analysis::summaryTable(shown.city);
  const Table distances = analysis::distanceTable(shown.city);
  const auto text = [](const Value& v) -> QString {
    if (const auto* d = std::get_if<double>(&v)) return number(*d);
    if (const auto* i = std::get_if<std::int64_t>(&v)) return QString::number(*i);
    return QString::fromStdString(std::get<std::string>(v));
  };
  const int rows = static_cast<int>(summary.rows.size() + distances.rows.size());
  const int columns = static_cast<int>(std::max(summary.columns.size(), distances.columns.size()));
  // Cells are written in place, and only those whose text changed: a table
  // cleared and filled again is laid out and painted whole after every update.
  bool resized = false;
  if (numbers_->rowCount() != rows + 1 || numbers_->columnCount() != columns) {
    numbers_->clear();
    numbers_->setRowCount(rows + 1);
    numbers_->setColumnCount(columns);
    resized = true;
  }
  bool longer = false;  // a text grew: the columns are fitted again
  const auto put = [&](int row, int column, const QString& value, bool bold) {
    QTableWidgetItem* item = numbers_->item(row, column);
    if (!item) {
      item = new QTableWidgetItem(value);
      if (bold) {
        QFont f = item->font();
        f.setBold(true);
        item->setFont(f);
      }
      numbers_->setItem(row, column, item);
      longer = true;
    } else if (item->text() != value) {
      longer = longer || value.size() > item->text().size();
      item->setText(value);
    }
  };
  QStringList header;
  for (const auto& c : summary.columns) header << QString::fromStdString(c.name);
  while (header.size() < columns) header << QString();
  if (resized) numbers_->setHorizontalHeaderLabels(header);
  // Street access of parcels whose context is still being measured.
  const bool pending = !shown.generated.contextPending.empty();
  int row = 0;
  for (const auto& r : summary.rows) {
    const bool measuring = pending && std::get<std::string>(r.front()) == "street_access_share";
    for (std::size_t c = 0; c < r.size(); ++c) {
      const bool unknown = measuring && std::holds_alternative<double>(r[c]) && std::isnan(std::get<double>(r[c]));
      // After a cancel, what was not measured will not be: say so rather than "measuring...".
      put(row, static_cast<int>(c),
          unknown ? (partialCancelled_ ? QStringLiteral("not measured (cancelled)") : QStringLiteral("measuring..."))
                  : text(r[c]),
          false);
    }
    ++row;
  }
  for (std::size_t c = 0; c < distances.columns.size(); ++c) {
    put(row, static_cast<int>(c), QString::fromStdString(distances.columns[c].name), true);
  }
  ++row;
  for (const auto& r : distances.rows) {
    for (std::size_t c = 0; c < r.size(); ++c) put(row, static_cast<int>(c), text(r[c]), false);
    ++row;
  }
  if (resized || longer) numbers_->resizeColumnsToContents();
}

double MainWindow::blockValue(const pipeline::CompareResult& r, int block, const std::string& name) const {
  const pipeline::CompareRequest& request = controller_.request();
  const Block& b = r.observed->analysis.blocks[block];
  if (const auto o = request.overrides.find(b.key); o != request.overrides.end()) {
    if (const auto v = o->second.parameters.find(name); v != o->second.parameters.end()) return v->second;
  }
  const analysis::BlockStatistics& s = r.observed->analysis.statistics[block];
  const std::map<std::string, double> own = {
      {"a-min", s.aMin}, {"a-max", s.aMax}, {"w-min", s.wMin}, {"w-max", s.wMax}};
  const auto derived = own.find(name);
  if (derived != own.end() && controller_.perBlockBounds() && !request.explicitParameters.count(name) &&
      std::isfinite(derived->second)) {
    const ParameterDescription& d = describe(name);
    return std::clamp(derived->second, d.minimum, d.maximum);
  }
  const auto it = request.parameters.find(name);
  return it != request.parameters.end() ? it->second : describe(name).defaultValue;
}

void MainWindow::fillOverridePanel(const pipeline::CompareResult& r) {
  const Block& block = r.observed->analysis.blocks[selected_];
  const auto o = controller_.request().overrides.find(block.key);
  const bool overridden = o != controller_.request().overrides.end();
  for (const auto& [name, widgets] : blockParameters_) {
    const QSignalBlocker a(widgets.first), b(widgets.second);
    const bool own = overridden && o->second.parameters.count(name);
    widgets.first->setChecked(own);
    widgets.second->setEnabled(own);
    widgets.second->setValue(blockValue(r, selected_, name));
  }
  const QSignalBlocker c(blockStyle_);
  const int style =
      overridden && !o->second.style.empty() ? blockStyle_->findText(QString::fromStdString(o->second.style)) : 0;
  blockStyle_->setCurrentIndex(std::max(0, style));
  panelBlock_ = block.key;
}

void MainWindow::showBlock() {
  showParcel();
  std::vector<const Polygon*> outline;
  if (!controller_.shownResult() || selected_ < 0) {
    observedView_->outline().setShapes(outline);
    proceduralView_->outline().setShapes(outline);
    setBlockInfo("Click a parcel or a block in either view.");
    if (panelBlock_ != 0) {  // no block: the panel shows the run's values again
      for (const auto& [name, widgets] : blockParameters_) {
        const QSignalBlocker x(widgets.first), y(widgets.second);
        widgets.first->setChecked(false);
        widgets.second->setEnabled(false);
        const auto it = controller_.request().parameters.find(name);
        widgets.second->setValue(it != controller_.request().parameters.end() ? it->second
                                                                              : describe(name).defaultValue);
      }
      const QSignalBlocker z(blockStyle_);
      blockStyle_->setCurrentIndex(0);
      panelBlock_ = 0;
    }
    return;
  }
  const pipeline::CompareResult& r = *controller_.shownResult();
  const Block& block = r.observed->analysis.blocks[selected_];
  if (block.key != panelBlock_) fillOverridePanel(r);  // a new selection; edits in the panel stay otherwise
  for (const Polygon& part : block.parts) outline.push_back(&part);
  observedView_->outline().setShapes(outline);
  proceduralView_->outline().setShapes(outline);
  const analysis::BlockStatistics& s = r.observed->analysis.statistics[selected_];
  const analysis::Comparison& c = r.blocks[selected_].comparison;
  QString styles;
  for (std::size_t k = 0; k < r.generated.blockIds.size(); ++k) {
    if (r.generated.blockIds[k] == block.id && !styles.contains(QString::fromStdString(r.generated.blockStyles[k]))) {
      styles += (styles.isEmpty() ? "" : ", ") + QString::fromStdString(r.generated.blockStyles[k]);
    }
  }
  const bool overridden = controller_.overridden(block);
  setBlockInfo(QString("<b>Block %1</b> (%2 m&sup2;; subdivided with %3%4)<br>"
                       "<table cellspacing=4><tr><th></th><th>observed</th><th>procedural</th></tr>"
                       "<tr><td>parcels</td><td>%5</td><td>%6</td></tr>"
                       "<tr><td>A-bar, s_A (m&sup2;)</td><td>%7, %8</td><td>%9, %10</td></tr>"
                       "<tr><td>W-bar, s_W (m)</td><td>%11, %12</td><td>%13, %14</td></tr></table>"
                       "derived A_min %15, A_max %16 m&sup2;; W_min %17, W_max %18 m; street access %19; KS area %20")
                   .arg(block.id)
                   .arg(number(s.blockArea))
                   .arg(styles)
                   .arg(overridden ? ", overridden" : "")
                   .arg(c.observed.parcels)
                   .arg(c.generated.parcels)
                   .arg(number(c.observed.meanArea), number(c.observed.sdArea), number(c.generated.meanArea),
                        number(c.generated.sdArea), number(c.observed.meanWidth), number(c.observed.sdWidth),
                        number(c.generated.meanWidth))
                   .arg(number(c.generated.sdWidth), number(s.aMin), number(s.aMax), number(s.wMin), number(s.wMax),
                        number(s.streetAccessShare), number(c.area.ks)));
}

QString MainWindow::lastError() const { return errorBar_->isVisible() ? errorBar_->text() : QString(); }

void MainWindow::setBlockInfo(const QString& html) {
  if (html == blockInfoHtml_) return;
  blockInfoHtml_ = html;
  blockInfo_->setHtml(html);
}

void MainWindow::showError(const QString& message) {
  const QString shown = windowWording(message);
  errorBar_->setText(shown);
  errorBar_->setVisible(true);
  status_->setText("error");
  emit errorShown(shown);
}

void MainWindow::updateActions() {
  // setEnabled does nothing when the state is unchanged, so this costs nothing per update.
  const bool result = controller_.finalResult() != nullptr;
  saveSessionAction_->setEnabled(result);
  leaderboardAction_->setEnabled(result);
  fitAction_->setEnabled(result && !fitTask_);
  exportMenu_->menuAction()->setEnabled(result);
  for (QAction* a : exportMenu_->actions()) a->setEnabled(result);
  zoomToExtentAction_->setEnabled(extent_.has_value() && controller_.shownResult() != nullptr);
  setCrsAction_->setEnabled(controller_.loaded() || controller_.failedRequest());
  filterAction_->setEnabled(controller_.loaded());
  streetsAction_->setEnabled(controller_.loaded());
  removeStreetsAction_->setEnabled(controller_.loaded() && controller_.request().streets.has_value());
  const bool shown = controller_.shownResult() != nullptr;
  overrideBlock_->setEnabled(shown);
  clearOverride_->setEnabled(shown);
  updateEditActions();
}

void MainWindow::dragEnterEvent(QDragEnterEvent* event) {
  if (event->mimeData()->hasUrls()) event->acceptProposedAction();
}

void MainWindow::dropEvent(QDropEvent* event) {
  const auto urls = event->mimeData()->urls();
  if (urls.isEmpty() || !urls.front().isLocalFile()) return;
  const QString path = urls.front().toLocalFile();
  if (path.endsWith(".json") && path.contains("session")) {
    openSession(path);
  } else {
    openFile(path);
  }
}

void MainWindow::rememberRecent(const io::ReadOptions& input) {
  const RecentFile opened{QString::fromStdString(input.path), QString::fromStdString(input.layer),
                          QString::fromStdString(input.where), QString::fromStdString(input.crsOverride)};
  std::vector<RecentFile> files = readRecentFiles();
  files.erase(std::remove_if(files.begin(), files.end(), [&](const RecentFile& f) { return f.path == opened.path; }),
              files.end());
  files.insert(files.begin(), opened);
  if (files.size() > 8) files.resize(8);
  writeRecentFiles(files);
  refreshRecent();
}

void MainWindow::refreshRecent() {
  recentMenu_->clear();
  for (const RecentFile& f : readRecentFiles()) {
    QAction* a = recentMenu_->addAction(f.path, this, [this, f] { openFile(f.path, f.layer, f.where, f.crs); });
    QStringList how;
    if (!f.layer.isEmpty()) how << "layer " + f.layer;
    if (!f.where.isEmpty()) how << "filter " + f.where;
    how << (f.crs.isEmpty() ? QString("CRS as the file declares it") : "CRS " + f.crs);
    a->setToolTip(how.join("; "));
  }
  recentMenu_->setEnabled(!recentMenu_->isEmpty());
}

}  // namespace parcelscope::gui
