#pragma once
// Interactive VTK scene pieces for the GUI's views, drawn by the same code as
// the exported figures (Figures.h), so a view and its export look alike. Only
// forward declarations of VTK types appear here; the caller owns the renderers.
#include <memory>
#include <string>
#include <vector>

#include "parcelscope/core/Geometry.h"
#include "parcelscope/viz/Figures.h"

class vtkChartXY;
class vtkRenderer;
class vtkScalarBarActor;

namespace parcelscope::viz {

/// Filled shapes coloured by value through a colour scale, with grey outlines.
class MapLayer {
public:
  MapLayer();
  ~MapLayer();
  MapLayer(const MapLayer&) = delete;
  MapLayer& operator=(const MapLayer&) = delete;
  /// Replaces the shapes (local metres; holes left open) and their values.
  /// `groups` (one per shape, or empty) keeps each group's shapes together in
  /// one of the layer's parts: only the parts whose shapes changed are built
  /// again, so give the block of each parcel. Throws Error(Usage) when the
  /// counts differ.
  ///
  /// The layer draws the shapes simplified for the scale it is drawn at
  /// (setMetresPerPixel): vertices within half a pixel of the drawn boundary
  /// are left out, and boundaries that shapes of one group share stay shared
  /// (detail::simplifyShared), so no gap opens between neighbours. It reads
  /// the shapes again when the scale halves or doubles: they must stay alive
  /// until the next setShapes.
  void setShapes(const std::vector<const Polygon*>& shapes, const std::vector<double>& values,
                 const std::vector<int>& groups = {});
  /// Replaces only the values (same shapes as the last setShapes), without
  /// triangulating again.
  void setValues(const std::vector<double>& values);
  void setScale(const ColourScale& scale);
  void addTo(vtkRenderer* renderer);
  /// Shows or hides the grey outlines (on by default).
  void setOutlinesVisible(bool visible);
  /// The scale drawn at (metres per pixel): only shapes at least
  /// kMinOutlinedPixels across get an outline, and the shapes are simplified
  /// for it. 0 (the default): every shape, exact.
  void setMetresPerPixel(double metresPerPixel);
  /// How many shapes have an outline at the current scale.
  std::size_t outlinedShapes() const;
  /// How many points the filled shapes are drawn with (after simplification).
  std::size_t pointsDrawn() const;
  /// How many of the layer's parts the last setShapes built again.
  std::size_t partsRebuilt() const;
  /// The scale's colour bar (horizontal), for the caller to place.
  vtkScalarBarActor* colourBar();

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Thick outlines drawn above a MapLayer (the selected block).
class OutlineLayer {
public:
  OutlineLayer();
  ~OutlineLayer();
  OutlineLayer(const OutlineLayer&) = delete;
  OutlineLayer& operator=(const OutlineLayer&) = delete;
  void setShapes(const std::vector<const Polygon*>& shapes);
  void addTo(vtkRenderer* renderer);

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// A street network drawn over a map: the street surface's kerb lines (thin,
/// grey) and the centre lines (dark grey), above the parcels.
class StreetLayer {
public:
  StreetLayer();
  ~StreetLayer();
  StreetLayer(const StreetLayer&) = delete;
  StreetLayer& operator=(const StreetLayer&) = delete;
  /// `centreLines`: open polylines; `surface`: the street surface's polygons
  /// (their rings are drawn). Empty: nothing is drawn.
  void setStreets(const std::vector<std::vector<Point>>& centreLines, const std::vector<Polygon>& surface);
  void addTo(vtkRenderer* renderer);
  /// Centre lines drawn (for tests).
  std::size_t lines() const;

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The handles of street editing, above everything else on a map: the
/// network's nodes (small dark squares), the selected street (thick, orange),
/// the control points of its curve (orange squares joined to the street's
/// ends) and the selected node (a larger orange square).
class HandleLayer {
public:
  HandleLayer();
  ~HandleLayer();
  HandleLayer(const HandleLayer&) = delete;
  HandleLayer& operator=(const HandleLayer&) = delete;
  void setNodes(const std::vector<Point>& nodes);
  /// `street`: the selected street's polyline (empty: none); `arms`: lines
  /// from a street end to a control point; `points`: selected handles.
  void setSelection(const std::vector<Point>& street, const std::vector<std::vector<Point>>& arms,
                    const std::vector<Point>& points);
  void setVisible(bool visible);
  bool visible() const;
  void addTo(vtkRenderer* renderer);
  /// Nodes and selected handles drawn (for tests).
  std::size_t nodes() const;
  std::size_t selectedPoints() const;

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Points the renderer's (parallel-projection) camera at `extent` with a margin.
void fitCamera(vtkRenderer* renderer, const Box& extent, double viewAspect);

/// Fills `chart` with overlaid histograms as renderHistogram draws them; font
/// sizes follow `height` (pixels).
void fillHistogramChart(vtkChartXY* chart, const std::string& title, const std::string& xTitle,
                        const std::string& yTitle, const std::vector<double>& edges,
                        const std::vector<HistogramSeries>& series, int height);

}  // namespace parcelscope::viz
