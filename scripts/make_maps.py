#!/usr/bin/python3
"""Draws the bundled maps in maps/ reproducibly (standard library only).

Each map is drawn as axis-aligned rectangles on a raster of RES metres: free space is
added (`free`) or removed (`wall`). The free cells are traced into rings (the outer
boundary counter-clockwise, holes clockwise, collinear vertices merged), checked
(one connected free region, no pinch points, so no ring touches another, no crossing
edges) and written as `.poly` files. Run from anywhere:

    /usr/bin/python3 scripts/make_maps.py [output_dir]
"""

import os
import sys

RES = 0.05  # raster cell [m]; every coordinate is a multiple of it


class Raster:
    """A boolean grid of free cells over [0, width] x [0, height] [m]."""

    def __init__(self, width, height):
        self.nx = int(round(width / RES))
        self.ny = int(round(height / RES))
        self.cells = [[False] * self.ny for _ in range(self.nx)]

    def _span(self, x0, y0, x1, y1):
        i0, i1 = int(round(x0 / RES)), int(round(x1 / RES))
        j0, j1 = int(round(y0 / RES)), int(round(y1 / RES))
        if not (0 <= i0 < i1 <= self.nx and 0 <= j0 < j1 <= self.ny):
            raise ValueError("rectangle %r outside the raster" % ((x0, y0, x1, y1),))
        return i0, i1, j0, j1

    def set(self, rect, value):
        i0, i1, j0, j1 = self._span(*rect)
        for i in range(i0, i1):
            column = self.cells[i]
            for j in range(j0, j1):
                column[j] = value

    def free(self, *rects):
        for rect in rects:
            self.set(rect, True)

    def wall(self, *rects):
        for rect in rects:
            self.set(rect, False)

    def at(self, i, j):
        return 0 <= i < self.nx and 0 <= j < self.ny and self.cells[i][j]


def check_connected(raster):
    """Raises unless the free cells form one 4-connected region."""
    seen = set()
    start = next(((i, j) for i in range(raster.nx) for j in range(raster.ny) if raster.cells[i][j]), None)
    if start is None:
        raise ValueError("no free space")
    stack = [start]
    seen.add(start)
    while stack:
        i, j = stack.pop()
        for n in ((i + 1, j), (i - 1, j), (i, j + 1), (i, j - 1)):
            if n not in seen and raster.at(*n):
                seen.add(n)
                stack.append(n)
    total = sum(sum(1 for v in column if v) for column in raster.cells)
    if len(seen) != total:
        raise ValueError("free space is not connected (%d of %d cells reachable)" % (len(seen), total))


def trace_rings(raster):
    """Traces the free region's boundary into rings with the free space on the left."""
    outgoing = {}
    for i in range(raster.nx):
        for j in range(raster.ny):
            if not raster.cells[i][j]:
                continue
            sides = (
                ((i, j - 1), (i, j), (i + 1, j)),
                ((i + 1, j), (i + 1, j), (i + 1, j + 1)),
                ((i, j + 1), (i + 1, j + 1), (i, j + 1)),
                ((i - 1, j), (i, j + 1), (i, j)),
            )
            for neighbour, a, b in sides:
                if not raster.at(*neighbour):
                    if a in outgoing:
                        raise ValueError("pinch point at %r (rings would touch)" % ((a[0] * RES, a[1] * RES),))
                    outgoing[a] = b
    rings = []
    while outgoing:
        start, _ = next(iter(outgoing.items()))
        loop = [start]
        v = outgoing.pop(start)
        while v != start:
            loop.append(v)
            v = outgoing.pop(v)
        rings.append(merge_collinear(loop))
    outer = [r for r in rings if area(r) > 0]
    if len(outer) != 1:
        raise ValueError("expected one outer ring, found %d" % len(outer))
    holes = [r for r in rings if area(r) < 0]
    holes.sort(key=lambda r: (min(p[0] for p in r), min(p[1] for p in r)))
    return [outer[0]] + holes


def merge_collinear(loop):
    n = len(loop)
    kept = []
    for k in range(n):
        a, b, c = loop[k - 1], loop[k], loop[(k + 1) % n]
        cross = (b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0])
        if cross != 0:
            kept.append(b)
    # start at the lowest-left vertex so the output is canonical
    first = min(range(len(kept)), key=lambda k: (kept[k][1], kept[k][0]))
    return kept[first:] + kept[:first]


def area(ring):
    s = 0
    for k in range(len(ring)):
        (x0, y0), (x1, y1) = ring[k - 1], ring[k]
        s += x0 * y1 - x1 * y0
    return s / 2.0


def segments_cross(p, q, r, s):
    """True when closed segments pq and rs share a point (integer coordinates)."""
    def orient(a, b, c):
        v = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
        return (v > 0) - (v < 0)

    def on(a, b, c):
        return min(a[0], b[0]) <= c[0] <= max(a[0], b[0]) and min(a[1], b[1]) <= c[1] <= max(a[1], b[1])

    o1, o2, o3, o4 = orient(p, q, r), orient(p, q, s), orient(r, s, p), orient(r, s, q)
    if o1 != o2 and o3 != o4:
        return True
    return (o1 == 0 and on(p, q, r)) or (o2 == 0 and on(p, q, s)) or \
        (o3 == 0 and on(r, s, p)) or (o4 == 0 and on(r, s, q))


def check_rings(rings):
    """Independent check: only consecutive edges of a ring may share a point (their vertex)."""
    edges = []
    for ri, ring in enumerate(rings):
        n = len(ring)
        if n < 4:
            raise ValueError("ring %d has %d vertices" % (ri, n))
        for k in range(n):
            edges.append((ri, k, n, ring[k], ring[(k + 1) % n]))
    for a in range(len(edges)):
        ra, ka, na, p, q = edges[a]
        for b in range(a + 1, len(edges)):
            rb, kb, nb, r, s = edges[b]
            if ra == rb and (kb - ka) % na in (1, na - 1):
                continue
            if segments_cross(p, q, r, s):
                raise ValueError("edges touch: ring %d edge %d and ring %d edge %d" % (ra, ka, rb, kb))


def write_poly(path, rings, comment):
    with open(path, "w") as out:
        for line in comment.strip().splitlines():
            out.write("# %s\n" % line)
        out.write("# Drawn by scripts/make_maps.py (raster %.2f m); units: metres.\n" % RES)
        for ri, ring in enumerate(rings):
            out.write("\n" if ri == 0 else "\n# hole %d\n" % ri)
            for i, j in ring:
                out.write("%s %s\n" % (fmt(i), fmt(j)))


def fmt(k):
    return ("%.2f" % (k * RES)).rstrip("0").rstrip(".") if k else "0"


def shifted(rings, dx, dy):
    """Rings in metres-on-raster units moved by whole cells (used to centre the square)."""
    return [[(i + dx, j + dy) for i, j in ring] for ring in rings]


def door_gaps_h(y0, y1, x_from, x_to, doors):
    """Horizontal wall [x_from, x_to] x [y0, y1] with door gaps (x, width); returns wall rects."""
    return _gapped(x_from, x_to, doors, lambda a, b: (a, y0, b, y1))


def door_gaps_v(x0, x1, y_from, y_to, doors):
    """Vertical wall [x0, x1] x [y_from, y_to] with door gaps (y, width); returns wall rects."""
    return _gapped(y_from, y_to, doors, lambda a, b: (x0, a, x1, b))


def _gapped(start, end, doors, rect):
    pieces = []
    cursor = start
    for pos, width in sorted(doors):
        if pos > cursor:
            pieces.append(rect(cursor, pos))
        cursor = pos + width
    if end > cursor:
        pieces.append(rect(cursor, end))
    return pieces


def square_room():
    r = Raster(2.0, 2.0)
    r.free((0, 0, 2, 2))
    return r, (-40 // 2, -40 // 2), (
        "square_room: a 2 m x 2 m empty square room centred on the origin, like the paper's\n"
        "square room. Symmetric on purpose: every pose has 4 equivalent answers (90 deg turns).")


def l_room():
    r = Raster(4.0, 3.0)
    r.free((0, 0, 4.0, 1.6), (0, 0, 1.8, 3.0))
    return r, (0, 0), "l_room: an L-shaped room, 4 m x 3 m, arms 1.6 m and 1.8 m wide (no symmetry)."


def office():
    t = 0.15
    r = Raster(20.0, 12.0)
    r.free((0, 0, 20, 12))
    # south row of rooms (y 0 .. 4.65) and the corridor's south wall (doors A, B, C, D)
    r.wall(*door_gaps_h(4.65, 4.8, 0, 20, [(3.4, 0.9), (6.0, 0.9), (12.6, 0.9), (15.0, 1.0)]))
    r.wall(*door_gaps_v(5.0, 5.0 + t, 0, 4.65, [(1.0, 0.9)]))  # A | B, connecting door
    r.wall((9.2, 0, 9.2 + t, 4.65), (14.0, 0, 14.0 + t, 4.65))
    r.wall(*door_gaps_v(18.0, 18.0 + t, 0, 2.15, [(0.6, 0.8)]))  # storage closet in D
    r.wall((18.0, 2.0, 20, 2.15))
    # corridor (y 4.8 .. 6.6): a column near its east end
    r.wall((17.8, 5.55, 18.1, 5.85))
    # corridor's north wall and the north row (y 6.75 .. 12)
    r.wall(*door_gaps_h(6.6, 6.75, 0, 20, [(1.2, 1.2), (6.5, 0.9), (10.0, 0.9), (13.2, 0.9), (16.4, 0.9)]))
    r.wall((8.0, 6.75, 8.0 + t, 12), (12.5, 6.75, 12.5 + t, 12), (15.5, 6.75, 15.5 + t, 12))
    # open-plan office: two pillars and a free-standing screen
    r.wall((2.5, 9.0, 2.9, 9.4), (5.5, 9.3, 5.9, 9.7), (1.0, 10.8, 4.0, 10.95))
    # meeting room table, kitchen counter, and room E split in two
    r.wall((9.3, 8.6, 11.3, 9.6), (13.0, 11.4, 15.5, 12))
    r.wall(*door_gaps_h(9.5, 9.65, 15.5 + t, 20, [(18.6, 0.8)]))
    return r, (0, 0), (
        "office: a 20 m x 12 m office floor: a corridor, 5 south rooms (one with a closet),\n"
        "an open-plan office with pillars and a screen, a meeting room with a table, a kitchen\n"
        "and a two-room suite. Walls 0.15 m; doors 0.8 to 1.2 m.")


def warehouse():
    r = Raster(48.0, 31.0)
    r.free((0, 1.0, 48, 31))
    r.free((5.0, 0, 8.5, 1.0), (12.0, 0, 15.5, 1.0), (19.0, 0, 22.5, 1.0), (33.0, 0, 36.5, 1.0))  # loading bays
    # office in the north-west corner, a partition in the north-east
    r.wall(*door_gaps_v(8.0, 8.15, 25.0, 31.0, [(27.0, 1.0)]))
    r.wall(*door_gaps_h(25.0, 25.15, 0, 8.0, [(2.5, 1.0)]))
    r.wall(*door_gaps_h(26.0, 26.1, 38.0, 48.0, [(41.0, 2.5)]))
    # racks 1.2 m deep in 6 rows with 2.6 m aisles; 11 columns with 1 m cross-aisles;
    # lengths vary and some racks are missing, so no two places look alike
    rows = [2.5, 6.3, 10.1, 13.9, 17.7, 21.5]
    missing = {(0, 5), (3, 2), (4, 4), (7, 1), (9, 3), (10, 5), (6, 0), (1, 3)}
    for ri, y in enumerate(rows):
        for ci in range(11):
            if (ci, ri) in missing:
                continue
            x0 = 2.0 + 4.2 * ci
            shorten = 0.3 * ((ri * 5 + ci * 7) % 4)
            r.wall((x0, y, x0 + 3.2 - shorten, y + 1.2))
    # structural columns (0.4 m) at aisle crossings, on an irregular pattern
    for k, (cx, cy) in enumerate([(5.5, 4.9), (13.9, 8.7), (22.3, 4.9), (30.7, 12.5), (39.1, 8.7),
                                  (9.7, 16.3), (26.5, 20.1), (43.3, 16.3), (18.1, 23.9), (35.0, 23.9)]):
        r.wall((cx - 0.2, cy - 0.2, cx + 0.2, cy + 0.2))
    return r, (0, 0), (
        "warehouse: a 48 m x 30 m hall (plus four loading bays) with 58 racks in 6 rows and\n"
        "11 columns, 10 structural columns, an office (north-west) and a partition wall (north-east).")


def corridor():
    r = Raster(40.0, 5.0)
    r.free((0, 1.5, 40, 3.5))
    r.free((3.0, 0.3, 4.5, 1.5), (9.0, 0.8, 11.5, 1.5), (17.2, 0, 18.4, 1.5), (26.0, 0.5, 29.0, 1.5),
           (35.5, 1.0, 36.3, 1.5))
    r.free((6.0, 3.5, 7.0, 4.6), (13.5, 3.5, 16.5, 4.0), (21.0, 3.5, 22.0, 5.0), (31.0, 3.5, 33.5, 4.4),
           (38.5, 3.5, 40.0, 4.8))
    r.wall((27.3, 0.9, 27.6, 1.2))  # a column in the widest alcove
    return r, (0, 0), (
        "corridor: a 40 m x 2 m corridor with ten alcoves of different sizes at irregular\n"
        "positions on both sides, and a column in one alcove.")


def apartment():
    r = Raster(12.0, 9.0)
    r.free((0, 0, 12, 9))
    r.wall(*door_gaps_h(5.0, 5.1, 0, 7.1, [(2.0, 1.6)]))             # living | hall opening
    r.wall(*door_gaps_h(6.3, 6.4, 0, 7.1, [(1.0, 0.9), (5.2, 0.8)]))  # hall | bedroom 1, bath
    r.wall((4.5, 6.4, 4.6, 9.0))                                      # bedroom 1 | bath
    r.wall(*door_gaps_v(7.0, 7.1, 0, 9.0, [(1.5, 1.0), (5.25, 0.9)]))  # living | kitchen, hall | bed 2
    r.wall((7.1, 4.0, 12.0, 4.1))                                     # kitchen | bedroom 2
    r.wall((9.0, 1.6, 10.6, 2.4))                                     # kitchen island
    r.wall((5.5, 3.5, 5.8, 3.8))                                      # column in the living room
    r.wall((11.4, 6.5, 12.0, 8.5))                                    # wardrobe in bedroom 2
    return r, (0, 0), (
        "apartment: a 12 m x 9 m flat: living room, kitchen with an island, hall, two bedrooms\n"
        "and a bathroom. Interior walls 0.1 m; used by the simulator demo.")


MAPS = {
    "square_room": square_room,
    "l_room": l_room,
    "office": office,
    "warehouse": warehouse,
    "corridor": corridor,
    "apartment": apartment,
}


def main():
    out_dir = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "maps")
    os.makedirs(out_dir, exist_ok=True)
    for name, draw in MAPS.items():
        raster, (dx, dy), comment = draw()
        check_connected(raster)
        rings = shifted(trace_rings(raster), dx, dy)
        check_rings(rings)
        path = os.path.join(out_dir, name + ".poly")
        write_poly(path, rings, comment)
        print("%-12s %3d rings %4d vertices -> %s" % (name, len(rings), sum(len(x) for x in rings), path))


if __name__ == "__main__":
    main()
