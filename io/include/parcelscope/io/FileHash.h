#pragma once
// Fingerprints of input files for run records, so that a result can be traced
// to the exact bytes it was computed from.
#include <cstdint>
#include <string>

namespace parcelscope::io {

/// SHA-256 (FIPS 180-4) of `bytes`, as 64 lowercase hex digits.
std::string sha256Hex(const std::string& bytes);

/// SHA-256 of the file's contents, as 64 lowercase hex digits; the file is read
/// in blocks, never whole. Throws Error(Input) naming the file when it cannot
/// be read.
std::string sha256File(const std::string& path);

}  // namespace parcelscope::io
