#pragma once
// Straight-skeleton subdivision of a block into parcels (Vanegas et al. 2012,
// section 4.2, Figures 3-5 and Algorithm 1): parcels in strips along the
// block's logical streets, back to back along the skeleton's centre line, or
// around inner patios when a finite offset is given.
//
// Steps, as implemented:
//  1. Initial split. The CGAL straight skeleton of the block (holes included).
//     With a finite d_offset, each skeleton face is cut where its distance to
//     its contour edge reaches d_offset; what lies beyond forms the patios.
//  2. Alpha-strips. Outer-contour edges are grouped into logical streets: a
//     corner turning by less than `streetAngle` continues the street; a ring
//     with fewer than two such breaks is broken at its sharpest corners.
//  3. Beta-strips. At each convex corner v between strips s_i and s_i+1,
//     T(v) is chosen by StreetWidth (the wider street's strip gains the corner;
//     equal or unknown widths fall back to StreetLength) or StreetLength (the
//     longer street's strip gains); reflex corners and ties get None. The point
//     p of the strips' shared skeleton boundary furthest from the contour is
//     joined by a straight cut to the nearest point q of the losing strip's
//     streets that it reaches inside the strip; the region between v, p and q
//     moves to the gaining strip, whose rays then run perpendicular to its own
//     street across it. Strips left empty disappear.
//  4. Slicing. Ray origins are placed along each strip's streets, n =
//     round(length / ((W_min + W_max) / 2)) parcels per strip, each origin
//     displaced from equal spacing by a normal deviate with variance 3 omega
//     (clamped to 45 % of the spacing). Within each skeleton face the ray runs
//     perpendicular to that face's street edge; where it meets the face's
//     skeleton arc the parcel boundary follows the arc (the paper's rays
//     following skeleton edges), because parcels are assembled face by face.
//  5. Post-processing. A block whose deepest point is less than W_min from its
//     contour is too shallow for two rows: it gets one row of parcels reaching
//     across it, cut perpendicular to its long axis at the same spacing.
//     Parcels above A_max are split by a second ray from the middle of their
//     longest street edge when both halves keep A_min, W_min and street access.
//     Triangular parcels, parcels below A_min and parcels without street access
//     (the faces along holes, pieces cut off by rays) are merged into the
//     neighbour sharing the longest boundary, smallest first, until none is
//     left or one parcel remains. Patios stay one parcel each or are
//     subdivided with the OBB style.
// Street access means at least `minFrontage` of boundary on the block's outer
// contour, as for the measured parcels.
//
// All cuts and unions are exact (CGAL Boolean operations, exact-constructions
// kernel) near the origin; the result is checked (valid polygons, areas summing
// to the block's) and a block whose skeleton cannot be built or checked is
// subdivided with the OBB style instead and flagged `fallback`.
#include <cstdint>
#include <string>
#include <vector>

#include "parcelscope/core/Geometry.h"
#include "parcelscope/core/Parameter.h"
#include "parcelscope/generation/ObbSubdivision.h"

namespace parcelscope::generation {

enum class CornerRule { StreetWidth, StreetLength };

struct SkeletonParameters {
  ObbParameters bounds;     ///< A_min, A_max, W_min, W_max, omega; xi and snap apply to OBB patios
  double offset = 0;        ///< d_offset in m; 0 means infinite (no patio)
  double streetAngle = 30;  ///< degrees; contour corners turning less continue the same logical street
  CornerRule corner = CornerRule::StreetWidth;
  bool subdividePatios = false;  ///< patios subdivided with the OBB style instead of one parcel each
  /// Slice widths to draw from (m), e.g. the block's observed parcel widths:
  /// each strip is cut into widths drawn from these, scaled to fill it. Empty:
  /// the paper's even spacing, (W_min + W_max) / 2 displaced by omega.
  std::vector<double> sliceWidths;
  /// slice-widths = observed: the style fills sliceWidths from the block's observed parcels.
  bool observedSliceWidths = false;
};

/// Descriptions of the skeleton-only parameters (offset, street-angle,
/// corner-rule: an enum, 0 street-width / 1 street-length, as CornerRule;
/// patio-obb: a boolean); the bounds are obbParameterDescriptions()'.
const std::vector<ParameterDescription>& skeletonParameterDescriptions();
/// Parameters from values named as in both description lists.
SkeletonParameters skeletonParametersFrom(const ParameterValues& values);

/// Street width per contour edge of the block, where known: widths[r][i] is
/// for the edge from vertex i to i+1 of ring r (0 the outer ring, then the
/// holes, as in the normalised block); NaN or missing entries are unknown.
using StreetWidths = std::vector<std::vector<double>>;
/// True when `a` and `b` hold the same widths, bit for bit (unknown ones included).
bool sameStreetWidths(const StreetWidths& a, const StreetWidths& b);

/// Steps 1 to 3 (the skeleton, the strips and their corner transfers) depend
/// on the block, its street widths, d_offset, the street angle and the corner
/// rule only; not on the bounds, omega or the seed; the skeleton itself on the
/// block and street widths alone. A run can record them
/// (Subdivision::skeletonLayout) and a later run of the same block reuses what
/// still applies, so the bounds, omega and seed sliders move without building
/// the skeleton or the strips again, and the other skeleton sliders without
/// building the skeleton again.
struct SkeletonReuse {
  /// Recorded by an earlier run; used only when it was made for the same
  /// block (vertex for vertex) and street widths, else ignored; its strips
  /// only with the same d_offset, street angle and corner rule.
  const SkeletonLayout* previous = nullptr;
  bool record = false;  ///< keep this run's layout (with what it reused) in Subdivision::skeletonLayout
  /// Steps 4 and 5 on the exact route only, never in floating point (for
  /// tests comparing the two routes).
  bool exactOnly = false;
};

/// True when the strips of a layout recorded with `recorded` serve a run with
/// `wanted` (same d_offset, street angle and corner rule).
bool skeletonLayoutReusable(const SkeletonParameters& recorded, const SkeletonParameters& wanted);

/// Subdivides one normalised block. Deterministic for a given seed. Never throws
/// on bad geometry: falls back to subdivideObb (fallback = true), and a block the
/// exact kernel rejects altogether comes back whole with failed = true.
/// With `reuse.previous`, the parcels are those a fresh run gives.
Subdivision subdivideSkeleton(const Polygon& block, const SkeletonParameters& parameters, std::uint64_t seed,
                              const StreetWidths& streetWidths = {}, const SkeletonReuse& reuse = {});

}  // namespace parcelscope::generation
