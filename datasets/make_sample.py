#!/usr/bin/env python3
"""Generate the synthetic ParcelScope sample town.

Writes sample/sample_town.geojson (relative to this script's folder): a GeoJSON
FeatureCollection in lon/lat (WGS84, no "crs" member) of a small made-up town
of ten blocks separated by streets, each block tiled exactly by parcels, plus a
fixed set of deliberate data quirks (see README.md in this folder); and
sample/sample_streets.geojson: the centre lines of its streets, with a name and
a width (m), a ring road around the town and one cul-de-sac.

Standard library only, deterministic: re-running gives a byte-identical file.

    python3 datasets/make_sample.py
"""

import json
import math
import os
import random

SEED = 20261121
LON0, LAT0 = -71.10, 42.37
M_PER_DEG_LON = 111320.0 * math.cos(math.radians(LAT0))
M_PER_DEG_LAT = 110540.0
# The town is laid out in metres in x 0..428, y 0..412; shift it so (0, 0)
# (= LON0, LAT0) sits near its middle.
SHIFT_X, SHIFT_Y = -214.0, -206.0
TOL = 1e-6

rng = random.Random(SEED)


# --------------------------------------------------------------------------
# small planar geometry helpers (rings are lists of (x, y), not closed)

def signed_area(ring):
    a = 0.0
    n = len(ring)
    for i in range(n):
        x1, y1 = ring[i]
        x2, y2 = ring[(i + 1) % n]
        a += x1 * y2 - x2 * y1
    return a / 2.0


def ccw(ring):
    return ring if signed_area(ring) > 0 else ring[::-1]


def orient(a, b, c):
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])


def on_segment(a, b, p):
    return (min(a[0], b[0]) - TOL <= p[0] <= max(a[0], b[0]) + TOL and
            min(a[1], b[1]) - TOL <= p[1] <= max(a[1], b[1]) + TOL)


def segments_touch(a, b, c, d):
    """True if closed segments ab and cd share at least one point."""
    o1, o2, o3, o4 = orient(a, b, c), orient(a, b, d), orient(c, d, a), orient(c, d, b)
    if ((o1 > TOL and o2 < -TOL) or (o1 < -TOL and o2 > TOL)) and \
       ((o3 > TOL and o4 < -TOL) or (o3 < -TOL and o4 > TOL)):
        return True
    if abs(o1) <= TOL and on_segment(a, b, c):
        return True
    if abs(o2) <= TOL and on_segment(a, b, d):
        return True
    if abs(o3) <= TOL and on_segment(c, d, a):
        return True
    if abs(o4) <= TOL and on_segment(c, d, b):
        return True
    return False


def is_simple(ring):
    n = len(ring)
    if n < 3 or len(set(ring)) != n:
        return False
    edges = [(ring[i], ring[(i + 1) % n]) for i in range(n)]
    for i in range(n):
        for j in range(i + 1, n):
            if j == i + 1 or (i == 0 and j == n - 1):
                continue  # adjacent edges share one vertex by construction
            if segments_touch(edges[i][0], edges[i][1], edges[j][0], edges[j][1]):
                return False
    return True


def point_in_ring(p, ring):
    x, y = p
    inside = False
    n = len(ring)
    for i in range(n):
        x1, y1 = ring[i]
        x2, y2 = ring[(i + 1) % n]
        if (y1 > y) != (y2 > y):
            xc = x1 + (y - y1) * (x2 - x1) / (y2 - y1)
            if xc > x:
                inside = not inside
    return inside


def dist_point_segment(p, a, b):
    dx, dy = b[0] - a[0], b[1] - a[1]
    t = ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / (dx * dx + dy * dy)
    t = max(0.0, min(1.0, t))
    return math.hypot(p[0] - a[0] - t * dx, p[1] - a[1] - t * dy)


def centroid(ring):
    a = signed_area(ring)
    cx = cy = 0.0
    n = len(ring)
    for i in range(n):
        x1, y1 = ring[i]
        x2, y2 = ring[(i + 1) % n]
        f = x1 * y2 - x2 * y1
        cx += (x1 + x2) * f
        cy += (y1 + y2) * f
    return cx / (6 * a), cy / (6 * a)


def node(rings, extra_points=()):
    """Insert into every ring each vertex of the other rings (and each extra
    point) that lies strictly inside one of its edges, so that parcels sharing
    a boundary stretch carry the same vertices along it (no T-junctions)."""
    pts = set(extra_points)
    for r in rings:
        pts.update(r)
    pts = sorted(pts)
    out = []
    for r in rings:
        new = []
        n = len(r)
        for i in range(n):
            a, b = r[i], r[(i + 1) % n]
            new.append(a)
            dx, dy = b[0] - a[0], b[1] - a[1]
            ln2 = dx * dx + dy * dy
            ins = []
            for p in pts:
                if p == a or p == b:
                    continue
                t = ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / ln2
                if t <= TOL or t >= 1 - TOL:
                    continue
                if abs(orient(a, b, p)) / math.sqrt(ln2) <= TOL:
                    ins.append((t, p))
            ins.sort()
            new.extend(p for _, p in ins)
        out.append(new)
    return out


# --------------------------------------------------------------------------
# block subdivision (in block-local coordinates)

def splits(length):
    """Lot boundaries along a frontage: widths drawn in 10..25 m."""
    s = [0.0]
    pos = 0.0
    while True:
        rem = length - pos
        if rem <= 25.0:
            s.append(length)
            return s
        w = round(rng.uniform(10.0, 25.0), 1)
        if rem - w < 10.0:
            w = round(rem / 2.0, 1)
        pos = round(pos + w, 1)
        s.append(pos)


def two_rows(u0, v0, length, depth, jitter=0.0, swap=False):
    """Two rows of lots back to back along the u axis of the rectangle
    [u0, u0+length] x [v0, v0+depth]; the rear line between the rows is at
    depth/2, optionally jittered by up to +-jitter at each lot corner.
    With swap=True the long axis is the local y axis instead of x."""
    front = splits(length)
    back = splits(length)
    allu = sorted(set(front) | set(back))
    mid = {}
    for u in allu:
        j = round(rng.uniform(-jitter, jitter), 1) if jitter else 0.0
        mid[u] = depth / 2.0 + j

    def pt(u, v):
        return (v0 + v, u0 + u) if swap else (u0 + u, v0 + v)

    lots = []
    for a, b in zip(front, front[1:]):
        inner = [u for u in allu if a < u < b]
        ring = [pt(a, 0.0), pt(b, 0.0), pt(b, mid[b])]
        ring += [pt(u, mid[u]) for u in reversed(inner)]
        ring += [pt(a, mid[a])]
        lots.append(("front", ring))
    for a, b in zip(back, back[1:]):
        inner = [u for u in allu if a < u < b]
        ring = [pt(a, mid[a])] + [pt(u, mid[u]) for u in inner]
        ring += [pt(b, mid[b]), pt(b, depth), pt(a, depth)]
        lots.append(("back", ring))
    return lots


def one_row(u0, v0, length, depth, swap=False):
    s = splits(length)

    def pt(u, v):
        return (v0 + v, u0 + u) if swap else (u0 + u, v0 + v)

    return [("row", [pt(a, 0.0), pt(b, 0.0), pt(b, depth), pt(a, depth)])
            for a, b in zip(s, s[1:])]


# --------------------------------------------------------------------------
# block transforms: local coordinates -> town metres (before the shift)

def translate(ox, oy):
    return lambda p: (ox + p[0], oy + p[1])


def rotate_about(cx, cy, hw, hh, deg):
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))

    def f(p):
        u, v = p[0] - hw, p[1] - hh
        return (cx + c * u - s * v, cy + s * u + c * v)
    return f


def bilinear(length, depth, p00, p10, p11, p01):
    def f(p):
        s, t = p[0] / length, p[1] / depth
        return tuple((1 - s) * (1 - t) * p00[k] + s * (1 - t) * p10[k] +
                     s * t * p11[k] + (1 - s) * t * p01[k] for k in range(2))
    return f


def to_metres(tf, p):
    x, y = tf(p)
    return (round(x + SHIFT_X, 2), round(y + SHIFT_Y, 2))


def to_lonlat(p):
    x, y = p
    return [round(LON0 + x / M_PER_DEG_LON, 7), round(LAT0 + y / M_PER_DEG_LAT, 7)]


# --------------------------------------------------------------------------
# the town

def build_blocks():
    """Return a list of blocks: dict(name, lots=[(row_tag, ring_in_metres)],
    area=nominal area in m2, use=default use)."""
    blocks = []

    def add(name, local_lots, tf, area, use="residential"):
        rings = node([r for _, r in local_lots])
        lots = []
        for (tag, _), r in zip(local_lots, rings):
            lots.append((tag, ccw([to_metres(tf, p) for p in r])))
        blocks.append(dict(name=name, lots=lots, area=area, use=use))

    # row 1 (south), all blocks end at y = 100
    add("B1 rectangle 160x80", two_rows(0, 0, 160, 80), translate(0, 20), 160 * 80)
    add("B2 rectangle 100x100", two_rows(0, 0, 100, 100), translate(176, 0), 100 * 100)
    add("B3 rectangle 120x90, jittered rear line",
        two_rows(0, 0, 120, 90, jitter=6.0), translate(290, 10), 120 * 90)

    # row 2, starts at y = 116
    # L = [0,160] x [0,60] plus [0,70] x [60,120]; the upper arm's lots run
    # north-south, fronting the west street and the inner corner of the L.
    l1 = two_rows(0, 0, 160, 60)
    l2 = [(t, [(x, y + 60.0) for x, y in r]) for t, r in two_rows(0, 0, 60, 70, swap=True)]
    add("B4 L-shape", l1 + l2, translate(0, 116), 160 * 60 + 70 * 60)

    court = (one_row(0, 0, 120, 40) + one_row(0, 80, 120, 40) +
             one_row(40, 0, 40, 40, swap=True) + one_row(40, 80, 40, 40, swap=True))
    add("B5 courtyard 120x120 around a 40x40 yard", court, translate(176, 116),
        120 * 120 - 40 * 40)

    quad = [(312.0, 116.0), (428.0, 116.0), (412.0, 236.0), (314.0, 234.0)]
    add("B6 irregular quadrilateral", two_rows(0, 0, 107, 118, jitter=5.0),
        bilinear(107, 118, *quad), abs(signed_area(quad)))

    # row 3, starts at y = 252
    add("B7 rectangle 140x70 rotated 20 deg", two_rows(0, 0, 140, 70),
        rotate_about(84, 310, 70, 35, 20.0), 140 * 70)
    add("B8 rectangle 80x160 (long axis north-south), jittered rear line",
        two_rows(0, 0, 160, 80, jitter=6.0, swap=True), translate(180, 252), 80 * 160)
    add("B9 rectangle 140x60", two_rows(0, 0, 140, 60), translate(276, 252),
        140 * 60, use="commercial")
    add("B10 rectangle 140x80", two_rows(0, 0, 140, 80), translate(276, 328), 140 * 80)
    return blocks


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    out_path = os.path.join(here, "sample", "sample_town.geojson")

    blocks = build_blocks()

    # right-of-way: fills the 16 m street gap between B1 (x 0..160, y 20..100)
    # and B2 (x 176..276, y 0..100) along B1's whole east side.
    row = [to_metres(translate(0, 0), p) for p in
           [(160.0, 20.0), (176.0, 20.0), (176.0, 100.0), (160.0, 100.0)]]
    b12 = blocks[0]["lots"] + blocks[1]["lots"]
    noded = node([row] + [r for _, r in b12])
    row = ccw(noded[0])
    k = 1
    for b in blocks[:2]:
        b["lots"] = [(t, noded[k + i]) for i, (t, _) in enumerate(b["lots"])]
        k += len(b["lots"])

    # ---- checks on the clean tiling
    for b in blocks:
        total = 0.0
        for _, r in b["lots"]:
            assert is_simple(r), (b["name"], r)
            assert signed_area(r) > 0
            total += signed_area(r)
        assert abs(total - b["area"]) < 1.0, (b["name"], total, b["area"])
    assert is_simple(row)

    # ---- choose the lots that carry the quirks (deterministic)
    def four_vertex(bi):
        return [i for i, (_, r) in enumerate(blocks[bi]["lots"]) if len(r) == 4]

    # bow-tie: a plain 4-vertex lot in B2
    bow = (1, rng.choice(four_vertex(1)))
    # lot with a 4x4 m hole: a large lot in B10 (axis-aligned, no jitter)
    cand = [i for i, (_, r) in enumerate(blocks[9]["lots"]) if signed_area(r) > 500]
    hole_lot = (9, rng.choice(cand))
    # multipolygon: front-row lots i and i+2 of B1 (never touching)
    fr = [i for i, (t, _) in enumerate(blocks[0]["lots"]) if t == "front"]
    j = rng.randrange(1, len(fr) - 3)
    multi = (0, fr[j], fr[j + 2])
    # condominium stack (original + 3 copies): a lot in B8
    stack = (7, rng.randrange(len(blocks[7]["lots"])))
    # one park lot in B4
    park = (3, rng.randrange(len(blocks[3]["lots"])))
    # commercial frontage: the front row of B3
    # (B9 is all commercial via its block default)

    def poly(rings):
        return [[to_lonlat(p) for p in r + [r[0]]] for r in rings]

    feats = []  # (geometry, use, unit)
    stats = dict(null=0, multipolygon=0, invalid=0, with_hole=0, duplicates=0, row=0)
    for bi, b in enumerate(blocks):
        for li, (tag, r) in enumerate(b["lots"]):
            use = b["use"]
            if bi == 2 and tag == "front":
                use = "commercial"
            if (bi, li) == park:
                use = "park"
            if bi == multi[0] and li == multi[2]:
                continue  # emitted as the second part of the multipolygon
            if bi == multi[0] and li == multi[1]:
                other = b["lots"][multi[2]][1]
                geom = {"type": "MultiPolygon", "coordinates": [poly([r]), poly([other])]}
                stats["multipolygon"] += 1
                feats.append((geom, use, 0))
                continue
            rings = [r]
            if (bi, li) == bow:
                r2 = list(r)
                r2[1], r2[2] = r2[2], r2[1]
                assert not is_simple(r2)
                rings = [r2]
                stats["invalid"] += 1
            if (bi, li) == hole_lot:
                cx, cy = centroid(r)
                cx, cy = round(cx, 2), round(cy, 2)
                h = [(cx - 2, cy - 2), (cx - 2, cy + 2), (cx + 2, cy + 2), (cx + 2, cy - 2)]
                assert signed_area(h) < 0  # clockwise
                for p in h:
                    assert point_in_ring(p, r)
                    assert min(dist_point_segment(p, r[i], r[(i + 1) % len(r)])
                               for i in range(len(r))) > 1.0
                rings = [r, h]
                stats["with_hole"] += 1
            geom = {"type": "Polygon", "coordinates": poly(rings)}
            feats.append((geom, use, 0))
            if (bi, li) == stack:
                for unit in (1, 2, 3):
                    feats.append((geom, use, unit))
                    stats["duplicates"] += 1
        if bi == 1:
            feats.append(({"type": "Polygon", "coordinates": poly([row])}, "ROW", 0))
            stats["row"] += 1
        if bi == 5:
            # a parcel record whose geometry is missing
            feats.append((None, "residential", 0))
            stats["null"] += 1

    features = []
    for n, (geom, use, unit) in enumerate(feats, 1):
        features.append({
            "type": "Feature",
            "properties": {"parcel_id": "S-%04d" % n, "use": use, "unit": unit},
            "geometry": geom,
        })

    os.makedirs(os.path.dirname(out_path), exist_ok=True)
    with open(out_path, "w", encoding="utf-8", newline="\n") as f:
        f.write('{"type":"FeatureCollection","features":[\n')
        f.write(",\n".join(json.dumps(ft, separators=(",", ":")) for ft in features))
        f.write("\n]}\n")

    print("features: %d" % len(features))
    for key in ("null", "multipolygon", "invalid", "with_hole", "duplicates", "row"):
        print("%s: %d" % (key, stats[key]))
    print("blocks: %d" % len(blocks))
    print("lots (clean tiling, before quirks): %d" % sum(len(b["lots"]) for b in blocks))
    print("wrote %s" % os.path.relpath(out_path))
    write_streets(os.path.join(here, "sample", "sample_streets.geojson"))


# Street centre lines in the town's metres (before the shift): the middle of
# each gap between blocks, a ring road around the town, a cul-de-sac into B5's
# courtyard side. (name, width in m, points)
STREETS = [
    ("Ring Road", 12.0, [(-8, -8), (440, -8), (440, 420), (-8, 420), (-8, -8)]),
    ("First Street", 16.0, [(-8, 108), (440, 108)]),
    ("Second Street", 16.0, [(-8, 244), (440, 244)]),
    ("Main Street", 16.0, [(168, -8), (168, 420)]),
    ("Mill Lane", 14.0, [(283, -8), (283, 108)]),
    ("Orchard Lane", 16.0, [(304, 108), (304, 244)]),
    ("Church Lane", 16.0, [(268, 244), (268, 420)]),
    ("Market Street", 16.0, [(268, 320), (440, 320)]),
    ("Court Close", 8.0, [(304, 176), (272, 176)]),
]


def write_streets(path):
    features = []
    for n, (name, width, points) in enumerate(STREETS, 1):
        features.append({
            "type": "Feature",
            "properties": {"street_id": "R-%02d" % n, "name": name, "width": width},
            "geometry": {"type": "LineString",
                         "coordinates": [to_lonlat(to_metres(translate(0, 0), p)) for p in points]},
        })
    with open(path, "w", encoding="utf-8", newline="\n") as f:
        f.write('{"type":"FeatureCollection","features":[\n')
        f.write(",\n".join(json.dumps(ft, separators=(",", ":")) for ft in features))
        f.write("\n]}\n")
    print("wrote %s (%d street centre lines)" % (os.path.relpath(path), len(features)))


if __name__ == "__main__":
    main()
