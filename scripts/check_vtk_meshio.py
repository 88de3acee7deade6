#!/usr/bin/env python3
"""Reads a cgdem run's VTK series with meshio (a reader that is not cgdem's) and checks it
against cgdem's own state; exits 1 with every problem listed.

usage: check_vtk_meshio.py RUN_DIR SCENE.toml

The run must have been made with `--set output.write_data=true`, so that every frame's
particles are also in a LAMMPS data file (`vtk/particles_NNNNNN.data`, written by another
code path: text, from the same state). Checked, per frame:
  - particles.pvd lists the frames; each .vtu holds one vertex cell per point and exactly
    the arrays id, species, radius, velocity, force, coordination_number, plus omega and
    torque when the scene's law rotates (Hertz), each with one value (or 3-vector) per point;
  - the frame's data file has the same time (its title) and the same particles: id + 1 =
    atom-ID, species + 1 = atom type, radius = diameter / 2, points = x y z, velocity =
    vx vy vz, omega = wx wy wz, all exact (%.17e text against float64);
  - coordination_number = the number of particles within the law's reach (Hertz: touching,
    r_i + r_j; WCA: 2^(1/6) sigma), counted here by brute force with periodic images;
  - force = m g and torque = 0 on every particle that touches nothing (no neighbour, more
    than a diameter from every wall plane; m from the data file's diameter and density);
  - kinetic energy (translation + rotation, from the frame's arrays) = the time series'
    kinetic_energy_j at the same time, and the particle count = its n_particles;
  - the last frame: the particle count and id set (0 .. n-1) of summary.json's end state.
  With bodies (bodies.pvd): the same times; the `body` cell array holds each body of the
  scene; a body at rest stays where it was in the first frame with zero velocity; a rotating
  body's vertices are the first frame's turned by rpm * 2 pi / 60 * (t - its start) about its
  axis, and their velocity is omega x (x - point), from the scene file's numbers.
"""
import csv
import json
import math
import pathlib
import sys
import tomllib
import xml.etree.ElementTree as ET

import meshio
import numpy as np

problems = []


def problem(msg):
    problems.append(msg)
    print("FAIL:", msg)


def pvd(path):
    root = ET.parse(path).getroot()
    return [(float(d.get("timestep")), path.parent / d.get("file")) for d in root.iter("DataSet")]


def read_data(path):
    """A LAMMPS data file (atom_style sphere) -> time from the title, dict id -> row."""
    lines = path.read_text().splitlines()
    title = lines[0]
    time = float(title.split(" at t = ")[1].split()[0])
    atoms, vel, section = {}, {}, None
    for line in lines[1:]:
        line = line.split("#")[0].strip()
        if not line:
            continue
        if line[0].isalpha():
            section = line
            continue
        t = line.split()
        if section == "Atoms":
            atoms[int(t[0])] = (int(t[1]), *map(float, t[2:7]))
        elif section == "Velocities":
            vel[int(t[0])] = tuple(map(float, t[1:7]))
    return time, atoms, vel


def min_image_distances(x, i, lo, hi, periodic):
    d = x[i] - x
    for a in range(3):
        if periodic[a]:
            L = hi[a] - lo[a]
            d[:, a] -= L * np.round(d[:, a] / L)
    return np.sqrt((d * d).sum(axis=1))


def rotation(axis, angle):
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K


def main():
    run = pathlib.Path(sys.argv[1])
    scene = tomllib.loads(pathlib.Path(sys.argv[2]).read_text())
    summary = json.loads((run / "summary.json").read_text())
    contact = scene["contact"]
    rotates = contact["model"] == "hertz"
    lam = summary["lambda"]
    lo = np.array(scene["domain"]["lo"], float)
    hi = np.array(scene["domain"]["hi"], float)
    periodic = scene["domain"].get("periodic", [False] * 3)
    gravity = np.array(scene.get("gravity", [0.0, 0.0, -9.81]), float)
    walls = [(np.array(w["point"], float), np.array(w["normal"], float)) for w in scene.get("wall", [])]
    expected = {"id", "species", "radius", "velocity", "force", "coordination_number"}
    if rotates:
        expected |= {"omega", "torque"}

    ts_rows = list(csv.DictReader(open(run / "timeseries.csv")))
    ts_time = np.array([float(r["time_s"]) for r in ts_rows])
    dt = summary["dt_s"]
    frames = pvd(run / "vtk" / "particles.pvd")
    if len(frames) < 2:
        problem(f"{run}: {len(frames)} frames in particles.pvd, expected at least 2")
    checked = {"frames": 0, "coordination_pairs": 0, "free": 0, "energy": 0}
    last_ids = None
    for time, vtu in frames:
        where = f"{vtu.name} (t = {time:.6g} s)"
        m = meshio.read(vtu)
        n = len(m.points)
        names = set(m.point_data)
        if names != expected:
            problem(f"{where}: arrays {sorted(names)}, expected {sorted(expected)}")
            continue
        shapes = {k: v.shape for k, v in m.point_data.items()}
        for k, v in m.point_data.items():
            want = (n, 3) if k in ("velocity", "force", "omega", "torque") else (n,)
            if v.reshape(v.shape[0], -1).shape != (want[0], 1 if len(want) == 1 else 3):
                problem(f"{where}: array {k} has shape {v.shape}, expected {want}")
        if sum(len(c.data) for c in m.cells if c.type == "vertex") != n:
            problem(f"{where}: {n} points but not one vertex cell each: {[(c.type, len(c.data)) for c in m.cells]}")
        if problems:
            continue
        pd = {k: (v.reshape(n) if v.ndim == 2 and v.shape[1] == 1 else v) for k, v in m.point_data.items()}
        ids = pd["id"].astype(np.int64)
        # The frame's data file: same state, written as text.
        data_time, atoms, vel = read_data(vtu.with_suffix(".data"))
        if data_time != time:
            problem(f"{where}: the data file says t = {data_time!r}, the .pvd {time!r}")
        if sorted(atoms) != sorted((ids + 1).tolist()):
            problem(f"{where}: ids differ from the data file's atom-IDs ({n} points, {len(atoms)} atoms)")
            continue
        row = np.array([atoms[i + 1] for i in ids])  # type d rho x y z
        v_row = np.array([vel[i + 1] for i in ids])
        for name, ours, theirs in [
            ("species", pd["species"].astype(np.int64), row[:, 0].astype(np.int64) - 1),
            ("radius", pd["radius"], 0.5 * row[:, 1]),
            ("points", m.points, row[:, 3:6]),
            ("velocity", pd["velocity"], v_row[:, 0:3]),
            ("omega", pd["omega"] if rotates else np.zeros((n, 3)), v_row[:, 3:6]),
        ]:
            if ours.shape != theirs.shape or not np.array_equal(ours, theirs):
                bad = np.argwhere(np.atleast_2d(ours != theirs).reshape(n, -1).any(axis=1)).ravel()
                problem(f"{where}: {name} differs from the data file at {len(bad)} particles, first id {ids[bad[0]] if len(bad) else '?'}")
        # Coordination: brute force over pairs, with the law's reach.
        x, r = m.points, pd["radius"]
        if rotates:
            reach = lambda i: r[i] + r  # noqa: E731
        else:
            sigma = contact["sigma"] * lam
            reach = lambda i: np.full(n, 2 ** (1 / 6) * sigma)  # noqa: E731
        coord_lo = np.zeros(n, int)
        coord_hi = np.zeros(n, int)
        for i in range(n):
            dist = min_image_distances(x, i, lo, hi, periodic)
            dist[i] = np.inf
            cut = reach(i)
            coord_lo[i] = (dist < cut * (1 - 1e-12)).sum()
            coord_hi[i] = (dist < cut * (1 + 1e-12)).sum()
        c = pd["coordination_number"].astype(int)
        bad = np.flatnonzero((c < coord_lo) | (c > coord_hi))
        if len(bad):
            i = bad[0]
            problem(f"{where}: coordination_number of id {ids[i]} is {c[i]}, counted {coord_lo[i]} (of {len(bad)} particles)")
        checked["coordination_pairs"] += int(coord_lo.sum()) // 2
        # Free particles: nothing within reach, more than a diameter from every wall plane.
        mass = row[:, 2] * math.pi / 6.0 * row[:, 1] ** 3
        free = coord_hi == 0
        for p, nrm in walls:
            free &= np.abs((x - p) @ (nrm / np.linalg.norm(nrm))) > 2 * r
        if "body" in scene:
            free &= False  # the bodies' surfaces are not modelled here
        want_f = mass[:, None] * gravity[None, :]
        f = pd["force"]
        badf = np.flatnonzero(free & (np.abs(f - want_f).max(axis=1) > 1e-12 * np.abs(want_f).max(axis=1).clip(1e-300)))
        if len(badf):
            i = badf[0]
            problem(f"{where}: force of the free particle id {ids[i]} is {f[i]}, expected m g = {want_f[i]}")
        if rotates and np.any(pd["torque"][free] != 0.0):
            problem(f"{where}: torque on a free particle is not zero")
        checked["free"] += int(free.sum())
        # Against the time series at the same step.
        k = int(np.argmin(np.abs(ts_time - time)))
        if abs(ts_time[k] - time) < 0.5 * dt:
            ke = 0.5 * (mass * (pd["velocity"] ** 2).sum(axis=1)).sum()
            if rotates:
                ke += 0.5 * (0.4 * mass * r**2 * (pd["omega"] ** 2).sum(axis=1)).sum()
            ts_ke = float(ts_rows[k]["kinetic_energy_j"])
            if abs(ke - ts_ke) > 1e-8 * abs(ts_ke) + 1e-300:
                problem(f"{where}: kinetic energy of the frame {ke:.9e} J, time series {ts_ke:.9e} J")
            if int(ts_rows[k]["n_particles"]) != n:
                problem(f"{where}: {n} particles, time series n_particles {ts_rows[k]['n_particles']}")
            checked["energy"] += 1
        checked["frames"] += 1
        last_ids = set(ids.tolist())
    # The run ends where its last stage ends, which need not be a frame time; the particles
    # are the same unless some were lost, deleted or added since the last frame.
    if last_ids is not None:
        if len(last_ids) != summary["n_particles"] or last_ids != set(range(summary["n_particles"])):
            problem(f"last frame: {len(last_ids)} ids (0..{max(last_ids)}), summary.json n_particles {summary['n_particles']}")
    if "body" in scene:
        check_bodies(run, scene, summary, [t for t, _ in frames], checked)
    if checked["energy"] == 0:
        problem("no frame fell on a time-series row: the kinetic energy was not compared")
    print(f"{run}: {checked['frames']} frames, arrays {sorted(expected)}; "
          f"{checked['coordination_pairs']} pairs counted, {checked['free']} free particles, "
          f"{checked['energy']} frames against timeseries.csv" + (f", {checked['bodies']} body frames" if "bodies" in checked else ""))


def check_bodies(run, scene, summary, times, checked):
    frames = pvd(run / "vtk" / "bodies.pvd")
    if [t for t, _ in frames] != times:
        problem("bodies.pvd and particles.pvd have different times")
    stage_start = {s["name"]: s["start_s"] for s in summary["stages"]}
    first = None
    for time, vtu in frames:
        where = f"{vtu.name} (t = {time:.6g} s)"
        m = meshio.read(vtu)
        tri = [c for c in m.cells if c.type == "triangle"]
        if len(tri) != 1 or "velocity" not in m.point_data or "body" not in m.cell_data:
            problem(f"{where}: expected triangles with point array velocity and cell array body, got {list(m.point_data)}, {list(m.cell_data)}, {[c.type for c in m.cells]}")
            return
        tri = tri[0].data
        body = np.asarray(m.cell_data["body"][0]).reshape(-1).astype(int)
        v = m.point_data["velocity"]
        if len(body) != len(tri) or v.shape != (len(m.points), 3):
            problem(f"{where}: body has {len(body)} values for {len(tri)} triangles, velocity {v.shape} for {len(m.points)} points")
            return
        if sorted(set(body.tolist())) != list(range(len(scene["body"]))):
            problem(f"{where}: body indices {sorted(set(body.tolist()))}, the scene has {len(scene['body'])} bodies")
            return
        if first is None:
            first = (m.points.copy(), tri, body)
        if len(m.points) != len(first[0]) or not np.array_equal(tri, first[1]):
            problem(f"{where}: the mesh changed between frames")
            return
        for k, b in enumerate(scene["body"]):
            verts = np.unique(tri[body == k])
            start = stage_start.get(b.get("start_stage"), 0.0) if b.get("start_stage") else 0.0
            w = b.get("rpm", 0.0) * 2 * math.pi / 60
            axis = np.array(b.get("axis", [1.0, 0.0, 0.0]), float)
            axis /= np.linalg.norm(axis)
            point = np.array(b.get("point", [0.0, 0.0, 0.0]), float)
            # A frame at the step a stage ends is written before the next stage starts a body.
            moving = w != 0 and time > start + 0.5 * summary["dt_s"]
            angle = w * (time - start) if moving else 0.0
            want = (first[0][verts] - point) @ rotation(axis, angle).T + point
            err = np.abs(m.points[verts] - want).max()
            # The pose's angle runs from the step the body started: within one step.
            tol = abs(w) * summary["dt_s"] * np.abs(first[0][verts] - point).max() * 1.01 + 1e-12
            if err > tol:
                problem(f"{where}: body {k} ({b['name']}) vertices off the rotated first pose by {err:.3e} m (allowed {tol:.1e})")
            want_v = np.cross(w * axis, m.points[verts] - point) if moving else np.zeros((len(verts), 3))
            if np.abs(v[verts] - want_v).max() > 1e-9 * max(1.0, np.abs(want_v).max()):
                problem(f"{where}: body {k} ({b['name']}) vertex velocity is not omega x (x - point)")
    checked["bodies"] = len(frames)


if __name__ == "__main__":
    main()
    if problems:
        print(f"{len(problems)} problems")
        sys.exit(1)
