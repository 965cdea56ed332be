#pragma once
// Parcels (land lots) and blocks as the libraries exchange them.
#include <cstdint>
#include <string>
#include <vector>

#include "parcelscope/core/Geometry.h"
#include "parcelscope/core/Keys.h"

namespace parcelscope {

/// One observed or generated parcel: a single polygon (multipart features are
/// split into one Parcel per part).
struct Parcel {
  Polygon shape;                ///< local metres, normalised
  std::int64_t sourceFid = -1;  ///< feature id in the input layer (-1 for generated parcels)
  int part = 0;                 ///< part index within a multipart feature
  int stackCount = 1;           ///< how many input features had this exact geometry
  bool repaired = false;        ///< geometry came out of make-valid
  /// Stable key of the input feature (see Keys.h): FNV-1a of its geometry as
  /// read (ISO WKB, little-endian), or of its key field's value; 0 for generated parcels.
  Key featureKey = 0;
};

/// The parcel's stable key: its feature's key, mixed with the part index for
/// parts of a multipart feature.
inline Key parcelKey(const Parcel& parcel) { return partKey(parcel.featureKey, parcel.part); }

/// A city block: a connected group of parcels and the union of their shapes.
struct Block {
  int id = -1;
  std::vector<Polygon> parts;  ///< usually one polygon; holes kept
  std::vector<int> parcels;    ///< indices into the parcel list
  /// Stable key: setKey of its member parcels' keys (see Keys.h), so neither
  /// the order of features nor any other block changes it.
  Key key = 0;
};

}  // namespace parcelscope
