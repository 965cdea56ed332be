#pragma once
// The template warping of Yang et al. 2013, section 4.1, for the template
// style: a template (a polygon split into parts, each allowed one class of
// deformation) is matched to a block by its corners, initialised by arc-length
// scaling of its boundary and mean value coordinates of its interior
// vertices, then improved by alternating registration (each part by the best
// transformation of its class) and regression (each vertex the weighted
// barycentre of its parts' images, boundary vertices projected onto the
// block's boundary). docs/algorithms/template.md gives the choices the paper
// leaves open.
#include <cstddef>
#include <string>
#include <vector>

#include "parcelscope/core/Geometry.h"

namespace parcelscope::generation::detail {

/// The deformations a part may undergo (the paper's three classes).
enum class PartClass {
  Rigid,       ///< rotation and translation
  Similarity,  ///< plus a uniform scale in [scaleMin, scaleMax]
  Affine,      ///< rotation, then scales along the template's x and y axes within their ranges
};

struct TemplatePart {
  std::vector<int> ring;  ///< vertex indices, counter-clockwise
  PartClass kind = PartClass::Affine;
  double scaleMin = 1, scaleMax = 1;    ///< Similarity: the uniform scale; Affine: along x
  double scaleMinY = 1, scaleMaxY = 1;  ///< Affine: along y
  double tolerance = 0.1;               ///< the paper's epsilon: regression weight 1 / tolerance
};

/// A template: vertices in template coordinates (m), its boundary, its parts
/// and its split lines.
struct Template {
  std::string name;
  std::vector<Point> vertices;
  std::vector<int> boundary;  ///< vertex indices, counter-clockwise
  /// Per boundary position: +1 convex corner, -1 concave corner, 0 regular.
  std::vector<signed char> corners;
  std::vector<TemplatePart> parts;
  /// The interior lines, in the order they split: vertex paths, each from a
  /// boundary vertex (or a vertex of an earlier line) to another.
  std::vector<std::vector<int>> splits;
};

/// A corner of a block's ring: where two of its sides (LotSplit.h's sidesOf)
/// meet turning by at least the threshold.
struct Corner {
  std::size_t index = 0;  ///< ring vertex
  signed char type = 1;   ///< +1 convex, -1 concave (counter-clockwise ring)
  double turn = 0;        ///< |turning angle|, radians
};

/// The corners of a counter-clockwise ring turning by at least `minTurn`
/// radians, in ring order; at most `maxCorners` (the sharpest, in ring order).
/// With `shortShare` > 0, two consecutive corners joined by a side shorter
/// than `shortShare` times both sides around them are one: a jog in a street
/// (turns cancelling: no corner) or a cut-off corner (one corner, their summed
/// turn, at the sharper of the two; not beyond 120 degrees, which are the two
/// ends of a narrow strip).
std::vector<Corner> cornersOf(const Ring& ring, double minTurn, std::size_t maxCorners, double shortShare = 0);

/// The template's boundary arc lengths, from each corner to the next.
std::vector<double> templateArcs(const Template& t);
/// The ring's arc lengths between consecutive matched vertices (counter-clockwise).
std::vector<double> ringArcs(const Ring& ring, const std::vector<std::size_t>& matched);
/// RMS over the arcs of log(block arc / template arc): the paper's
/// boundary-length distortion.
double boundaryDistortion(const std::vector<double>& templateArcs, const std::vector<double>& blockArcs);

/// A 2D affine map p -> A p + t.
struct AffineMap {
  double a11 = 1, a12 = 0, a21 = 0, a22 = 1;
  Point t;
  Point operator()(const Point& p) const { return {a11 * p.x + a12 * p.y + t.x, a21 * p.x + a22 * p.y + t.y}; }
};

/// The map of `part`'s class that moves `from` closest to `to` in least
/// squares (the paper's registration, equation 1).
AffineMap registerPart(const std::vector<Point>& from, const std::vector<Point>& to, const TemplatePart& part);

/// Mean value coordinates of `x` (strictly inside) with respect to `polygon`.
std::vector<double> meanValueCoordinates(const Point& x, const std::vector<Point>& polygon);

struct Warp {
  std::vector<Point> positions;  ///< every template vertex, in block coordinates
  double initialResidual = 0;    ///< RMS registration distance (m) of the initialisation
  double residual = 0;           ///< RMS registration distance (m) after the iterations
  int iterations = 0;
};

/// Warps template `t` onto `ring` (counter-clockwise), its k-th corner (in
/// boundary order) onto ring vertex `matched[k]` (counter-clockwise order),
/// with `iterations` rounds of registration and regression.
Warp warpTemplate(const Template& t, const Ring& ring, const std::vector<std::size_t>& matched, int iterations);

}  // namespace parcelscope::generation::detail
