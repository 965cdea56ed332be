#pragma once
// The subdivision styles, each registered once: its name, description,
// parameters and run function. The command line (--style, --help), the GUI's
// style lists, the run record and the pipeline read this registry; adding a
// style is one source file defining a Style and one line in the registry's
// list (generation/src/Styles.cpp).
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "parcelscope/core/Parameter.h"
#include "parcelscope/generation/ObbSubdivision.h"
#include "parcelscope/generation/SkeletonSubdivision.h"

namespace parcelscope::generation {

/// A block's observed parcels, for styles that fit them (sexton): their areas
/// (m²), widths (MBR short side, m) and aspect ratios (MBR long over short
/// side), as analysis measures them.
struct ObservedSample {
  std::vector<double> areas, widths, aspectRatios;
  /// Per parcel, 1 where it has street access; empty when unknown.
  std::vector<unsigned char> access;
  /// Per parcel, its length on the block's outline (m); empty when unknown.
  std::vector<double> frontages;
  double accessShare = NAN;  ///< share of the parcels with street access; NaN when unknown
  /// The same parcels' values, field by field (an unknown share equals an unknown one).
  bool operator==(const ObservedSample& o) const {
    const bool share = accessShare == o.accessShare || (std::isnan(accessShare) && std::isnan(o.accessShare));
    return share && areas == o.areas && widths == o.widths && aspectRatios == o.aspectRatios && access == o.access &&
           frontages == o.frontages;
  }
};

/// One block's run of a style.
struct StyleRun {
  const Polygon& block;           ///< normalised, local metres
  const ParameterValues& values;  ///< the block's values (see Style::parameterNames); missing names: defaults
  std::uint64_t seed = 0;
  /// Street widths per contour edge (see StreetWidths); empty when unknown or
  /// when the style does not use them.
  const StreetWidths& streetWidths;
  /// The block's last outcome, when the caller kept it, made by style
  /// `previousStyle` with `previousValues` and `previousSeed`: a style may reuse
  /// what it recorded there; the parcels are those of a fresh run.
  const Subdivision* previous = nullptr;
  const std::string* previousStyle = nullptr;
  const ParameterValues* previousValues = nullptr;
  std::uint64_t previousSeed = 0;
  /// Keep what a later run may reuse in the outcome (Subdivision::obbSplits, ::skeletonLayout).
  bool record = false;
  /// The observed parcels of the block this one is part of, when known; null otherwise.
  const ObservedSample* observed = nullptr;
  /// This part's share of its block's area (multipart blocks: the sample is the whole block's).
  double observedShare = 1.0;
};

/// What a style knows of a block before choosing (for styles that choose
/// another per block, like auto).
struct BlockFacts {
  double accessShare = 0;                    ///< share of its observed parcels with street access; NaN when unknown
  const Polygon* shape = nullptr;            ///< the block (part), local metres; null when unknown
  const ObservedSample* observed = nullptr;  ///< its block's observed parcels; null when none
  double observedShare = 1.0;                ///< this part's share of its block's area
};

class Style {
public:
  virtual ~Style() = default;
  /// Flag value and name in run records, e.g. "obb".
  virtual std::string name() const = 0;
  /// One line for --help and the GUI.
  virtual std::string description() const = 0;
  /// The parameters this style reads (bounds and its own), each described once.
  virtual const std::vector<ParameterDescription>& parameters() const = 0;
  /// Whether run() reads street widths (they are measured only when some block needs them).
  virtual bool usesStreetWidths() const { return false; }
  /// The concrete style a block is subdivided with: this one, or for a style
  /// that chooses per block (auto), the one it picks.
  virtual const Style& resolve(const BlockFacts&) const { return *this; }
  /// Values a style that chooses per block fixes for the style it picked
  /// (access: the paper's even slices), whatever the run's values say.
  virtual void pinValues(ParameterValues&) const {}
  /// Subdivides one block. Deterministic: the same block, values and seed give
  /// the same parcels. Geometric failures come back in the Subdivision (failed,
  /// or fallback to obb with the reason); memory, a stop or a usage error throw.
  virtual Subdivision run(const StyleRun& run) const = 0;

  /// run() followed by the post-processing every style shares: slivers
  /// (parcels narrower than 1 mm, numerical crumbs of a cut) merged into a
  /// neighbour; a style other than obb that leaves one falls back to obb.
  /// What callers use.
  Subdivision subdivide(const StyleRun& run) const;
};

/// Every registered style, in the order of --help and the GUI: obb, skeleton, offset, parish, sexton, template,
/// access, auto.
const std::vector<const Style*>& styles();
/// The style called `name`; throws Error(Usage) naming the styles otherwise.
const Style& style(const std::string& name);

/// (name, description) of every style (compatibility view of styles()).
const std::vector<std::pair<std::string, std::string>>& generationStyles();

/// Every parameter `generate` takes: every style's and the block-building ones,
/// each name once (CLI flags, GUI sliders, run record).
std::vector<ParameterDescription> generationParameterDescriptions();

/// The values of `values` that style `s` reads (its parameters()): what a
/// block's plan holds, so that two plans are equal exactly when the style would
/// make the same parcels.
ParameterValues styleValues(const Style& s, const ParameterValues& values);

/// Whether `s` chooses another style per block (access, auto) rather than subdividing itself.
bool choosesPerBlock(const Style& s);

/// Subdivides one block with a concrete style by name (not auto).
Subdivision subdivideBlock(const Polygon& block, const std::string& style, const ParameterValues& values,
                           std::uint64_t seed, const StreetWidths& streetWidths = {});

/// Share of observed parcels with street access at or above which `access` picks skeleton.
constexpr double kAccessSkeletonShare = 0.9;

/// The registered styles (defined beside their algorithms).
const Style& obbStyle();
const Style& skeletonStyle();
const Style& offsetStyle();
const Style& parishStyle();
const Style& sextonStyle();
const Style& templateStyle();
const Style& accessStyle();
const Style& autoStyle();

}  // namespace parcelscope::generation
