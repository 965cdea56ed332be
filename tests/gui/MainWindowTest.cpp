// parcelscope-gui driven as a user drives it, headless under Xvfb (QTest):
// load the sample, move a slider, change the colouring, click a block,
// override it, export every figure and table, survive a bad file, match a
// screenshot baseline, offer each parameter in its group with a control of
// its kind, ignore VTK's own keys, zoom about the cursor, remember how each
// recent file was opened, and offer only what can be done. Run through
// scripts/with-xvfb.sh.
#include <QVTKOpenGLStereoWidget.h>
#include <QApplication>
#include <QCheckBox>
#include <QComboBox>
#include <QDir>
#include <QDoubleSpinBox>
#include <QDragEnterEvent>
#include <QFileInfo>
#include <QGroupBox>
#include <QLabel>
#include <QMenu>
#include <QMessageBox>
#include <QMimeData>
#include <QPushButton>
#include <QRegularExpression>
#include <QScrollArea>
#include <QScrollBar>
#include <QSignalSpy>
#include <QSlider>
#include <QStandardPaths>
#include <QTableWidget>
#include <QTemporaryDir>
#include <QTest>
#include <QTextBrowser>
#include <QTimer>
#include <QUrl>
#include <QWheelEvent>
#include <QWindow>

#include <vtkActor.h>
#include <vtkActorCollection.h>
#include <vtkCallbackCommand.h>
#include <vtkCamera.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkProperty.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderer.h>
#include <vtkRendererCollection.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "LeaderboardDialog.h"
#include "MainWindow.h"
#include "MapView.h"
#include "ParameterPanel.h"
#include "parcelscope/analysis/Comparison.h"
#include "parcelscope/core/Keys.h"
#include "parcelscope/generation/Styles.h"
#include "parcelscope/io/Writers.h"
#include "parcelscope/pipeline/Calibrate.h"
#include "parcelscope/pipeline/CompareJob.h"
#include "parcelscope/pipeline/Inspect.h"
#include "parcelscope/pipeline/Leaderboard.h"
#include "parcelscope/pipeline/StreetEditor.h"
#include "parcelscope/pipeline/StreetsJob.h"
#include "viz/ImageCheck.h"

using parcelscope::gui::MainWindow;

namespace {

std::string slurp(const QString& path) {
  std::stringstream s;
  s << std::ifstream(path.toStdString()).rdbuf();
  return s.str();
}

// The action of a menu, by its text without the '&' of its shortcut letter.
QAction* findAction(QWidget* window, const QString& text) {
  for (QAction* a : window->findChildren<QAction*>()) {
    if (QString(a->text()).remove('&') == text) return a;
  }
  return nullptr;
}

// The paths File > Open recent lists, newest first.
QStringList recentFiles(QWidget* window) {
  QStringList paths;
  for (QMenu* menu : window->findChildren<QMenu*>()) {
    if (QString(menu->title()).remove('&') != "Open recent") continue;
    for (QAction* a : menu->actions()) paths << a->text();
  }
  return paths;
}

struct CameraState {
  double focal[3], position[3], scale;
};
CameraState cameraState(vtkCamera* camera) {
  CameraState s{};
  camera->GetFocalPoint(s.focal);
  camera->GetPosition(s.position);
  s.scale = camera->GetParallelScale();
  return s;
}
bool sameCamera(const CameraState& a, const CameraState& b) {
  for (int i = 0; i < 3; ++i) {
    if (a.focal[i] != b.focal[i] || a.position[i] != b.position[i]) return false;
  }
  return a.scale == b.scale;
}

// A turn of the wheel by one notch (120 eighths of a degree; negative: towards
// the user) at `at`, in the coordinates of `window`.
void turnWheel(QWindow* window, QPoint at, int delta) {
  QWheelEvent wheel(QPointF(at), QPointF(window->mapToGlobal(at)), QPoint(), QPoint(0, delta), Qt::NoButton,
                    Qt::NoModifier, Qt::NoScrollPhase, false);
  QGuiApplication::sendEvent(window, &wheel);
}

}  // namespace

class MainWindowTest : public QObject {
  Q_OBJECT

private:
  MainWindow* window_ = nullptr;
  QTemporaryDir dir_;

  // Waits for the views to show the newest request.
  bool settle(int timeoutMs = 60000) {
    QElapsedTimer t;
    t.start();
    while (window_->busy() && t.elapsed() < timeoutMs) QTest::qWait(20);
    QTest::qWait(50);
    return !window_->busy();
  }

  int libraryParcelCount() {
    return static_cast<int>(parcelscope::pipeline::compare(window_->request()).generated.parcels.size());
  }

private slots:
  void initTestCase() {
    QStandardPaths::setTestModeEnabled(true);
    window_ = new MainWindow;
    window_->resize(1400, 900);
    window_->show();
    QVERIFY(QTest::qWaitForWindowExposed(window_));
    window_->openSample();
    QVERIFY(settle());
    QVERIFY(window_->result());
  }

  void cleanupTestCase() { delete window_; }

  void loadsTheSample() {
    const auto r = window_->result();
    QCOMPARE(static_cast<int>(r->observed->analysis.blocks.size()), 10);
    QVERIFY(window_->lastError().isEmpty());
    QVERIFY(window_->observedView()->title().contains(QString::number(r->observedLots.size())));
    QCOMPARE(static_cast<int>(window_->result()->generated.parcels.size()), libraryParcelCount());
    QCOMPARE(window_->histogramCounts().size(), std::size_t(2));
    QVERIFY(window_->numbers()->rowCount() > 10);
    // Linked views: one camera, so a zoom in one is a zoom in the other.
    QCOMPARE(window_->observedView()->camera(), window_->proceduralView()->camera());
  }

  void droppingAFileOpensIt() {
    QMimeData data;
    data.setUrls({QUrl::fromLocalFile(QString(PARCELSCOPE_SOURCE_DIR) + "/datasets/sample/sample_town.geojson")});
    QDragEnterEvent enter(QPoint(10, 10), Qt::CopyAction, &data, Qt::LeftButton, Qt::NoModifier);
    QApplication::sendEvent(window_, &enter);
    QVERIFY(enter.isAccepted());
    QDropEvent drop(QPointF(10, 10), Qt::CopyAction, &data, Qt::LeftButton, Qt::NoModifier);
    QApplication::sendEvent(window_, &drop);
    QVERIFY(settle());
    // Opened as dropped: without the sample's right-of-way filter, so its street
    // features are read too.
    QCOMPARE(window_->request().input.where, std::string());
    QVERIFY(window_->lastError().isEmpty());
    QVERIFY(window_->result()->observed->layer.parcels.size() > 168);
    window_->openSample();
    QVERIFY(settle());
  }

  void movingASliderRegeneratesLikeTheLibrary() {
    const auto before = window_->result();
    const auto histogramBefore = window_->histogramCounts();
    const QStringList textsBefore = window_->histogramTexts();
    // Drag the W_max slider down, step by step as a drag does, to about 18 m:
    // narrower parcels, so more of them.
    QSlider* slider = window_->parameterPanel()->slider("w-max");
    QDoubleSpinBox* spin = window_->parameterPanel()->spinBox("w-max");
    while (spin->value() > 18 && slider->value() > slider->minimum()) slider->setValue(slider->value() - 1);
    QVERIFY(spin->value() > 12);
    QVERIFY(settle());
    QVERIFY2(window_->lastError().isEmpty(), qPrintable(window_->lastError()));
    const auto after = window_->result();
    QVERIFY(after != before);
    QVERIFY(after->generated.parcels.size() > before->generated.parcels.size());
    QVERIFY(window_->histogramCounts() != histogramBefore);
    // The chart's texts stay the same while its counts change: a text new with
    // every result would make VTK draw all of them again on each redraw.
    QCOMPARE(window_->histogramTexts(), textsBefore);
    QVERIFY(textsBefore.size() >= 5);
    QVERIFY(window_->proceduralView()->title().contains(QString::number(after->generated.parcels.size())));
    QVERIFY(window_->request().explicitParameters.count("w-max"));
    QCOMPARE(static_cast<int>(after->generated.parcels.size()), libraryParcelCount());
    // The spin box follows the slider.
    QCOMPARE(window_->parameterPanel()->spinBox("w-max")->value(), window_->request().parameters.at("w-max"));
    // The time split: the library's part and the views', within the whole.
    const auto t = window_->lastTimings();
    QVERIFY(t.library > 0);
    QVERIFY(t.views > 0);
    const double parts = t.library + t.layers + t.histogram + t.text + t.views;
    QVERIFY2(parts <= window_->lastLatencyMs() + 0.5, qPrintable(QString::number(parts)));
  }

  void colourByChangesHistogramWithoutRegenerating() {
    const auto before = window_->result();
    window_->setColourBy("area");
    QVERIFY(window_->histogramTitle().contains("Parcel area"));
    QCOMPARE(window_->result(), before);
    window_->setColourBy("aspect_ratio");
    QVERIFY(window_->histogramTitle().contains("aspect ratio"));
    QCOMPARE(window_->lastTimings().library, 0.0);  // the window alone
    QVERIFY(window_->lastTimings().views > 0);
  }

  void clickingABlockSelectsItAndOverridingRegeneratesIt() {
    const auto r = window_->result();
    const parcelscope::Point inside = parcelscope::interiorPoint(r->observed->analysis.blocks[4].parts.front());
    auto* view = window_->proceduralView();
    QTest::mouseClick(view->vtkWidget()->embeddedOpenGLWindow(), Qt::LeftButton, {}, view->widgetPoint(inside));
    QTest::qWait(50);
    QCOMPARE(window_->selectedBlock(), 4);
    const std::int64_t before = r->blocks[4].comparison.generated.parcels;
    window_->overrideSelectedBlock("obb", {{"a-max", 250.0}, {"a-min", 80.0}, {"w-min", 4.0}});
    QVERIFY(settle());
    const auto after = window_->result();
    QVERIFY(after->blocks[4].comparison.generated.parcels > before);
    QCOMPARE(after->blocks[3].comparison.generated.parcels, r->blocks[3].comparison.generated.parcels);
    QCOMPARE(static_cast<int>(after->generated.parcels.size()), libraryParcelCount());
    auto* info = window_->findChild<QTextBrowser*>("blockInfo");
    QVERIFY(info);
    QVERIFY(info->toPlainText().contains("Block 4"));
    QVERIFY(info->toPlainText().contains("overridden"));
  }

  void exportsFiguresTablesParcelsAndSession() {
    const QString d = dir_.path();
    window_->exportFigure("map_aspect_ratio", d + "/map.png", 900, 450);
    window_->exportFigure("hist_aspect_ratio", d + "/hist.svg", 900, 450);
    window_->exportFigure("map_blocks", d + "/blocks.png", 900, 450);
    window_->exportTables(d);
    window_->exportParcels(d + "/parcels.gpkg");
    window_->exportParcels(d + "/parcels.geojson");
    window_->saveSession(d + "/session.json");
    QVERIFY2(window_->lastError().isEmpty(), qPrintable(window_->lastError()));
    for (const char* png : {"map.png", "blocks.png"}) {
      const auto image = parcelscope::test::readPng((d + "/" + png).toStdString());
      QCOMPARE(image.width, 900);
      QVERIFY(parcelscope::test::ink(image).share > 0.05);
    }
    QVERIFY(slurp(d + "/hist.svg").find("<svg") != std::string::npos);
    const std::string generated = slurp(d + "/generated_parcels.csv");
    const auto lines = std::count(generated.begin(), generated.end(), '\n');
    QCOMPARE(static_cast<std::size_t>(lines), window_->result()->generated.parcels.size() + 1);
    for (const char* table : {"observed_parcels.csv", "blocks.csv", "summary.csv", "distances.csv"}) {
      QVERIFY2(QFileInfo(d + "/" + table).size() > 50, table);
    }
    QVERIFY(slurp(d + "/parcels.geojson").find("\"FeatureCollection\"") != std::string::npos);
    QVERIFY(QFileInfo(d + "/parcels.gpkg").size() > 10000);
    QVERIFY(QDir(d).entryList(QStringList() << ".*partial*", QDir::Hidden | QDir::Files).isEmpty());
    // The session restores the overrides and parameters: the same parcels.
    const auto shown = window_->result();
    const auto session = parcelscope::pipeline::readSession((d + "/session.json").toStdString());
    QCOMPARE(session.overrides.size(), std::size_t(1));
    QCOMPARE(session.parameters.at("w-max"), window_->request().parameters.at("w-max"));
    window_->setParameter("seed", 9);
    QVERIFY(settle());
    window_->openSession(d + "/session.json");
    QVERIFY(settle());
    QCOMPARE(window_->result()->generated.parcels.size(), shown->generated.parcels.size());
    QCOMPARE(window_->result()->city.area.ks, shown->city.area.ks);
  }

  void aBadFileIsAMessageInTheWindow() {
    const auto before = window_->result();
    const QString bad = dir_.path() + "/broken.geojson";
    std::ofstream(bad.toStdString()) << "{ this is not geojson";
    window_->openFile(bad);
    QVERIFY(settle());
    QTRY_VERIFY_WITH_TIMEOUT(!window_->lastError().isEmpty(), 10000);
    QVERIFY2(window_->lastError().contains("broken.geojson"), qPrintable(window_->lastError()));
    QCOMPARE(window_->result(), before);  // the last result stays on screen
    window_->openSample();
    QVERIFY(settle());
    QVERIFY(window_->lastError().isEmpty());
    // A file that opens but cannot be read as asked fails in the update; the
    // request is then the last good one again, so a later edit builds on it
    // instead of reading the file as asked again (and failing again).
    const auto good = window_->result();
    const QString sample = QString(PARCELSCOPE_SOURCE_DIR) + "/datasets/sample/sample_town.geojson";
    window_->openFile(sample, {}, "no_such_field = 1");
    QVERIFY(settle());
    QTRY_VERIFY_WITH_TIMEOUT(!window_->lastError().isEmpty(), 10000);
    QVERIFY2(window_->lastError().contains("no_such_field"), qPrintable(window_->lastError()));
    QCOMPARE(window_->result(), good);
    QVERIFY(window_->controller().failedRequest());
    QCOMPARE(window_->controller().failedRequest()->input.where, std::string("no_such_field = 1"));
    QCOMPARE(window_->request().input.where, std::string("use <> 'ROW'"));
    const double seed = window_->request().parameters.at("seed");
    window_->setParameter("seed", seed + 1);
    QVERIFY(settle());
    QVERIFY2(window_->lastError().isEmpty(), qPrintable(window_->lastError()));
    QVERIFY(window_->result() != good);
    QCOMPARE(window_->result()->observed, good->observed);  // the same input, not read again
    window_->setParameter("seed", seed);
    QVERIFY(settle());
  }

  // File > Filter features does what --where does: the sample without its
  // filter holds its right-of-way parcel too; a filter that fails leaves the
  // last good state usable.
  void aFilterKeepsTheMatchingFeaturesAsWhereDoes() {
    window_->openSample();
    QVERIFY(settle());
    const auto filtered = window_->result();
    window_->setFilter("");
    QVERIFY(settle());
    QVERIFY2(window_->lastError().isEmpty(), qPrintable(window_->lastError()));
    QCOMPARE(window_->request().input.where, std::string());
    QCOMPARE(window_->result()->observed->layer.parcels.size(), filtered->observed->layer.parcels.size() + 1);
    window_->setFilter("use = 'residential'");
    QVERIFY(settle());
    QVERIFY2(window_->lastError().isEmpty(), qPrintable(window_->lastError()));
    QCOMPARE(window_->result()->observed->layer.report.features, std::int64_t(146));
    window_->setFilter("no_such_field = 2");
    QVERIFY(settle());
    QTRY_VERIFY_WITH_TIMEOUT(!window_->lastError().isEmpty(), 10000);
    window_->setFilter("use <> 'ROW'");
    QVERIFY(settle());
    QVERIFY2(window_->lastError().isEmpty(), qPrintable(window_->lastError()));
    QCOMPARE(window_->result()->observed->layer.parcels.size(), filtered->observed->layer.parcels.size());
  }

  // The block panel shows the selected block's own values (its derived bounds
  // under per-block bounds), follows the selection, and refuses a W_max below
  // the block's W_min instead of moving W_min without a word.
  void theOverridePanelFollowsTheBlockAndRefusesCrossedBounds() {
    window_->openSample();
    QVERIFY(settle());
    auto* perBlock = window_->findChild<QCheckBox*>("perBlockBounds");
    QVERIFY(perBlock);
    const bool wasPerBlock = perBlock->isChecked();
    if (!perBlock->isChecked()) {
      perBlock->setChecked(true);
      QVERIFY(settle());
    }
    QVERIFY(window_->controller().perBlockBounds());
    const auto r = window_->result();
    auto* wMin = window_->findChild<QDoubleSpinBox*>("block-spin-w-min");
    auto* wMax = window_->findChild<QDoubleSpinBox*>("block-spin-w-max");
    auto* wMaxCheck = window_->findChild<QCheckBox*>("block-check-w-max");
    auto* apply = window_->findChild<QPushButton*>("overrideBlock");
    QVERIFY(wMin && wMax && wMaxCheck && apply);
    for (int b : {2, 5}) {
      window_->selectBlock(b);
      QVERIFY(settle());
      const auto& s = r->observed->analysis.statistics[b];
      QCOMPARE(wMin->value(), std::round(s.wMin * 100) / 100);  // the spin box shows two decimals
      QCOMPARE(wMax->value(), std::round(s.wMax * 100) / 100);
    }
    const auto overridesBefore = window_->request().overrides.size();
    wMaxCheck->setChecked(true);
    wMax->setValue(wMin->value() / 2);
    apply->click();
    QTRY_VERIFY_WITH_TIMEOUT(window_->lastError().contains("w-max"), 5000);
    QVERIFY2(window_->lastError().contains("below the block's w-min"), qPrintable(window_->lastError()));
    QCOMPARE(window_->request().overrides.size(), overridesBefore);
    wMaxCheck->setChecked(false);
    window_->selectBlock(-1);
    QVERIFY(settle());
    QCOMPARE(wMax->value(), std::round(window_->request().parameters.at("w-max") * 100) / 100);
    if (!wasPerBlock) {
      perBlock->setChecked(false);
      QVERIFY(settle());
    }
  }

  // The main window with the sample at seed 1 against a baseline screenshot;
  // PARCELSCOPE_UPDATE_BASELINES=1 makes the screenshot the baseline.
  void screenshotMatchesItsBaseline() {
    window_->openSample();
    QVERIFY(settle());
    window_->setStyle("obb");
    window_->setParameter("seed", 1);
    QVERIFY(settle());
    window_->selectBlock(-1);
    QTest::qWait(300);
    const QString shot = dir_.path() + "/window.png";
    QVERIFY(window_->screenshot().save(shot));
    const std::string baseline = std::string(PARCELSCOPE_SOURCE_DIR) + "/tests/data/baseline/gui_main_window.png";
    if (qEnvironmentVariableIsSet("PARCELSCOPE_UPDATE_BASELINES")) {
      std::filesystem::copy_file(shot.toStdString(), baseline, std::filesystem::copy_options::overwrite_existing);
      QSKIP("baseline written");
    }
    const auto a = parcelscope::test::readPng(shot.toStdString());
    const auto b = parcelscope::test::readPng(baseline);
    QCOMPARE(a.width, b.width);
    QCOMPARE(a.height, b.height);
    const double differing = parcelscope::test::differingShare(a, b);
    if (differing > 0.02) {
      std::filesystem::copy_file(shot.toStdString(), std::string(PARCELSCOPE_RENDER_FAILURES) + "/gui_main_window.png",
                                 std::filesystem::copy_options::overwrite_existing);
    }
    QVERIFY2(differing <= 0.02, qPrintable(QString("%1 of the pixels differ").arg(differing)));
  }

  // The views are drawn from the parcels' shapes; their neighbours and street
  // access are measured after, and the numbers then match the library's.
  void streetAccessFollowsTheViews() {
    QSignalSpy drawn(window_, &MainWindow::viewsUpdated);
    QSignalSpy completed(window_, &MainWindow::contextCompleted);
    window_->setParameter("omega", 0.45);
    QVERIFY(settle());
    QVERIFY(drawn.count() >= 1);
    QCOMPARE(completed.count(), 1);
    QCOMPARE(completed.last().at(0).toLongLong(), drawn.last().at(0).toLongLong());
    QVERIFY(window_->result()->generated.contextPending.empty());
    QVERIFY(window_->lastCompleteMs() >= window_->lastLatencyMs());
    const auto expected = parcelscope::pipeline::compare(window_->request());
    QCOMPARE(window_->result()->city.generated.streetAccessShare, expected.city.generated.streetAccessShare);
    QTableWidget* numbers = window_->numbers();
    int row = 0;
    while (row < numbers->rowCount() && numbers->item(row, 0)->text() != "street_access_share") ++row;
    QVERIFY(row < numbers->rowCount());
    QCOMPARE(numbers->item(row, 3)->text(), QString::number(expected.city.generated.streetAccessShare, 'g', 5));

    // Coloured by street access, the views need it: measured before drawing.
    window_->setColourBy("street_access");
    drawn.clear();
    completed.clear();
    window_->setParameter("omega", 0.5);
    QVERIFY(settle());
    QVERIFY(drawn.count() >= 1);
    QCOMPARE(completed.count(), 0);
    QVERIFY(window_->result()->generated.contextPending.empty());
    QVERIFY2(window_->histogramTitle().contains("street_access"), qPrintable(window_->histogramTitle()));
    window_->setColourBy("aspect_ratio");
  }

  // The panel is built from the descriptions' groups and kinds: a box per
  // group, combo boxes of labels for enums, check boxes for booleans, and no
  // control for the settings of written files.
  void parametersComeInTheirGroupsWithCombosAndCheckBoxes() {
    parcelscope::gui::ParameterPanel* panel = window_->parameterPanel();
    for (const char* group : {"Bounds", "Blocks", "Subdivision", "Skeleton", "Comparison", "Figures"}) {
      QVERIFY2(panel->groupBox(group), group);
    }
    QVERIFY(!panel->groupBox("Output"));  // spatial-index only: no box
    QVERIFY(panel->groupBox("Bounds")->findChild<QSlider*>("slider-a-min"));
    QVERIFY(panel->groupBox("Skeleton")->findChild<QDoubleSpinBox*>("spin-street-angle"));
    QVERIFY(!window_->findChild<QCheckBox*>("check-figures"));
    QVERIFY(!window_->findChild<QDoubleSpinBox*>("spin-figure-width"));

    QComboBox* corner = window_->findChild<QComboBox*>("combo-corner-rule");
    QVERIFY(corner);
    QCOMPARE(corner, panel->comboBox("corner-rule"));
    QVERIFY(!panel->slider("corner-rule"));
    QCOMPARE(corner->count(), 2);
    QCOMPARE(corner->itemText(0), QString("street-width"));
    QCOMPARE(corner->itemText(1), QString("street-length"));
    QCOMPARE(corner->currentIndex(), 0);
    QCheckBox* rightOfWay = window_->findChild<QCheckBox*>("check-detect-right-of-way");
    QVERIFY(rightOfWay);
    QVERIFY(rightOfWay->isChecked());
    QCheckBox* patios = panel->checkBox("patio-obb");
    QVERIFY(patios);
    QVERIFY(!patios->isChecked());

    // A choice reaches the request as the number the run records hold.
    corner->setCurrentIndex(1);
    QCOMPARE(window_->request().parameters.at("corner-rule"), 1.0);
    QVERIFY(window_->request().explicitParameters.count("corner-rule"));
    QCOMPARE(panel->value("corner-rule"), 1.0);
    patios->setChecked(true);
    QCOMPARE(window_->request().parameters.at("patio-obb"), 1.0);
    QVERIFY(settle());
    QVERIFY2(window_->lastError().isEmpty(), qPrintable(window_->lastError()));
    corner->setCurrentIndex(0);
    patios->setChecked(false);
    QCOMPARE(window_->request().parameters.at("corner-rule"), 0.0);
    QCOMPARE(window_->request().parameters.at("patio-obb"), 0.0);
    // Values set from outside (a session) show in the controls.
    panel->setValues({{"corner-rule", 1.0}, {"detect-right-of-way", 0.0}});
    QCOMPARE(corner->currentIndex(), 1);
    QVERIFY(!rightOfWay->isChecked());
    QCOMPARE(window_->request().parameters.at("corner-rule"), 0.0);  // setValues emits nothing
    panel->setValues(window_->request().parameters);
    QVERIFY(settle());
  }

  // VTK's own keys ('w' wireframe, 's' surface, '3' stereo, 'r' reset the
  // camera, 'f' fly to, 'p' pick, 'e'/'q' quit, 'j'/'t' joystick or trackball)
  // do nothing in the views or the histogram.
  void vtkKeysDoNothingInTheViews() {
    for (parcelscope::gui::MapView* view : {window_->observedView(), window_->proceduralView()}) {
      vtkRenderWindow* window = view->vtkWidget()->renderWindow();
      vtkRenderer* map = window->GetRenderers()->GetFirstRenderer();
      QWindow* surface = view->vtkWidget()->embeddedOpenGLWindow();
      int exits = 0;
      vtkNew<vtkCallbackCommand> exit;
      exit->SetClientData(&exits);
      exit->SetCallback([](vtkObject*, unsigned long, void* count, void*) { ++*static_cast<int*>(count); });
      const unsigned long observer = window->GetInteractor()->AddObserver(vtkCommand::ExitEvent, exit);
      QTest::mouseMove(surface, QPoint(surface->width() / 2, surface->height() / 3));
      const CameraState before = cameraState(view->camera());
      for (char key : {'w', '3', 'r', 'f', 'p', 'j', 't', 'u', 'e', 'q'}) {
        QTest::keyClick(surface, key);
        QTest::qWait(20);
      }
      window->GetInteractor()->RemoveObserver(observer);
      QCOMPARE(exits, 0);
      QVERIFY(!window->GetStereoRender());
      QVERIFY(sameCamera(cameraState(view->camera()), before));
      vtkActorCollection* actors = map->GetActors();
      actors->InitTraversal();
      int surfaces = 0;
      while (vtkActor* actor = actors->GetNextActor()) {
        QCOMPARE(actor->GetProperty()->GetRepresentation(), VTK_SURFACE);
        ++surfaces;
      }
      QVERIFY(surfaces > 0);
    }
    QVTKOpenGLStereoWidget* histogram = nullptr;
    for (QVTKOpenGLStereoWidget* w : window_->findChildren<QVTKOpenGLStereoWidget*>()) {
      if (w != window_->observedView()->vtkWidget() && w != window_->proceduralView()->vtkWidget()) histogram = w;
    }
    QVERIFY(histogram);
    QTest::keyClick(histogram->embeddedOpenGLWindow(), '3');
    QVERIFY(!histogram->renderWindow()->GetStereoRender());
  }

  // The wheel keeps the world point under the cursor under it; View > Zoom to
  // extent (Home) fits the views to the data again.
  void wheelZoomsAboutTheCursorAndHomeFitsTheData() {
    QAction* fit = findAction(window_, "Zoom to extent");
    QVERIFY(fit);
    QVERIFY(fit->isEnabled());
    QCOMPARE(fit->shortcut(), QKeySequence(Qt::Key_Home));
    fit->trigger();
    parcelscope::gui::MapView* view = window_->proceduralView();
    QWindow* surface = view->vtkWidget()->embeddedOpenGLWindow();
    const CameraState fitted = cameraState(view->camera());
    // A point well away from the view's centre.
    const parcelscope::Point p{fitted.focal[0] + 0.4 * fitted.scale, fitted.focal[1] + 0.4 * fitted.scale};
    const QPoint at = view->widgetPoint(p);
    QVERIFY(QRect(QPoint(0, 0), surface->size()).contains(at));
    turnWheel(surface, at, 120);
    const CameraState in = cameraState(view->camera());
    QVERIFY(in.scale < 0.9 * fitted.scale);
    QVERIFY2((view->widgetPoint(p) - at).manhattanLength() <= 2, qPrintable(QString("(%1, %2) moved to (%3, %4)")
                                                                                .arg(at.x())
                                                                                .arg(at.y())
                                                                                .arg(view->widgetPoint(p).x())
                                                                                .arg(view->widgetPoint(p).y())));
    // The other view follows (one camera).
    QCOMPARE(window_->observedView()->camera()->GetParallelScale(), in.scale);
    turnWheel(surface, at, -120);
    QVERIFY((view->widgetPoint(p) - at).manhattanLength() <= 2);
    QVERIFY(std::abs(view->camera()->GetParallelScale() - fitted.scale) < 1e-6 * fitted.scale);
    for (int i = 0; i < 3; ++i) turnWheel(surface, at, 120);
    QVERIFY(!sameCamera(cameraState(view->camera()), fitted));
    // Home, with the keyboard focus in a view (Xvfb has no window manager to
    // activate the window).
    window_->activateWindow();
    QVERIFY(QTest::qWaitForWindowActive(window_));
    QTest::keyClick(surface, Qt::Key_Home);
    QTest::qWait(20);
    const CameraState home = cameraState(view->camera());
    QCOMPARE(home.scale, fitted.scale);
    QCOMPARE(home.focal[0], fitted.focal[0]);
    QCOMPARE(home.focal[1], fitted.focal[1]);
  }

  // A file that fails does not go to File > Open recent; one that opens goes
  // there with its layer, filter and CRS, which opening it from there uses.
  void recentFilesRememberHowTheyOpened() {
    // The sample in metres of EPSG:26986 with no CRS declared: GeoJSON means
    // lon/lat, so it fails until it is given its CRS.
    const QString projected = dir_.path() + "/projected_town.geojson";
    {
      const QString text =
          QString::fromStdString(slurp(QString(PARCELSCOPE_SOURCE_DIR) + "/datasets/sample/sample_town.geojson"));
      QString out;
      const QRegularExpression pair(R"(\[(-?\d+\.?\d*),(-?\d+\.?\d*)\])");
      int last = 0;
      for (auto it = pair.globalMatch(text); it.hasNext();) {
        const auto m = it.next();
        const double x = 231000 + (m.captured(1).toDouble() + 71.1) * 82270;
        const double y = 902000 + (m.captured(2).toDouble() - 42.37) * 111050;
        out += text.mid(last, m.capturedStart() - last) + QString("[%1,%2]").arg(x, 0, 'f', 3).arg(y, 0, 'f', 3);
        last = m.capturedEnd();
      }
      out += text.mid(last);
      std::ofstream(projected.toStdString()) << out.toStdString();
    }
    window_->openFile(projected, {}, "use <> 'ROW'");
    QVERIFY(settle());
    QTRY_VERIFY_WITH_TIMEOUT(!window_->lastError().isEmpty(), 10000);
    QVERIFY2(window_->lastError().contains("File > Set input CRS"), qPrintable(window_->lastError()));
    QVERIFY2(!window_->lastError().contains("--crs"), qPrintable(window_->lastError()));
    QVERIFY(!recentFiles(window_).contains(projected));

    window_->openFile(projected, {}, "use <> 'ROW'", "EPSG:26986");
    QVERIFY(settle());
    QVERIFY2(window_->lastError().isEmpty(), qPrintable(window_->lastError()));
    QCOMPARE(static_cast<int>(window_->result()->observed->analysis.blocks.size()), 10);
    QCOMPARE(recentFiles(window_).value(0), projected);

    // A CRS GDAL does not know: a message in the window's words, and the file
    // keeps the CRS it opened with.
    window_->openFile(projected, {}, "use <> 'ROW'", "NOT_A_CRS");
    QVERIFY(settle());
    QTRY_VERIFY_WITH_TIMEOUT(!window_->lastError().isEmpty(), 10000);
    QVERIFY2(window_->lastError().contains("NOT_A_CRS"), qPrintable(window_->lastError()));
    QVERIFY2(!window_->lastError().contains("--"), qPrintable(window_->lastError()));

    window_->openSample();
    QVERIFY(settle());
    QCOMPARE(window_->request().input.crsOverride, std::string());
    QMenu* recent = nullptr;
    for (QMenu* menu : window_->findChildren<QMenu*>()) {
      if (QString(menu->title()).remove('&') == "Open recent") recent = menu;
    }
    QVERIFY(recent);
    QAction* entry = nullptr;
    for (QAction* a : recent->actions()) {
      if (a->text() == projected) entry = a;
    }
    QVERIFY(entry);
    entry->trigger();
    QVERIFY(settle());
    QVERIFY2(window_->lastError().isEmpty(), qPrintable(window_->lastError()));
    QCOMPARE(window_->request().input.path, projected.toStdString());
    QCOMPARE(window_->request().input.crsOverride, std::string("EPSG:26986"));
    QCOMPARE(window_->request().input.where, std::string("use <> 'ROW'"));
    window_->openSample();
    QVERIFY(settle());
  }

  // Before any result, what needs one is disabled (so no file dialog opens
  // for nothing to export); with one, it is enabled. Messages name the
  // window's controls, not the command line's flags, which keeps its words.
  void menusWaitForAResultAndMessagesUseTheWindowsWords() {
    const QStringList needResult = {"Save session...",      "Figure...",        "Tables (CSV)...",
                                    "Generated parcels...", "Set input CRS...", "Zoom to extent"};
    {
      MainWindow fresh;
      for (const QString& text : needResult) {
        QAction* action = findAction(&fresh, text);
        QVERIFY2(action, qPrintable(text));
        QVERIFY2(!action->isEnabled(), qPrintable(text));
      }
      for (const char* text : {"Override block", "Clear override"}) {
        QPushButton* button = nullptr;
        for (QPushButton* b : fresh.findChildren<QPushButton*>()) {
          if (b->text() == text) button = b;
        }
        QVERIFY2(button, text);
        QVERIFY2(!button->isEnabled(), text);
      }
      QVERIFY(findAction(&fresh, "Open...")->isEnabled());
      QVERIFY(findAction(&fresh, "Open session...")->isEnabled());
    }
    for (const QString& text : needResult) {
      QAction* action = findAction(window_, text);
      QVERIFY2(action && action->isEnabled(), qPrintable(text));
    }

    const double wMax = window_->request().parameters.at("w-max");
    window_->setParameter("w-min", wMax + 10);
    QVERIFY(settle());
    QTRY_VERIFY_WITH_TIMEOUT(!window_->lastError().isEmpty(), 10000);
    QVERIFY2(window_->lastError().contains("w-min must not exceed w-max"), qPrintable(window_->lastError()));
    QVERIFY2(!window_->lastError().contains("--"), qPrintable(window_->lastError()));
    // The command line says it with its flags.
    QVERIFY(window_->controller().failedRequest());
    try {
      parcelscope::pipeline::compare(*window_->controller().failedRequest());
      QFAIL("w-min above w-max was accepted");
    } catch (const std::exception& e) {
      QVERIFY2(std::string(e.what()).find("--w-min must not exceed --w-max") != std::string::npos, e.what());
    }
    QCOMPARE(window_->request().parameters.at("w-max"), wMax);
    QVERIFY(window_->request().parameters.at("w-min") < wMax);
  }
  // A click selects the parcel under the cursor and its block: the inspector
  // shows the parcel's attributes and metrics, the block panel its block.
  void clickingAParcelInspectsItAndItsBlock() {
    window_->openSample();
    QVERIFY(settle());
    const auto r = window_->result();
    // A procedural parcel of block 3.
    const int block = 3;
    int parcel = -1;
    for (std::size_t e = 0; e < r->generated.blocks.size() && parcel < 0; ++e) {
      if (r->generated.blockIds[e] == block && !r->generated.blocks[e].parcels.empty())
        parcel = r->generated.blocks[e].parcels.front();
    }
    QVERIFY(parcel >= 0);
    const parcelscope::Point inside = parcelscope::interiorPoint(r->generated.parcels[parcel]);
    auto* view = window_->proceduralView();
    window_->zoomToExtent();
    QTest::mouseClick(view->vtkWidget()->embeddedOpenGLWindow(), Qt::LeftButton, {}, view->widgetPoint(inside));
    QTest::qWait(50);
    QCOMPARE(window_->selectedParcel(), parcel);
    QVERIFY(window_->selectedParcelIsProcedural());
    QCOMPARE(window_->selectedBlock(), block);
    const QString info = window_->parcelInfoText();
    QVERIFY2(info.contains("Procedural parcel " + QString::number(parcel)), qPrintable(info));
    for (const auto& q : parcelscope::analysis::parcelMetrics())
      QVERIFY2(info.contains(QString::fromStdString(q.name)), qPrintable(info));
    auto* blockInfo = window_->findChild<QTextBrowser*>("blockInfo");
    QVERIFY(blockInfo->toPlainText().contains("Block 3"));

    // An observed parcel: its key and its block.
    const auto& observed = r->observed->layer.parcels;
    std::size_t lot = 0;
    while (lot < observed.size() && r->observed->analysis.blockOf[lot] != 5) ++lot;
    QVERIFY(lot < observed.size());
    const parcelscope::Point there = parcelscope::interiorPoint(observed[lot].shape);
    auto* left = window_->observedView();
    QTest::mouseClick(left->vtkWidget()->embeddedOpenGLWindow(), Qt::LeftButton, {}, left->widgetPoint(there));
    QTest::qWait(50);
    QCOMPARE(window_->selectedParcel(), static_cast<int>(lot));
    QVERIFY(!window_->selectedParcelIsProcedural());
    QCOMPARE(window_->selectedBlock(), 5);
    QVERIFY2(window_->parcelInfoText().contains(
                 QString::fromStdString(parcelscope::keyText(parcelscope::parcelKey(observed[lot])))),
             qPrintable(window_->parcelInfoText()));
    QVERIFY(blockInfo->toPlainText().contains("Block 5"));
    window_->selectBlock(-1);
  }

  // Under each view: a scale bar of a round length that follows the zoom, and
  // the input coordinates (lon/lat for the sample) of the point under the cursor.
  void viewsHaveAScaleBarAndACoordinateReadout() {
    window_->zoomToExtent();
    QTest::qWait(50);
    parcelscope::gui::MapView* view = window_->proceduralView();
    view->render();
    const double metres = view->scaleBarMetres();
    QVERIFY(metres > 0);
    QVERIFY(view->scaleBarPixels() > 20 && view->scaleBarPixels() <= 120);
    QVERIFY(std::abs(metres / view->scaleBarPixels() - view->metresPerPixel()) < 0.02 * view->metresPerPixel());
    const double mantissa = metres / std::pow(10.0, std::floor(std::log10(metres)));
    QVERIFY2(std::abs(mantissa - 1) < 1e-9 || std::abs(mantissa - 2) < 1e-9 || std::abs(mantissa - 5) < 1e-9,
             qPrintable(view->scaleBarText()));
    QVERIFY(view->scaleBarText().endsWith(" m") || view->scaleBarText().endsWith(" km"));
    QWindow* surface = view->vtkWidget()->embeddedOpenGLWindow();
    const CameraState fitted = cameraState(view->camera());
    const parcelscope::Point p{fitted.focal[0] + 0.2 * fitted.scale, fitted.focal[1] - 0.1 * fitted.scale};
    for (int i = 0; i < 4; ++i) turnWheel(surface, view->widgetPoint(p), 120);
    QTest::qWait(50);
    view->render();
    QVERIFY2(view->scaleBarMetres() < metres, qPrintable(view->scaleBarText()));

    QTest::mouseMove(surface, view->widgetPoint(p));
    QTest::qWait(50);
    const parcelscope::Point source = window_->result()->observed->layer.frame.toSource(p);
    const QString readout = view->readout();
    QVERIFY2(readout.startsWith("lon -71."), qPrintable(readout));
    const QRegularExpression numbers(R"(lon (-?[\d.]+), lat (-?[\d.]+))");
    const auto m = numbers.match(readout);
    QVERIFY2(m.hasMatch(), qPrintable(readout));
    // Within a pixel or two of the point (about 1e-5 degrees here).
    QVERIFY2(std::abs(m.captured(1).toDouble() - source.x) < 2e-5, qPrintable(readout));
    QVERIFY2(std::abs(m.captured(2).toDouble() - source.y) < 2e-5, qPrintable(readout));
    QCOMPARE(window_->observedView()->readout(), readout);  // both views say where the cursor is
    window_->zoomToExtent();
  }

  // Help > About names the version and the licences of the code, its
  // libraries and the data.
  void helpAboutNamesVersionAndLicences() {
    QAction* about = findAction(window_, "About ParcelScope...");
    QVERIFY(about);
    about->trigger();
    QMessageBox* box = nullptr;
    QTRY_VERIFY((box = window_->findChild<QMessageBox*>("aboutBox")) != nullptr);
    const QString text = box->text();
    QVERIFY2(text.contains(QString::fromStdString(parcelscope::pipeline::version())), qPrintable(text));
    for (const char* licence : {"CC0 1.0", "PDDL 1.0", "Licence Ouverte 2.0", "LGPL", "BSD", "no licence stated"}) {
      QVERIFY2(text.contains(licence), licence);
    }
    box->accept();
  }

  // A bound slider moves in fine steps where the values matter (a 40 px drag
  // of W_max from 30 m stays well within a factor of three), and moving one
  // while blocks have their own bounds says so, with the parcel count.
  void boundSlidersAreFineAndSayWhenPerBlockBoundsGo() {
    window_->openSample();
    QVERIFY(settle());
    auto* perBlock = window_->findChild<QCheckBox*>("perBlockBounds");
    perBlock->setChecked(true);
    QVERIFY(settle());
    QVERIFY(window_->notice().isEmpty());
    QSlider* slider = window_->parameterPanel()->slider("w-max");
    QDoubleSpinBox* spin = window_->parameterPanel()->spinBox("w-max");
    window_->parameterPanel()->setValues({{"w-max", 30.0}});
    const int at30 = slider->value();
    // A drag of 40 px moves the slider by 40 / width of its range.
    const int steps = static_cast<int>(std::ceil(40.0 * (slider->maximum() - slider->minimum()) / slider->width()));
    const auto before = window_->result();
    slider->setValue(at30 + steps);
    const double moved = spin->value();
    QVERIFY2(moved > 30 && moved < 120, qPrintable(QString("40 px moved W_max from 30 m to %1 m").arg(moved)));
    QVERIFY(!perBlock->isChecked());
    QVERIFY2(window_->notice().contains("every block"), qPrintable(window_->notice()));
    QVERIFY(settle());
    const QString notice = window_->notice();
    QVERIFY2(notice.contains(QString("%1 before, %2 now")
                                 .arg(before->generated.parcels.size())
                                 .arg(window_->result()->generated.parcels.size())),
             qPrintable(notice));
    // One slider step is a small change anywhere on it.
    for (int position : {slider->minimum() + 10, (slider->minimum() + slider->maximum()) / 2, slider->maximum() - 10}) {
      slider->setValue(position);
      const double a = spin->value();
      slider->setValue(position + 1);
      const double b = spin->value();
      QVERIFY2(b > a && b < a * 1.02 + 0.05 + 1e-9, qPrintable(QString("%1 -> %2").arg(a).arg(b)));
    }
    perBlock->setChecked(true);
    QVERIFY(settle());
    QVERIFY(window_->notice().isEmpty());
  }

  // Small screens and scaling: at 1280x720, and at the logical sizes of
  // 1280x720 and 1366x768 at 1.5x and 1920x1080 at 2x, every parameter's
  // control can be scrolled into view, whole, with a usable size.
  void everyParameterIsReachableOnSmallScreens() {
    const QSize original = window_->size();
    auto* scroll = window_->findChild<QScrollArea*>("controlsScroll");
    QVERIFY(scroll);
    for (const QSize size : {QSize(1280, 720), QSize(853, 480), QSize(910, 512), QSize(960, 540)}) {
      window_->resize(size);
      QTest::qWait(100);
      QVERIFY2(window_->size() == size, qPrintable(QString("asked %1x%2, got %3x%4 (minimum %5x%6)")
                                                       .arg(size.width())
                                                       .arg(size.height())
                                                       .arg(window_->width())
                                                       .arg(window_->height())
                                                       .arg(window_->minimumSizeHint().width())
                                                       .arg(window_->minimumSizeHint().height())));
      QVERIFY(
          window_->rect().contains(scroll->geometry().translated(scroll->parentWidget()->mapTo(window_, QPoint()))));
      QList<QWidget*> controls;
      for (QWidget* w : window_->parameterPanel()->findChildren<QWidget*>()) {
        if (qobject_cast<QSlider*>(w) || qobject_cast<QDoubleSpinBox*>(w) || qobject_cast<QComboBox*>(w) ||
            qobject_cast<QCheckBox*>(w))
          controls << w;
      }
      for (const char* name : {"block-spin-w-max", "block-check-seed", "overrideBlock", "perBlockBounds", "style"}) {
        controls << window_->findChild<QWidget*>(name);
      }
      QVERIFY(controls.size() > 20);
      for (QWidget* w : controls) {
        QVERIFY(w);
        // As ensureWidgetVisible, for the whole widget (it keeps only a spin box's text cursor in view).
        const QPoint at = w->mapTo(scroll->widget(), QPoint(0, 0));
        scroll->ensureVisible(at.x() + w->width() / 2, at.y() + w->height() / 2, (w->width() + 1) / 2,
                              (w->height() + 1) / 2);
        QTest::qWait(5);
        const QString what = QString("%1 at %2x%3").arg(w->objectName()).arg(size.width()).arg(size.height());
        QVERIFY2(w->isVisibleTo(window_), qPrintable(what));
        QVERIFY2(w->width() >= 12 && w->height() >= 12, qPrintable(what));
        if (qobject_cast<QSlider*>(w)) QVERIFY2(w->width() >= 60, qPrintable(what + ": slider too short"));
        const QRect inViewport(w->mapTo(scroll->viewport(), QPoint(0, 0)), w->size());
        QVERIFY2(
            scroll->viewport()->rect().contains(inViewport),
            qPrintable(QString("%1 is clipped: (%2, %3) %4x%5 in a viewport of %6x%7, scrolled %8 of %9, panel %10")
                           .arg(what)
                           .arg(inViewport.x())
                           .arg(inViewport.y())
                           .arg(inViewport.width())
                           .arg(inViewport.height())
                           .arg(scroll->viewport()->width())
                           .arg(scroll->viewport()->height())
                           .arg(scroll->verticalScrollBar()->value())
                           .arg(scroll->verticalScrollBar()->maximum())
                           .arg(scroll->widget()->height())));
      }
      // The views and the histogram keep a size of their own.
      for (parcelscope::gui::MapView* v : {window_->observedView(), window_->proceduralView()}) {
        QVERIFY(v->vtkWidget()->width() >= 100 && v->vtkWidget()->height() >= 80);
      }
      QVERIFY(window_->numbers()->isVisible() && window_->numbers()->height() > 40);
    }
    window_->resize(original);
    QTest::qWait(100);
  }

  // Cancel during a long update that showed a result in between: the view's
  // title says it is partly updated and which styles it shows, and the
  // numbers do not promise measurements that will not come.
  void cancelLeavesATruthfulTitleAndTable() {
    // The sample ten by ten times over: 1,000 blocks, long enough (seconds in
    // the skeleton style) to show results in between and be cancelled before the end.
    const QString big = dir_.path() + "/big_town.geojson";
    {
      const std::string text = slurp(QString(PARCELSCOPE_SOURCE_DIR) + "/datasets/sample/sample_town.geojson");
      const std::size_t open = text.find("\"features\"");
      const std::size_t first = text.find('[', open);
      const std::size_t last = text.rfind(']');
      const QString features = QString::fromStdString(text.substr(first + 1, last - first - 1));
      const QRegularExpression pair(R"(\[(-?\d+\.?\d*),\s*(-?\d+\.?\d*)\])");
      QStringList copies;
      for (int i = 0; i < 10; ++i) {
        for (int j = 0; j < 10; ++j) {
          QString out;
          int at = 0;
          for (auto it = pair.globalMatch(features); it.hasNext();) {
            const auto m = it.next();
            out +=
                features.mid(at, m.capturedStart() - at) + QString("[%1,%2]")
                                                               .arg(m.captured(1).toDouble() + 0.006 * i, 0, 'f', 7)
                                                               .arg(m.captured(2).toDouble() + 0.0045 * j, 0, 'f', 7);
            at = m.capturedEnd();
          }
          copies << out + features.mid(at);
        }
      }
      std::ofstream(big.toStdString()) << text.substr(0, first + 1) << copies.join(",").toStdString()
                                       << text.substr(last);
    }
    window_->setStyle("obb");
    window_->openFile(big, {}, "use <> 'ROW'");
    QVERIFY(settle(120000));
    QVERIFY2(window_->lastError().isEmpty(), qPrintable(window_->lastError()));
    QVERIFY(window_->result()->observed->analysis.blocks.size() >= 1000);
    auto* cancel = window_->findChild<QPushButton*>("cancelButton");
    QVERIFY(cancel);
    bool clicked = false;
    QMetaObject::Connection c = connect(window_, &MainWindow::partialShown, this, [&] {
      if (!clicked) {
        clicked = true;
        cancel->click();
      }
    });
    window_->setStyle("skeleton");
    QVERIFY(settle(120000));
    disconnect(c);
    QVERIFY2(clicked, "no result in between was shown");
    QVERIFY(window_->controller().failedOrCancelled());
    const QString title = window_->proceduralView()->title();
    QVERIFY2(title.contains("partly updated") && title.contains("cancelled"), qPrintable(title));
    QVERIFY2(title.contains("obb") && title.contains("skeleton"), qPrintable(title));
    QVERIFY2(!title.startsWith("Procedural (skeleton"), qPrintable(title));
    QTableWidget* numbers = window_->numbers();
    for (int row = 0; row < numbers->rowCount(); ++row) {
      for (int column = 0; column < numbers->columnCount(); ++column) {
        const QTableWidgetItem* item = numbers->item(row, column);
        QVERIFY2(!item || item->text() != "measuring...", qPrintable(QString("row %1").arg(row)));
      }
    }
    // The next change finishes the job and the title is the plain one again.
    window_->setStyle("obb");
    QVERIFY(settle(120000));
    QVERIFY2(window_->proceduralView()->title().startsWith("Procedural (obb"),
             qPrintable(window_->proceduralView()->title()));
    window_->openSample();
    QVERIFY(settle());
  }

  // Streets opened with the parcels: the blocks are the street network's (the
  // command line's --streets gives the same parcels), the centre lines are
  // drawn over both views, and removing them brings the parcel blocks back.
  // Analysis > Compare every style: the command line's leaderboard (the same
  // library call on the same request), shown and saved as `compare --style all`.
  void leaderboardShowsEveryStyleAsTheCommandLine() {
    QVERIFY(settle());
    parcelscope::gui::LeaderboardDialog* dialog = window_->showLeaderboard();
    QVERIFY(dialog);
    QSignalSpy finished(dialog, &parcelscope::gui::LeaderboardDialog::finished);
    QVERIFY(finished.wait(120000));
    QVERIFY2(dialog->board(), qPrintable(dialog->error()));
    const auto expected = parcelscope::pipeline::leaderboard(window_->controller().finalRequest());
    const parcelscope::Table t = parcelscope::pipeline::leaderboardTable(expected);
    QTableWidget* shown = dialog->styles();
    QCOMPARE(shown->rowCount(), static_cast<int>(parcelscope::generation::styles().size()));
    const auto fit = static_cast<int>(t.column("fit"));
    for (int r = 0; r < shown->rowCount(); ++r) {
      QCOMPARE(shown->item(r, 0)->text(), QString::fromStdString(std::get<std::string>(t.rows[r][0])));
      QCOMPARE(shown->item(r, fit)->text(), QString::number(std::get<double>(t.rows[r][fit]), 'g', 3));
    }
    QCOMPARE(dialog->layout()->rowCount(), shown->rowCount() + 1);  // the observed layout first
    const QString out = dir_.filePath("leaderboard");
    QVERIFY2(dialog->save(out), qPrintable(dialog->error()));
    for (const char* f : {"leaderboard.csv", "leaderboard_blocks.csv", "layout.csv", "leaderboard.png", "run.json"}) {
      QVERIFY2(QFileInfo::exists(out + "/" + f), f);
    }
    dialog->close();
    QTRY_VERIFY(!window_->findChild<parcelscope::gui::LeaderboardDialog*>());
  }

  // Analysis > Fit to observed: calibrate's choice per block becomes each
  // block's override, and the views show what `compare --session` of
  // calibrate's session.json gives.
  void fitToObservedGivesEachBlockItsCalibratedStyle() {
    QVERIFY(settle());
    const auto expected = parcelscope::pipeline::calibrate(window_->controller().finalRequest());
    window_->fitToObserved();
    QVERIFY(window_->fitting());
    QTRY_VERIFY_WITH_TIMEOUT(!window_->fitting(), 120000);
    QVERIFY(settle());
    QVERIFY2(window_->lastError().isEmpty(), qPrintable(window_->lastError()));
    QVERIFY(window_->notice().contains("After:"));
    QVERIFY(window_->notice().contains(QString("total count error %1").arg(expected.after.totalCountError, 0, 'f', 3)));
    const auto& overrides = window_->request().overrides;
    QCOMPARE(overrides.size(), expected.session.overrides.size());
    for (const auto& [key, o] : expected.session.overrides) QCOMPARE(overrides.at(key).style, o.style);
    QCOMPARE(window_->result()->city.area.ks, expected.after.ksArea);
    QVERIFY(window_->unsavedOverrides());
    window_->openSample();  // back to no overrides for the tests that follow
    QVERIFY(settle());
  }

  void streetsOpenedWithTheParcelsGiveTheirBlocksAndAreDrawn() {
    window_->openSample();
    QVERIFY(settle());
    const std::size_t parcelBlocks = window_->result()->observed->analysis.blocks.size();
    QCOMPARE(window_->proceduralView()->streets().lines(), std::size_t(0));
    window_->openStreets(QString(PARCELSCOPE_SOURCE_DIR) + "/datasets/sample/sample_streets.geojson", "width", "name");
    QVERIFY(settle());
    QVERIFY2(window_->lastError().isEmpty(), qPrintable(window_->lastError()));
    const auto r = window_->result();
    QVERIFY(r->observed->streets);
    QCOMPARE(r->observed->analysis.blocks.size(), r->observed->streets->blocks.blocks.size());
    QCOMPARE(r->observed->analysis.blocks.size(), std::size_t(10));
    std::size_t streetEdges = 0;
    for (const auto& e : r->observed->streets->graph.edges) streetEdges += !e.boundary;
    QVERIFY(streetEdges >= 9);
    QCOMPARE(window_->observedView()->streets().lines(), streetEdges);
    QCOMPARE(window_->proceduralView()->streets().lines(), streetEdges);
    QCOMPARE(static_cast<int>(r->generated.parcels.size()), libraryParcelCount());
    auto* remove = window_->findChild<QAction*>("removeStreetsAction");
    QVERIFY(remove && remove->isEnabled());
    window_->removeStreets();
    QVERIFY(settle());
    QVERIFY(!window_->result()->observed->streets);
    QCOMPARE(window_->result()->observed->analysis.blocks.size(), parcelBlocks);
    QCOMPARE(window_->proceduralView()->streets().lines(), std::size_t(0));
    QVERIFY(!remove->isEnabled());
  }

  // Edit > Edit streets (Vanegas et al. 2012, section 5): the editor starts
  // from the comparison's parcels; a drag is one edit whose parcels follow
  // the node; a parcel's label follows it; undo gives back the parcels before
  // bit for bit; width, curve (by its control points), delete and draw are
  // edits; the saved edits replayed by the library give the same parcels and
  // keys; leaving editing shows the comparison again.
  void streetEditingFollowsDragsUndoesAndSavesItsEdits() {
    window_->openSample();
    QVERIFY(settle());
    auto* edit = window_->findChild<QAction*>("editStreetsAction");
    QVERIFY(edit);
    QVERIFY(!edit->isEnabled());  // no street network yet
    window_->openStreets(QString(PARCELSCOPE_SOURCE_DIR) + "/datasets/sample/sample_streets.geojson", "width", "name");
    QVERIFY(settle());
    QVERIFY(edit->isEnabled());
    const auto compared = window_->result();
    const auto sameParcels = [](const std::vector<parcelscope::Polygon>& a,
                                const std::vector<parcelscope::Polygon>& b) {
      if (a.size() != b.size()) return false;
      for (std::size_t i = 0; i < a.size(); ++i) {
        if (a[i].outer.size() != b[i].outer.size() || a[i].holes.size() != b[i].holes.size()) return false;
        for (std::size_t k = 0; k < a[i].outer.size(); ++k) {
          if (a[i].outer[k].x != b[i].outer[k].x || a[i].outer[k].y != b[i].outer[k].y) return false;
        }
      }
      return true;
    };
    const auto settleEdits = [&] {
      return QTest::qWaitFor([&] { return window_->editState() && !window_->editBusy(); }, 30000);
    };
    QVERIFY(window_->setEditing(true));
    QVERIFY(settleEdits());
    QVERIFY2(window_->lastError().isEmpty(), qPrintable(window_->lastError()));
    QVERIFY(sameParcels(window_->editState()->snapshot->parcels().parcels, compared->generated.parcels));
    QVERIFY(window_->proceduralView()->handles().visible());
    QVERIFY(window_->proceduralView()->handles().nodes() >= 8);
    QVERIFY(window_->proceduralView()->title().startsWith("Edited streets"));

    // Drag the busiest node 3 m in two moves: one edit.
    const parcelscope::analysis::RoadGraph graph = window_->editState()->snapshot->network().graph;
    std::size_t busiest = 0;
    for (std::size_t i = 0; i < graph.nodes.size(); ++i) {
      if (graph.nodes[i].degree > graph.nodes[busiest].degree) busiest = i;
    }
    const parcelscope::analysis::RoadNode node = graph.nodes[busiest];
    const double pixel = window_->proceduralView()->metresPerPixel();
    QVERIFY(pixel > 0);
    QVERIFY(window_->pressAt(node.at.x + 2 * pixel, node.at.y));
    window_->dragTo(node.at.x + 1.5, node.at.y);
    window_->dragTo(node.at.x + 3, node.at.y + 1);
    window_->dropAt(node.at.x + 3, node.at.y + 1);
    QVERIFY(settleEdits());
    const parcelscope::gui::StreetEditState* moved = window_->editState();
    QCOMPARE(moved->history.size(), std::size_t(1));
    QCOMPARE(moved->undo, std::size_t(1));
    for (const auto& n : moved->snapshot->network().graph.nodes) {
      if (n.key != node.key) continue;
      QCOMPARE(n.at.x, node.at.x + 3);
      QCOMPARE(n.at.y, node.at.y + 1);
    }
    QVERIFY(moved->report && !moved->report->blocksAffected.empty());
    QVERIFY2(static_cast<double>(moved->report->matched) >=
                 0.8 * static_cast<double>(std::min(moved->report->parcelsBefore, moved->report->parcelsAfter)),
             qPrintable(QString("%1 of %2").arg(moved->report->matched).arg(moved->report->parcelsBefore)));
    QVERIFY(!sameParcels(moved->snapshot->parcels().parcels, compared->generated.parcels));
    QVERIFY(window_->lastEditLatencyMs() > 0);

    // Click a parcel: it is selected, labelled, and its label follows it across an edit.
    const auto& parcels = moved->snapshot->parcels();
    const parcelscope::Polygon& lot = parcels.parcels[parcels.blocks.back().parcels.front()];
    parcelscope::Point inside{0, 0};
    const auto vertices = static_cast<double>(lot.outer.size());
    for (const auto& p : lot.outer) inside = {inside.x + p.x / vertices, inside.y + p.y / vertices};
    const int at = parcelscope::pipeline::generatedParcelAt(parcels, inside);
    QVERIFY(at >= 0);
    const parcelscope::Key lotKey = moved->snapshot->parcelKeys()[static_cast<std::size_t>(at)];
    window_->editClickAt(inside.x, inside.y);
    if (window_->selectedEditParcel() == 0) QSKIP("the parcel's vertex mean lies near a street");
    QCOMPARE(window_->selectedEditParcel(), lotKey);
    window_->labelSelectedParcel("blue house");
    QVERIFY(settleEdits());
    QCOMPARE(window_->editState()->snapshot->labels().at(lotKey), std::string("blue house"));
    QVERIFY(window_->parcelInfoText().contains("blue house"));

    // Undo twice: the comparison's parcels, bit for bit; redo twice: back.
    window_->undoEdit();
    QVERIFY(settleEdits());
    QVERIFY(window_->editState()->snapshot->labels().empty());
    window_->undoEdit();
    QVERIFY(settleEdits());
    QVERIFY(sameParcels(window_->editState()->snapshot->parcels().parcels, compared->generated.parcels));
    window_->redoEdit();
    QVERIFY(settleEdits());
    window_->redoEdit();
    QVERIFY(settleEdits());
    QCOMPARE(window_->editState()->snapshot->labels().at(lotKey), std::string("blue house"));
    QCOMPARE(window_->editState()->history.size(), std::size_t(2));

    // A street selected by a click on its middle: width, curve, its control point dragged, deleted.
    const parcelscope::analysis::RoadGraph& now = window_->editState()->snapshot->network().graph;
    parcelscope::Key street = 0;
    parcelscope::Point middle;
    double longest = 0;
    for (const auto& e : now.edges) {
      if (e.boundary || e.line.size() != 2 || e.from == e.to) continue;
      const double length = std::hypot(e.line[1].x - e.line[0].x, e.line[1].y - e.line[0].y);
      if (length > longest) {
        longest = length;
        street = e.key;
        middle = {(e.line[0].x + e.line[1].x) / 2, (e.line[0].y + e.line[1].y) / 2};
      }
    }
    QVERIFY(street != 0);
    window_->editClickAt(middle.x, middle.y);
    QCOMPARE(window_->selectedStreet(), street);
    window_->setSelectedStreetWidth(21);
    QVERIFY(settleEdits());
    const auto edgeOf = [&](parcelscope::Key key) -> const parcelscope::analysis::RoadEdge* {
      for (const auto& e : window_->editState()->snapshot->network().graph.edges) {
        if (e.key == key) return &e;
      }
      return nullptr;
    };
    QVERIFY(edgeOf(street));
    QCOMPARE(edgeOf(street)->width, 21.0);
    window_->setSelectedStreetCurved(true);
    QVERIFY(settleEdits());
    QVERIFY(edgeOf(street)->controls.has_value());
    const parcelscope::Point control = (*edgeOf(street)->controls)[0];
    QVERIFY(window_->pressAt(control.x, control.y));
    window_->dragTo(control.x + 4, control.y + 4);
    window_->dropAt(control.x + 4, control.y + 4);
    QVERIFY(settleEdits());
    QCOMPARE((*edgeOf(street)->controls)[0].x, control.x + 4);
    window_->deleteSelectedStreet();
    QVERIFY(settleEdits());
    QVERIFY(!edgeOf(street));

    // Draw a street between two nodes of the network.
    const std::size_t edgesBefore = window_->editState()->snapshot->network().graph.edges.size();
    window_->setDrawingStreet(true);
    window_->editClickAt(node.at.x + 3, node.at.y + 1);  // the node dragged above
    const parcelscope::Point far{node.at.x + 3 + 0.3 * longest, node.at.y + 1};
    window_->editClickAt(far.x, far.y);
    QVERIFY(settleEdits());
    QVERIFY2(window_->lastError().isEmpty(), qPrintable(window_->lastError()));
    QVERIFY(window_->editState()->snapshot->network().graph.edges.size() > edgesBefore);

    // The saved edits, replayed by the library on the same comparison: the same parcels and keys.
    QTemporaryDir dir;
    const QString editsPath = dir.filePath("edits.json");
    window_->saveEdits(editsPath);
    QVERIFY2(window_->lastError().isEmpty(), qPrintable(window_->lastError()));
    parcelscope::pipeline::StreetEditor replay(window_->controller().shownRequest(), window_->result()->observed);
    const auto edits = parcelscope::pipeline::readEdits(editsPath.toStdString(),
                                                        [&](const parcelscope::Point& p) { return replay.toLocal(p); });
    QCOMPARE(edits.size(), window_->editState()->history.size());
    for (std::size_t i = 0; i < edits.size(); ++i) {
      try {
        replay.apply(edits[i]);
      } catch (const std::exception& e) {
        QFAIL(qPrintable(QString("edit %1 (%2): %3\n%4")
                             .arg(i)
                             .arg(parcelscope::pipeline::editOpName(edits[i].op))
                             .arg(e.what())
                             .arg(QString::fromStdString(slurp(editsPath)))));
      }
    }
    const auto& shown = *window_->editState()->snapshot;
    // The same blocks and parcels; the keys too, but for a parcel whose
    // match in its block turned on a difference of the conversion's rounding.
    QCOMPARE(replay.parcels().blockKeys, shown.parcels().blockKeys);
    QCOMPARE(replay.parcelKeys().size(), shown.parcelKeys().size());
    std::size_t sameKeys = 0;
    for (std::size_t i = 0; i < shown.parcelKeys().size(); ++i)
      sameKeys += replay.parcelKeys()[i] == shown.parcelKeys()[i];
    QVERIFY2(static_cast<double>(sameKeys) >= 0.97 * static_cast<double>(shown.parcelKeys().size()),
             qPrintable(QString("%1 of %2 keys").arg(sameKeys).arg(shown.parcelKeys().size())));
    QCOMPARE(replay.parcels().parcels.size(), shown.parcels().parcels.size());
    // Coordinates went through the input's CRS and back: areas equal to within 0.001 m².
    for (std::size_t i = 0; i < shown.parcels().parcels.size(); ++i) {
      QVERIFY(std::abs(parcelscope::area(replay.parcels().parcels[i]) - parcelscope::area(shown.parcels().parcels[i])) <
              1e-3);
    }
    QCOMPARE(replay.labels(), shown.labels());

    // Leaving editing: the comparison's parcels and no handles.
    QVERIFY(window_->setEditing(false));
    QVERIFY(!window_->proceduralView()->handles().visible());
    QVERIFY(window_->proceduralView()->title().startsWith("Procedural"));
    window_->removeStreets();
    QVERIFY(settle());
  }

  // Quitting with block overrides changed since the last save asks Save,
  // Discard or Cancel (answered here by a timer, as a user would click);
  // without changes it does not ask.
  void quittingWithUnsavedOverridesAsks() {
    window_->openSample();
    QVERIFY(settle());
    QVERIFY(!window_->unsavedOverrides());
    window_->selectBlock(2);
    window_->overrideSelectedBlock("obb", {{"seed", 5.0}});
    QVERIFY(settle());
    QVERIFY(window_->unsavedOverrides());
    QStringList buttons;
    auto answer = [&buttons](QMessageBox::StandardButton button) {
      QTimer::singleShot(100, [&buttons, button] {
        auto* box = qobject_cast<QMessageBox*>(QApplication::activeModalWidget());
        if (!box) return;
        buttons.clear();
        for (QAbstractButton* b : box->buttons()) buttons << QString(b->text()).remove('&');
        box->button(button)->click();
      });
    };
    answer(QMessageBox::Cancel);
    QVERIFY(!window_->close());
    QVERIFY(window_->isVisible());
    QVERIFY2(buttons.contains("Save") && buttons.contains("Discard") && buttons.contains("Cancel"),
             qPrintable(buttons.join(",")));
    // Saved: no question.
    window_->saveSession(dir_.path() + "/quit-session.json");
    QVERIFY(!window_->unsavedOverrides());
    buttons.clear();
    answer(QMessageBox::Cancel);
    QVERIFY(window_->close());
    QTest::qWait(200);
    QVERIFY(buttons.isEmpty());
    window_->show();
    QVERIFY(QTest::qWaitForWindowExposed(window_));
    window_->clearSelectedOverride();
    QVERIFY(settle());
    answer(QMessageBox::Discard);
    QVERIFY(window_->close());
    QCOMPARE(buttons.size(), 3);
  }
};

int main(int argc, char** argv) {
  MainWindow::prepareApplication();
  QApplication app(argc, argv);
  // The quit prompt's test closes the window: that must not end the application.
  QApplication::setQuitOnLastWindowClosed(false);
  std::filesystem::create_directories(PARCELSCOPE_RENDER_FAILURES);
  MainWindowTest test;
  return QTest::qExec(&test, argc, argv);
}

#include "MainWindowTest.moc"
