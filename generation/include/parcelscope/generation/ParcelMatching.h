#pragma once
// Parcel matching across an edit of a block (Vanegas et al. 2012, section 5.2):
// each parcel of the block after the edit is matched to a parcel of the block
// before it by their relative positions in the block, a generalisation of
// barycentric coordinates over the block contour's vertices. A matched parcel
// can keep what the one before carried (its key, its building's parameters).
// See docs/algorithms/persistence.md for the choices the paper leaves open.
//
// Complexity for a contour of K vertices, m parcels before and n after:
// O(K^2) to reduce and correspond the contours, O((m + n) K) for the
// positions, O(m n K) for the distances and O(m n log(m n)) for the one-to-one
// assignment: well under a millisecond for a few hundred parcels.
#include <cstddef>
#include <utility>
#include <vector>

#include "parcelscope/core/Geometry.h"

namespace parcelscope::generation {

/// A contour vertex is dropped as collinear when its distance to the chord
/// between its neighbours is at most this share of the chord's length (and it
/// lies between them): 1 mm on a 10 m edge. Scale-free, so scaling a block
/// drops the same vertices; far above the rounding of a node inserted into an
/// edge (a T-junction), far below any street's geometry.
constexpr double kCollinearShare = 1e-4;

/// Two cyclic correspondences of contours of equal vertex count whose
/// residuals (see correspondContours) differ by at most this fit equally well
/// (about 3 % of the block's radius of mean vertex displacement); among them
/// the one needing the smallest rotation is taken.
constexpr double kCorrespondenceBand = 1e-3;

/// The contour the matching uses: `contour` counter-clockwise, without the
/// vertices collinear with their neighbours (kCollinearShare) and repeated
/// vertices. Vertices are removed one at a time, the straightest first (ties
/// to the lowest x, then y), so the result does not depend on the start
/// vertex or the orientation of `contour`, only on its cycle of vertices.
Ring matchingContour(const Ring& contour);

/// Pairs (vertex of `before`, vertex of `after`) of two matching contours
/// (see matchingContour) that stand for the same block corner, in the cyclic
/// order of `before`; empty when they cannot be put in correspondence.
///  - Equal vertex counts: every vertex, by the cyclic shift whose residual
///    after the best similarity transform (translation, rotation, uniform
///    scale; vertices centred on their mean and scaled to unit sum of squared
///    radii) is smallest; among shifts within kCorrespondenceBand of it, the
///    one needing the smallest rotation, then the lowest shift. Invariant to
///    similarity transforms and to the start vertex; for a block with a
///    rotational symmetry a rotation by a symmetry angle is indistinguishable
///    from a new start vertex, and is read as the latter.
///  - Different counts (a corner added or removed): the mutual nearest
///    vertices after centring both on their area centroid and scaling by the
///    square root of their area (no rotation: such edits are local). Nothing
///    when fewer than 3 pairs remain or the pairs do not keep their cyclic
///    order on both contours.
std::vector<std::pair<std::size_t, std::size_t>> correspondContours(const Ring& before, const Ring& after);

/// The point a parcel's relative position is taken at: its area centroid
/// (holes subtracted). It may lie outside a concave parcel, which does not
/// matter here: it only needs to move with the parcel.
Point parcelCentre(const Polygon& parcel);

/// The paper's relative position of `point` in a block with contour vertices
/// b_1..b_K: l_k = |point - b_k| / sum_j |point - b_j|, summing to 1. Empty
/// without vertices; when the point is every vertex (a degenerate contour),
/// the uniform 1 / K.
std::vector<double> relativePosition(const Point& point, const Ring& vertices);

/// Distance between two relative positions over the same vertices: the L1
/// distance sum_k |l_k - l'_k|, in [0, 2]. The paper's formula divides each
/// term by sum_k (l_k - l'_k), which is 0 because both positions sum to 1;
/// the L1 distance of the normalised coordinates is what is left once that
/// normalisation, already applied to l and l', is taken as meant.
double positionDistance(const std::vector<double>& a, const std::vector<double>& b);

/// The outcome of matchParcels, per parcel after the edit.
struct ParcelMatches {
  /// Index of the matched parcel before the edit, or -1: no parcel before is
  /// used twice, so parcels after beyond the count before stay unmatched.
  std::vector<int> before;
  /// positionDistance to the matched parcel (or the fallback's distance, see
  /// matchParcels); -1 when unmatched.
  std::vector<double> distance;
};

/// Matches the parcels of a block after an edit to those before it. Holes of
/// the blocks are ignored: positions are relative to the outer contour only
/// (matchingContour, correspondContours; positions are taken on the
/// corresponded vertices, renormalised to sum to 1). The paper matches each
/// parcel after to its nearest parcel before, possibly several to one; keys
/// must stay unique, so here the pairs are taken one to one, greedily by
/// increasing distance (ties to the lower index after, then before): a pair
/// of strictly mutually nearest parcels is always matched, as in the paper.
/// When the contours cannot be corresponded (a street's width or a node's
/// move changed the block's outline beyond a vertex added or removed), a
/// parcel's position is its centre relative to the block's area centroid, in
/// units of the square root of the block's area, and the distance Euclidean
/// (`distance` is then in those units). Deterministic.
ParcelMatches matchParcels(const Polygon& blockBefore, const std::vector<Polygon>& parcelsBefore,
                           const Polygon& blockAfter, const std::vector<Polygon>& parcelsAfter);

}  // namespace parcelscope::generation
