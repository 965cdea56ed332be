// The side-by-side maps as vector figures (SVG, PDF), written directly: VTK
// 9.1's GL2PS export rasterises polygons, and a paper figure must zoom. The
// layout follows renderMaps (Figures.cpp): title band on top, the panels with
// their titles and scale bars, the colour bar below.
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <memory>
#include <regex>
#include <sstream>

#include "Pdf.h"
#include "parcelscope/core/Error.h"
#include "parcelscope/viz/Figures.h"

namespace parcelscope::viz {

namespace {

using Path = std::vector<std::vector<Point>>;  // rings in page coordinates (px, y down)

enum class Anchor { Start, Middle, End };

// What a figure is drawn with; page coordinates in pixels, y down.
class Canvas {
public:
  virtual ~Canvas() = default;
  virtual void fill(const Path& rings, const Rgb& colour, const Rgb* outline, double outlineWidth) = 0;
  virtual void line(const std::vector<Point>& points, const Rgb& colour, double width) = 0;
  virtual void text(double x, double y, const std::string& utf8, double size, Anchor anchor, bool bold) = 0;
  virtual void save(const std::string& path) = 0;
};

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", v);
  std::string s = buf;
  while (!s.empty() && s.back() == '0') s.pop_back();
  if (!s.empty() && s.back() == '.') s.pop_back();
  return s == "-0" ? "0" : s;
}

std::string hex(const Rgb& c) {
  char buf[8];
  auto byte = [](double v) { return static_cast<int>(std::lround(std::clamp(v, 0.0, 1.0) * 255)); };
  std::snprintf(buf, sizeof buf, "#%02x%02x%02x", byte(c.r), byte(c.g), byte(c.b));
  return buf;
}

void writeFile(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) throw ioError(path + ": cannot write");
}

class SvgCanvas : public Canvas {
public:
  SvgCanvas(int width, int height) {
    body_ << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\"" << height
          << "\" viewBox=\"0 0 " << width << ' ' << height << "\" font-family=\"Arial, Helvetica, sans-serif\">\n"
          << "<rect width=\"100%\" height=\"100%\" fill=\"#ffffff\"/>\n";
  }
  void fill(const Path& rings, const Rgb& colour, const Rgb* outline, double outlineWidth) override {
    body_ << "<path fill-rule=\"evenodd\" fill=\"" << hex(colour) << '"';
    if (outline) {
      body_ << " stroke=\"" << hex(*outline) << "\" stroke-width=\"" << number(outlineWidth)
            << "\" stroke-linejoin=\"round\"";
    }
    body_ << " d=\"";
    for (const auto& ring : rings) {
      for (std::size_t i = 0; i < ring.size(); ++i) {
        body_ << (i ? 'L' : 'M') << number(ring[i].x) << ' ' << number(ring[i].y);
      }
      body_ << 'Z';
    }
    body_ << "\"/>\n";
  }
  void line(const std::vector<Point>& points, const Rgb& colour, double width) override {
    body_ << "<polyline fill=\"none\" stroke=\"" << hex(colour) << "\" stroke-width=\"" << number(width)
          << "\" points=\"";
    for (const Point& p : points) body_ << number(p.x) << ',' << number(p.y) << ' ';
    body_ << "\"/>\n";
  }
  void text(double x, double y, const std::string& utf8, double size, Anchor anchor, bool bold) override {
    body_ << "<text x=\"" << number(x) << "\" y=\"" << number(y) << "\" font-size=\"" << number(size) << '"'
          << " text-anchor=\""
          << (anchor == Anchor::Start    ? "start"
              : anchor == Anchor::Middle ? "middle"
                                         : "end")
          << '"' << (bold ? " font-weight=\"bold\"" : "") << '>';
    std::string escaped;
    detail::appendXmlText(escaped, utf8);
    body_ << escaped << "</text>\n";
  }
  void save(const std::string& path) override { writeFile(path, body_.str() + "</svg>\n"); }

private:
  std::ostringstream body_;
};

// PDF 1.4 with one page, the drawing in one Flate-compressed content stream,
// texts in the standard Helvetica fonts (WinAnsi encoding).
class PdfCanvas : public Canvas {
public:
  PdfCanvas(int width, int height) : width_(width), height_(height) {
    // Pixels to points at 2 px per point, y flipped to PDF's upward axis.
    content_ << kScale << " 0 0 " << -kScale << " 0 " << number(height * kScale) << " cm 1 J 1 j\n";
  }
  void fill(const Path& rings, const Rgb& colour, const Rgb* outline, double outlineWidth) override {
    content_ << rgb(colour) << " rg\n";
    if (outline) content_ << rgb(*outline) << " RG " << number(outlineWidth) << " w\n";
    for (const auto& ring : rings) {
      for (std::size_t i = 0; i < ring.size(); ++i) {
        content_ << number(ring[i].x) << ' ' << number(ring[i].y) << (i ? " l\n" : " m\n");
      }
      content_ << "h\n";
    }
    content_ << (outline ? "B*\n" : "f*\n");
  }
  void line(const std::vector<Point>& points, const Rgb& colour, double width) override {
    content_ << rgb(colour) << " RG " << number(width) << " w\n";
    for (std::size_t i = 0; i < points.size(); ++i) {
      content_ << number(points[i].x) << ' ' << number(points[i].y) << (i ? " l\n" : " m\n");
    }
    content_ << "S\n";
  }
  void text(double x, double y, const std::string& utf8, double size, Anchor anchor, bool bold) override {
    const std::string s = winAnsi(utf8);
    const double w = advance(s, bold) * size;
    const double left = anchor == Anchor::Start ? x : anchor == Anchor::Middle ? x - 0.5 * w : x - w;
    content_ << "BT /" << (bold ? "F2 " : "F1 ") << number(size) << " Tf 0 g 1 0 0 -1 " << number(left) << ' '
             << number(y) << " Tm (";
    for (char c : s) {
      if (c == '(' || c == ')' || c == '\\') content_ << '\\';
      content_ << c;
    }
    content_ << ") Tj ET\n";
  }
  void save(const std::string& path) override {
    const std::string raw = content_.str();
    uLongf size = compressBound(static_cast<uLong>(raw.size()));
    std::string packed(size, '\0');
    if (compress2(reinterpret_cast<Bytef*>(packed.data()), &size, reinterpret_cast<const Bytef*>(raw.data()),
                  static_cast<uLong>(raw.size()), Z_BEST_COMPRESSION) != Z_OK) {
      throw ioError(path + ": cannot compress the PDF drawing");
    }
    packed.resize(size);
    std::vector<std::string> objects = {
        "<< /Type /Catalog /Pages 2 0 R >>",
        "<< /Type /Pages /Kids [3 0 R] /Count 1 >>",
        "<< /Type /Page /Parent 2 0 R /MediaBox [0 0 " + number(width_ * kScale) + ' ' + number(height_ * kScale) +
            "] /Resources << /Font << /F1 5 0 R /F2 6 0 R >> >> /Contents 4 0 R >>",
        "<< /Length " + std::to_string(packed.size()) + " /Filter /FlateDecode >>\nstream\n" + packed + "\nendstream",
        "<< /Type /Font /Subtype /Type1 /BaseFont /Helvetica /Encoding /WinAnsiEncoding >>",
        "<< /Type /Font /Subtype /Type1 /BaseFont /Helvetica-Bold /Encoding /WinAnsiEncoding >>"};
    std::string file = "%PDF-1.4\n%\xe2\xe3\xcf\xd3\n";
    std::vector<std::size_t> offsets;
    for (std::size_t i = 0; i < objects.size(); ++i) {
      offsets.push_back(file.size());
      file += std::to_string(i + 1) + " 0 obj\n" + objects[i] + "\nendobj\n";
    }
    const std::size_t xref = file.size();
    file += "xref\n0 " + std::to_string(objects.size() + 1) + "\n0000000000 65535 f \n";
    for (std::size_t o : offsets) {
      char entry[24];
      std::snprintf(entry, sizeof entry, "%010zu 00000 n \n", o);
      file += entry;
    }
    file += "trailer\n<< /Size " + std::to_string(objects.size() + 1) + " /Root 1 0 R >>\nstartxref\n" +
            std::to_string(xref) + "\n%%EOF\n";
    writeFile(path, file);
  }

private:
  static constexpr double kScale = 0.5;  // points per pixel

  static std::string rgb(const Rgb& c) {
    return number(std::clamp(c.r, 0.0, 1.0)) + ' ' + number(std::clamp(c.g, 0.0, 1.0)) + ' ' +
           number(std::clamp(c.b, 0.0, 1.0));
  }
  // Width of `s` in em: the advances of the standard Helvetica and
  // Helvetica-Bold (Adobe's AFM files) for printable ASCII, 0.556 for others.
  static double advance(const std::string& s, bool bold) {
    static constexpr short kRegular[95] = {
        278, 278, 355, 556, 556, 889, 667, 191, 333, 333, 389, 584, 278, 333,  278, 278, 556, 556, 556,
        556, 556, 556, 556, 556, 556, 556, 278, 278, 584, 584, 584, 556, 1015, 667, 667, 722, 722, 667,
        611, 778, 722, 278, 500, 667, 556, 833, 722, 778, 667, 778, 722, 667,  611, 722, 667, 944, 667,
        667, 611, 278, 278, 278, 469, 556, 333, 556, 556, 500, 556, 556, 278,  556, 556, 222, 222, 500,
        222, 833, 556, 556, 556, 556, 333, 500, 278, 556, 500, 722, 500, 500,  500, 334, 260, 334, 584};
    static constexpr short kBold[95] = {278, 333, 474, 556, 556, 889, 722, 238, 333, 333, 389, 584, 278, 333, 278, 278,
                                        556, 556, 556, 556, 556, 556, 556, 556, 556, 556, 333, 333, 584, 584, 584, 611,
                                        975, 722, 722, 722, 722, 667, 611, 778, 722, 278, 556, 722, 611, 833, 722, 778,
                                        667, 778, 722, 667, 611, 722, 667, 944, 667, 667, 611, 333, 278, 333, 584, 556,
                                        333, 556, 611, 556, 611, 556, 333, 611, 611, 278, 278, 556, 278, 889, 611, 611,
                                        611, 611, 389, 556, 333, 611, 556, 778, 556, 556, 500, 389, 280, 389, 584};
    double total = 0;
    for (char ch : s) {
      const auto c = static_cast<unsigned char>(ch);
      total += c >= 32 && c < 127 ? (bold ? kBold : kRegular)[c - 32] : 556;
    }
    return total / 1000.0;
  }

  // UTF-8 to WinAnsi: Latin-1 letters and signs (², é, ...) kept, others '?'.
  static std::string winAnsi(const std::string& utf8) {
    std::string out;
    for (std::size_t i = 0; i < utf8.size(); ++i) {
      const auto c = static_cast<unsigned char>(utf8[i]);
      if (c < 0x80) {
        out += static_cast<char>(c);
      } else if ((c & 0xE0) == 0xC0 && i + 1 < utf8.size()) {
        const unsigned code = ((c & 0x1Fu) << 6) | (static_cast<unsigned char>(utf8[++i]) & 0x3Fu);
        out += code >= 0xA0 && code <= 0xFF ? static_cast<char>(code) : '?';
      } else {
        while (i + 1 < utf8.size() && (static_cast<unsigned char>(utf8[i + 1]) & 0xC0) == 0x80) ++i;
        out += '?';
      }
    }
    return out;
  }

  int width_, height_;
  std::ostringstream content_;
};

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

void draw(Canvas& c, const std::string& title, const std::vector<MapPanel>& panels, const ColourScale& scale, int width,
          int height) {
  Box extent{std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
             std::numeric_limits<double>::lowest(), std::numeric_limits<double>::lowest()};
  bool anyNaN = false;
  for (const MapPanel& p : panels) {
    for (const Polygon* s : p.shapes) {
      const Box b = bounds(*s);
      extent = {std::min(extent.minX, b.minX), std::min(extent.minY, b.minY), std::max(extent.maxX, b.maxX),
                std::max(extent.maxY, b.maxY)};
    }
    for (double v : p.values) anyNaN = anyNaN || std::isnan(v);
  }
  const double W = width, H = height;
  // Bands as renderMaps: title above 87 % of the height (from the bottom), colour bar below 15 %.
  const double barTop = 0.15, titleBottom = 0.87;
  const int n = static_cast<int>(panels.size());
  const double panelW = W / n, panelH = H * (titleBottom - barTop);
  const double panelAspect = panelW / panelH;
  const double margin = 0.03 * std::max(extent.width(), extent.height());
  const double halfHeight = std::max(0.5 * extent.height() + margin, (0.5 * extent.width() + margin) / panelAspect);
  const double cx = 0.5 * (extent.minX + extent.maxX), cy = 0.5 * (extent.minY + extent.maxY);
  const double pxPerMetre = panelH / (2 * halfHeight);
  const double panelTop = H * (1 - titleBottom);

  c.text(0.5 * W, panelTop * 0.55, title, std::max(8.0, std::round(H * 0.034)), Anchor::Middle, true);
  const Rgb grey{0.45, 0.45, 0.45}, black{0, 0, 0};
  for (int i = 0; i < n; ++i) {
    const MapPanel& p = panels[static_cast<std::size_t>(i)];
    const double ox = (i + 0.5) * panelW, oy = panelTop + 0.5 * panelH;
    auto page = [&](const Point& q) { return Point{ox + (q.x - cx) * pxPerMetre, oy - (q.y - cy) * pxPerMetre}; };
    c.text(ox, panelTop * 0.92, p.title, std::max(8.0, std::round(H * 0.026)), Anchor::Middle, false);
    const std::vector<Rgb> colours = scaleColours(scale, p.values);
    for (std::size_t k = 0; k < p.shapes.size(); ++k) {
      const Polygon& s = *p.shapes[k];
      Path rings;
      rings.emplace_back();
      for (const Point& q : s.outer) rings.back().push_back(page(q));
      for (const Ring& h : s.holes) {
        rings.emplace_back();
        for (const Point& q : h) rings.back().push_back(page(q));
      }
      // Shapes too small to show an outline are drawn without one (as the PNG).
      const bool outlined = outlineSize(s) * pxPerMetre >= kMinOutlinedPixels;
      c.fill(rings, colours[k], outlined ? &grey : nullptr, 1.0);
    }
    // Scale bar: a quarter of the panel's width, rounded, at its lower left.
    const double visibleW = 2 * halfHeight * panelAspect;
    const double length = roundLength(0.25 * visibleW);
    const double x0 = ox - 0.5 * panelW + 0.04 * panelW, y0 = panelTop + panelH - 0.04 * panelH;
    const double tick = 0.012 * panelH, len = length * pxPerMetre;
    c.line({{x0, y0 - tick}, {x0, y0}, {x0 + len, y0}, {x0 + len, y0 - tick}}, black, 3.0);
    c.text(x0 + 0.5 * len, y0 - 1.5 * tick, lengthLabel(length), std::max(8.0, std::round(H * 0.022)), Anchor::Middle,
           false);
  }

  // Colour bar: 128 steps from the minimum to the maximum, six labels, the title above.
  const double band = barTop * H, bandTop = H - band;
  const double barLeft = 0.2 * W, barWidth = 0.6 * W;
  const double barUpper = bandTop + 0.38 * band, barLower = bandTop + 0.65 * band, barHeight = barLower - barUpper;
  const double labelSize = std::max(8.0, std::round(H * 0.02));
  c.text(0.5 * W, bandTop + 0.27 * band, scale.title, std::max(8.0, std::round(H * 0.024)), Anchor::Middle, false);
  constexpr int kSteps = 128;
  std::vector<double> steps;
  for (int k = 0; k < kSteps; ++k)
    steps.push_back(scale.minimum + (scale.maximum - scale.minimum) * (k + 0.5) / kSteps);
  const std::vector<Rgb> stepColours = scaleColours(scale, steps);
  for (int k = 0; k < kSteps; ++k) {
    const double x = barLeft + barWidth * k / kSteps, w = barWidth / kSteps + 0.5;  // overlap: no hairline seams
    c.fill({{{x, barUpper}, {x + w, barUpper}, {x + w, barLower}, {x, barLower}}},
           stepColours[static_cast<std::size_t>(k)], nullptr, 0);
  }
  for (int k = 0; k < 6; ++k) {
    char label[32];
    std::snprintf(label, sizeof label, "%.3g", scale.minimum + (scale.maximum - scale.minimum) * k / 5.0);
    c.text(barLeft + barWidth * k / 5.0, barLower + labelSize * 1.2, label, labelSize, Anchor::Middle, false);
  }
  if (anyNaN) {
    const Rgb none = scaleColours(scale, {std::nan("")}).front();
    const double x = barLeft + barWidth + 0.03 * W;
    c.fill({{{x, barUpper}, {x + barHeight, barUpper}, {x + barHeight, barLower}, {x, barLower}}}, none, nullptr, 0);
    c.text(x + barHeight * 1.3, barLower - 0.2 * barHeight, "no value", labelSize, Anchor::Start, false);
  }
}

}  // namespace

void writeVectorMaps(const std::string& title, const std::vector<MapPanel>& panels, const ColourScale& scale, int width,
                     int height, const std::string& path) {
  std::unique_ptr<Canvas> canvas;
  const std::string extension = path.size() >= 4 ? path.substr(path.size() - 4) : "";
  if (extension == ".svg") {
    canvas = std::make_unique<SvgCanvas>(width, height);
  } else if (extension == ".pdf") {
    canvas = std::make_unique<PdfCanvas>(width, height);
  } else {
    throw usageError(path + ": a vector map is written as .svg or .pdf");
  }
  bool any = false;
  for (const MapPanel& p : panels) {
    if (p.values.size() != p.shapes.size()) {
      throw usageError(path + ": panel '" + p.title + "' has " + std::to_string(p.shapes.size()) + " shapes but " +
                       std::to_string(p.values.size()) + " values");
    }
    any = any || !p.shapes.empty();
  }
  if (!any) throw usageError(path + ": no shape to draw");
  draw(*canvas, title, panels, scale, width, height);
  canvas->save(path);
}

namespace detail {

namespace {
std::string deflate(const std::string& raw, const std::string& path) {
  uLongf size = compressBound(static_cast<uLong>(raw.size()));
  std::string packed(size, '\0');
  if (compress2(reinterpret_cast<Bytef*>(packed.data()), &size, reinterpret_cast<const Bytef*>(raw.data()),
                static_cast<uLong>(raw.size()), Z_BEST_COMPRESSION) != Z_OK) {
    throw ioError(path + ": cannot compress a PDF stream");
  }
  packed.resize(size);
  return packed;
}
}  // namespace

void appendXmlText(std::string& out, const std::string& text) {
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      default:
        out += c;
    }
  }
}

void escapeSvgTexts(const std::string& path) {
  std::string svg;
  {
    std::ifstream in(path, std::ios::binary);
    svg.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  std::string out;
  out.reserve(svg.size());
  std::size_t at = 0;
  while (at < svg.size()) {
    // The next <title> or <text>, its content from the end of its opening tag.
    const std::size_t title = svg.find("<title", at), text = svg.find("<text", at);
    const std::size_t open = std::min(title, text);
    const char* closing = open == title ? "</title>" : "</text>";
    const std::size_t start = open == std::string::npos ? std::string::npos : svg.find('>', open);
    const std::size_t end = start == std::string::npos ? std::string::npos : svg.find(closing, start);
    if (end == std::string::npos) break;
    out.append(svg, at, start + 1 - at);
    appendXmlText(out, svg.substr(start + 1, end - start - 1));
    at = end;
  }
  out.append(svg, at, std::string::npos);
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  file << out;
  file.close();
  if (!file) throw ioError(path + ": cannot write vector figure");
}

int compressPdfStreams(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ioError(path + ": cannot read");
  const std::string pdf((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto malformed = [&](const std::string& what) {
    return ioError(path + ": not a PDF this can rewrite (" + what + ")");
  };
  const std::size_t xref = pdf.rfind("\nxref\n");
  const std::size_t trailer = pdf.find("trailer", xref == std::string::npos ? 0 : xref);
  if (pdf.rfind("%PDF-", 0) != 0 || xref == std::string::npos || trailer == std::string::npos) {
    throw malformed("no header, cross-reference table or trailer");
  }
  // Objects before the table, copied with their uncompressed streams deflated.
  std::string out;
  int compressed = 0;
  std::size_t at = 0;
  const std::regex length(R"(/Length (\d+)(?! \d+ R))");
  for (;;) {
    const std::size_t stream = pdf.find("stream\n", at);
    if (stream == std::string::npos || stream > xref) break;
    if (stream >= 3 && pdf.compare(stream - 3, 3, "end") == 0) {  // "endstream\n"
      out.append(pdf, at, stream + 7 - at);
      at = stream + 7;
      continue;
    }
    const std::size_t object = pdf.rfind(" obj", stream);
    if (object == std::string::npos || object < at) throw malformed("a stream outside an object");
    const std::string dictionary = pdf.substr(object, stream - object);
    std::smatch m;
    if (dictionary.find("/Filter") != std::string::npos || !std::regex_search(dictionary, m, length)) {
      out.append(pdf, at, stream + 7 - at);
      at = stream + 7;
      continue;
    }
    const std::size_t dataAt = stream + 7, size = std::stoul(m[1]);
    if (dataAt + size > xref) throw malformed("a stream longer than the file");
    const std::string packed = deflate(pdf.substr(dataAt, size), path);
    out.append(pdf, at, object - at);
    out += dictionary.substr(0, static_cast<std::size_t>(m.position(0))) + "/Length " + std::to_string(packed.size()) +
           " /Filter /FlateDecode" + dictionary.substr(static_cast<std::size_t>(m.position(0) + m.length(0)));
    out += "stream\n" + packed;
    at = dataAt + size;
    ++compressed;
  }
  out.append(pdf, at, xref + 1 - at);
  // A new cross-reference table: where each "N 0 obj" now starts.
  std::vector<std::size_t> offsets;
  const std::regex header(R"((?:^|\n)(\d+) 0 obj)");
  for (std::sregex_iterator it(out.begin(), out.end(), header), end; it != end; ++it) {
    const std::size_t n = std::stoul((*it)[1]);
    if (offsets.size() <= n) offsets.resize(n + 1, 0);
    offsets[n] = static_cast<std::size_t>(it->position(1));
  }
  if (offsets.empty()) throw malformed("no object");
  const std::size_t table = out.size();
  out += "xref\n0 " + std::to_string(offsets.size()) + "\n0000000000 65535 f \n";
  for (std::size_t n = 1; n < offsets.size(); ++n) {
    char entry[24];
    std::snprintf(entry, sizeof entry, offsets[n] ? "%010zu 00000 n \n" : "%010zu 65535 f \n", offsets[n]);
    out += entry;
  }
  const std::size_t startxref = pdf.find("startxref", trailer);
  if (startxref == std::string::npos) throw malformed("no startxref");
  out += pdf.substr(trailer, startxref - trailer) + "startxref\n" + std::to_string(table) + "\n%%EOF\n";
  if (compressed == 0) return 0;
  const std::string staged = path + ".compressing";
  writeFile(staged, out);
  std::error_code ec;
  std::filesystem::rename(staged, path, ec);
  if (ec) {
    std::filesystem::remove(staged, ec);
    throw ioError(path + ": cannot replace the file");
  }
  return compressed;
}

}  // namespace detail

}  // namespace parcelscope::viz
