#pragma once
// PDF files written by others (VTK's GL2PS export) made smaller in place.
#include <string>

namespace parcelscope::viz::detail {

/// Flate-compresses, in place, every stream of the PDF at `path` that has a
/// literal /Length and no /Filter, and rewrites the cross-reference table.
/// Debian's GL2PS writes its streams uncompressed, among them the raster of
/// the 3D layer: 4.9 MB of white under a histogram. Returns the number of
/// streams compressed. Throws Error(IO) when the file cannot be read, parsed
/// or written (it is then left as it was).
int compressPdfStreams(const std::string& path);

}  // namespace parcelscope::viz::detail
