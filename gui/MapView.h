#pragma once
// One parcel map view: a VTK render window in a Qt widget, a map layer, the
// selected block's outline and, optionally, the shared colour bar. Drag pans,
// the wheel zooms about the point under the cursor, a click reports the world
// point under the cursor; VTK's own keys (wireframe, stereo, quit, ...) are off.
// Below the map: a scale bar and the coordinates of the point under the cursor.
#include <QWidget>

#include <functional>
#include <optional>

#include <vtkNew.h>
#include <vtkSmartPointer.h>

#include "parcelscope/viz/Scenes.h"

class QLabel;
class QVTKOpenGLStereoWidget;
class vtkCamera;
class vtkGenericOpenGLRenderWindow;
class vtkRenderer;

namespace parcelscope::gui {

class MapView : public QWidget {
  Q_OBJECT
public:
  explicit MapView(const QString& title, bool withColourBar, QWidget* parent = nullptr);
  ~MapView() override;

  viz::MapLayer& layer() { return layer_; }
  viz::OutlineLayer& outline() { return outline_; }
  viz::StreetLayer& streets() { return streets_; }
  viz::HandleLayer& handles() { return handles_; }
  /// Asked at each left press with its world point (local metres): true takes
  /// the press as the start of a drag (dragged follows each move, dropped the
  /// release, and the map does not pan). None: every drag pans.
  void setGrab(std::function<bool(double x, double y)> grab) { grab_ = std::move(grab); }
  void setTitle(const QString& title);
  QString title() const;
  /// Shares `camera` with this view (linked views follow each other).
  void useCamera(vtkCamera* camera);
  vtkCamera* camera();
  void fit(const Box& extent);
  /// Renders now.
  void render();
  QVTKOpenGLStereoWidget* vtkWidget() { return widget_; }
  /// Where the world point `p` (local metres) appears in vtkWidget(), in widget coordinates.
  QPoint widgetPoint(const Point& p);
  /// Metres per (logical) pixel of the map at the current zoom; 0 before it has a size.
  double metresPerPixel();
  /// The scale bar: its length in metres, in logical pixels, and its label ("50 m").
  double scaleBarMetres() const { return barMetres_; }
  int scaleBarPixels() const { return barPixels_; }
  QString scaleBarText() const;
  /// The coordinate readout under the map (set by the window from pointerMoved).
  void setReadout(const QString& text);
  QString readout() const;

signals:
  void clicked(double x, double y);       ///< local metres
  void pointerMoved(double x, double y);  ///< local metres of the point under the cursor
  void dragged(double x, double y);       ///< a drag the grab took moved here (local metres)
  void dropped(double x, double y);       ///< and ended here

private:
  /// The world point (local metres) at display point (x, y), if any.
  std::optional<Point> worldAt(int x, int y);
  void scheduleRender();
  /// Chooses the scale bar's length (1, 2 or 5 times a power of ten metres, at most 120 px).
  void updateScaleBar();
  QLabel* title_;
  QWidget* scaleBar_;
  QLabel* readout_;
  double barMetres_ = 0;
  int barPixels_ = 0;
  QVTKOpenGLStereoWidget* widget_;
  vtkNew<vtkGenericOpenGLRenderWindow> window_;
  vtkNew<vtkRenderer> renderer_;
  vtkNew<vtkRenderer> legend_;
  viz::MapLayer layer_;
  viz::OutlineLayer outline_;
  viz::StreetLayer streets_;
  viz::HandleLayer handles_;
  std::function<bool(double, double)> grab_;
  bool renderPending_ = false;
  unsigned long observer_ = 0;
  unsigned long scaleObserver_ = 0;
  vtkSmartPointer<vtkCamera> camera_;
};

}  // namespace parcelscope::gui
