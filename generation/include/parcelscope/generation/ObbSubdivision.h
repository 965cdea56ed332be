#pragma once
// OBB recursive subdivision of a block into parcels (Vanegas et al. 2012,
// section 4.3 and Algorithm 2), with the paper's edge-aligned OBBs, child seeds
// drawn before recursion and snapping to block contour vertices.
//
// Stopping rule (the paper's pseudocode is garbled; this one makes the bounds
// mean what a user expects):
//   - a parcel whose area is at most A_max and whose width (OBB short side) is
//     at most W_max is final;
//   - otherwise it is split, but only by a split all of whose pieces have
//     area >= A_min and width >= W_min (and street access, see xi); several
//     split lines are tried (the random one first); when none qualifies the
//     parcel stays as it is and is counted as oversize.
// So parcels never fall below A_min or W_min unless the block itself does, and
// exceed A_max or W_max only where the geometry leaves no admissible split.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "parcelscope/core/Geometry.h"
#include "parcelscope/core/Parameter.h"

namespace parcelscope::generation {

struct ObbParameters {
  double aMin = 200;          ///< m², smallest parcel area a split may create
  double aMax = 800;          ///< m², parcels above this are split
  double wMin = 8;            ///< m, smallest parcel width (OBB short side) a split may create
  double wMax = 30;           ///< m, parcels wider than this are split
  double omega = 0.3;         ///< split irregularity in [0, 1]: random shift of the split line
  double xi = 1.0;            ///< street-access preference in [0, 1]
  double snapDistance = 2.0;  ///< m, split lines this close to a block contour vertex pass through it
  double minFrontage = 1.0;   ///< m of block contour a parcel needs to count as having street access
};

/// The descriptions of every OBB parameter (CLI flags, GUI controls, run record),
/// including "seed" and min-frontage (analysis::minFrontageParameter(), shared
/// with the analysis of observed parcels).
const std::vector<ParameterDescription>& obbParameterDescriptions();
/// Parameters from values named as in obbParameterDescriptions(); missing names keep defaults.
ObbParameters obbParametersFrom(const ParameterValues& values);

/// The splits an OBB subdivision made, piece by piece. Which split a piece gets
/// does not depend on A_max or W_max, only where the recursion stops; a later
/// run of the same block, seed and other parameters reuses them, so a bounds
/// slider moves without splitting again (parcels persist under edits, as in
/// Vanegas et al. 2012). Opaque; shared, never changed once made.
struct ObbSplits;

/// The parameter-independent part of a skeleton subdivision (see
/// SkeletonSubdivision.h). Opaque; shared, never changed once made.
struct SkeletonLayout;

struct Subdivision {
  std::vector<Polygon> parcels;  ///< tile the block (normalised, local metres)
  int oversize = 0;              ///< parcels above A_max or W_max with no admissible split
  int withoutAccess = 0;         ///< parcels without street access
  bool failed = false;           ///< the block could not be split (invalid for exact geometry); parcels = {block}
  std::string failure;           ///< why, when failed
  bool fallback = false;         ///< another style could not subdivide the block; OBB did
  std::string fallbackReason;    ///< why, when fallback
  int patioParcels = 0;          ///< parcels that are (parts of) inner patios, without street access by design
  /// The last unassignedParcels parcels (after any patios) are land the style
  /// left to no parcel (parish: lots without street access, which Parish &
  /// Muller discard); kept so that the parcels still tile the block. Not
  /// counted in withoutAccess.
  int unassignedParcels = 0;
  /// Styles that aim at a number of parcels (sexton): that number; 0 otherwise.
  int targetParcels = 0;
  /// Styles that choose among variants per block (template: the template
  /// used, "row", "grid" or "spike"); empty otherwise and on a fallback.
  std::string variant;
  std::shared_ptr<const ObbSplits> obbSplits;  ///< OBB only, when asked to record them
  /// OBB only: 1 when the block has no holes and a strictly simple ring, 0
  /// when not, -1 when it was not tested (for ObbReuse::blockSimple).
  signed char blockSimple = -1;
  std::shared_ptr<const SkeletonLayout> skeletonLayout;  ///< skeleton styles only, when asked to record it
  /// Skeleton styles only: steps 4 and 5 ran on the exact route (the block has
  /// patios, or the floating-point route could not certify a step, or
  /// SkeletonReuse::exactOnly).
  bool skeletonExact = false;
};

/// Splits to reuse and whether to record this run's.
struct ObbReuse {
  /// Splits recorded by an earlier run of the same block and seed whose
  /// parameters pass obbSplitsReusable; nullptr: split afresh.
  const ObbSplits* previous = nullptr;
  bool record = false;  ///< keep this run's splits (with those reused) in Subdivision::obbSplits
  /// The block passed the validity check in an earlier run that did not fail:
  /// the check is skipped.
  bool blockChecked = false;
  /// With blockChecked: that run's Subdivision::blockSimple (-1: test again if needed).
  signed char blockSimple = -1;
};

/// True when splits recorded with `recorded` serve a run with `wanted`: every
/// parameter but A_max and W_max is the same.
bool obbSplitsReusable(const ObbParameters& recorded, const ObbParameters& wanted);

/// Subdivides one block (normalised polygon, holes allowed) into parcels.
/// Deterministic: the same block, parameters and seed give the same parcels.
/// Never throws on bad geometry: a block the exact kernel rejects comes back
/// whole with failed = true.
/// With `reuse.previous`, the parcels are those a fresh run gives.
Subdivision subdivideObb(const Polygon& block, const ObbParameters& parameters, std::uint64_t seed,
                         const ObbReuse& reuse = {});

/// Seed of the block with key `blockKey` (generate uses the block's position)
/// in a run with seed `runSeed` (splitmix64 mix), so a block's parcels do not
/// depend on the other blocks.
std::uint64_t blockSeed(std::uint64_t runSeed, std::int64_t blockKey);

}  // namespace parcelscope::generation
