// Off-screen figures read back pixel by pixel: the requested size, ink where
// the shapes are, the colour scale's ends, holes left open, panels drawn at the
// same extent and scale, and charts with their text in the SVG copy.
// Runs under scripts/with-xvfb.sh (its own Xvfb).
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "TestUtil.h"
#include "parcelscope/core/Error.h"
#include "parcelscope/viz/Figures.h"
#include "parcelscope/viz/Scenes.h"
#include "viz/ImageCheck.h"

#include <vtkActor.h>
#include <vtkActorCollection.h>
#include <vtkCellArray.h>
#include <vtkDataArray.h>
#include <vtkIdList.h>
#include <vtkImageData.h>
#include <vtkMapper.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkRendererCollection.h>
#include <vtkSmartPointer.h>
#include <vtkWindowToImageFilter.h>

#include <cmath>

namespace parcelscope::viz {
namespace {

using test::rect;
using test::TempDir;

int red(std::uint32_t c) { return static_cast<int>(c >> 16); }
int green(std::uint32_t c) { return static_cast<int>((c >> 8) & 0xff); }
int blue(std::uint32_t c) { return static_cast<int>(c & 0xff); }

FigureOutput output(const TempDir& dir, const std::string& name, int width, int height) {
  FigureOutput o;
  o.png = dir.file(name + ".png");
  o.width = width;
  o.height = height;
  return o;
}

TEST(RenderMaps, PanelsShareExtentAndScaleAndTheColourScaleRunsRedToGreen) {
  TempDir dir;
  // A 1:1 square (red) and a 5:1 strip (green) far apart: the extent is their union.
  const Polygon square = rect(0, 0, 40, 40), strip = rect(200, 0, 400, 40);
  MapPanel left{"left", {&square, &strip}, {1.0, 5.0}};
  MapPanel right = left;
  right.title = "right";
  ColourScale scale;
  scale.minimum = 1;
  scale.maximum = 5;
  scale.title = "aspect ratio";
  const FigureOutput out = output(dir, "maps", 800, 400);
  renderMaps("two panels", {left, right}, scale, out);
  const test::Image image = test::readPng(out.png);
  ASSERT_EQ(image.width, 800);
  ASSERT_EQ(image.height, 400);
  // The map band (between the title and the colour bar) of the left half equals the right half.
  struct {
    int differing = 0, inked = 0;
  } h;
  for (int y = static_cast<int>(0.15 * 400); y < static_cast<int>(0.85 * 400); ++y) {
    for (int x = 0; x < 400; ++x) {
      h.differing += image.rgb(x, y) != image.rgb(x + 400, y);
      h.inked += image.rgb(x, y) != 0xffffff;
    }
  }
  EXPECT_GT(h.inked, 2000);
  EXPECT_LT(h.differing, h.inked / 100) << "the two panels differ: not the same extent and scale";
  // Somewhere in the left band: a clearly red pixel (the square) and a clearly green one (the strip).
  bool sawRed = false, sawGreen = false;
  for (int y = 60; y < 340; ++y) {
    for (int x = 0; x < 400; ++x) {
      const std::uint32_t c = image.rgb(x, y);
      sawRed = sawRed || (red(c) > 180 && green(c) < 80 && blue(c) < 80);
      sawGreen = sawGreen || (green(c) > 140 && red(c) < 80 && blue(c) < 80);
    }
  }
  EXPECT_TRUE(sawRed);
  EXPECT_TRUE(sawGreen);
}

TEST(RenderMaps, HolesStayOpen) {
  TempDir dir;
  Polygon ring = rect(0, 0, 100, 100);
  ring.holes.push_back({{30, 30}, {30, 70}, {70, 70}, {70, 30}});  // clockwise hole
  MapPanel panel{"ring", {&ring}, {1.0}};
  ColourScale scale;
  scale.title = "value";
  const FigureOutput out = output(dir, "ring", 600, 600);
  renderMaps("a ring", {panel}, scale, out);
  const test::Image image = test::readPng(out.png);
  ASSERT_EQ(image.width, 600);
  // The map band runs from 13 % to 85 % of the height (from the top); its centre is the hole's.
  const int cy = static_cast<int>(600 * (1 - 0.5 * (0.15 + 0.87)));
  EXPECT_EQ(image.rgb(300, cy), 0xffffffu) << "the hole is filled";
  EXPECT_NE(image.rgb(300 - 120, cy), 0xffffffu) << "the ring is not drawn";
}

// A concave shape (ear cutting) fills its own area and leaves its notch empty.
TEST(RenderMaps, ConcaveShapesFillOnlyThemselves) {
  TempDir dir;
  // A U: 100 x 100 with a 40 m wide notch from the top down to y = 30.
  Polygon u = test::poly({{0, 0}, {100, 0}, {100, 100}, {70, 100}, {70, 30}, {30, 30}, {30, 100}, {0, 100}});
  MapPanel panel{"U", {&u}, {1.0}};
  ColourScale scale;
  scale.title = "value";
  const FigureOutput out = output(dir, "u", 600, 600);
  renderMaps("a U", {panel}, scale, out);
  const test::Image image = test::readPng(out.png);
  ASSERT_EQ(image.width, 600);
  // Map band from 13 % to 85 % of the height; the U spans it vertically with a margin.
  const int top = static_cast<int>(600 * (1 - 0.87)), bottom = static_cast<int>(600 * (1 - 0.15));
  const int notchY = top + (bottom - top) / 4;     // y = 75 in the U
  const int baseY = top + 7 * (bottom - top) / 8;  // y = 12
  EXPECT_EQ(image.rgb(300, notchY), 0xffffffu) << "the notch is filled";
  EXPECT_NE(image.rgb(300, baseY), 0xffffffu) << "the base of the U is empty";
  EXPECT_NE(image.rgb(300 - 200, notchY), 0xffffffu) << "the left arm is empty";
}

// Outlines only around shapes at least kMinOutlinedPixels across: a grid of
// 4 px cells is drawn as its fill alone, a grid of 100 px cells with outlines.
TEST(RenderMaps, OutlinesOnlyAroundShapesLargeEnoughToShowThem) {
  TempDir dir;
  ColourScale scale;
  scale.minimum = 1;
  scale.maximum = 5;
  scale.title = "value";
  // The share of the map's inked pixels that are not the fill's colour.
  const auto outlineShare = [&](int cells) {
    std::vector<Polygon> grid;
    const double side = 1000.0 / cells;
    for (int i = 0; i < cells; ++i) {
      for (int j = 0; j < cells; ++j) grid.push_back(rect(i * side, j * side, (i + 1) * side, (j + 1) * side));
    }
    MapPanel panel{"grid", {}, {}};
    for (const Polygon& g : grid) {
      panel.shapes.push_back(&g);
      panel.values.push_back(1.0);
    }
    const FigureOutput out = output(dir, "grid" + std::to_string(cells), 600, 600);
    renderMaps("a grid", {panel}, scale, out);
    const test::Image image = test::readPng(out.png);
    const std::uint32_t fill = image.rgb(250, 250);  // inside a cell of either grid
    EXPECT_GT(red(fill), 200);
    int other = 0, inked = 0;
    for (int y = static_cast<int>(0.15 * 600); y < static_cast<int>(0.85 * 600); ++y) {
      for (int x = 0; x < 600; ++x) {
        const std::uint32_t c = image.rgb(x, y);
        if (c == 0xffffff) continue;
        ++inked;
        other += std::abs(red(c) - red(fill)) + std::abs(green(c) - green(fill)) + std::abs(blue(c) - blue(fill)) > 30;
      }
    }
    EXPECT_GT(inked, 100000);
    return static_cast<double>(other) / inked;
  };
  // 1000 m over about 400 px: 2.5 m per pixel, so 10 m cells are 4 px across
  // (outlined, they would cover half the map; the square's own edge, blended
  // with the white around it, is about 1.3 %) and 250 m cells 100 px (their
  // outlines, two pixels wide once smoothed, about 5 %).
  EXPECT_LT(outlineShare(100), 0.025);
  EXPECT_GT(outlineShare(4), 0.035);
}

TEST(OutlineSize, IsTheSideOfASquareAndAboutTwiceAStripsWidth) {
  EXPECT_DOUBLE_EQ(outlineSize(rect(0, 0, 40, 40)), 40.0);
  EXPECT_NEAR(outlineSize(rect(0, 0, 100, 2)), 4 * 200.0 / 204.0, 1e-12);
  Polygon empty;
  EXPECT_EQ(outlineSize(empty), 0.0);
}

TEST(MapLayer, OutlinesFollowTheScaleDrawn) {
  const Polygon small = rect(0, 0, 10, 10), large = rect(20, 0, 120, 100);
  Polygon courtyard = rect(200, 0, 300, 100);
  courtyard.holes.push_back({{230, 30}, {230, 70}, {270, 70}, {270, 30}});
  MapLayer layer;
  layer.setShapes({&small, &large, &courtyard}, {1, 2, 3});
  EXPECT_EQ(layer.outlinedShapes(), 3u);  // no scale yet: every shape
  layer.setMetresPerPixel(1.0);           // 6 m and up
  EXPECT_EQ(layer.outlinedShapes(), 3u);
  layer.setMetresPerPixel(5.0);  // 30 m and up: the courtyard is 4 * 8400 / 560 = 60 m across
  EXPECT_EQ(layer.outlinedShapes(), 2u);
  layer.setMetresPerPixel(12.0);  // 72 m and up
  EXPECT_EQ(layer.outlinedShapes(), 1u);
  layer.setMetresPerPixel(100.0);
  EXPECT_EQ(layer.outlinedShapes(), 0u);
  // New shapes keep the scale.
  layer.setShapes({&large}, {1});
  EXPECT_EQ(layer.outlinedShapes(), 0u);
  layer.setMetresPerPixel(0.5);
  EXPECT_EQ(layer.outlinedShapes(), 1u);
}

// The street layer's two polydata (kerbs, centre lines), from the actors it
// adds to a renderer: every kerb ring closed (its first point again), every
// centre line open, lines of fewer than 2 points and rings of fewer than 3
// left out.
TEST(StreetLayer, DrawsEachKerbRingClosedAndEachCentreLineOpen) {
  Polygon yard = rect(0, 0, 100, 60);
  yard.holes.push_back({{40, 20}, {40, 40}, {60, 40}, {60, 20}});
  const Polygon block = rect(120, 0, 180, 60);
  const Polygon sliver{{{0, 0}, {1, 1}}, {}};
  const std::vector<std::vector<Point>> lines = {{{-10, 70}, {50, 70}, {190, 70}}, {{110, -5}}, {{110, 0}, {110, 60}}};
  StreetLayer layer;
  layer.setStreets(lines, {yard, block, sliver});
  EXPECT_EQ(layer.lines(), 3u);
  vtkNew<vtkRenderer> renderer;
  layer.addTo(renderer);
  vtkActorCollection* actors = renderer->GetActors();
  ASSERT_EQ(actors->GetNumberOfItems(), 2);
  actors->InitTraversal();
  auto* kerbs = vtkPolyData::SafeDownCast(actors->GetNextActor()->GetMapper()->GetInput());
  auto* centre = vtkPolyData::SafeDownCast(actors->GetNextActor()->GetMapper()->GetInput());
  ASSERT_TRUE(kerbs && centre);
  // Kerbs: the yard's outer ring and hole, the block's ring; no sliver.
  ASSERT_EQ(kerbs->GetNumberOfLines(), 3);
  EXPECT_EQ(kerbs->GetNumberOfPoints(), 12);
  EXPECT_EQ(kerbs->GetNumberOfPolys(), 0);
  vtkNew<vtkIdList> cell;
  const std::vector<const Ring*> rings = {&yard.outer, &yard.holes[0], &block.outer};
  for (vtkIdType c = 0; c < 3; ++c) {
    kerbs->GetLines()->GetCellAtId(c, cell);
    const Ring& ring = *rings[static_cast<std::size_t>(c)];
    ASSERT_EQ(cell->GetNumberOfIds(), static_cast<vtkIdType>(ring.size() + 1));
    EXPECT_EQ(cell->GetId(0), cell->GetId(cell->GetNumberOfIds() - 1));
    for (std::size_t v = 0; v < ring.size(); ++v) {
      double xyz[3];
      kerbs->GetPoint(cell->GetId(static_cast<vtkIdType>(v)), xyz);
      EXPECT_EQ(xyz[0], ring[v].x);
      EXPECT_EQ(xyz[1], ring[v].y);
    }
  }
  // Centre lines: the two of 2 points or more, open, in order.
  ASSERT_EQ(centre->GetNumberOfLines(), 2);
  EXPECT_EQ(centre->GetNumberOfPoints(), 5);
  centre->GetLines()->GetCellAtId(1, cell);
  ASSERT_EQ(cell->GetNumberOfIds(), 2);
  double end[3];
  centre->GetPoint(cell->GetId(1), end);
  EXPECT_EQ(end[0], 110);
  EXPECT_EQ(end[1], 60);
  // Empty: nothing drawn.
  layer.setStreets({}, {});
  EXPECT_EQ(kerbs->GetNumberOfLines(), 0);
  EXPECT_EQ(centre->GetNumberOfLines(), 0);
}

// The layer drawn off screen, as RGB bytes. One window for every drawing (and
// requireDisplay's connection kept open): Xvfb resets when its last client
// leaves, and a connection opened during the reset fails.
std::vector<unsigned char> draw(MapLayer& layer, const Box& extent) {
  requireDisplay();
  static vtkSmartPointer<vtkRenderWindow> window;
  if (!window) {
    window = vtkSmartPointer<vtkRenderWindow>::New();
    window->SetOffScreenRendering(1);
    window->SetSize(600, 200);
  }
  while (window->GetRenderers()->GetNumberOfItems() > 0) {
    window->RemoveRenderer(window->GetRenderers()->GetFirstRenderer());
  }
  vtkNew<vtkRenderer> renderer;
  renderer->SetBackground(1, 1, 1);
  window->AddRenderer(renderer);
  layer.addTo(renderer);
  fitCamera(renderer, extent, 3.0);
  window->Render();
  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(window);
  grab->SetInputBufferTypeToRGB();
  grab->Update();
  vtkDataArray* pixels = grab->GetOutput()->GetPointData()->GetScalars();
  std::vector<unsigned char> out(static_cast<std::size_t>(pixels->GetNumberOfValues()));
  for (vtkIdType i = 0; i < pixels->GetNumberOfValues(); ++i)
    out[static_cast<std::size_t>(i)] = static_cast<unsigned char>(pixels->GetVariantValue(i).ToInt());
  return out;
}

// Blocks of parcels in a row, each block cut into `cuts[b]` strips.
struct Row {
  std::vector<Polygon> parcels;
  std::vector<const Polygon*> shapes;
  std::vector<double> values;
  std::vector<int> blocks;
  Row(const std::vector<int>& cuts, double shift) {
    for (std::size_t b = 0; b < cuts.size(); ++b) {
      for (int c = 0; c < cuts[b]; ++c) {
        const double x = 30.0 * static_cast<double>(b), w = 25.0 / cuts[b];
        parcels.push_back(rect(x + c * w, 0, x + (c + 1) * w, 60));
        values.push_back(1 + std::fmod(shift + static_cast<double>(parcels.size()) * 0.37, 4.0));
        blocks.push_back(static_cast<int>(b));
      }
    }
    for (const Polygon& p : parcels) shapes.push_back(&p);
  }
};

// Only the parts holding a changed block are built again, and a layer updated
// so draws exactly what a layer given the final shapes at once draws.
TEST(MapLayer, RebuildsOnlyChangedPartsAndDrawsWhatAFreshLayerDraws) {
  std::vector<int> cuts(40, 3);
  const Row first(cuts, 0);
  cuts[7] = 5;
  const Row second(cuts, 0), recoloured(cuts, 1.5);
  ColourScale scale;
  scale.minimum = 1;
  scale.maximum = 5;
  scale.title = "value";
  MapLayer updated;
  updated.setScale(scale);
  updated.setShapes(first.shapes, first.values, first.blocks);
  EXPECT_EQ(updated.partsRebuilt(), 16u);
  updated.setShapes(second.shapes, second.values, second.blocks);  // block 7 cut again
  EXPECT_EQ(updated.partsRebuilt(), 1u);
  updated.setShapes(recoloured.shapes, recoloured.values, recoloured.blocks);  // new values only
  EXPECT_EQ(updated.partsRebuilt(), 0u);
  // At 2 m per pixel, outlines around the 8.3 m strips (14.6 m across) but not
  // around block 7's 5 m strips (9.2 m across).
  updated.setMetresPerPixel(2.0);
  EXPECT_EQ(updated.outlinedShapes(), 39u * 3u);
  MapLayer fresh;
  fresh.setScale(scale);
  fresh.setMetresPerPixel(2.0);
  fresh.setShapes(recoloured.shapes, recoloured.values, recoloured.blocks);
  EXPECT_EQ(fresh.outlinedShapes(), 39u * 3u);
  const Box extent{0, 0, 1200, 60};
  const auto a = draw(updated, extent), b = draw(fresh, extent);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_TRUE(a == b) << "an updated layer draws other pixels than a fresh one";
  // And not what the first shapes drew.
  MapLayer old;
  old.setScale(scale);
  old.setMetresPerPixel(2.0);
  old.setShapes(first.shapes, first.values, first.blocks);
  EXPECT_FALSE(draw(old, extent) == a);
}

// Squares of 20 m in a row whose shared sides carry 9 points each, up to 0.3 m
// off the straight side: drawn with fewer points when a pixel is metres wide,
// with every point again when zoomed in, and alike however the scale was reached.
TEST(MapLayer, DrawsFewerPointsAtCoarseScalesAndEveryPointZoomedIn) {
  std::vector<Polygon> squares(4);
  for (std::size_t i = 0; i < squares.size(); ++i) {
    const double x0 = 20.0 * static_cast<double>(i), x1 = x0 + 20;
    Ring& r = squares[i].outer;
    r.push_back({x0, 0});
    r.push_back({x1, 0});
    for (int k = 1; k <= 9; ++k) r.push_back({x1 + 0.3 * std::sin(k * (static_cast<double>(i) + 1)), 2.0 * k});
    r.push_back({x1, 20});
    r.push_back({x0, 20});
    if (i > 0) {  // the left neighbour's right side, run downwards
      for (int k = 9; k >= 1; --k) r.push_back({x0 + 0.3 * std::sin(k * static_cast<double>(i)), 2.0 * k});
    }
  }
  std::vector<const Polygon*> shapes;
  std::size_t total = 0;
  for (const Polygon& s : squares) {
    shapes.push_back(&s);
    total += s.outer.size();
  }
  const std::vector<double> values(shapes.size(), 1.0);
  const std::vector<int> blocks(shapes.size(), 0);  // one group: the sides are shared
  MapLayer layer;
  layer.setShapes(shapes, values, blocks);
  EXPECT_EQ(layer.pointsDrawn(), total);
  layer.setMetresPerPixel(8.0);  // 4 m: the squares' corners only
  EXPECT_EQ(layer.pointsDrawn(), 4u * shapes.size());
  layer.setMetresPerPixel(0.01);
  EXPECT_EQ(layer.pointsDrawn(), total);
  layer.setMetresPerPixel(8.0);
  MapLayer fresh;
  fresh.setMetresPerPixel(8.0);
  fresh.setShapes(shapes, values, blocks);
  EXPECT_EQ(fresh.pointsDrawn(), layer.pointsDrawn());
  const Box extent{0, 0, 80, 20};
  EXPECT_TRUE(draw(layer, extent) == draw(fresh, extent));
}

TEST(RenderMaps, RefusesMismatchedValuesAndEmptyMaps) {
  TempDir dir;
  const Polygon square = rect(0, 0, 1, 1);
  ColourScale scale;
  EXPECT_THROW(renderMaps("x", {MapPanel{"p", {&square}, {}}}, scale, output(dir, "a", 400, 300)), Error);
  EXPECT_THROW(renderMaps("x", {MapPanel{"p", {}, {}}}, scale, output(dir, "b", 400, 300)), Error);
  EXPECT_THROW(renderMaps("x", {MapPanel{"p", {&square}, {1}}}, scale, output(dir, "c", 50, 50)), Error);
}

TEST(RenderHistogram, OverlaidSeriesInTheirColoursWithTextInTheSvg) {
  TempDir dir;
  FigureOutput out = output(dir, "hist", 900, 500);
  out.vector = dir.file("hist.svg");
  renderHistogram("Parcel area", "area (m\xc2\xb2)", "parcels (count)", {0, 100, 200, 300},
                  {{"observed", {5, 10, 2}, {0.84, 0.15, 0.16}}, {"procedural", {3, 12, 4}, {0.12, 0.38, 0.75}}}, out);
  const test::Image image = test::readPng(out.png);
  ASSERT_EQ(image.width, 900);
  ASSERT_EQ(image.height, 500);
  const test::Ink ink = test::ink(image);
  EXPECT_GT(ink.share, 0.05);
  EXPECT_GT(ink.colours, 20u);
  bool sawRed = false, sawBlue = false;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const std::uint32_t c = image.rgb(x, y);
      sawRed = sawRed || (red(c) > 180 && green(c) < 90 && blue(c) < 90);
      sawBlue = sawBlue || (blue(c) > 150 && red(c) < 80 && green(c) < 130);
    }
  }
  EXPECT_TRUE(sawRed);
  EXPECT_TRUE(sawBlue);
  std::stringstream svg;
  svg << std::ifstream(out.vector).rdbuf();
  for (const char* text : {"Parcel area", "parcels (count)", "observed", "procedural"}) {
    EXPECT_NE(svg.str().find(text), std::string::npos) << text;
  }
  EXPECT_THROW(renderHistogram("x", "x", "y", {0, 1, 2}, {{"bad", {1}, {}}}, out), Error);
  // Texts holding XML's special characters (an input named "R&D <b>.geojson")
  // are escaped: the title and the chart's text keep the file well formed.
  renderHistogram("Parcel area, R&D <b>.geojson", "area", "parcels (count)", {0, 100, 200},
                  {{"observed", {5, 10}, {0.84, 0.15, 0.16}}}, out);
  std::stringstream escaped;
  escaped << std::ifstream(out.vector).rdbuf();
  EXPECT_EQ(escaped.str().find("R&D"), std::string::npos);
  EXPECT_EQ(escaped.str().find("<b>"), std::string::npos);
  EXPECT_NE(escaped.str().find("<title>Parcel area, R&amp;D &lt;b&gt;.geojson</title>"), std::string::npos);
  EXPECT_NE(escaped.str().find(">Parcel area, R&amp;D &lt;b&gt;.geojson</text>"), std::string::npos);
}

// The band of the title (the top `share` of the image): no ink in the columns
// at either border or in the top row (text cut off there), and ink spanning
// most of the width (the title is there, in a legible size).
void expectTitleInside(const test::Image& image, double share, const std::string& what) {
  ASSERT_GT(image.width, 0) << what;
  const auto inked = [&](int x, int y) {
    const std::uint32_t c = image.rgb(x, y);
    return red(c) < 230 || green(c) < 230 || blue(c) < 230;
  };
  const int rows = static_cast<int>(share * image.height);
  int left = image.width, right = -1, touching = 0;
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < image.width; ++x) {
      if (!inked(x, y)) continue;
      left = std::min(left, x);
      right = std::max(right, x);
      touching += x <= 1 || x >= image.width - 2 || y == 0;
    }
  }
  EXPECT_EQ(touching, 0) << what << ": the title touches the border (cut off); its ink runs from x = " << left << " to "
                         << right << " of " << image.width;
  EXPECT_GT(right - left, image.width / 2) << what << ": the title is missing or tiny";
}

const std::string kLongTitle =
    "Parcel area: observed and procedural (skeleton, seed 12345, 3 blocks overridden), "
    "ASSESSING_ParcelsFY2014_with_a_long_file_name.topojson";

TEST(RenderHistogram, LongTitlesFitTheFigureWidth) {
  TempDir dir;
  for (const auto& [width, height] : {std::pair{600, 300}, {800, 600}, {1800, 900}}) {
    const FigureOutput out = output(dir, "hist" + std::to_string(width), width, height);
    renderHistogram(kLongTitle, "area (m\xc2\xb2)", "parcels (count)", {0, 100, 200, 300},
                    {{"observed", {5, 10, 2}, {0.84, 0.15, 0.16}}, {"procedural", {3, 12, 4}, {0.12, 0.38, 0.75}}},
                    out);
    // The title band: above the plot, whose top is below 12 % of the height at these sizes.
    expectTitleInside(test::readPng(out.png), 0.06, out.png);
  }
}

TEST(RenderMaps, LongTitlesFitTheFigureWidth) {
  TempDir dir;
  const Polygon a = rect(0, 0, 100, 60), b = rect(120, 0, 200, 60);
  MapPanel panel{"10 blocks (10 with parcels on both sides)", {&a, &b}, {0.2, 0.7}};
  ColourScale scale;
  scale.kind = ColourScale::Kind::Sequential;
  scale.title = "KS statistic of parcel area (0: same distribution, 1: disjoint)";
  for (const auto& [width, height] : {std::pair{600, 300}, {800, 600}, {1800, 900}}) {
    const FigureOutput out = output(dir, "blocks" + std::to_string(width), width, height);
    renderMaps("Per-block difference in " + kLongTitle, {panel}, scale, out);
    // The title band is the top 13 %; its upper part holds the figure's title.
    expectTitleInside(test::readPng(out.png), 0.08, out.png);
  }
}

}  // namespace
}  // namespace parcelscope::viz
