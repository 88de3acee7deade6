#!/usr/bin/env python3
"""Draws one frame of a cgdem VTK series from what meshio reads (not from cgdem): the
particles as circles of their radius coloured by speed, and the bodies' triangles in their
pose, seen from the side (x-z) and along the axis (y-z).

usage: vtk_frame_figure.py RUN_DIR OUT.png [FRAME]   (FRAME: index in particles.pvd, default last)

reports/vtk/frame-meshio.png is made by
  bash scripts/check-vtk-meshio.sh
  python3 scripts/vtk_frame_figure.py target/vtk-meshio/screw reports/vtk/frame-meshio.png
"""
import pathlib
import sys
import xml.etree.ElementTree as ET

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import meshio  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import EllipseCollection, PolyCollection  # noqa: E402


def series(pvd):
    root = ET.parse(pvd).getroot()
    return [(float(d.get("timestep")), pvd.parent / d.get("file")) for d in root.iter("DataSet")]


def main():
    run, out = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
    index = int(sys.argv[3]) if len(sys.argv) > 3 else -1
    vtk = run / "vtk"
    time, particles_file = series(vtk / "particles.pvd")[index]
    p = meshio.read(particles_file)
    radius = p.point_data["radius"].reshape(-1)
    speed = np.linalg.norm(p.point_data["velocity"], axis=1)
    bodies = None
    if (vtk / "bodies.pvd").exists():
        b = meshio.read(series(vtk / "bodies.pvd")[index][1])
        tri = [c.data for c in b.cells if c.type == "triangle"][0]
        bodies = b.points[tri]  # (n, 3, 3)
    fig, axes = plt.subplots(1, 2, figsize=(12, 5), gridspec_kw={"width_ratios": [2.2, 1]})
    for ax, (h, v, name) in zip(axes, [(0, 2, "side (x-z)"), (1, 2, "along the axis (y-z)")]):
        if bodies is not None:
            ax.add_collection(PolyCollection(bodies[:, :, [h, v]], facecolor="0.85",
                                             edgecolor="0.6", linewidth=0.1, zorder=1))
        # Far particles first, so the near ones are drawn over them.
        depth = 1 if h == 0 else 0
        order = np.argsort(-p.points[:, depth])
        circles = EllipseCollection(2 * radius[order], 2 * radius[order], 0.0, units="xy",
                                    offsets=p.points[order][:, [h, v]],
                                    offset_transform=ax.transData, array=speed[order],
                                    cmap="viridis", edgecolor="k", linewidth=0.2, zorder=2)
        ax.add_collection(circles)
        pts = p.points[:, [h, v]]
        if bodies is not None:
            pts = np.vstack([pts, bodies[:, :, [h, v]].reshape(-1, 2)])
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        pad = 0.03 * (hi - lo).max()
        ax.set_xlim(lo[0] - pad, hi[0] + pad)
        ax.set_ylim(lo[1] - pad, hi[1] + pad)
        ax.set_aspect("equal")
        ax.set_xlabel(["x", "y", "z"][h] + " (m)")
        ax.set_ylabel(["x", "y", "z"][v] + " (m)")
        ax.set_title(name)
    fig.colorbar(circles, ax=axes, label="speed (m/s)", shrink=0.8)
    fig.suptitle(f"{run.name}: {particles_file.name} at t = {time:.4g} s, {len(radius)} particles"
                 + (f", {len(bodies)} body triangles" if bodies is not None else "")
                 + f" (read by meshio {meshio.__version__})")
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
