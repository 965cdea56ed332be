#pragma once
// The subdivision styles: their names, descriptions and parameters, and one
// block subdivided with a concrete style.
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "parcelscope/core/Parameter.h"
#include "parcelscope/generation/ObbSubdivision.h"
#include "parcelscope/generation/SkeletonSubdivision.h"

namespace parcelscope::generation {

/// The subdivision styles `generate` offers, each with a one-line description:
///  - obb: OBB recursive subdivision (Vanegas et al. 2012, 4.3);
///  - skeleton: straight-skeleton strips (4.2), d_offset from --offset (0: none);
///  - offset: skeleton with a finite offset (30 m unless --offset is given) and
///    the patios subdivided with the OBB style;
///  - auto: per block, skeleton where at least 90 % of its observed parcels have
///    street access (the paper's first variety: every parcel on a street, rears
///    abutting), obb otherwise; blocks without observed parcels (a block layer
///    without a street_access_share field) use skeleton.
const std::vector<std::pair<std::string, std::string>>& generationStyles();

/// Every parameter `generate` takes: OBB, skeleton and block-building ones, each
/// name once (CLI flags, GUI sliders, run record).
std::vector<ParameterDescription> generationParameterDescriptions();

/// Subdivides one block with a concrete style (obb, skeleton or offset; not
/// auto): `parameters.bounds` for obb, all of `parameters` for the skeleton
/// styles (offset: d_offset 30 m when 0, patios always subdivided).
/// `streetWidths` (per contour edge, see StreetWidths) feed the StreetWidth rule;
/// `reuse` serves the skeleton styles.
Subdivision subdivideBlock(const Polygon& block, const std::string& style, const SkeletonParameters& parameters,
                           std::uint64_t seed, const StreetWidths& streetWidths = {},
                           const SkeletonReuse& reuse = {});

/// Share of observed parcels with street access at or above which `auto` picks skeleton.
constexpr double kAutoSkeletonAccessShare = 0.9;

}  // namespace parcelscope::generation
