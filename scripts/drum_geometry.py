#!/usr/bin/env python3
"""Triangles of the rotating drum of the open-source DEM comparison (Dosta et al. 2024, case 2).

Usage: python3 scripts/drum_geometry.py --out validation/cases/drum/drum.stl [options]

Writes the drum's inner surface as one closed binary STL: a cylinder about the y axis
(inner radius R, from y = -W/2 to y = +W/2) and the two flat end plates at y = -W/2 and
y = +W/2, normals pointing out of the cavity. Defaults are the benchmark's dimensions
(reference/DRUM.md): R = 0.1 m, W = 0.06 m, 100 divisions around the axis with the vertices
on the circle of radius R, as in the benchmark's own triangles (MercuryDPM's
`Drum/walls.txt`). Those triangles also carry a 2 mm outer shell, which grains never touch;
this surface has none, because cgdem meets it as a mesh (`contact = "mesh"`: the closest
point of a face, an edge or a vertex, no inside needed). The cylinder is cut into rings at
most --max-edge long along the axis, and each end plate into rings at most --max-edge apart
radially, so that no triangle grains touch is a long sliver.
"""
import argparse
import math
import os
import struct


def ring_positions(length, max_edge):
    """0 .. length in equal pieces at most max_edge long."""
    n = max(1, math.ceil(length / max_edge - 1e-9))
    return [length * i / n for i in range(n + 1)]


def drum_triangles(radius, width, segments, max_edge):
    """(normal, a, b, c) of every triangle, counter-clockwise seen from outside the cavity."""
    tris = []
    angles = [2.0 * math.pi * k / segments for k in range(segments)]
    # the point at angle t on a circle of radius r in the x-z plane, at height y
    def p(r, t, y):
        return (r * math.cos(t), y, r * math.sin(t))

    half = 0.5 * width
    ys = [-half + s for s in ring_positions(width, max_edge)]
    for k in range(segments):
        t0, t1 = angles[k], angles[(k + 1) % segments]
        for j in range(len(ys) - 1):
            y0, y1 = ys[j], ys[j + 1]
            a, b, c, d = p(radius, t0, y0), p(radius, t1, y0), p(radius, t1, y1), p(radius, t0, y1)
            tris.append(oriented(a, b, c, outward=mid_radial(t0, t1)))
            tris.append(oriented(a, c, d, outward=mid_radial(t0, t1)))
    radii = ring_positions(radius, max_edge)
    for y, sign in ((-half, -1.0), (half, 1.0)):
        out = (0.0, sign, 0.0)
        for k in range(segments):
            t0, t1 = angles[k], angles[(k + 1) % segments]
            for j in range(len(radii) - 1):
                r0, r1 = radii[j], radii[j + 1]
                if r0 == 0.0:
                    tris.append(oriented((0.0, y, 0.0), p(r1, t0, y), p(r1, t1, y), outward=out))
                    continue
                a, b, c, d = p(r0, t0, y), p(r0, t1, y), p(r1, t1, y), p(r1, t0, y)
                tris.append(oriented(a, b, c, outward=out))
                tris.append(oriented(a, c, d, outward=out))
    return tris


def mid_radial(t0, t1):
    t = 0.5 * (t0 + t1) if t1 > t0 else 0.5 * (t0 + t1 + 2.0 * math.pi)
    return (math.cos(t), 0.0, math.sin(t))


def sub(u, v):
    return (u[0] - v[0], u[1] - v[1], u[2] - v[2])


def cross(u, v):
    return (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])


def oriented(a, b, c, outward):
    """The triangle with its vertices ordered so that its normal points along `outward`."""
    n = cross(sub(b, a), sub(c, a))
    if sum(n[i] * outward[i] for i in range(3)) < 0.0:
        b, c = c, b
        n = (-n[0], -n[1], -n[2])
    norm = math.sqrt(sum(x * x for x in n))
    return (tuple(x / norm for x in n), a, b, c)


def write_stl(path, tris, name):
    with open(path, "wb") as f:
        f.write(name.encode("ascii")[:80].ljust(80, b" "))
        f.write(struct.pack("<I", len(tris)))
        for n, a, b, c in tris:
            f.write(struct.pack("<12fH", *n, *a, *b, *c, 0))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", required=True, help="the STL file to write")
    ap.add_argument("--radius", type=float, default=0.1, help="inner radius, m (0.1)")
    ap.add_argument("--width", type=float, default=0.06, help="inner depth along the axis, m (0.06)")
    ap.add_argument("--segments", type=int, default=100, help="divisions around the axis (100)")
    ap.add_argument("--max-edge", type=float, default=0.01, help="ring spacing, m (0.01)")
    args = ap.parse_args()
    tris = drum_triangles(args.radius, args.width, args.segments, args.max_edge)
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    name = "drum R=%g W=%g segments=%d (Dosta et al. 2024, case 2)" % (args.radius, args.width, args.segments)
    write_stl(args.out, tris, name)
    print("wrote %s: %d triangles" % (args.out, len(tris)))


if __name__ == "__main__":
    main()
