// parcelscope-gui [INPUT] [--layer L] [--where SQL] [--crs EPSG:N] [--session FILE] [--sample]
//                 [--streets FILE [--width-field F] [--name-field F]]
//                 [--subdivision-style STYLE] [--screenshot PNG] [--window-size WxH]
#include <QApplication>
#include <QCommandLineParser>
#include <QTimer>

#include <cstdio>

#include "MainWindow.h"

int main(int argc, char** argv) {
  parcelscope::gui::MainWindow::prepareApplication();
  QApplication app(argc, argv);
  QApplication::setApplicationName("parcelscope-gui");
  QCommandLineParser parser;
  parser.setApplicationDescription("ParcelScope: observed and procedural parcels side by side");
  parser.addHelpOption();
  parser.addPositionalArgument("INPUT", "parcel dataset to open (any polygon format GDAL reads)", "[INPUT]");
  const QCommandLineOption layer("layer", "layer to read", "NAME");
  const QCommandLineOption where("where", "OGR SQL attribute filter", "SQL");
  const QCommandLineOption crs("crs", "CRS of the input, replacing a missing or wrong one", "CRS");
  const QCommandLineOption session("session", "session file to restore", "FILE");
  const QCommandLineOption sample("sample", "open the bundled sample");
  const QCommandLineOption style(
      "subdivision-style", "subdivision style: obb, skeleton, offset or auto (Qt takes --style for its widget style)",
      "STYLE");
  const QCommandLineOption screenshot("screenshot", "save the window as PNG once it shows its first result, then quit",
                                      "PNG");
  const QCommandLineOption size("window-size",
                                "size of the window in screen pixels (e.g. 1366x768; at QT_SCALE_FACTOR=1.5 "
                                "that is 911 x 512 of the window's own)",
                                "WxH");
  const QCommandLineOption streets("streets", "street centre lines: blocks from the street network", "FILE");
  const QCommandLineOption widthField("width-field", "with --streets: the street width field", "F");
  const QCommandLineOption nameField("name-field", "with --streets: the street name field", "F");
  parser.addOptions({layer, where, crs, session, sample, style, screenshot, size, streets, widthField, nameField});
  parser.process(app);

  parcelscope::gui::MainWindow window;
  if (parser.isSet(size)) {
    const QStringList wh = parser.value(size).split('x');
    bool okW = false, okH = false;
    const int w = wh.value(0).toInt(&okW), h = wh.value(1).toInt(&okH);
    if (wh.size() != 2 || !okW || !okH || w <= 0 || h <= 0) {
      std::fprintf(stderr, "parcelscope-gui: --window-size %s is not WxH\n",
                   parser.value(size).toLocal8Bit().constData());
      return 2;
    }
    const double ratio = window.devicePixelRatioF();
    window.resize(static_cast<int>(w / ratio), static_cast<int>(h / ratio));
  }
  window.show();
  if (parser.isSet(style)) window.setStyle(parser.value(style));
  if (parser.isSet(screenshot)) {
    const QString path = parser.value(screenshot);
    QObject::connect(&window, &parcelscope::gui::MainWindow::viewsUpdated, &window, [&window, path] {
      QTimer::singleShot(300, &window, [&window, path] {
        const bool ok = window.screenshot().save(path);
        std::fprintf(stderr, ok ? "screenshot written to %s\n" : "cannot write %s\n", path.toLocal8Bit().constData());
        QApplication::exit(ok ? 0 : 1);
      });
    });
    QObject::connect(&window, &parcelscope::gui::MainWindow::errorShown, &window, [](const QString& message) {
      std::fprintf(stderr, "%s\n", message.toLocal8Bit().constData());
      QApplication::exit(1);
    });
  }
  if (parser.isSet(session)) {
    window.openSession(parser.value(session));
  } else if (parser.isSet(sample)) {
    window.openSample();
  } else if (!parser.positionalArguments().isEmpty()) {
    window.openFile(parser.positionalArguments().front(), parser.value(layer), parser.value(where), parser.value(crs));
  }
  if (parser.isSet(streets))
    window.openStreets(parser.value(streets), parser.value(widthField), parser.value(nameField));
  return QApplication::exec();
}
