#include "MapView.h"

#include <QVTKOpenGLStereoWidget.h>
#include <QHBoxLayout>
#include <QLabel>
#include <QPainter>
#include <QTimer>
#include <QVBoxLayout>

#include <vtkCallbackCommand.h>
#include <vtkCamera.h>
#include <vtkCoordinate.h>
#include <vtkCullerCollection.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkInteractorStyleTrackballCamera.h>
#include <vtkObjectFactory.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>

#include <cmath>
#include <functional>

namespace parcelscope::gui {

namespace {

constexpr double kLegendBand = 0.14;  // of the view's height

// Left drag pans, the wheel (about the point under the cursor) and right drag
// (about the view's centre) zoom, a click without movement picks. VTK's own
// keys ('w' wireframe, 's' surface, '3' stereo, 'r' reset the camera, 'e'/'q'
// quit, ...) are not the window's: keys do nothing here, and the window's
// shortcuts (View > Zoom to extent) reach the window.
// The scale bar under a map: a bar of MapView::scaleBarPixels() with its length in metres.
class ScaleBarWidget : public QWidget {
public:
  ScaleBarWidget(MapView* view, QWidget* parent) : QWidget(parent), view_(view) {
    setMinimumSize(100, fontMetrics().height() + 6);
    setObjectName("scaleBar");
  }

  QSize sizeHint() const override { return {200, minimumHeight()}; }

protected:
  void paintEvent(QPaintEvent*) override {
    if (view_->scaleBarPixels() <= 0) return;
    QPainter p(this);
    p.setRenderHint(QPainter::Antialiasing, false);
    const int h = height(), x0 = 4, x1 = x0 + view_->scaleBarPixels(), y = h - 4;
    p.setPen(QPen(Qt::black, 2));
    p.drawLine(x0, y, x1, y);
    p.drawLine(x0, y, x0, y - 5);
    p.drawLine(x1, y, x1, y - 5);
    p.drawText(QRect(x1 + 6, 0, width() - x1 - 6, h), Qt::AlignLeft | Qt::AlignVCenter, view_->scaleBarText());
  }

private:
  MapView* view_;
};

class PanZoomStyle : public vtkInteractorStyleTrackballCamera {
public:
  static PanZoomStyle* New();
  vtkTypeMacro(PanZoomStyle, vtkInteractorStyleTrackballCamera) std::function<void(int, int)> onClick;
  std::function<void(int, int)> onMove;
  /// A left press at a display point: true when the owner takes it as the
  /// start of a drag of its own (then onDrag follows each move and onDrop the
  /// release, and the map does not pan).
  std::function<bool(int, int)> onPress;
  std::function<void(int, int)> onDrag, onDrop;

  void OnMouseMove() override {
    const int* p = GetInteractor()->GetEventPosition();
    if (grabbing_) {
      if (onDrag) onDrag(p[0], p[1]);
      if (onMove) onMove(p[0], p[1]);
      return;
    }
    vtkInteractorStyleTrackballCamera::OnMouseMove();
    if (onMove) onMove(p[0], p[1]);
  }

  void OnChar() override {}
  void OnKeyPress() override {}
  void OnKeyRelease() override {}
  void OnKeyDown() override {}
  void OnKeyUp() override {}

  // One notch zooms by VTK's step (1.1 ^ (MotionFactor / 5)), as before.
  void OnMouseWheelForward() override { zoomAtCursor(std::pow(1.1, MotionFactor * 0.2 * MouseWheelMotionFactor)); }
  void OnMouseWheelBackward() override { zoomAtCursor(std::pow(1.1, -MotionFactor * 0.2 * MouseWheelMotionFactor)); }

  void OnLeftButtonDown() override {
    int* p = GetInteractor()->GetEventPosition();
    pressX_ = p[0];
    pressY_ = p[1];
    FindPokedRenderer(p[0], p[1]);
    if (!CurrentRenderer) return;
    GrabFocus(EventCallbackCommand);
    if (onPress && onPress(p[0], p[1])) {
      grabbing_ = true;
      return;
    }
    StartPan();
  }
  void OnLeftButtonUp() override {
    int* p = GetInteractor()->GetEventPosition();
    if (grabbing_) {
      grabbing_ = false;
      if (Interactor) ReleaseFocus();
      if (onDrop) onDrop(p[0], p[1]);
      return;
    }
    if (State == VTKIS_PAN) {
      EndPan();
      if (Interactor) ReleaseFocus();
    }
    if (std::abs(p[0] - pressX_) + std::abs(p[1] - pressY_) <= 3 && onClick) onClick(p[0], p[1]);
  }

private:
  // The world point at display position (x, y) of the current renderer.
  bool worldAt(int x, int y, double out[2]) {
    CurrentRenderer->SetDisplayPoint(x, y, 0);
    CurrentRenderer->DisplayToWorld();
    double w[4];
    CurrentRenderer->GetWorldPoint(w);
    if (w[3] == 0) return false;
    out[0] = w[0] / w[3];
    out[1] = w[1] / w[3];
    return true;
  }

  // Zooms by `factor` (> 1: in) keeping the world point under the cursor under it.
  void zoomAtCursor(double factor) {
    const int* p = GetInteractor()->GetEventPosition();
    FindPokedRenderer(p[0], p[1]);
    if (!CurrentRenderer) return;
    GrabFocus(EventCallbackCommand);
    StartDolly();
    vtkCamera* camera = CurrentRenderer->GetActiveCamera();
    double before[2], after[2];
    const bool anchored = worldAt(p[0], p[1], before);
    if (camera->GetParallelProjection()) {
      camera->SetParallelScale(camera->GetParallelScale() / factor);
    } else {
      camera->Dolly(factor);
    }
    if (anchored && worldAt(p[0], p[1], after)) {
      double focal[3], position[3];
      camera->GetFocalPoint(focal);
      camera->GetPosition(position);
      const double dx = before[0] - after[0], dy = before[1] - after[1];
      camera->SetFocalPoint(focal[0] + dx, focal[1] + dy, focal[2]);
      camera->SetPosition(position[0] + dx, position[1] + dy, position[2]);
    }
    if (AutoAdjustCameraClippingRange) CurrentRenderer->ResetCameraClippingRange();
    EndDolly();
    ReleaseFocus();
    GetInteractor()->Render();
  }

  int pressX_ = 0, pressY_ = 0;
  bool grabbing_ = false;
};
vtkStandardNewMacro(PanZoomStyle);

}  // namespace

MapView::MapView(const QString& title, bool withColourBar, QWidget* parent) : QWidget(parent) {
  auto* layout = new QVBoxLayout(this);
  layout->setContentsMargins(0, 0, 0, 0);
  layout->setSpacing(2);
  title_ = new QLabel(title, this);
  title_->setAlignment(Qt::AlignCenter);
  title_->setWordWrap(true);  // a long title takes two lines rather than widening the window
  QFont f = title_->font();
  f.setBold(true);
  title_->setFont(f);
  layout->addWidget(title_);
  // A native OpenGL window in a container: its frames go to the screen as
  // they are. In a QOpenGLWidget (QVTKOpenGLNativeWidget) Qt composes the
  // whole window through OpenGL after every frame instead, which with a
  // software OpenGL costs about 30 ms per change.
  widget_ = new QVTKOpenGLStereoWidget(this);
  widget_->setMinimumSize(160, 120);
  // No multisampling: with a software OpenGL (Xvfb, remote desktops) it makes
  // every frame several times slower; the maps are flat fills and thin lines.
  window_->SetMultiSamples(0);
  widget_->setRenderWindow(window_);
  layout->addWidget(widget_, 1);
  auto* below = new QHBoxLayout;
  below->setContentsMargins(2, 0, 2, 0);
  scaleBar_ = new ScaleBarWidget(this, this);
  readout_ = new QLabel(this);
  readout_->setObjectName("readout");
  readout_->setAlignment(Qt::AlignRight | Qt::AlignVCenter);
  readout_->setTextInteractionFlags(Qt::TextSelectableByMouse);
  readout_->setMinimumWidth(60);
  readout_->setSizePolicy(QSizePolicy::Ignored, QSizePolicy::Preferred);
  below->addWidget(scaleBar_, 0);
  below->addWidget(readout_, 1);
  layout->addLayout(below);

  // The map above, a legend band below (the same in both views, so that
  // linked views show the same extent).
  renderer_->SetBackground(1, 1, 1);
  // No frustum culling: the layer is a few dozen actors, nearly always all
  // in view, and culling computes every changed part's bounds cell by cell
  // before each frame.
  renderer_->GetCullers()->RemoveAllItems();
  renderer_->SetViewport(0, kLegendBand, 1, 1);
  legend_->SetBackground(1, 1, 1);
  legend_->SetViewport(0, 0, 1, kLegendBand);
  legend_->InteractiveOff();
  window_->AddRenderer(renderer_);
  window_->AddRenderer(legend_);
  layer_.addTo(renderer_);
  streets_.addTo(renderer_);
  outline_.addTo(renderer_);
  handles_.addTo(renderer_);
  // Before every frame, whoever asks for it (a change, a pan or zoom of the
  // shared camera): outlines for the shapes large enough at this zoom.
  vtkNew<vtkCallbackCommand> scale;
  scale->SetClientData(this);
  scale->SetCallback([](vtkObject*, unsigned long, void* self, void*) {
    auto* view = static_cast<MapView*>(self);
    const int* size = view->renderer_->GetSize();
    if (size[1] > 0)
      view->layer_.setMetresPerPixel(2 * view->renderer_->GetActiveCamera()->GetParallelScale() / size[1]);
  });
  scaleObserver_ = renderer_->AddObserver(vtkCommand::StartEvent, scale);
  if (withColourBar) {
    vtkScalarBarActor* bar = layer_.colourBar();
    bar->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
    bar->GetPositionCoordinate()->SetValue(0.08, 0.05);
    bar->SetWidth(0.84);
    bar->SetHeight(0.9);
    legend_->AddActor2D(bar);
  } else {
    vtkNew<vtkTextActor> hint;
    hint->SetInput("drag: pan   wheel or right drag: zoom   click: select a block");
    hint->GetTextProperty()->SetColor(0.35, 0.35, 0.35);
    hint->GetTextProperty()->SetFontSize(12);
    hint->GetTextProperty()->SetJustificationToCentered();
    hint->GetTextProperty()->SetVerticalJustificationToCentered();
    hint->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
    hint->GetPositionCoordinate()->SetValue(0.5, 0.5);
    legend_->AddActor2D(hint);
  }
  vtkNew<PanZoomStyle> style;
  style->onMove = [this](int x, int y) {
    if (const auto w = worldAt(x, y)) emit pointerMoved(w->x, w->y);
  };
  style->onClick = [this](int x, int y) {
    if (const auto w = worldAt(x, y)) emit clicked(w->x, w->y);
  };
  style->onPress = [this](int x, int y) {
    const auto w = worldAt(x, y);
    return w && grab_ && grab_(w->x, w->y);
  };
  style->onDrag = [this](int x, int y) {
    if (const auto w = worldAt(x, y)) emit dragged(w->x, w->y);
  };
  style->onDrop = [this](int x, int y) {
    if (const auto w = worldAt(x, y)) emit dropped(w->x, w->y);
  };
  window_->GetInteractor()->SetInteractorStyle(style);
  useCamera(renderer_->GetActiveCamera());
}

MapView::~MapView() {
  if (camera_ && observer_) camera_->RemoveObserver(observer_);
  renderer_->RemoveObserver(scaleObserver_);
}

std::optional<Point> MapView::worldAt(int x, int y) {
  renderer_->SetDisplayPoint(x, y, 0);
  renderer_->DisplayToWorld();
  double w[4];
  renderer_->GetWorldPoint(w);
  if (w[3] == 0) return std::nullopt;
  return Point{w[0] / w[3], w[1] / w[3]};
}

void MapView::setTitle(const QString& title) { title_->setText(title); }
QString MapView::title() const { return title_->text(); }

void MapView::useCamera(vtkCamera* camera) {
  if (camera_ && observer_) camera_->RemoveObserver(observer_);
  camera_ = camera;
  renderer_->SetActiveCamera(camera);
  vtkNew<vtkCallbackCommand> command;
  command->SetClientData(this);
  command->SetCallback(
      [](vtkObject*, unsigned long, void* self, void*) { static_cast<MapView*>(self)->scheduleRender(); });
  observer_ = camera->AddObserver(vtkCommand::ModifiedEvent, command);
}

vtkCamera* MapView::camera() { return camera_; }

void MapView::fit(const Box& extent) {
  const double mapHeight = widget_->height() * (1 - kLegendBand);
  const double aspect = mapHeight > 0 ? widget_->width() / mapHeight : 1.0;
  viz::fitCamera(renderer_, extent, aspect);
  renderer_->ResetCameraClippingRange();
  camera_->SetClippingRange(1, 1000);
}

QPoint MapView::widgetPoint(const Point& p) {
  renderer_->SetWorldPoint(p.x, p.y, 0, 1);
  renderer_->WorldToDisplay();
  double d[3];
  renderer_->GetDisplayPoint(d);
  const double ratio = widget_->devicePixelRatioF();
  return QPoint(static_cast<int>(std::lround(d[0] / ratio)),
                static_cast<int>(std::lround(widget_->height() - d[1] / ratio)));
}

void MapView::render() {
  renderPending_ = false;
  window_->Render();
  updateScaleBar();
}

double MapView::metresPerPixel() {
  const double mapHeight = widget_->height() * (1 - kLegendBand);
  if (mapHeight <= 0 || !camera_) return 0;
  return 2 * camera_->GetParallelScale() / mapHeight;
}

void MapView::updateScaleBar() {
  const double perPixel = metresPerPixel();
  double metres = 0;
  int pixels = 0;
  if (perPixel > 0 && std::isfinite(perPixel)) {
    // The longest bar, in metres: 120 px, or less in a narrow view.
    const double most = std::min(120, std::max(20, scaleBar_->width() - 70)) * perPixel;
    const double decade = std::pow(10.0, std::floor(std::log10(most)));
    for (double step : {5.0, 2.0, 1.0}) {
      if (step * decade <= most) {
        metres = step * decade;
        break;
      }
    }
    pixels = static_cast<int>(std::lround(metres / perPixel));
  }
  if (metres == barMetres_ && pixels == barPixels_) return;
  barMetres_ = metres;
  barPixels_ = pixels;
  scaleBar_->update();
}

QString MapView::scaleBarText() const {
  if (barMetres_ <= 0) return {};
  if (barMetres_ >= 1000) return QString::number(barMetres_ / 1000, 'g', 6) + " km";
  return QString::number(barMetres_, 'g', 6) + " m";
}

void MapView::setReadout(const QString& text) {
  if (readout_->text() != text) readout_->setText(text);
}
QString MapView::readout() const { return readout_->text(); }

void MapView::scheduleRender() {
  if (renderPending_) return;
  renderPending_ = true;
  QTimer::singleShot(0, this, [this] {
    if (renderPending_) render();
  });
}

}  // namespace parcelscope::gui
