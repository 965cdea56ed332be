#pragma once
#include <cstddef>

// VTK's text goes through FreeType's glyph cache. FreeType 2.12 (Debian 12)
// allocates the cache manager without zeroing it; when the manager's weight
// counter holds leftover heap data (a heap address was seen), the cache
// believes itself full and drops every glyph after each lookup, and every
// string is laid out and rasterised from the font again. This happened in
// every `compare` run (69,462 glyphs loaded for the five figures of
// cambridge_ma) and in about half of the application's runs.

namespace parcelscope::viz::detail {

/// Gives VTK's FreeType library an allocator that returns zeroed memory, and
/// starts its glyph cache afresh on it. Called once, before the first text is
/// drawn (further calls do nothing); must run on the thread that draws.
void prepareTextRendering();

/// How many blocks FreeType has allocated for VTK's text since
/// prepareTextRendering (0 before): a glyph served from the cache allocates
/// nothing.
std::size_t textAllocations();

}  // namespace parcelscope::viz::detail
