#pragma once
// The quality measures of Yang et al. 2013, section 7, that the parcel
// metrics lack: land shares, blocks and block boundary lengths, street
// densities (when blocks come from streets) and parcel densities, for the
// observed parcels and for each style's (the spirit of that paper's Table 1).
#include <cmath>
#include <string>
#include <vector>

#include "parcelscope/core/Table.h"
#include "parcelscope/pipeline/GenerateJob.h"
#include "parcelscope/pipeline/StatsJob.h"

namespace parcelscope::pipeline {

/// What the observed and the generated layouts share: the study area, its
/// blocks and its streets. Densities are per km² of the study area: the
/// blocks' area, plus the street surface (centre lines buffered by their half
/// widths) when blocks come from streets.
struct LayoutContext {
  double blockArea = 0;                                      ///< m²
  double streetArea = NAN;                                   ///< m², street surface; NaN without streets
  double studyArea = 0;                                      ///< m²
  std::int64_t blocks = 0;                                   ///< observed blocks
  double boundaryMin = 0, boundaryAvg = 0, boundaryMax = 0;  ///< m, block boundary (perimeter) lengths
  double streetLength = NAN;                                 ///< m of centre line (study-area boundary lines excluded)
  std::int64_t intersections = 0, deadEnds = 0;              ///< nodes of degree >= 3 and 1
};

/// The context of `observed`'s blocks and streets (the street surface is built once here).
LayoutContext layoutContext(const ObservedData& observed);

/// One layout's row: Yang's l_s, l_r, l_o, b_n, b_max, b_avg, b_min, s_l, s_i,
/// s_d, p_n, p_angle, p_area.
struct LayoutMeasures {
  std::string layout;                                        ///< "observed" or a style
  double streetShare = NAN;                                  ///< l_s, % of the study area
  double parcelShare = 0;                                    ///< l_r, % in parcels (lots; unassigned land not)
  double otherShare = 0;                                     ///< l_o, % of block land in no parcel
  double blocksPerKm2 = 0;                                   ///< b_n
  double boundaryMax = 0, boundaryAvg = 0, boundaryMin = 0;  ///< b_max, b_avg, b_min (m)
  double streetLengthPerKm2 = NAN;                           ///< s_l, km per km²
  double intersectionsPerKm2 = NAN;                          ///< s_i
  double deadEndsPerKm2 = NAN;                               ///< s_d
  double parcelsPerKm2 = 0;                                  ///< p_n
  double meanPAngle = 0;                                     ///< p_angle, mean over parcels (degrees)
  double meanPArea = 0;                                      ///< p_area, mean over parcels
};

/// The observed parcels' layout (lots in blocks).
LayoutMeasures observedLayout(const LayoutContext& context, const ObservedData& observed);
/// A style's layout (parcels, unassigned land left out).
LayoutMeasures generatedLayout(const LayoutContext& context, const GeneratedParcels& generated,
                               const std::string& style);

/// layout.csv: one row per layout, the columns of LayoutMeasures.
Table layoutTable(const std::vector<LayoutMeasures>& rows);

}  // namespace parcelscope::pipeline
