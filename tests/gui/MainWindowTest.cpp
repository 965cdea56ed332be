// parcelscope-gui driven as a user drives it, headless under Xvfb (QTest):
// load the sample, move a slider, change the colouring, click a block,
// override it, export every figure and table, survive a bad file, match a
// screenshot baseline, and offer each parameter in its group with a control of
// its kind. Run through scripts/with-xvfb.sh.
#include <QApplication>
#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QGroupBox>
#include <QDir>
#include <QLabel>
#include <QMimeData>
#include <QUrl>
#include <QDragEnterEvent>
#include <QSignalSpy>
#include <QSlider>
#include <QStandardPaths>
#include <QSurfaceFormat>
#include <QTableWidget>
#include <QTemporaryDir>
#include <QTest>
#include <QTextBrowser>
#include <QVTKOpenGLStereoWidget.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "MainWindow.h"
#include "MapView.h"
#include "ParameterPanel.h"
#include "parcelscope/io/Writers.h"
#include "parcelscope/pipeline/CompareJob.h"
#include "viz/ImageCheck.h"

using parcelscope::gui::MainWindow;

namespace {

std::string slurp(const QString& path) {
  std::stringstream s;
  s << std::ifstream(path.toStdString()).rdbuf();
  return s.str();
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
};

int main(int argc, char** argv) {
  QSurfaceFormat::setDefaultFormat(QVTKOpenGLStereoWidget::defaultFormat());
  QApplication app(argc, argv);
  std::filesystem::create_directories(PARCELSCOPE_RENDER_FAILURES);
  MainWindowTest test;
  return QTest::qExec(&test, argc, argv);
}

#include "MainWindowTest.moc"
