#pragma once
// Parcels (land lots) and blocks as the libraries exchange them.
#include <cstdint>
#include <string>
#include <vector>

#include "parcelscope/core/Geometry.h"

namespace parcelscope {

/// One observed or generated parcel: a single polygon (multipart features are
/// split into one Parcel per part).
struct Parcel {
  Polygon shape;                ///< local metres, normalised
  std::int64_t sourceFid = -1;  ///< feature id in the input layer (-1 for generated parcels)
  int part = 0;                 ///< part index within a multipart feature
  int stackCount = 1;           ///< how many input features had this exact geometry
  bool repaired = false;        ///< geometry came out of make-valid
};

/// A city block: a connected group of parcels and the union of their shapes.
struct Block {
  int id = -1;
  std::vector<Polygon> parts;   ///< usually one polygon; holes kept
  std::vector<int> parcels;     ///< indices into the parcel list
};

}  // namespace parcelscope
