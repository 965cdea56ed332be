#pragma once
// Vector files written by others (VTK's GL2PS export) mended in place: PDFs made
// smaller, SVGs made well-formed XML.
#include <string>

namespace parcelscope::viz::detail {

/// Flate-compresses, in place, every stream of the PDF at `path` that has a
/// literal /Length and no /Filter, and rewrites the cross-reference table.
/// Debian's GL2PS writes its streams uncompressed, among them the raster of
/// the 3D layer: 4.9 MB of white under a histogram. Returns the number of
/// streams compressed. Throws Error(IO) when the file cannot be read, parsed
/// or written (it is then left as it was).
int compressPdfStreams(const std::string& path);

/// Appends `text` to `out` as XML character data (&, < and > escaped).
void appendXmlText(std::string& out, const std::string& text);

/// Escapes, in place, the characters of the SVG at `path`'s texts (its
/// <title> and each <text>): GL2PS writes them as they are, and an input named
/// "R&D.geojson" in a chart's title made the file unreadable as XML. Throws
/// Error(IO) when the file cannot be written.
void escapeSvgTexts(const std::string& path);

}  // namespace parcelscope::viz::detail
