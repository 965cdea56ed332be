// The maps as vector figures: every shape a path of its own, in its colour,
// in an SVG and a PDF a reader can open (the PDF's cross-reference table and
// compressed drawing checked byte by byte). No display needed.
#include <gtest/gtest.h>
#include <zlib.h>

#include <fstream>
#include <regex>
#include <sstream>

#include "Pdf.h"
#include "TestUtil.h"
#include "parcelscope/core/Error.h"
#include "parcelscope/viz/Figures.h"

namespace parcelscope::viz {
namespace {

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + what.size())) ++n;
  return n;
}

std::string hex(const Rgb& c) {
  char buf[8];
  auto byte = [](double v) { return static_cast<int>(std::lround(std::clamp(v, 0.0, 1.0) * 255)); };
  std::snprintf(buf, sizeof buf, "#%02x%02x%02x", byte(c.r), byte(c.g), byte(c.b));
  return buf;
}

struct Maps {
  std::vector<Polygon> shapes;
  std::vector<MapPanel> panels;
  ColourScale scale;
  Maps() {
    shapes = {test::rect(0, 0, 40, 20), test::rect(40, 0, 80, 20), test::rect(0, 0, 80, 30)};
    shapes[2].holes.push_back({{10, 10}, {10, 20}, {30, 20}, {30, 10}});  // a courtyard
    MapPanel observed, generated;
    observed.title = "Observed: 2 parcels";
    observed.shapes = {&shapes[0], &shapes[1]};
    observed.values = {1.0, 4.0};
    generated.title = "Procedural (obb): 1 parcel";
    generated.shapes = {&shapes[2]};
    generated.values = {std::nan("")};
    panels = {observed, generated};
    scale.minimum = 1;
    scale.maximum = 5;
    scale.title = "Aspect ratio (length / width), m\u00b2 & <more>";
  }
};

constexpr int kColourBarSteps = 128;

TEST(VectorMaps, SvgHasOnePathPerShapeInItsColour) {
  const Maps m;
  test::TempDir dir;
  const std::string path = dir.file("map.svg");
  writeVectorMaps("Parcel aspect ratio", m.panels, m.scale, 1800, 900, path);
  const std::string svg = slurp(path);
  ASSERT_EQ(svg.rfind("<svg", 0), 0u);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  // Three shapes, the colour bar's steps and the no-value swatch (one value is NaN).
  EXPECT_EQ(count(svg, "<path"), 3u + kColourBarSteps + 1);
  const std::vector<Rgb> colours = scaleColours(m.scale, {1.0, 4.0, std::nan("")});
  // The courtyard is a second ring of the same path, filled even-odd.
  const std::regex shape(
      R"re(<path fill-rule="evenodd" fill="(#[0-9a-f]{6})" stroke="[^"]*" stroke-width="1"[^>]* d="([^"]*)"/>)re");
  std::vector<std::pair<std::string, std::string>> outlined;
  for (std::sregex_iterator it(svg.begin(), svg.end(), shape), end; it != end; ++it) {
    outlined.emplace_back((*it)[1], (*it)[2]);
  }
  ASSERT_EQ(outlined.size(), 3u);
  for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(outlined[k].first, hex(colours[k])) << "shape " << k;
  EXPECT_EQ(count(outlined[2].second, "M"), 2u);
  EXPECT_EQ(count(outlined[0].second, "M"), 1u);
  // Texts escaped, as text.
  EXPECT_NE(svg.find(">Parcel aspect ratio</text>"), std::string::npos);
  EXPECT_NE(svg.find("m\u00b2 &amp; &lt;more&gt;</text>"), std::string::npos);
  EXPECT_NE(svg.find(">no value</text>"), std::string::npos);
}

TEST(VectorMaps, PdfIsWellFormedWithOnePathPerShape) {
  const Maps m;
  test::TempDir dir;
  const std::string path = dir.file("map.pdf");
  writeVectorMaps("Parcel aspect ratio", m.panels, m.scale, 1800, 900, path);
  const std::string pdf = slurp(path);
  ASSERT_EQ(pdf.rfind("%PDF-1.4\n", 0), 0u);
  // The cross-reference table points at each object.
  const std::size_t startxref = pdf.rfind("startxref\n");
  ASSERT_NE(startxref, std::string::npos);
  const std::size_t xref = std::stoul(pdf.substr(startxref + 10));
  ASSERT_EQ(pdf.compare(xref, 5, "xref\n"), 0);
  std::istringstream table(pdf.substr(xref + 5));
  int first = 0, objects = 0;
  table >> first >> objects;
  ASSERT_EQ(objects, 7);
  std::string offset, generation, kind;
  table >> offset >> generation >> kind;  // the free entry
  for (int i = 1; i < objects; ++i) {
    table >> offset >> generation >> kind;
    EXPECT_EQ(pdf.compare(std::stoul(offset), std::to_string(i).size() + 6, std::to_string(i) + " 0 obj"), 0)
        << "object " << i;
  }
  EXPECT_NE(pdf.find("/MediaBox [0 0 900 450]"), std::string::npos);
  // The drawing: Flate-compressed, one filled path per shape and colour-bar step.
  const std::size_t lengthAt = pdf.find("/Length ");
  ASSERT_NE(lengthAt, std::string::npos);
  const std::size_t length = std::stoul(pdf.substr(lengthAt + 8));
  const std::size_t streamAt = pdf.find("stream\n", lengthAt) + 7;
  std::string drawing(1 << 20, '\0');
  uLongf size = drawing.size();
  ASSERT_EQ(uncompress(reinterpret_cast<Bytef*>(drawing.data()), &size,
                       reinterpret_cast<const Bytef*>(pdf.data() + streamAt), length),
            Z_OK);
  drawing.resize(size);
  EXPECT_EQ(count(drawing, "B*\n"), 3u);                             // outlined shapes
  EXPECT_EQ(count(drawing, "f*\n"), kColourBarSteps + 1u);           // colour bar and no-value swatch
  EXPECT_EQ(count(drawing, "h\n"), 3u + 1u + kColourBarSteps + 1u);  // rings: the courtyard is one more
  EXPECT_NE(drawing.find("(no value) Tj"), std::string::npos);
  EXPECT_NE(drawing.find("m\xb2 & <more>) Tj"), std::string::npos);  // WinAnsi superscript two
}

TEST(VectorMaps, RefusesWhatItCannotDraw) {
  const Maps m;
  test::TempDir dir;
  EXPECT_THROW(writeVectorMaps("t", m.panels, m.scale, 1800, 900, dir.file("map.eps")), Error);
  MapPanel empty;
  EXPECT_THROW(writeVectorMaps("t", {empty}, m.scale, 1800, 900, dir.file("map.svg")), Error);
  MapPanel mismatched = m.panels[0];
  mismatched.values.pop_back();
  EXPECT_THROW(writeVectorMaps("t", {mismatched}, m.scale, 1800, 900, dir.file("map.svg")), Error);
}

// GL2PS's PDF (as Debian builds it) holds its streams uncompressed: the
// rewrite deflates them and keeps every object findable.
TEST(VectorMaps, PdfStreamsAreCompressedInPlace) {
  test::TempDir dir;
  const std::string image(100000, '\xff');  // a white raster
  std::vector<std::string> objects = {"<< /Type /Catalog /Pages 2 0 R >>", "<< /Type /Pages /Kids [] /Count 0 >>",
                                      "<< /Type /XObject /Subtype /Image /Length " + std::to_string(image.size()) +
                                          " >>\nstream\n" + image + "\nendstream",
                                      "<< /Length 5 0 R >>\nstream\nq Q\nendstream", "3"};
  std::string pdf = "%PDF-1.4\n";
  std::vector<std::size_t> offsets;
  for (std::size_t i = 0; i < objects.size(); ++i) {
    offsets.push_back(pdf.size());
    pdf += std::to_string(i + 1) + " 0 obj\n" + objects[i] + "\nendobj\n";
  }
  const std::size_t xref = pdf.size();
  pdf += "xref\n0 6\n0000000000 65535 f \n";
  for (std::size_t o : offsets) {
    char entry[24];
    std::snprintf(entry, sizeof entry, "%010zu 00000 n \n", o);
    pdf += entry;
  }
  pdf += "trailer\n<< /Size 6 /Root 1 0 R >>\nstartxref\n" + std::to_string(xref) + "\n%%EOF\n";
  const std::string path = dir.write("chart.pdf", pdf);

  EXPECT_EQ(detail::compressPdfStreams(path), 1);  // the image; not the stream whose length is an object
  const std::string out = slurp(path);
  EXPECT_LT(out.size(), 2000u);
  const std::size_t startxref = out.rfind("startxref\n");
  const std::size_t table = std::stoul(out.substr(startxref + 10));
  ASSERT_EQ(out.compare(table, 9, "xref\n0 6\n"), 0);
  std::istringstream entries(out.substr(table + 9));
  std::string offset, generation, kind;
  entries >> offset >> generation >> kind;
  for (int i = 1; i <= 5; ++i) {
    entries >> offset >> generation >> kind;
    EXPECT_EQ(out.compare(std::stoul(offset), 7, std::to_string(i) + " 0 obj"), 0) << "object " << i;
  }
  const std::size_t lengthAt = out.find("/Length ", out.find("/Subtype /Image"));
  ASSERT_NE(out.find("/Filter /FlateDecode", lengthAt), std::string::npos);
  const std::size_t length = std::stoul(out.substr(lengthAt + 8));
  const std::size_t data = out.find("stream\n", lengthAt) + 7;
  std::string raw(image.size() + 16, '\0');
  uLongf size = raw.size();
  ASSERT_EQ(uncompress(reinterpret_cast<Bytef*>(raw.data()), &size, reinterpret_cast<const Bytef*>(out.data() + data),
                       length),
            Z_OK);
  raw.resize(size);
  EXPECT_EQ(raw, image);
  EXPECT_NE(out.find("<< /Length 5 0 R >>\nstream\nq Q\nendstream"), std::string::npos);
}

}  // namespace
}  // namespace parcelscope::viz
