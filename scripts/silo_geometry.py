#!/usr/bin/env python3
"""Triangles of the silo of the open-source DEM comparison (Dosta et al. 2024, case 1).

Usage: python3 scripts/silo_geometry.py --out DIR [--orifice-diameter 0.04] [options]
       python3 scripts/silo_geometry.py --preset cases --out validation/cases/silo

Writes DIR/NAME.stl (NAME = --name, default silo): the silo wall as one closed solid of
revolution about the z axis (a cylinder on a conical hopper, open at the top and at the
orifice), the same triangles for cgdem (an SDF body) and LIGGGHTS (`fix mesh/surface`). With
--fill-top Z it also writes DIR/NAME_fill.stl, the silo's inside from the orifice plane to
z = Z, closed: cgdem's `[[insert]] mesh` (positions inside it by one radius). `--preset
cases` writes the meshes validation/cases/silo*.toml used before the silo was built in: the
cases now take `silo:wall` / `silo:fill` from their `[silo]` table
(crates/cgdem-core/src/geometry/silo.rs), whose test checks that it gives these files'
triangles (validation/cases/silo/*.stl, kept as that reference).

Dimensions (defaults: the benchmark's, reference/silo/SOURCE.md): inner radius R, hopper
half-angle 45 deg from the vertical down to the orifice radius r0 at z = z0, cylinder of
height H above the hopper. The wall is a shell of horizontal thickness t (the benchmark's
triangles are 2 mm thick; 10 mm here so an SDF grid of a few mm resolves it); the orifice
lip is the flat ring from r0 to r0 + t at z0, as in the benchmark's files. The inner
surfaces are cut into rings at most --max-edge apart, so no triangle grains touch is a long
sliver (LIGGGHTS bins triangles by their bounding boxes); the outer ones, which no grain
touches, at four times that.
"""
import argparse
import math
import os
import struct
import sys

# The benchmark's orifice heights (its walls files, OSSilo.cpp getOrificeHeight): the frame
# of its particle files, kept so that heights compare directly.
BENCHMARK_ORIFICE_Z = {0.04: -0.0593008, 0.06: -0.0554222}


def profile_points(outline, max_edges):
    """Splits edge i of the closed (r, z) outline into pieces at most max_edges[i] long."""
    pts = []
    for i, a in enumerate(outline):
        b = outline[(i + 1) % len(outline)]
        n = max(1, math.ceil(math.dist(a, b) / max_edges[i]))
        for k in range(n):
            s = k / n
            pts.append((a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1])))
    return pts


def revolve(outline, segments, max_edges):
    """Triangles of the closed outline (r, z) turned about z. Points on the axis (r = 0)
    become one vertex, so the surface is closed there (fans instead of quads)."""
    pts = profile_points(outline, max_edges)
    angles = [2.0 * math.pi * j / segments for j in range(segments)]

    def vertex(p, j):
        r, z = p
        c, s = math.cos(angles[j % segments]), math.sin(angles[j % segments])
        return (r * c, r * s, z)

    tris = []
    for i, a in enumerate(pts):
        b = pts[(i + 1) % len(pts)]
        for j in range(segments):
            a0, a1, b0, b1 = vertex(a, j), vertex(a, j + 1), vertex(b, j), vertex(b, j + 1)
            if a[0] > 0.0:
                tris.append((a0, b0, a1))
            if b[0] > 0.0:
                tris.append((a1, b0, b1))
    return tris


def signed_volume(tris):
    return sum(
        a[0] * (b[1] * c[2] - b[2] * c[1])
        - a[1] * (b[0] * c[2] - b[2] * c[0])
        + a[2] * (b[0] * c[1] - b[1] * c[0])
        for a, b, c in tris
    ) / 6.0


def unit_normal(a, b, c):
    u = [b[k] - a[k] for k in range(3)]
    v = [c[k] - a[k] for k in range(3)]
    n = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
    length = math.sqrt(sum(x * x for x in n)) or 1.0
    return [x / length for x in n]


def write_stl(path, tris, name, binary, header):
    """STL with outward normals: ASCII (LIGGGHTS 3.8 reads only ASCII) or binary (a third of
    the size, for the case files; the harness writes LIGGGHTS's ASCII from the same
    triangles). The binary header holds `header`, the command's parameters."""
    if signed_volume(tris) < 0.0:
        tris = [(a, c, b) for a, b, c in tris]
    if binary:
        # Vertices as f32, what the format holds; 80-byte header, then the count.
        with open(path, "wb") as f:
            f.write(header.encode("ascii")[:80].ljust(80, b" "))
            f.write(struct.pack("<I", len(tris)))
            for a, b, c in tris:
                f.write(struct.pack("<12fH", *unit_normal(a, b, c), *a, *b, *c, 0))
        return len(tris)
    with open(path, "w") as f:
        f.write(f"solid {name}\n")
        for a, b, c in tris:
            f.write("  facet normal {:.9e} {:.9e} {:.9e}\n    outer loop\n".format(*unit_normal(a, b, c)))
            for p in (a, b, c):
                f.write("      vertex {:.9e} {:.9e} {:.9e}\n".format(*p))
            f.write("    endloop\n  endfacet\n")
        f.write(f"endsolid {name}\n")
    return len(tris)


# The case files' meshes: (name, orifice diameter, cylinder height, fill top above the hopper,
# ring spacing), all with z0 = 0, 96 divisions, binary.
PRESET_CASES = [
    ("full_d40", 0.04, 0.45, 0.40, 0.02),
    ("full_d60", 0.06, 0.45, 0.40, 0.02),
    ("reduced_d40", 0.04, 0.12, 0.08, 0.01),
    ("reduced_d60", 0.06, 0.12, 0.08, 0.01),
]


def main():
    if "--preset" in sys.argv:
        ap = argparse.ArgumentParser()
        ap.add_argument("--preset", choices=["cases"], required=True)
        ap.add_argument("--out", required=True)
        a = ap.parse_args()
        for name, d0, height, fill, edge in PRESET_CASES:
            hopper_top = 0.1 - d0 / 2  # 45 deg, R = 0.1 m, z0 = 0
            args = ["--out", a.out, "--name", name, "--orifice-diameter", str(d0), "--orifice-z", "0",
                    "--cylinder-height", str(height), "--fill-top", f"{hopper_top + fill:.6g}",
                    "--segments", "96", "--max-edge", str(edge), "--binary"]
            sys.argv = [sys.argv[0]] + args
            main()
        return
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", required=True)
    ap.add_argument("--silo-diameter", type=float, default=0.2, help="inner diameter 2R, m")
    ap.add_argument("--orifice-diameter", type=float, default=0.04, help="D0 = 2 r0, m")
    ap.add_argument("--hopper-half-angle", type=float, default=45.0, help="from the vertical, deg")
    ap.add_argument("--cylinder-height", type=float, default=0.3, help="H above the hopper, m")
    ap.add_argument("--orifice-z", type=float, help="z0, m (default: the benchmark's for D0 = 0.04 / 0.06 m, else 0)")
    ap.add_argument("--wall-thickness", type=float, default=0.01, help="t, horizontal, m")
    ap.add_argument("--segments", type=int, default=128, help="around the axis")
    ap.add_argument("--max-edge", type=float, default=0.01, help="ring spacing along the outline, m")
    ap.add_argument("--fill-top", type=float, help="also write fill.stl up to this z, m")
    ap.add_argument("--binary", action="store_true", help="binary STL (default ASCII)")
    ap.add_argument("--name", default="silo", help="file name stem: NAME.stl (and NAME_fill.stl)")
    a = ap.parse_args()

    R, r0, t, H = a.silo_diameter / 2, a.orifice_diameter / 2, a.wall_thickness, a.cylinder_height
    if not (0 < r0 < R and t > 0 and H > 0 and 0 < a.hopper_half_angle < 90 and a.segments >= 8 and a.max_edge > 0):
        sys.exit("silo_geometry.py: need 0 < orifice < silo diameter, positive thickness, height and max-edge, "
                 "0 < half-angle < 90 deg and at least 8 segments")
    z0 = a.orifice_z
    if z0 is None:
        z0 = next((z for d, z in BENCHMARK_ORIFICE_Z.items() if abs(d - a.orifice_diameter) < 1e-12 and abs(R - 0.1) < 1e-12), 0.0)
    z_hopper_top = z0 + (R - r0) / math.tan(math.radians(a.hopper_half_angle))
    z_top = z_hopper_top + H

    # The wall's cross-section: inner surface up, rim, outer surface down, lip.
    wall = [(r0, z0), (R, z_hopper_top), (R, z_top), (R + t, z_top), (R + t, z_hopper_top), (r0 + t, z0)]
    edges = [a.max_edge, a.max_edge] + [4 * a.max_edge] * 3 + [a.max_edge]
    os.makedirs(a.out, exist_ok=True)
    header = (f"silo_geometry.py D={a.silo_diameter:g} D0={a.orifice_diameter:g} z0={z0:.7g} "
              f"a={a.hopper_half_angle:g} H={H:g} t={t:g} n={a.segments} e={a.max_edge:g}")
    n = write_stl(os.path.join(a.out, f"{a.name}.stl"), revolve(wall, a.segments, edges), a.name, a.binary, header)
    print(f"{a.name}.stl: {n} triangles; orifice r0 = {r0:g} m at z0 = {z0:.7g} m, hopper top z = {z_hopper_top:.7g} m, "
          f"rim z = {z_top:.7g} m, inner radius {R:g} m, wall {t:g} m")
    if a.fill_top is not None:
        if not z_hopper_top < a.fill_top <= z_top:
            sys.exit(f"silo_geometry.py: --fill-top must lie in the cylinder, ({z_hopper_top:.6g}, {z_top:.6g}] m")
        fill = [(0.0, z0), (r0, z0), (R, z_hopper_top), (R, a.fill_top), (0.0, a.fill_top)]
        n = write_stl(os.path.join(a.out, f"{a.name}_fill.stl"), revolve(fill, a.segments, [4 * a.max_edge] * len(fill)),
                      f"{a.name}_fill", a.binary, header + f" fill={a.fill_top:g}")
        print(f"{a.name}_fill.stl: {n} triangles, z0 .. {a.fill_top:g} m")


if __name__ == "__main__":
    main()
