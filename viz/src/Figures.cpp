#include "parcelscope/viz/Figures.h"

#include "parcelscope/viz/Scenes.h"

#include "Pdf.h"

#include <vtkActor.h>
#include <vtkAxis.h>
#include <vtkBrush.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkChartLegend.h>
#include <vtkChartXY.h>
#include <vtkContextScene.h>
#include <vtkContextView.h>
#include <vtkContourTriangulator.h>
#include <vtkDoubleArray.h>
#include <vtkGL2PSExporter.h>
#include <vtkIdList.h>
#include <vtkIdTypeArray.h>
#include <vtkLookupTable.h>
#include <vtkNew.h>
#include <vtkOpenGLPolyDataMapper.h>
#include <vtkOpenGLVertexBufferObject.h>
#include <vtkPNGWriter.h>
#include <vtkPen.h>
#include <vtkPlotArea.h>
#include <vtkPlotLine.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkPolygon.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkRendererCollection.h>
#include <vtkScalarBarActor.h>
#include <vtkTable.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkTextRenderer.h>
#include <vtkVersion.h>
#include <vtkWindowToImageFilter.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <functional>
#include <limits>
#include <unordered_map>

#include "EarClip.h"
#include "Simplify.h"
#include "TextCache.h"
#include "parcelscope/core/Error.h"
#include "parcelscope/core/Parallel.h"

namespace parcelscope::viz {

namespace {

constexpr double kNoValueGrey = 0.82;

void checkOutput(const FigureOutput& out) {
  if (out.width < 200 || out.height < 150 || out.width > 10000 || out.height > 10000) {
    throw usageError(out.png + ": figure size " + std::to_string(out.width) + " x " + std::to_string(out.height) +
                     " px is outside 200 x 150 .. 10000 x 10000");
  }
}

// Font sizes follow the figure height, so a figure stays legible at any size.
int fontSize(const FigureOutput& out, double fraction) {
  return std::max(8, static_cast<int>(std::lround(out.height * fraction)));
}

void styleText(vtkTextProperty* p, int size, bool bold = false) {
  p->SetFontFamilyToArial();
  p->SetFontSize(size);
  p->SetBold(bold);
  p->SetItalic(false);
  p->SetShadow(false);
  p->SetColor(0.1, 0.1, 0.1);
}

// The smallest font a fitted text shrinks to before it wraps, and the smallest
// at all (a single word wider than the figure at that size is cut off).
constexpr int kMinFontSize = 8;
constexpr int kLastResortFontSize = 6;

// Width in pixels of `text` (lines separated by '\n') drawn with `style` at
// `size`, at the window's `dpi`.
int textWidth(vtkTextProperty* style, const std::string& text, int size, int dpi) {
  vtkNew<vtkTextProperty> p;
  p->ShallowCopy(style);
  p->SetFontSize(size);
  p->SetOrientation(0);
  int box[4] = {0, 0, 0, 0};
  if (!vtkTextRenderer::GetInstance()->GetBoundingBox(p, text, box, dpi)) return 0;
  return box[1] - box[0] + 1;
}

// `text` as two lines, broken at the space that leaves the longer line
// shortest; a break after punctuation (", ", ": ", "; ") is taken if its
// longer line is at most a fifth longer than that. Empty when there is no space.
std::string splitInTwo(vtkTextProperty* style, const std::string& text, int size, int dpi) {
  std::string best, bestAfterPunctuation;
  int bestWidth = std::numeric_limits<int>::max(), bestPunctuationWidth = bestWidth;
  for (std::size_t i = text.find(' '); i != std::string::npos; i = text.find(' ', i + 1)) {
    const std::size_t end = text.find_last_not_of(' ', i);
    const std::size_t start = text.find_first_not_of(' ', i);
    if (end == std::string::npos || start == std::string::npos) continue;
    const std::string first = text.substr(0, end + 1), second = text.substr(start);
    const int width = std::max(textWidth(style, first, size, dpi), textWidth(style, second, size, dpi));
    if (width < bestWidth) {
      bestWidth = width;
      best = first + "\n" + second;
    }
    const char last = text[end];
    if ((last == ',' || last == ':' || last == ';') && width < bestPunctuationWidth) {
      bestPunctuationWidth = width;
      bestAfterPunctuation = first + "\n" + second;
    }
  }
  if (!bestAfterPunctuation.empty() && bestPunctuationWidth <= 1.2 * bestWidth) return bestAfterPunctuation;
  return best;
}

// The largest font size from `size` down to `floor` at which `text` is at
// most `maxWidth` pixels wide; 0 when none is.
int largestFitting(vtkTextProperty* style, const std::string& text, int size, int floor, double maxWidth, int dpi) {
  const int full = textWidth(style, text, size, dpi);
  if (full <= maxWidth) return size;
  // Widths grow about in proportion to the size: start there, and step down.
  int s = std::min(size - 1, static_cast<int>(std::floor(size * maxWidth / std::max(1, full))));
  while (s >= floor && textWidth(style, text, s, dpi) > maxWidth) --s;
  return s >= floor ? s : 0;
}

// A text laid out to fit a width: its lines (joined by '\n') and font size.
struct FittedText {
  std::string text;
  int size = 0;
};

// Lays `text` out within `maxWidth` pixels, drawn with `style` at up to
// `size`: on one line, shrunk to no less than 4/5 of `size`; otherwise on two
// lines (splitInTwo) at the largest size that fits, down to kMinFontSize;
// otherwise (a long word on a narrow figure) at the size that fits, down to
// kLastResortFontSize. With `oneLine`, it only shrinks (down to
// kLastResortFontSize): vector copies (GL2PS) draw a text as one line whatever
// it holds, and their text stays sharp when enlarged.
FittedText fitText(vtkTextProperty* style, const std::string& text, int size, double maxWidth, int dpi,
                   bool oneLine = false) {
  detail::prepareTextRendering();
  if (text.empty()) return {text, size};
  if (oneLine) {
    const int s = largestFitting(style, text, size, std::min(size, kLastResortFontSize), maxWidth, dpi);
    return {text, s > 0 ? s : std::min(size, kLastResortFontSize)};
  }
  if (size <= kMinFontSize) return {text, size};
  const int shrunk = std::max(kMinFontSize, static_cast<int>(std::ceil(0.8 * size)));
  if (const int s = largestFitting(style, text, size, shrunk, maxWidth, dpi)) return {text, s};
  const std::string twoLines = splitInTwo(style, text, size, dpi);
  const std::string& laidOut = twoLines.empty() ? text : twoLines;
  if (const int s = largestFitting(style, laidOut, size, kMinFontSize, maxWidth, dpi)) return {laidOut, s};
  const int s = largestFitting(style, laidOut, kMinFontSize, kLastResortFontSize, maxWidth, dpi);
  return {laidOut, s > 0 ? s : kLastResortFontSize};
}

// One hidden window serves every figure of the process: a new window means a
// new OpenGL context, whose shaders a software renderer (llvmpipe under Xvfb)
// compiles again, about half a second each time. Each figure starts by
// removing the renderers of the previous one. Rendering is not thread-safe:
// figures are drawn one at a time.
vtkSmartPointer<vtkRenderWindow> offscreenWindow(const FigureOutput& out) {
  requireDisplay();
  detail::prepareTextRendering();
  static vtkSmartPointer<vtkRenderWindow> window;
  if (!window) {
    window = vtkSmartPointer<vtkRenderWindow>::New();
    window->SetOffScreenRendering(1);
    window->SetMultiSamples(8);  // smooth edges and text
  }
  while (window->GetRenderers()->GetNumberOfItems() > 0) {
    window->RemoveRenderer(window->GetRenderers()->GetFirstRenderer());
  }
  window->SetSize(out.width, out.height);
  return window;
}

// Writes the PNG (and the vector copy) of what `window` shows. `adjust` runs
// after the scene was drawn (and laid out) once, and returns whether it changed
// it, which is then drawn again; `beforeVector` may change the scene between
// the PNG and the vector copy.
void writeFigure(vtkRenderWindow* window, const FigureOutput& out, const std::string& title,
                 const std::function<bool()>& adjust = {}, const std::function<void()>& beforeVector = {}) {
  window->Render();
  if (adjust && adjust()) window->Render();
  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(window);
  grab->SetInputBufferTypeToRGB();
  grab->ReadFrontBufferOff();
  grab->Update();
  int dims[3];
  grab->GetOutput()->GetDimensions(dims);
  if (dims[0] != out.width || dims[1] != out.height) {
    throw ioError(out.png + ": rendered " + std::to_string(dims[0]) + " x " + std::to_string(dims[1]) +
                  " px instead of " + std::to_string(out.width) + " x " + std::to_string(out.height));
  }
  vtkNew<vtkPNGWriter> png;
  png->SetFileName(out.png.c_str());
  png->SetInputConnection(grab->GetOutputPort());
  png->Write();
  if (png->GetErrorCode() != 0 || !std::filesystem::exists(out.png)) throw ioError(out.png + ": cannot write PNG");
  if (out.vector.empty()) return;
  if (beforeVector) beforeVector();

  const std::filesystem::path path(out.vector);
  vtkNew<vtkGL2PSExporter> exporter;
  exporter->SetRenderWindow(window);
  if (path.extension() == ".svg") {
    exporter->SetFileFormatToSVG();
  } else if (path.extension() == ".pdf") {
    exporter->SetFileFormatToPDF();
  } else {
    throw usageError(out.vector + ": vector figures are .svg or .pdf");
  }
  exporter->SetFilePrefix((path.parent_path() / path.stem()).string().c_str());
  exporter->CompressOff();   // compression would rename the file (.svgz)
  exporter->SetSortToOff();  // flat figures: drawing order is the stacking order
  exporter->SetTitle(title.c_str());
  exporter->SilentOn();
  exporter->Write();
  if (!std::filesystem::exists(path)) throw ioError(out.vector + ": cannot write vector figure");
  if (path.extension() == ".pdf") detail::compressPdfStreams(out.vector);
  if (path.extension() == ".svg") detail::escapeSvgTexts(out.vector);
}

vtkSmartPointer<vtkLookupTable> lookupTable(const ColourScale& scale) {
  auto lut = vtkSmartPointer<vtkLookupTable>::New();
  const int n = 256;
  lut->SetNumberOfTableValues(n);
  lut->SetTableRange(scale.minimum, scale.maximum);
  if (scale.kind == ColourScale::Kind::RedToGreen) {
    // Hue from red (0) through orange and yellow to green (1/3).
    lut->SetHueRange(0.0, 1.0 / 3.0);
    lut->SetSaturationRange(0.85, 0.85);
    lut->SetValueRange(0.92, 0.72);
    lut->Build();
  } else {
    // Pale yellow to dark purple, perceptually ordered (after ColorBrewer YlOrRd/RdPu).
    const double stops[][3] = {
        {1.0, 0.97, 0.74}, {0.99, 0.73, 0.36}, {0.94, 0.40, 0.22}, {0.74, 0.10, 0.28}, {0.35, 0.0, 0.38}};
    const int segments = 4;
    for (int i = 0; i < n; ++i) {
      const double t = static_cast<double>(i) / (n - 1) * segments;
      const int s = std::min(segments - 1, static_cast<int>(t));
      const double f = t - s;
      lut->SetTableValue(i, stops[s][0] + f * (stops[s + 1][0] - stops[s][0]),
                         stops[s][1] + f * (stops[s + 1][1] - stops[s][1]),
                         stops[s][2] + f * (stops[s + 1][2] - stops[s][2]), 1.0);
    }
  }
  lut->SetNanColor(kNoValueGrey, kNoValueGrey, kNoValueGrey, 1.0);
  return lut;
}

struct PanelGeometry {
  vtkNew<vtkPolyData> fill;
  vtkNew<vtkPolyData> rings;
};

// Every turn of the ring goes the same way; turns below about 0.01 degrees
// (collinear vertices and rounding noise) are ignored, which a fan draws
// without visible error.
bool isConvex(const Ring& ring) {
  const std::size_t n = ring.size();
  if (n < 3) return false;
  int sign = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Point& a = ring[i];
    const Point& b = ring[(i + 1) % n];
    const Point& c = ring[(i + 2) % n];
    const double ux = b.x - a.x, uy = b.y - a.y, vx = c.x - b.x, vy = c.y - b.y;
    const double cross = ux * vy - uy * vx;
    const double tolerance = 2e-4 * std::sqrt((ux * ux + uy * uy) * (vx * vx + vy * vy));
    const int s = cross > tolerance ? 1 : cross < -tolerance ? -1 : 0;
    if (s == 0) continue;
    if (sign == 0) sign = s;
    if (s != sign) return false;
  }
  return sign != 0;
}

// Triangles of a shape as cells (count, point ids...) with ids relative to the
// shape's first point, by a hash of the shape's coordinates: a map redrawn with
// mostly the same shapes triangulates only the new ones (those VTK
// triangulates; fans and ear clipping cost less than the lookup).
using TriangleCache = std::unordered_map<std::uint64_t, std::vector<vtkIdType>>;

std::uint64_t shapeHash(const Polygon& shape) {
  std::uint64_t h = 0xcbf29ce484222325ull;
  auto mix = [&](std::uint64_t v) { h ^= v + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2); };
  auto ring = [&](const Ring& r) {
    mix(r.size());
    for (const Point& p : r) {
      std::uint64_t x, y;
      std::memcpy(&x, &p.x, sizeof x);
      std::memcpy(&y, &p.y, sizeof y);
      mix(x);
      mix(y);
    }
  };
  ring(shape.outer);
  for (const Ring& hole : shape.holes) ring(hole);
  return h;
}

// Triangle cells of one shape whose rings were appended from point 0 (outer
// ring, then holes), ids relative to that point: VTK's ear cut for a ring
// too large for earClip or refused by it, VTK's contour triangulator for a
// shape with holes.
std::vector<vtkIdType> triangulate(const Polygon& shape, vtkPolygon* earCut, vtkIdList* earIds) {
  std::vector<vtkIdType> cells;
  const auto n = static_cast<vtkIdType>(shape.outer.size());
  if (shape.holes.empty()) {
    earCut->GetPoints()->SetNumberOfPoints(n);
    earCut->GetPointIds()->SetNumberOfIds(n);
    for (vtkIdType i = 0; i < n; ++i) {
      earCut->GetPoints()->SetPoint(i, shape.outer[i].x, shape.outer[i].y, 0.0);
      earCut->GetPointIds()->SetId(i, i);
    }
    earIds->Reset();
    if (earCut->Triangulate(earIds) && earIds->GetNumberOfIds() == 3 * (n - 2)) {
      for (vtkIdType t = 0; t < earIds->GetNumberOfIds(); t += 3) {
        cells.insert(cells.end(), {3, earIds->GetId(t), earIds->GetId(t + 1), earIds->GetId(t + 2)});
      }
      return cells;
    }
  }
  // Holes, or a ring ear cutting refuses: the contour triangulator on this
  // shape's own small contour set (its cost grows with the whole input).
  const double up[3] = {0, 0, 1};
  vtkNew<vtkPolyData> contours;
  vtkNew<vtkPoints> shapePoints;
  vtkNew<vtkCellArray> shapeLines, shapeTriangles;
  vtkIdType start = 0;
  auto addShapeRing = [&](const Ring& ring) {
    for (const Point& p : ring) shapePoints->InsertNextPoint(p.x, p.y, 0.0);
    shapeLines->InsertNextCell(static_cast<int>(ring.size() + 1));
    for (std::size_t v = 0; v < ring.size(); ++v) shapeLines->InsertCellPoint(start + static_cast<vtkIdType>(v));
    shapeLines->InsertCellPoint(start);
    start += static_cast<vtkIdType>(ring.size());
  };
  addShapeRing(shape.outer);
  for (const Ring& hole : shape.holes) addShapeRing(hole);
  contours->SetPoints(shapePoints);
  contours->SetLines(shapeLines);
  vtkContourTriangulator::TriangulateContours(contours, 0, shapeLines->GetNumberOfCells(), shapeTriangles, up);
  vtkIdType size = 0;
  const vtkIdType* ids = nullptr;
  for (shapeTriangles->InitTraversal(); shapeTriangles->GetNextCell(size, ids);) {
    cells.push_back(size);
    cells.insert(cells.end(), ids, ids + size);
  }
  return cells;
}

// Room for the points of the shapes drawn (outer ring of 3 vertices or more):
// x, y and 0 for each vertex of their rings.
vtkSmartPointer<vtkDoubleArray> pointRoom(const std::vector<const Polygon*>& shapes) {
  vtkIdType count = 0;
  for (const Polygon* shape : shapes) {
    if (shape->outer.size() < 3) continue;
    count += static_cast<vtkIdType>(shape->outer.size());
    for (const Ring& hole : shape->holes) count += static_cast<vtkIdType>(hole.size());
  }
  auto coordinates = vtkSmartPointer<vtkDoubleArray>::New();
  coordinates->SetNumberOfComponents(3);
  coordinates->SetNumberOfTuples(count);
  return coordinates;
}

// Triangles filling every shape (holes left open), each shape's points
// carrying its value (a point value, not a cell value per triangle: a cell
// value costs VTK a colour texture rebuilt and read per pixel), and the rings
// of shapes at least `minOutlined` across (outlineSize) as closed polylines.
// A convex shape without holes is a fan, another ring of up to
// kEarClipMaxVertices is clipped into ears; with `cache`, the other shapes
// (large or with holes) found in it are not triangulated again, and it is
// left holding this panel's such shapes. The arrays are filled directly,
// sized in advance: a view redrawn after every slider move builds them for
// every procedural parcel. `pointsPerShape` receives each shape's count of
// points.
void buildPanel(const MapPanel& panel, PanelGeometry& g, std::vector<vtkIdType>* pointsPerShape = nullptr,
                TriangleCache* cache = nullptr, double minOutlined = 0) {
  const vtkSmartPointer<vtkDoubleArray> coordinates = pointRoom(panel.shapes);
  const vtkIdType pointCount = coordinates->GetNumberOfTuples();
  double* xyz = coordinates->GetPointer(0);
  std::vector<vtkIdType> lineOffsets{0}, lineIds, triangleIds;
  std::vector<double> values;
  triangleIds.reserve(3 * static_cast<std::size_t>(pointCount));
  values.reserve(static_cast<std::size_t>(pointCount));
  vtkNew<vtkPolygon> earCut;
  vtkNew<vtkIdList> earIds;
  std::vector<int> ears;
  TriangleCache next;
  vtkIdType offset = 0;
  for (std::size_t k = 0; k < panel.shapes.size(); ++k) {
    const Polygon& shape = *panel.shapes[k];
    if (shape.outer.size() < 3) {  // nothing to draw (a shape simplified away)
      if (pointsPerShape) pointsPerShape->push_back(0);
      continue;
    }
    const bool outlined = minOutlined <= 0 || outlineSize(shape) >= minOutlined;
    vtkIdType first = offset;
    auto addRing = [&](const Ring& ring) {
      for (const Point& p : ring) {
        *xyz++ = p.x;
        *xyz++ = p.y;
        *xyz++ = 0.0;
      }
      const auto size = static_cast<vtkIdType>(ring.size());
      if (outlined) {
        for (vtkIdType v = 0; v < size; ++v) lineIds.push_back(first + v);
        lineIds.push_back(first);
        lineOffsets.push_back(static_cast<vtkIdType>(lineIds.size()));
      }
      first += size;
    };
    addRing(shape.outer);
    for (const Ring& hole : shape.holes) addRing(hole);
    ears.clear();
    if (shape.holes.empty() && isConvex(shape.outer)) {
      // Most parcels: a triangle fan.
      for (vtkIdType i = 1; i + 1 < static_cast<vtkIdType>(shape.outer.size()); ++i) {
        triangleIds.insert(triangleIds.end(), {offset, offset + i, offset + i + 1});
      }
    } else if (shape.holes.empty() && detail::earClip(shape.outer, ears)) {
      for (int v : ears) triangleIds.push_back(offset + v);
    } else {
      std::vector<vtkIdType> fresh;
      const std::vector<vtkIdType>* cells = nullptr;
      std::uint64_t hash = 0;
      if (cache) {
        hash = shapeHash(shape);
        if (const auto it = cache->find(hash); it != cache->end()) cells = &it->second;
      }
      if (!cells) {
        fresh = triangulate(shape, earCut, earIds);
        cells = &fresh;
      }
      // Cells are (size, ids...); both triangulations give triangles, the only
      // cells the three-id layout below can hold.
      for (std::size_t c = 0; c < cells->size(); c += static_cast<std::size_t>((*cells)[c]) + 1) {
        if ((*cells)[c] != 3) continue;
        for (std::size_t i = 1; i <= 3; ++i) triangleIds.push_back(offset + (*cells)[c + i]);
      }
      if (cache) next.emplace(hash, *cells);
    }
    values.insert(values.end(), static_cast<std::size_t>(first - offset), panel.values[k]);
    if (pointsPerShape) pointsPerShape->push_back(first - offset);
    offset = first;
  }
  if (cache) *cache = std::move(next);
  const auto idArray = [](const std::vector<vtkIdType>& ids) {
    vtkNew<vtkIdTypeArray> a;
    a->SetNumberOfValues(static_cast<vtkIdType>(ids.size()));
    if (!ids.empty()) std::memcpy(a->GetPointer(0), ids.data(), ids.size() * sizeof(vtkIdType));
    return vtkSmartPointer<vtkIdTypeArray>(a.GetPointer());
  };
  std::vector<vtkIdType> triangleOffsets(triangleIds.size() / 3 + 1);
  for (std::size_t t = 0; t < triangleOffsets.size(); ++t) triangleOffsets[t] = static_cast<vtkIdType>(3 * t);
  vtkNew<vtkCellArray> lines, triangles;
  lines->SetData(idArray(lineOffsets), idArray(lineIds));
  triangles->SetData(idArray(triangleOffsets), idArray(triangleIds));
  vtkNew<vtkPoints> points;
  points->SetData(coordinates);
  vtkNew<vtkDoubleArray> pointValues;
  pointValues->SetName("value");
  pointValues->SetNumberOfValues(static_cast<vtkIdType>(values.size()));
  if (!values.empty()) std::memcpy(pointValues->GetPointer(0), values.data(), values.size() * sizeof(double));
  g.rings->SetPoints(points);
  g.rings->SetLines(lines);
  g.fill->SetPoints(points);
  g.fill->SetPolys(triangles);
  g.fill->GetPointData()->SetScalars(pointValues);
}

// The rings of `shapes` as closed lines (buildPanel's rings, without its
// triangulated fill): outlines only, such as kerbs or a selection.
void buildRings(const std::vector<const Polygon*>& shapes, vtkPolyData* out) {
  const vtkSmartPointer<vtkDoubleArray> coordinates = pointRoom(shapes);
  const vtkIdType pointCount = coordinates->GetNumberOfTuples();
  double* xyz = coordinates->GetPointer(0);
  vtkNew<vtkIdTypeArray> offsets, ids;
  std::vector<vtkIdType> lineOffsets{0}, lineIds;
  lineIds.reserve(static_cast<std::size_t>(pointCount) + shapes.size());
  vtkIdType first = 0;
  auto addRing = [&](const Ring& ring) {
    for (const Point& p : ring) {
      *xyz++ = p.x;
      *xyz++ = p.y;
      *xyz++ = 0.0;
    }
    const auto size = static_cast<vtkIdType>(ring.size());
    for (vtkIdType v = 0; v < size; ++v) lineIds.push_back(first + v);
    lineIds.push_back(first);
    lineOffsets.push_back(static_cast<vtkIdType>(lineIds.size()));
    first += size;
  };
  for (const Polygon* shape : shapes) {
    if (shape->outer.size() < 3) continue;  // as buildPanel: nothing to draw
    addRing(shape->outer);
    for (const Ring& hole : shape->holes) addRing(hole);
  }
  offsets->SetNumberOfValues(static_cast<vtkIdType>(lineOffsets.size()));
  std::memcpy(offsets->GetPointer(0), lineOffsets.data(), lineOffsets.size() * sizeof(vtkIdType));
  ids->SetNumberOfValues(static_cast<vtkIdType>(lineIds.size()));
  if (!lineIds.empty()) std::memcpy(ids->GetPointer(0), lineIds.data(), lineIds.size() * sizeof(vtkIdType));
  vtkNew<vtkCellArray> lines;
  lines->SetData(offsets, ids);
  vtkNew<vtkPoints> points;
  points->SetData(coordinates);
  vtkNew<vtkPolyData> rings;
  rings->SetPoints(points);
  rings->SetLines(lines);
  out->ShallowCopy(rings);
}

// A round length (1, 2 or 5 times a power of ten) of at most `limit` metres.
double roundLength(double limit) {
  const double p = std::pow(10.0, std::floor(std::log10(limit)));
  for (double m : {5.0, 2.0, 1.0}) {
    if (m * p <= limit) return m * p;
  }
  return p;
}

std::string lengthLabel(double metres) {
  char buf[32];
  if (metres >= 1000) {
    std::snprintf(buf, sizeof buf, "%g km", metres / 1000);
  } else {
    std::snprintf(buf, sizeof buf, "%g m", metres);
  }
  return buf;
}

// A text centred at (x, y) of `r` (normalised viewport coordinates), fitted
// to `maxWidth` pixels (fitText).
void addText(vtkRenderer* r, const std::string& text, double x, double y, int size, bool bold, int vertical,
             double maxWidth, int dpi) {
  vtkNew<vtkTextActor> a;
  styleText(a->GetTextProperty(), size, bold);
  const FittedText fitted = fitText(a->GetTextProperty(), text, size, maxWidth, dpi);
  a->GetTextProperty()->SetFontSize(fitted.size);
  a->SetInput(fitted.text.c_str());
  a->GetTextProperty()->SetJustificationToCentered();
  a->GetTextProperty()->SetVerticalJustification(vertical);
  a->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
  a->GetPositionCoordinate()->SetValue(x, y);
  r->AddActor2D(a);
}

// A scale bar in the lower left of the visible region, in world coordinates.
void addScaleBar(vtkRenderer* r, double left, double bottom, double visibleWidth, double visibleHeight,
                 const FigureOutput& out) {
  const double length = roundLength(0.25 * visibleWidth);
  const double x0 = left + 0.04 * visibleWidth, y0 = bottom + 0.04 * visibleHeight;
  const double tick = 0.012 * visibleHeight;
  vtkNew<vtkPoints> pts;
  for (const auto& [x, y] : {std::pair{x0, y0 + tick}, {x0, y0}, {x0 + length, y0}, {x0 + length, y0 + tick}}) {
    pts->InsertNextPoint(x, y, 2.0);
  }
  vtkNew<vtkCellArray> line;
  line->InsertNextCell(4);
  for (vtkIdType i = 0; i < 4; ++i) line->InsertCellPoint(i);
  vtkNew<vtkPolyData> bar;
  bar->SetPoints(pts);
  bar->SetLines(line);
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputData(bar);
  vtkNew<vtkActor> actor;
  actor->SetMapper(mapper);
  actor->GetProperty()->SetColor(0, 0, 0);
  actor->GetProperty()->SetLineWidth(3.0f);
  r->AddActor(actor);
  vtkNew<vtkTextActor> label;
  label->SetInput(lengthLabel(length).c_str());
  styleText(label->GetTextProperty(), fontSize(out, 0.022));
  label->GetTextProperty()->SetJustificationToCentered();
  label->GetTextProperty()->SetVerticalJustificationToBottom();
  label->GetPositionCoordinate()->SetCoordinateSystemToWorld();
  label->GetPositionCoordinate()->SetValue(x0 + 0.5 * length, y0 + 1.5 * tick, 2.0);
  r->AddActor2D(label);
}

}  // namespace

std::vector<Rgb> scaleColours(const ColourScale& scale, const std::vector<double>& values) {
  const auto lut = lookupTable(scale);
  std::vector<Rgb> out;
  out.reserve(values.size());
  for (double v : values) {
    double rgb[3];
    lut->GetColor(v, rgb);
    out.push_back({rgb[0], rgb[1], rgb[2]});
  }
  return out;
}

std::string vtkVersionString() { return std::string("VTK ") + vtkVersion::GetVTKVersion(); }

double outlineSize(const Polygon& shape) {
  const double p = perimeter(shape);
  return p > 0 ? 4 * area(shape) / p : 0.0;
}

void renderMaps(const std::string& title, const std::vector<MapPanel>& panels, const ColourScale& scale,
                const FigureOutput& out) {
  checkOutput(out);
  Box extent{std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
             std::numeric_limits<double>::lowest(), std::numeric_limits<double>::lowest()};
  bool anyValue = false, anyNaN = false;
  for (const MapPanel& p : panels) {
    if (p.values.size() != p.shapes.size()) {
      throw usageError(out.png + ": panel '" + p.title + "' has " + std::to_string(p.shapes.size()) + " shapes but " +
                       std::to_string(p.values.size()) + " values");
    }
    for (const Polygon* s : p.shapes) {
      const Box b = bounds(*s);
      extent = {std::min(extent.minX, b.minX), std::min(extent.minY, b.minY), std::max(extent.maxX, b.maxX),
                std::max(extent.maxY, b.maxY)};
      anyValue = true;
    }
    for (double v : p.values) anyNaN = anyNaN || std::isnan(v);
  }
  if (!anyValue) throw usageError(out.png + ": no shape to draw");
  auto window = offscreenWindow(out);

  // Bands: title on top, colour bar below, panels in between.
  const double barTop = 0.15, titleBottom = 0.87;
  const auto lut = lookupTable(scale);
  const int n = static_cast<int>(panels.size());
  const double panelAspect = (out.width / static_cast<double>(n)) / (out.height * (titleBottom - barTop));
  const double margin = 0.03 * std::max(extent.width(), extent.height());
  const double halfHeight = std::max(0.5 * extent.height() + margin, (0.5 * extent.width() + margin) / panelAspect);
  const double cx = 0.5 * (extent.minX + extent.maxX), cy = 0.5 * (extent.minY + extent.maxY);

  // Texts keep a margin of 2 % of the width on either side.
  const int dpi = window->GetDPI();
  const double textRoom = 0.96 * out.width;
  vtkNew<vtkRenderer> titles;
  titles->SetViewport(0, titleBottom, 1, 1);
  titles->SetBackground(1, 1, 1);
  addText(titles, title, 0.5, 0.66, fontSize(out, 0.034), true, VTK_TEXT_CENTERED, textRoom, dpi);
  window->AddRenderer(titles);

  std::vector<PanelGeometry> geometry(panels.size());
  const double metresPerPixel = 2 * halfHeight / (out.height * (titleBottom - barTop));
  for (int i = 0; i < n; ++i) {
    addText(titles, panels[i].title, (i + 0.5) / n, 0.18, fontSize(out, 0.026), false, VTK_TEXT_CENTERED, textRoom / n,
            dpi);
    buildPanel(panels[i], geometry[i], nullptr, nullptr, kMinOutlinedPixels * metresPerPixel);
    vtkNew<vtkRenderer> r;
    r->SetViewport(static_cast<double>(i) / n, barTop, static_cast<double>(i + 1) / n, titleBottom);
    r->SetBackground(1, 1, 1);
    vtkNew<vtkPolyDataMapper> fillMapper;
    fillMapper->SetInputData(geometry[i].fill);
    fillMapper->SetLookupTable(lut);
    fillMapper->SetScalarModeToUsePointData();
    fillMapper->UseLookupTableScalarRangeOn();
    fillMapper->ScalarVisibilityOn();
    vtkNew<vtkActor> fill;
    fill->SetMapper(fillMapper);
    fill->GetProperty()->LightingOff();
    r->AddActor(fill);
    vtkNew<vtkPolyDataMapper> ringMapper;
    ringMapper->SetInputData(geometry[i].rings);
    ringMapper->ScalarVisibilityOff();
    vtkNew<vtkActor> rings;
    rings->SetMapper(ringMapper);
    rings->SetPosition(0, 0, 1);  // above the fill
    rings->GetProperty()->SetColor(0.45, 0.45, 0.45);
    rings->GetProperty()->SetLineWidth(1.0f);
    rings->GetProperty()->LightingOff();
    r->AddActor(rings);

    fitCamera(r, extent, panelAspect);
    addScaleBar(r, cx - halfHeight * panelAspect, cy - halfHeight, 2 * halfHeight * panelAspect, 2 * halfHeight, out);
    window->AddRenderer(r);
  }

  vtkNew<vtkRenderer> legend;
  legend->SetViewport(0, 0, 1, barTop);
  legend->SetBackground(1, 1, 1);
  vtkNew<vtkScalarBarActor> bar;
  bar->SetLookupTable(lut);
  bar->SetOrientationToHorizontal();
  // The bar's own title would sit among the labels: the title is a text of its own above the bar.
  addText(legend, scale.title, 0.5, 0.97, fontSize(out, 0.024), false, VTK_TEXT_TOP, textRoom, dpi);
  bar->SetNumberOfLabels(6);
  bar->SetLabelFormat("%.3g");
  bar->UnconstrainedFontSizeOn();
  bar->SetTextPositionToPrecedeScalarBar();
  styleText(bar->GetLabelTextProperty(), fontSize(out, 0.02));
  styleText(bar->GetAnnotationTextProperty(), fontSize(out, 0.02));
  if (anyNaN) {
    bar->DrawNanAnnotationOn();
    bar->SetNanAnnotation("no value");
  }
  bar->SetBarRatio(0.45);
  bar->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
  bar->GetPositionCoordinate()->SetValue(0.2, 0.02);
  bar->SetWidth(0.6);
  bar->SetHeight(0.66);
  legend->AddActor2D(bar);
  window->AddRenderer(legend);

  writeFigure(window, out, title);
  for (const std::string& path : out.mapVectors) writeVectorMaps(title, panels, scale, out.width, out.height, path);
}

void fillHistogramChart(vtkChartXY* chart, const std::string& title, const std::string& xTitle,
                        const std::string& yTitle, const std::vector<double>& edges,
                        const std::vector<HistogramSeries>& series, int height) {
  detail::prepareTextRendering();
  FigureOutput size;
  size.height = height;
  const std::size_t bins = edges.size() - 1;
  int highest = 1;
  for (const HistogramSeries& s : series) {
    for (int c : s.counts) highest = std::max(highest, c);
  }
  chart->ClearPlots();
  chart->SetTitle(title);
  styleText(chart->GetTitleProperties(), fontSize(size, 0.034), true);
  for (const HistogramSeries& s : series) {
    // Step outline: up at each left edge, across the bin, down at the last edge.
    vtkNew<vtkTable> table;
    for (const char* name : {"x", "zero", "count"}) {
      vtkNew<vtkDoubleArray> column;
      column->SetName(name);
      table->AddColumn(column);
    }
    table->SetNumberOfRows(static_cast<vtkIdType>(2 * bins + 2));
    vtkIdType row = 0;
    auto put = [&](double x, double y) {
      table->SetValue(row, 0, x);
      table->SetValue(row, 1, 0.0);
      table->SetValue(row, 2, y);
      ++row;
    };
    put(edges.front(), 0);
    for (std::size_t k = 0; k < bins; ++k) {
      put(edges[k], s.counts[k]);
      put(edges[k + 1], s.counts[k]);
    }
    put(edges.back(), 0);

    auto* area = vtkPlotArea::SafeDownCast(chart->AddPlot(vtkChart::AREA));
    area->SetInputData(table);
    area->SetInputArray(0, "x");
    area->SetInputArray(1, "zero");
    area->SetInputArray(2, "count");
    area->GetBrush()->SetColorF(s.colour.r, s.colour.g, s.colour.b, 0.3);
    area->GetPen()->SetLineType(vtkPen::NO_PEN);
    area->SetLabel(s.label);
    auto* line = vtkPlotLine::SafeDownCast(chart->AddPlot(vtkChart::LINE));
    line->SetInputData(table, "x", "count");
    line->GetPen()->SetColorF(s.colour.r, s.colour.g, s.colour.b, 1.0);
    line->SetWidth(2.5f);
    line->SetLegendVisibility(false);
  }

  vtkAxis* x = chart->GetAxis(vtkAxis::BOTTOM);
  vtkAxis* y = chart->GetAxis(vtkAxis::LEFT);
  x->SetTitle(xTitle);
  y->SetTitle(yTitle);
  x->SetBehavior(vtkAxis::FIXED);
  x->SetRange(edges.front(), edges.back());
  y->SetBehavior(vtkAxis::FIXED);
  y->SetRange(0, 1.08 * highest);
  x->SetNotation(vtkAxis::FIXED_NOTATION);
  x->SetPrecision(edges.back() - edges.front() >= 20 ? 0 : 1);
  y->SetNotation(vtkAxis::FIXED_NOTATION);
  y->SetPrecision(0);
  for (vtkAxis* a : {x, y}) {
    styleText(a->GetTitleProperties(), fontSize(size, 0.028), true);
    styleText(a->GetLabelProperties(), fontSize(size, 0.022));
    a->GetGridPen()->SetColorF(0.88, 0.88, 0.88);
  }
  chart->SetShowLegend(true);
  chart->GetLegend()->SetLabelSize(fontSize(size, 0.026));
  chart->GetLegend()->SetHorizontalAlignment(vtkChartLegend::RIGHT);
  chart->GetLegend()->SetVerticalAlignment(vtkChartLegend::TOP);
}

void renderHistogram(const std::string& title, const std::string& xTitle, const std::string& yTitle,
                     const std::vector<double>& edges, const std::vector<HistogramSeries>& series,
                     const FigureOutput& out) {
  checkOutput(out);
  if (edges.size() < 2) throw usageError(out.png + ": a histogram needs at least one bin");
  const std::size_t bins = edges.size() - 1;
  for (const HistogramSeries& s : series) {
    if (s.counts.size() != bins) {
      throw usageError(out.png + ": series '" + s.label + "' has " + std::to_string(s.counts.size()) + " counts for " +
                       std::to_string(bins) + " bins");
    }
  }
  const auto window = offscreenWindow(out);
  vtkNew<vtkContextView> view;
  view->SetRenderWindow(window);
  view->GetRenderer()->SetBackground(1, 1, 1);
  vtkNew<vtkChartXY> chart;
  view->GetScene()->AddItem(chart);
  fillHistogramChart(chart, title, xTitle, yTitle, edges, series, out.height);
  // The chart centres its title and the x axis's title on the plot area
  // horizontally, and the y axis's title vertically, and lays the plot area out
  // when drawn: once drawn, each is fitted to the room around its centre (less
  // a margin of 2 % of the figure on either side), and, when that changed one,
  // the chart is drawn again. The vector copy has them on one line.
  struct ChartText {
    std::string text;
    vtkTextProperty* style;
    std::function<void(const std::string&)> set;
    bool horizontal;
    int size = 0;
    double room = 0;
    FittedText fitted{};
  };
  vtkAxis* x = chart->GetAxis(vtkAxis::BOTTOM);
  vtkAxis* y = chart->GetAxis(vtkAxis::LEFT);
  std::array<ChartText, 3> texts{{
      {title, chart->GetTitleProperties(), [&](const std::string& t) { chart->SetTitle(t); }, true},
      {xTitle, x->GetTitleProperties(), [x](const std::string& t) { x->SetTitle(t); }, true},
      {yTitle, y->GetTitleProperties(), [y](const std::string& t) { y->SetTitle(t); }, false},
  }};
  const int dpi = window->GetDPI();
  const auto fitTexts = [&] {
    const int* p1 = chart->GetPoint1();
    const int* p2 = chart->GetPoint2();
    bool changed = false;
    for (ChartText& t : texts) {
      const double centre = t.horizontal ? 0.5 * (p1[0] + p2[0]) : 0.5 * (p1[1] + p2[1]);
      const double extent = t.horizontal ? out.width : out.height;
      t.size = t.style->GetFontSize();
      t.room = 2 * std::min(centre, extent - centre) - 0.04 * extent;
      t.fitted = fitText(t.style, t.text, t.size, t.room, dpi);
      if (t.fitted.text == t.text && t.fitted.size == t.size) continue;
      t.set(t.fitted.text);
      t.style->SetFontSize(t.fitted.size);
      changed = true;
    }
    return changed;
  };
  const auto oneLine = [&] {
    for (ChartText& t : texts) {
      if (t.fitted.text == t.text) continue;
      t.style->SetFontSize(fitText(t.style, t.text, t.size, t.room, dpi, true).size);
      t.set(t.text);
    }
  };
  writeFigure(window, out, title, fitTexts, oneLine);
}

// Interactive pieces (Scenes.h).

// The layer is drawn in kLayerParts parts, each with its own VTK data, so that
// a change to a few shapes (one block regenerated) rebuilds, and sends to
// OpenGL again, only the parts holding them.
constexpr std::size_t kLayerParts = 16;

struct LayerPart {
  PanelGeometry geometry;
  vtkNew<vtkPolyDataMapper> fillMapper, ringMapper;
  vtkNew<vtkActor> fill, rings;
  std::vector<std::size_t> members;  // the layer's shapes drawn here, in order
  std::uint64_t hash = 0;            // of those shapes
  std::vector<double> values;
  std::vector<vtkIdType> pointsPerShape;
  TriangleCache triangles;
  std::vector<Polygon> simple;  // the members as drawn, when simplified (memory reused)
  // Every member's rings (cells ringStart[k] to ringStart[k + 1]), its size
  // across, and the sizes sorted: the outlined members are those at least
  // kMinOutlinedPixels * metresPerPixel across.
  vtkSmartPointer<vtkCellArray> allRings = vtkSmartPointer<vtkCellArray>::New();
  std::vector<vtkIdType> ringStart{0};
  std::vector<double> size, sortedSize;
  std::size_t outlined = 0;

  std::size_t outlinedAt(double metresPerPixel) const {
    const double least = kMinOutlinedPixels * metresPerPixel;
    return static_cast<std::size_t>(sortedSize.end() - std::lower_bound(sortedSize.begin(), sortedSize.end(), least));
  }

  // Keeps only the outlined members' rings in the drawn outlines.
  void selectOutlines(double metresPerPixel, bool force) {
    const std::size_t count = outlinedAt(metresPerPixel);
    if (count == outlined && !force) return;
    outlined = count;
    if (count == size.size()) {
      geometry.rings->SetLines(allRings);
      return;
    }
    const double least = kMinOutlinedPixels * metresPerPixel;
    vtkNew<vtkCellArray> some;
    vtkNew<vtkIdList> cell;
    for (std::size_t k = 0; k < size.size(); ++k) {
      if (size[k] < least) continue;
      for (vtkIdType c = ringStart[k]; c < ringStart[k + 1]; ++c) {
        allRings->GetCellAtId(c, cell);
        some->InsertNextCell(cell);
      }
    }
    geometry.rings->SetLines(some);
  }

  // Builds the part again from its members, simplified for `tolerance`
  // (metres; 0: as they are).
  void rebuild(const std::vector<const Polygon*>& shapes, double metresPerPixel, double tolerance) {
    MapPanel panel;
    for (std::size_t k : members) panel.shapes.push_back(shapes[k]);
    const std::vector<const Polygon*> original = panel.shapes;
    // The parts hold whole groups (blocks), whose parcels share no boundary
    // with other groups: each part is simplified on its own.
    if (tolerance > 0) {
      detail::simplifyShared(original, tolerance, simple);
      for (std::size_t i = 0; i < simple.size(); ++i) panel.shapes[i] = &simple[i];
    }
    panel.values = values;
    PanelGeometry fresh;
    pointsPerShape.clear();
    buildPanel(panel, fresh, &pointsPerShape, &triangles);
    geometry.fill->ShallowCopy(fresh.fill);
    geometry.rings->ShallowCopy(fresh.rings);
    allRings = fresh.rings->GetLines();
    ringStart.assign(1, 0);
    size.clear();
    for (std::size_t i = 0; i < panel.shapes.size(); ++i) {
      const Polygon& drawn = *panel.shapes[i];
      // The rings buildPanel outlined, all of them (outlines are chosen below).
      const vtkIdType outlines = drawn.outer.size() < 3 ? 0 : 1 + static_cast<vtkIdType>(drawn.holes.size());
      ringStart.push_back(ringStart.back() + outlines);
      size.push_back(outlineSize(*original[i]));
    }
    sortedSize = size;
    std::sort(sortedSize.begin(), sortedSize.end());
    selectOutlines(metresPerPixel, true);
  }

  // New cell values from `values` (this part's), when they differ.
  void recolour(std::vector<double> fresh) {
    // Compared bit for bit, so that NaN (no value) counts as unchanged.
    if (fresh.size() == values.size() &&
        (fresh.empty() || std::memcmp(fresh.data(), values.data(), fresh.size() * sizeof(double)) == 0)) {
      return;
    }
    values = std::move(fresh);
    vtkNew<vtkDoubleArray> scalars;
    scalars->SetName("value");
    vtkIdType total = 0;
    for (vtkIdType n : pointsPerShape) total += n;
    scalars->SetNumberOfValues(total);
    vtkIdType next = 0;
    for (std::size_t k = 0; k < values.size(); ++k) {
      for (vtkIdType t = 0; t < pointsPerShape[k]; ++t) scalars->SetValue(next++, values[k]);
    }
    geometry.fill->GetPointData()->SetScalars(scalars);
    geometry.fill->Modified();
  }
};

// How far a drawn boundary may stray from the shape's (metres) at a scale:
// half a pixel, rounded down to a power of two, so that the layer is built
// again only when the scale halves or doubles. 0 (no scale yet): exact.
double drawingTolerance(double metresPerPixel) {
  if (!(metresPerPixel > 0) || !std::isfinite(metresPerPixel)) return 0;
  return std::exp2(std::floor(std::log2(0.5 * metresPerPixel)));
}

// Orders `parts` (indices into `all`) by their count of shapes, the largest
// first (ties by index).
void largestFirst(const std::array<LayerPart, kLayerParts>& all, std::vector<std::size_t>& parts) {
  std::stable_sort(parts.begin(), parts.end(),
                   [&](std::size_t a, std::size_t b) { return all[a].members.size() > all[b].members.size(); });
}

struct MapLayer::Impl {
  std::array<LayerPart, kLayerParts> parts;
  std::vector<const Polygon*> drawn;  // the last setShapes's shapes
  double tolerance = 0;               // drawingTolerance of the scale they were built for
  vtkSmartPointer<vtkLookupTable> lut = lookupTable(ColourScale{});
  vtkNew<vtkScalarBarActor> bar;
  double metresPerPixel = 0;
  std::size_t rebuilt = 0;
};

MapLayer::MapLayer() : impl_(std::make_unique<Impl>()) {
  detail::prepareTextRendering();  // before the colour bar's first text
  Impl& m = *impl_;
  for (LayerPart& p : m.parts) {
    // The coordinates are local metres around the data's centre: no shift
    // and scale is needed, and VTK would otherwise scan every point for it
    // each time a part is sent again.
    for (vtkPolyDataMapper* mapper : {p.fillMapper.GetPointer(), p.ringMapper.GetPointer()}) {
      if (auto* gl = vtkOpenGLPolyDataMapper::SafeDownCast(mapper)) {
        gl->SetVBOShiftScaleMethod(vtkOpenGLVertexBufferObject::DISABLE_SHIFT_SCALE);
      }
    }
    p.fillMapper->SetInputData(p.geometry.fill);
    p.fillMapper->SetScalarModeToUsePointData();
    p.fillMapper->UseLookupTableScalarRangeOn();
    p.fillMapper->ScalarVisibilityOn();
    p.fillMapper->SetLookupTable(m.lut);
    p.fill->SetMapper(p.fillMapper);
    p.fill->GetProperty()->LightingOff();
    p.ringMapper->SetInputData(p.geometry.rings);
    p.ringMapper->ScalarVisibilityOff();
    p.rings->SetMapper(p.ringMapper);
    p.rings->SetPosition(0, 0, 1);
    p.rings->GetProperty()->SetColor(0.45, 0.45, 0.45);
    p.rings->GetProperty()->LightingOff();
  }
  m.bar->SetLookupTable(m.lut);
  m.bar->SetOrientationToHorizontal();
  m.bar->SetNumberOfLabels(5);
  m.bar->SetLabelFormat("%.3g");
  m.bar->UnconstrainedFontSizeOn();
  styleText(m.bar->GetLabelTextProperty(), 11);
  styleText(m.bar->GetTitleTextProperty(), 12);
  m.bar->SetTextPositionToPrecedeScalarBar();
}

MapLayer::~MapLayer() = default;

void MapLayer::setShapes(const std::vector<const Polygon*>& shapes, const std::vector<double>& values,
                         const std::vector<int>& groups) {
  if (shapes.size() != values.size() || (!groups.empty() && groups.size() != shapes.size())) {
    throw usageError("map layer: " + std::to_string(shapes.size()) + " shapes but " + std::to_string(values.size()) +
                     " values and " + std::to_string(groups.size()) + " groups");
  }
  Impl& m = *impl_;
  std::array<std::vector<std::size_t>, kLayerParts> members;
  for (std::size_t k = 0; k < shapes.size(); ++k) {
    // Without groups, runs of consecutive shapes.
    const std::size_t part = groups.empty() ? k * kLayerParts / shapes.size()
                                            : static_cast<std::size_t>(static_cast<unsigned>(groups[k])) % kLayerParts;
    members[part].push_back(k);
  }
  std::array<std::size_t, kLayerParts> before{};  // each part's count of members until now
  std::vector<std::size_t> order(kLayerParts);
  for (std::size_t i = 0; i < kLayerParts; ++i) {
    before[i] = m.parts[i].members.size();
    m.parts[i].members = std::move(members[i]);
    order[i] = i;
  }
  // The parts share nothing: each is compared with what it drew (by a hash
  // of its shapes), then recoloured or triangulated again, side by side, the
  // largest first, so that no thread is left with a large part at the end.
  largestFirst(m.parts, order);
  std::array<char, kLayerParts> stale{};
  parallelFor(order.size(), [&](std::size_t j) {
    const std::size_t i = order[j];
    LayerPart& p = m.parts[i];
    std::uint64_t hash = p.members.size();
    for (std::size_t k : p.members) hash = hash * 0x100000001b3ull ^ shapeHash(*shapes[k]);
    std::vector<double> partValues;
    partValues.reserve(p.members.size());
    for (std::size_t k : p.members) partValues.push_back(values[k]);
    if (hash == p.hash && p.members.size() == before[i]) {
      p.recolour(std::move(partValues));
      return;
    }
    p.hash = hash;
    p.values = std::move(partValues);
    p.rebuild(shapes, m.metresPerPixel, m.tolerance);
    stale[i] = 1;
  });
  m.rebuilt = static_cast<std::size_t>(std::count(stale.begin(), stale.end(), 1));
  m.drawn = shapes;
}

void MapLayer::setMetresPerPixel(double metresPerPixel) {
  Impl& m = *impl_;
  m.metresPerPixel = metresPerPixel;
  const double tolerance = drawingTolerance(metresPerPixel);
  if (tolerance != m.tolerance) {
    // Another level of detail: every part is built again for it.
    m.tolerance = tolerance;
    std::vector<std::size_t> all;
    for (std::size_t i = 0; i < m.parts.size(); ++i) {
      if (!m.parts[i].members.empty()) all.push_back(i);
    }
    largestFirst(m.parts, all);
    parallelFor(all.size(), [&](std::size_t i) { m.parts[all[i]].rebuild(m.drawn, metresPerPixel, tolerance); });
    return;
  }
  for (LayerPart& p : m.parts) p.selectOutlines(metresPerPixel, false);
}

std::size_t MapLayer::partsRebuilt() const { return impl_->rebuilt; }

std::size_t MapLayer::pointsDrawn() const {
  std::size_t n = 0;
  for (const LayerPart& p : impl_->parts) {
    for (vtkIdType k : p.pointsPerShape) n += static_cast<std::size_t>(k);
  }
  return n;
}

std::size_t MapLayer::outlinedShapes() const {
  std::size_t n = 0;
  for (const LayerPart& p : impl_->parts) n += p.outlined;
  return n;
}

void MapLayer::setValues(const std::vector<double>& values) {
  if (values.size() != impl_->drawn.size()) {
    throw usageError("map layer: " + std::to_string(impl_->drawn.size()) + " shapes but " +
                     std::to_string(values.size()) + " values");
  }
  for (LayerPart& p : impl_->parts) {
    std::vector<double> partValues;
    partValues.reserve(p.members.size());
    for (std::size_t k : p.members) partValues.push_back(values[k]);
    p.recolour(std::move(partValues));
  }
}

void MapLayer::setScale(const ColourScale& scale) {
  const auto lut = lookupTable(scale);
  impl_->lut->DeepCopy(lut);
  impl_->lut->Modified();
  impl_->bar->SetTitle(scale.title.c_str());
  for (LayerPart& p : impl_->parts) p.fillMapper->Modified();
}

void MapLayer::addTo(vtkRenderer* renderer) {
  for (LayerPart& p : impl_->parts) {
    renderer->AddActor(p.fill);
    renderer->AddActor(p.rings);
  }
}

vtkScalarBarActor* MapLayer::colourBar() { return impl_->bar; }

void MapLayer::setOutlinesVisible(bool visible) {
  for (LayerPart& p : impl_->parts) p.rings->SetVisibility(visible);
}

struct OutlineLayer::Impl {
  vtkNew<vtkPolyData> rings;
  vtkNew<vtkPolyDataMapper> mapper;
  vtkNew<vtkActor> actor;
};

OutlineLayer::OutlineLayer() : impl_(std::make_unique<Impl>()) {
  impl_->mapper->SetInputData(impl_->rings);
  impl_->mapper->ScalarVisibilityOff();
  impl_->actor->SetMapper(impl_->mapper);
  impl_->actor->SetPosition(0, 0, 2);
  impl_->actor->GetProperty()->SetColor(0.05, 0.35, 0.95);
  impl_->actor->GetProperty()->SetLineWidth(4.0f);
  impl_->actor->GetProperty()->LightingOff();
}

OutlineLayer::~OutlineLayer() = default;

void OutlineLayer::setShapes(const std::vector<const Polygon*>& shapes) { buildRings(shapes, impl_->rings); }

void OutlineLayer::addTo(vtkRenderer* renderer) { renderer->AddActor(impl_->actor); }

struct StreetLayer::Impl {
  vtkNew<vtkPolyData> centre, kerbs;
  vtkNew<vtkPolyDataMapper> centreMapper, kerbMapper;
  vtkNew<vtkActor> centreActor, kerbActor;
  std::size_t lines = 0;
};

StreetLayer::StreetLayer() : impl_(std::make_unique<Impl>()) {
  auto style = [](vtkPolyDataMapper* mapper, vtkPolyData* data, vtkActor* actor, double grey, float width) {
    mapper->SetInputData(data);
    mapper->ScalarVisibilityOff();
    actor->SetMapper(mapper);
    actor->SetPosition(0, 0, 1.5);
    actor->GetProperty()->SetColor(grey, grey, grey);
    actor->GetProperty()->SetLineWidth(width);
    actor->GetProperty()->LightingOff();
  };
  style(impl_->centreMapper, impl_->centre, impl_->centreActor, 0.25, 1.5f);
  style(impl_->kerbMapper, impl_->kerbs, impl_->kerbActor, 0.55, 1.0f);
}

StreetLayer::~StreetLayer() = default;

void StreetLayer::setStreets(const std::vector<std::vector<Point>>& centreLines, const std::vector<Polygon>& surface) {
  // Filled in bulk: a city's centre lines are redrawn on every edit.
  std::size_t pointCount = 0;
  for (const auto& line : centreLines) pointCount += line.size() < 2 ? 0 : line.size();
  vtkNew<vtkDoubleArray> coordinates;
  coordinates->SetNumberOfComponents(3);
  coordinates->SetNumberOfTuples(static_cast<vtkIdType>(pointCount));
  double* xyz = coordinates->GetPointer(0);
  vtkNew<vtkIdTypeArray> offsets, ids;
  offsets->InsertNextValue(0);
  ids->SetNumberOfValues(static_cast<vtkIdType>(pointCount));
  vtkIdType next = 0;
  for (const auto& line : centreLines) {
    if (line.size() < 2) continue;
    for (const Point& p : line) {
      *xyz++ = p.x;
      *xyz++ = p.y;
      *xyz++ = 0.0;
      ids->SetValue(next, next);
      ++next;
    }
    offsets->InsertNextValue(next);
  }
  vtkNew<vtkCellArray> cells;
  cells->SetData(offsets, ids);
  vtkNew<vtkPoints> points;
  points->SetData(coordinates);
  vtkNew<vtkPolyData> centre;
  centre->SetPoints(points);
  centre->SetLines(cells);
  impl_->centre->ShallowCopy(centre);
  impl_->lines = centreLines.size();
  std::vector<const Polygon*> kerbs;
  for (const Polygon& p : surface) kerbs.push_back(&p);
  buildRings(kerbs, impl_->kerbs);
}

void StreetLayer::addTo(vtkRenderer* renderer) {
  renderer->AddActor(impl_->kerbActor);
  renderer->AddActor(impl_->centreActor);
}

std::size_t StreetLayer::lines() const { return impl_->lines; }

namespace {

// Points as vertices and polylines as lines of one polydata.
void fillPolyData(vtkPolyData* out, const std::vector<Point>& points, const std::vector<std::vector<Point>>& lines) {
  vtkNew<vtkPoints> xyz;
  vtkNew<vtkCellArray> verts, cells;
  for (const Point& p : points) {
    const vtkIdType id = xyz->InsertNextPoint(p.x, p.y, 0);
    verts->InsertNextCell(1, &id);
  }
  for (const auto& line : lines) {
    if (line.size() < 2) continue;
    cells->InsertNextCell(static_cast<vtkIdType>(line.size()));
    for (const Point& p : line) cells->InsertCellPoint(xyz->InsertNextPoint(p.x, p.y, 0));
  }
  vtkNew<vtkPolyData> data;
  data->SetPoints(xyz);
  data->SetVerts(verts);
  data->SetLines(cells);
  out->ShallowCopy(data);
}

}  // namespace

struct HandleLayer::Impl {
  vtkNew<vtkPolyData> nodes, street, handles;
  vtkNew<vtkPolyDataMapper> nodeMapper, streetMapper, handleMapper;
  vtkNew<vtkActor> nodeActor, streetActor, handleActor;
  std::size_t nodeCount = 0, selected = 0;
};

HandleLayer::HandleLayer() : impl_(std::make_unique<Impl>()) {
  auto style = [](vtkPolyDataMapper* mapper, vtkPolyData* data, vtkActor* actor, const double rgb[3], float size,
                  double z) {
    mapper->SetInputData(data);
    mapper->ScalarVisibilityOff();
    actor->SetMapper(mapper);
    actor->SetPosition(0, 0, z);
    actor->GetProperty()->SetColor(rgb[0], rgb[1], rgb[2]);
    actor->GetProperty()->SetPointSize(size);
    actor->GetProperty()->SetLineWidth(size / 2);
    actor->GetProperty()->LightingOff();
  };
  const double dark[3] = {0.15, 0.15, 0.15}, orange[3] = {0.95, 0.45, 0.05};
  style(impl_->nodeMapper, impl_->nodes, impl_->nodeActor, dark, 5.0f, 3);
  style(impl_->streetMapper, impl_->street, impl_->streetActor, orange, 8.0f, 3.5);
  style(impl_->handleMapper, impl_->handles, impl_->handleActor, orange, 10.0f, 4);
  impl_->handleActor->GetProperty()->SetLineWidth(1.5f);
  setVisible(false);
}

HandleLayer::~HandleLayer() = default;

void HandleLayer::setNodes(const std::vector<Point>& nodes) {
  fillPolyData(impl_->nodes, nodes, {});
  impl_->nodeCount = nodes.size();
}

void HandleLayer::setSelection(const std::vector<Point>& street, const std::vector<std::vector<Point>>& arms,
                               const std::vector<Point>& points) {
  fillPolyData(impl_->street, {}, {street});
  fillPolyData(impl_->handles, points, arms);
  impl_->selected = points.size();
}

void HandleLayer::setVisible(bool visible) {
  for (vtkActor* a : {impl_->nodeActor.Get(), impl_->streetActor.Get(), impl_->handleActor.Get()}) {
    a->SetVisibility(visible);
  }
}

bool HandleLayer::visible() const { return impl_->nodeActor->GetVisibility() != 0; }

void HandleLayer::addTo(vtkRenderer* renderer) {
  renderer->AddActor(impl_->streetActor);
  renderer->AddActor(impl_->nodeActor);
  renderer->AddActor(impl_->handleActor);
}

std::size_t HandleLayer::nodes() const { return impl_->nodeCount; }
std::size_t HandleLayer::selectedPoints() const { return impl_->selected; }

void fitCamera(vtkRenderer* renderer, const Box& extent, double viewAspect) {
  const double margin = 0.03 * std::max(extent.width(), extent.height());
  const double halfHeight =
      std::max(0.5 * extent.height() + margin, (0.5 * extent.width() + margin) / std::max(1e-3, viewAspect));
  const double cx = 0.5 * (extent.minX + extent.maxX), cy = 0.5 * (extent.minY + extent.maxY);
  vtkCamera* camera = renderer->GetActiveCamera();
  camera->ParallelProjectionOn();
  camera->SetFocalPoint(cx, cy, 0);
  camera->SetPosition(cx, cy, 100);
  camera->SetViewUp(0, 1, 0);
  camera->SetParallelScale(halfHeight);
  camera->SetClippingRange(1, 1000);
}

}  // namespace parcelscope::viz
