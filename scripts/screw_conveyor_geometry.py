#!/usr/bin/env python3
"""Triangles of a long screw conveyor: a U-shaped trough and a screw, as a CAD export gives them.

Usage: python3 scripts/screw_conveyor_geometry.py --out DIR [--length 5.0] [options]

Writes DIR/trough.stl and DIR/screw.stl (binary STL, metres) and prints each mesh's triangle
count and area. The screw's axis is the x axis, from x = 0 to x = --length.

- The trough: a half cylinder of radius R below the axis, two flat sides from the axis up
  to --side-height, and an end plate of the same U at each end. One sheet (a surface, not a
  solid), as meshes of equipment are often exported; cgdem meets it on its triangles
  (`contact = "mesh"`), as LIGGGHTS meets a `fix mesh/surface`.
- The screw: a shaft (a tube, open at its ends) and a flight of the given thickness, its two
  helicoid faces joined along the tip by a strip; the flight's root lies inside the shaft.

The defaults make a conveyor of 0.4 m bore, 5 m long (2500 diameters of a 2 mm grain),
with about 11 m2 of triangles: the scene of real-equipment size in
validation/cases/screw_conveyor_long.toml and reports/exact_walls/NOTE.md. Its SDF grid
would need billions of cells at a quarter of a grain's diameter.
"""
import argparse
import math
import os
import struct


def cross(a, b, c):
    """(b - a) x (c - a): the triangle's normal times twice its area."""
    u = [b[i] - a[i] for i in range(3)]
    v = [c[i] - a[i] for i in range(3)]
    return [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]


def write_stl(path, triangles, name):
    """Binary STL: an 80-byte header, the count, then per triangle a normal and 3 corners."""
    with open(path, "wb") as f:
        f.write(name.encode()[:80].ljust(80, b" "))
        f.write(struct.pack("<I", len(triangles)))
        for a, b, c in triangles:
            n = cross(a, b, c)
            length = math.sqrt(sum(x * x for x in n)) or 1.0
            f.write(struct.pack("<3f", *(x / length for x in n)))
            for p in (a, b, c):
                f.write(struct.pack("<3f", *p))
            f.write(b"\0\0")


def area(triangles):
    return sum(0.5 * math.sqrt(sum(x * x for x in cross(*t))) for t in triangles)


def grid(rows, cols, point):
    """Two triangles per cell of a (rows x cols) patch of points point(i, j)."""
    tris = []
    for i in range(rows):
        for j in range(cols):
            a, b = point(i, j), point(i + 1, j)
            c, d = point(i + 1, j + 1), point(i, j + 1)
            tris += [(a, b, c), (a, c, d)]
    return tris


def u_outline(radius, side_height, arc_segments, side_segments):
    """The trough's cross-section (y, z), from the top of one side round to the other."""
    pts = [(radius, side_height * (1 - k / side_segments)) for k in range(side_segments)]
    for k in range(arc_segments + 1):
        phi = -math.pi * k / arc_segments  # from +y down through -z to -y
        pts.append((radius * math.cos(phi), radius * math.sin(phi)))
    pts += [(-radius, side_height * k / side_segments) for k in range(1, side_segments + 1)]
    return pts


def trough(args):
    outline = u_outline(args.trough_radius, args.side_height, args.arc_segments, 8)
    rings = max(1, math.ceil(args.length / args.axial_step))
    xs = [args.length * k / rings for k in range(rings + 1)]
    tris = grid(rings, len(outline) - 1, lambda i, j: (xs[i], outline[j][0], outline[j][1]))
    # End plates: the U closed by its top edge (a convex outline), fanned from a point inside.
    centre = (0.0, 0.5 * (args.side_height - args.trough_radius))
    for x, flip in ((0.0, False), (args.length, True)):
        ring = outline + [outline[0]]
        for p, q in zip(ring, ring[1:]):
            t = ((x, centre[0], centre[1]), (x, p[0], p[1]), (x, q[0], q[1]))
            tris.append((t[0], t[2], t[1]) if flip else t)
    return tris


def screw(args):
    r_shaft, r_tip = 0.5 * args.shaft_diameter, 0.5 * args.screw_diameter
    x0, x1 = args.flight_gap, args.length - args.flight_gap
    turns = (x1 - x0) / args.pitch
    steps = max(1, math.ceil(turns * args.segments_per_turn))
    around = args.segments_per_turn
    rings = max(1, math.ceil(args.length / args.axial_step))
    # The shaft: a tube from end to end.
    tris = grid(
        rings,
        around,
        lambda i, j: (
            args.length * i / rings,
            r_shaft * math.cos(2 * math.pi * j / around),
            r_shaft * math.sin(2 * math.pi * j / around),
        ),
    )
    # The flight: two helicoid faces half a thickness either side of the centre helix, from
    # a root 2 mm inside the shaft to the tip, and the strip along the tip between them.
    r_root = r_shaft - 0.002
    radial = args.radial_segments

    def face(offset):
        def point(i, j):
            s = i / steps
            angle = 2 * math.pi * turns * s
            r = r_root + (r_tip - r_root) * j / radial
            return (x0 + (x1 - x0) * s + offset, r * math.cos(angle), r * math.sin(angle))

        return point

    half = 0.5 * args.flight_thickness
    back, front = face(-half), face(half)
    tris += grid(steps, radial, back)
    tris += [(a, c, b) for a, b, c in grid(steps, radial, front)]
    tris += grid(steps, 1, lambda i, j: back(i, radial) if j == 0 else front(i, radial))
    return tris


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--out", required=True)
    p.add_argument("--length", type=float, default=5.0, help="m, along x")
    p.add_argument("--trough-radius", type=float, default=0.2, help="m")
    p.add_argument("--side-height", type=float, default=0.3, help="m above the axis")
    p.add_argument("--screw-diameter", type=float, default=0.38, help="m, flight tip")
    p.add_argument("--shaft-diameter", type=float, default=0.1, help="m")
    p.add_argument("--pitch", type=float, default=0.3, help="m")
    p.add_argument("--flight-thickness", type=float, default=0.008, help="m")
    p.add_argument("--flight-gap", type=float, default=0.02, help="m from each end plate")
    p.add_argument("--segments-per-turn", type=int, default=96)
    p.add_argument("--radial-segments", type=int, default=8)
    p.add_argument("--arc-segments", type=int, default=64, help="round the trough's bottom")
    p.add_argument("--axial-step", type=float, default=0.02, help="m between rings")
    args = p.parse_args()
    if args.screw_diameter >= 2 * args.trough_radius or args.shaft_diameter >= args.screw_diameter:
        p.error("need shaft diameter < screw diameter < trough diameter")
    os.makedirs(args.out, exist_ok=True)
    for name, tris in (("trough", trough(args)), ("screw", screw(args))):
        write_stl(os.path.join(args.out, name + ".stl"), tris, name)
        print(f"{name}.stl: {len(tris)} triangles, {area(tris):.3f} m2")


if __name__ == "__main__":
    main()
