//! Triangle meshes of the screw feeder of paper A (Hirose, secs. 4 and 6, Fig. 3): screw,
//! casing, hopper and the insertion region, for conversion to signed-distance fields.
//!
//! # Frame and units
//! SI metres. The screw axis is the x axis, material is conveyed toward +x, gravity is -z.
//! x = 0 is where the flight starts. Angles θ about +x are measured from +y toward +z.
//!
//! # Screw (`screw_mesh`)
//! Paper values: outer diameter Ds = 205 mm, shaft diameter ds = 55 mm, pitch ps = 150 mm,
//! length 4.5 pitches.
//! - Flight: one right-handed helical band of constant *axial* thickness
//!   `flight_thickness` = 8 mm (not given in the paper; 8 mm is a typical plate for a screw of
//!   this size, thin enough (5 % of the pitch) to leave the free volume per turn close to
//!   Eq. (7)'s (pi/4)(Ds^2 - ds^2) ps and thick enough to be resolved by an SDF grid of a few
//!   mm). Its mid-surface is `x = t/2 + ps θ / 2π` for θ in [0, 2π·4.5], so the solid flight
//!   occupies x in [0, 4.5 ps + t] = [0, 0.683] m. Its outer edge is at Ds/2; its inner edge is
//!   `flight_root_embedding` = 2 mm *inside* the shaft (r = 25.5 mm).
//!   Handedness: the flight advances +x as θ grows, so the screw conveys toward +x when it turns
//!   with angular velocity `-|ω| x̂` (clockwise seen from +x looking back at the origin).
//! - Shaft: a solid cylinder of diameter ds, extended `shaft_extension` = 15 mm beyond the
//!   flight at both ends: x in [-0.015, 0.698] m.
//! - The screw mesh is the **union of two closed meshes** (shaft, flight), each closed and
//!   outward oriented, overlapping where the flight root sits inside the shaft. Fusing them
//!   into a single 2-manifold is not done: the generalized winding number of the union is >= 1
//!   inside and 0 outside, which is all an SDF built with it needs. The signed volume of the
//!   mesh counts the 2 mm overlap twice (about 0.4 % of the screw volume, 1.2e-5 m3).
//!
//! # Casing (`casing_mesh`)
//! Paper values: bore 229.6 mm, inlet opening 318 mm, outlet opening 324 mm.
//! - A tube coaxial with the screw, bore Ri = 114.8 mm, wall `casing_wall_thickness` = 10 mm
//!   (assumed: a usual sheet thickness; the paper models the casing as surfaces), so
//!   Ro = 124.8 mm.
//! - Inlet-side end plate (a disk of radius Ro, thickness = wall) with its inner face
//!   `end_plate_clearance` = 5 mm behind the shaft end: x in [-0.030, -0.020] m.
//! - Inlet: x in [0, 0.318] m (starts where the flight starts), the whole upper half of the
//!   wall removed, i.e. the opening spans the bore's full width 229.6 mm across y. Above the
//!   tube axis the inlet continues as a vertical rectangular chute up to z = Ro (the hopper's
//!   bottom): two side "cheeks" (|y| in [Ri, Ro], z in [0, Ro]) and two "gables", slabs of
//!   wall thickness at both x ends of the opening that fill the space between the bore and the
//!   chute's top (the rectangle |y| <= Ro, z in [0, Ro] minus the bore). Without the gables a
//!   particle could leave the hopper sideways above the tube's outer surface.
//! - Outlet: x in [0.525, 0.849] m, the whole lower half of the wall removed (width = bore).
//!   It starts 3.5 pitches into the flight, so the last ~1 pitch of flight runs over it and the
//!   last 166 mm of the opening is beyond the flight's end.
//! - The tube ends `casing_end_collar` = 20 mm after the outlet (x = 0.869 m). That end is
//!   open by default (only the inlet-side end plate is specified); set `discharge_end_plate`
//!   to close it with a second plate.
//! - Construction: a union of closed prisms extruded along x, each cross-section a simple
//!   polygon in (y, z): end plate (disk), lower half-annulus from the end plate to the outlet,
//!   upper half-annulus up to the first gable and from the second gable to the end, lower
//!   half-annulus after the outlet, gables, cheeks. The openings are the missing halves, so
//!   they are real holes. Pieces touch along shared planar faces (never overlap in volume);
//!   those internal faces lie inside the wall and do not change the distance to the wall seen
//!   from the bore or from outside.
//!
//! # Hopper (`hopper_mesh`)
//! A rectangular funnel, one closed thick-walled solid (genus 1). Inner bottom opening =
//! inlet (318 mm x 229.6 mm) at z = Ro (on top of the chute), inner top opening
//! `hopper_top_length` x `hopper_top_width` = 450 mm x 350 mm at z = Ro + 300 mm, centred
//! over the inlet (assumed; the paper gives no hopper size). Walls are
//! `hopper_wall_thickness` = 10 mm thick measured horizontally; the outer bottom rim
//! coincides with the chute's walls.
//!
//! # Insertion region (`insertion_region_mesh`)
//! Union of two closed pieces inset `insertion_margin` = 5 mm from every wall: a box in the
//! inlet chute from just above the flight tips (z = Ds/2 + margin) to z = Ro, and the hopper
//! interior frustum from z = Ro to the hopper top minus the margin.
//!
//! # Resolution
//! `segments_per_turn` (shaft polygon and flight, per 2π), `radial_segments` (across the
//! flight face), `casing_segments` (per 2π for the casing arcs), `axial_step` (largest
//! spacing of rings along x on the shaft and casing tubes).

use std::f64::consts::PI;
use std::fmt;
use std::fs;
use std::io;
use std::path::{Path, PathBuf};

use crate::geometry::mesh::TriMesh;
use crate::geometry::mesh_builder::{
    append, empty, extrude_x, frustum_z, grow, rect_corners, stations, sweep_rings, RectXY,
};
use crate::math::{Real, Vec3};

/// Every dimension of the screw feeder (metres) and the mesh resolution.
/// `Default` gives paper A's feeder with the choices documented at the top of this module.
#[derive(Clone, Debug, PartialEq)]
pub struct ScrewFeederSpec {
    /// Ds, outer diameter of the flight (paper: 205 mm).
    pub screw_outer_diameter: Real,
    /// ds, shaft diameter (paper: 55 mm).
    pub shaft_diameter: Real,
    /// ps, pitch (paper: 150 mm).
    pub pitch: Real,
    /// Number of turns of the flight (paper: 4.5).
    pub flight_turns: Real,
    /// Axial thickness of the flight (chosen: 8 mm).
    pub flight_thickness: Real,
    /// How deep the flight's inner edge sits inside the shaft (chosen: 2 mm).
    pub flight_root_embedding: Real,
    /// Shaft length beyond the flight at each end (chosen: 15 mm).
    pub shaft_extension: Real,
    /// Bore of the casing (paper: 229.6 mm).
    pub casing_inner_diameter: Real,
    /// Casing wall and end-plate thickness (chosen: 10 mm).
    pub casing_wall_thickness: Real,
    /// Axial gap between the shaft end and the inlet-side end plate (chosen: 5 mm).
    pub end_plate_clearance: Real,
    /// x where the inlet opening starts (chosen: 0, the flight start).
    pub inlet_start_x: Real,
    /// Inlet opening length along x (paper: 318 mm).
    pub inlet_length: Real,
    /// x where the outlet opening starts (chosen: 3.5 pitches, 525 mm).
    pub outlet_start_x: Real,
    /// Outlet opening length along x (paper: 324 mm).
    pub outlet_length: Real,
    /// Tube length after the outlet (chosen: 20 mm).
    pub casing_end_collar: Real,
    /// Close the discharge end with a second end plate (default: false, open).
    pub discharge_end_plate: bool,
    /// Inner length (x) of the hopper's top opening (chosen: 450 mm).
    pub hopper_top_length: Real,
    /// Inner width (y) of the hopper's top opening (chosen: 350 mm).
    pub hopper_top_width: Real,
    /// Height of the hopper above the chute (chosen: 300 mm).
    pub hopper_height: Real,
    /// Horizontal wall thickness of the hopper (chosen: 10 mm).
    pub hopper_wall_thickness: Real,
    /// Inset of the insertion region from all walls (chosen: 5 mm).
    pub insertion_margin: Real,
    /// Polygon segments per 2π for the shaft and per turn of the flight (default 96).
    pub segments_per_turn: usize,
    /// Segments across the flight's faces, root to tip (default 8).
    pub radial_segments: usize,
    /// Polygon segments per 2π for the casing arcs (default 128).
    pub casing_segments: usize,
    /// Largest spacing of rings along x on shaft and casing tubes (default 10 mm).
    pub axial_step: Real,
}

// 0.318 m is the paper's inlet length, not an approximation of 1/pi.
#[allow(clippy::approx_constant)]
impl Default for ScrewFeederSpec {
    fn default() -> Self {
        Self {
            screw_outer_diameter: 0.205,
            shaft_diameter: 0.055,
            pitch: 0.150,
            flight_turns: 4.5,
            flight_thickness: 0.008,
            flight_root_embedding: 0.002,
            shaft_extension: 0.015,
            casing_inner_diameter: 0.2296,
            casing_wall_thickness: 0.010,
            end_plate_clearance: 0.005,
            inlet_start_x: 0.0,
            inlet_length: 0.318,
            outlet_start_x: 0.525,
            outlet_length: 0.324,
            casing_end_collar: 0.020,
            discharge_end_plate: false,
            hopper_top_length: 0.450,
            hopper_top_width: 0.350,
            hopper_height: 0.300,
            hopper_wall_thickness: 0.010,
            insertion_margin: 0.005,
            segments_per_turn: 96,
            radial_segments: 8,
            casing_segments: 128,
            axial_step: 0.010,
        }
    }
}

/// Positions derived from a [`ScrewFeederSpec`] (metres), useful for setting up a scene
/// (e.g. the outlet's x range for deleting particles).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScrewFeederLayout {
    /// x range of the solid flight.
    pub flight_x: [Real; 2],
    /// x range of the shaft.
    pub shaft_x: [Real; 2],
    /// Outer and inner face of the inlet-side end plate.
    pub end_plate_x: [Real; 2],
    /// x range of the inlet opening.
    pub inlet_x: [Real; 2],
    /// x range of the outlet opening.
    pub outlet_x: [Real; 2],
    /// x where the casing tube ends (the discharge plate, if any, lies beyond).
    pub casing_end_x: Real,
    /// Bore radius Ri.
    pub bore_radius: Real,
    /// Outer radius of the casing Ro.
    pub casing_outer_radius: Real,
    /// z of the chute top = hopper bottom.
    pub hopper_bottom_z: Real,
    /// z of the hopper top.
    pub hopper_top_z: Real,
}

/// Errors of this module, each naming what the user has to change.
#[derive(Debug)]
pub enum ScrewFeederError {
    /// A field of the spec is out of range.
    InvalidSpec { field: &'static str, reason: String },
    /// Writing a file or creating the output directory failed.
    Io { path: PathBuf, source: io::Error },
}

impl fmt::Display for ScrewFeederError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::InvalidSpec { field, reason } => {
                write!(f, "invalid screw feeder spec: `{field}` {reason}")
            }
            Self::Io { path, source } => write!(f, "cannot write {}: {source}", path.display()),
        }
    }
}

impl std::error::Error for ScrewFeederError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::Io { source, .. } => Some(source),
            Self::InvalidSpec { .. } => None,
        }
    }
}

fn invalid(field: &'static str, reason: impl Into<String>) -> ScrewFeederError {
    ScrewFeederError::InvalidSpec {
        field,
        reason: reason.into(),
    }
}

impl ScrewFeederSpec {
    /// Positions derived from the spec.
    pub fn layout(&self) -> ScrewFeederLayout {
        let flight_end = self.flight_turns * self.pitch + self.flight_thickness;
        let shaft_x = [-self.shaft_extension, flight_end + self.shaft_extension];
        let plate_inner = shaft_x[0] - self.end_plate_clearance;
        let ri = 0.5 * self.casing_inner_diameter;
        let ro = ri + self.casing_wall_thickness;
        let outlet_end = self.outlet_start_x + self.outlet_length;
        ScrewFeederLayout {
            flight_x: [0.0, flight_end],
            shaft_x,
            end_plate_x: [plate_inner - self.casing_wall_thickness, plate_inner],
            inlet_x: [self.inlet_start_x, self.inlet_start_x + self.inlet_length],
            outlet_x: [self.outlet_start_x, outlet_end],
            casing_end_x: outlet_end + self.casing_end_collar,
            bore_radius: ri,
            casing_outer_radius: ro,
            hopper_bottom_z: ro,
            hopper_top_z: ro + self.hopper_height,
        }
    }

    /// Checks that the dimensions describe a buildable feeder.
    pub fn validate(&self) -> Result<(), ScrewFeederError> {
        let positive = [
            ("screw_outer_diameter", self.screw_outer_diameter),
            ("shaft_diameter", self.shaft_diameter),
            ("pitch", self.pitch),
            ("flight_turns", self.flight_turns),
            ("flight_thickness", self.flight_thickness),
            ("flight_root_embedding", self.flight_root_embedding),
            ("casing_inner_diameter", self.casing_inner_diameter),
            ("casing_wall_thickness", self.casing_wall_thickness),
            ("inlet_length", self.inlet_length),
            ("outlet_length", self.outlet_length),
            ("hopper_height", self.hopper_height),
            ("hopper_wall_thickness", self.hopper_wall_thickness),
            ("insertion_margin", self.insertion_margin),
            ("axial_step", self.axial_step),
        ];
        for (field, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return Err(invalid(field, format!("must be finite and > 0, got {v}")));
            }
        }
        let non_negative = [
            ("shaft_extension", self.shaft_extension),
            ("end_plate_clearance", self.end_plate_clearance),
            ("casing_end_collar", self.casing_end_collar),
        ];
        for (field, v) in non_negative {
            if !(v.is_finite() && v >= 0.0) {
                return Err(invalid(field, format!("must be finite and >= 0, got {v}")));
            }
        }
        for (field, v) in [
            ("inlet_start_x", self.inlet_start_x),
            ("outlet_start_x", self.outlet_start_x),
        ] {
            if !v.is_finite() {
                return Err(invalid(field, format!("must be finite, got {v}")));
            }
        }
        let l = self.layout();
        let t = self.casing_wall_thickness;
        let checks: [(bool, &'static str, String); 10] = [
            (
                self.shaft_diameter < self.screw_outer_diameter,
                "shaft_diameter",
                "must be smaller than screw_outer_diameter".into(),
            ),
            (
                self.screw_outer_diameter < self.casing_inner_diameter,
                "screw_outer_diameter",
                "must be smaller than casing_inner_diameter".into(),
            ),
            (
                self.flight_root_embedding < 0.5 * self.shaft_diameter,
                "flight_root_embedding",
                "must be smaller than the shaft radius".into(),
            ),
            (
                self.flight_thickness < self.pitch,
                "flight_thickness",
                "must be smaller than pitch".into(),
            ),
            (
                l.inlet_x[0] - t >= l.end_plate_x[1],
                "inlet_start_x",
                format!(
                    "must be >= {} (end plate inner face + wall thickness)",
                    l.end_plate_x[1] + t
                ),
            ),
            (
                l.inlet_x[1] + t <= l.outlet_x[0],
                "outlet_start_x",
                format!(
                    "must be >= {} (inlet end + wall thickness)",
                    l.inlet_x[1] + t
                ),
            ),
            (
                l.shaft_x[1] < l.casing_end_x,
                "casing_end_collar",
                "too short: the shaft would stick out of the casing".into(),
            ),
            (
                self.hopper_top_length >= self.inlet_length
                    && self.hopper_top_width >= self.casing_inner_diameter,
                "hopper_top_length",
                "hopper top (length x width) must be at least the inlet (length x bore)".into(),
            ),
            (
                0.5 * self.screw_outer_diameter + self.insertion_margin < l.hopper_bottom_z
                    && 2.0 * self.insertion_margin < self.hopper_height
                    && 2.0 * self.insertion_margin < self.inlet_length,
                "insertion_margin",
                "too large for the inlet chute or hopper".into(),
            ),
            (
                self.segments_per_turn >= 8
                    && self.casing_segments >= 8
                    && self.radial_segments >= 1
                    && self.segments_per_turn <= 100_000
                    && self.casing_segments <= 100_000
                    && self.radial_segments <= 10_000,
                "segments_per_turn",
                "segments_per_turn and casing_segments must be in 8..=100000, \
                 radial_segments in 1..=10000"
                    .into(),
            ),
        ];
        for (ok, field, reason) in checks {
            if !ok {
                return Err(invalid(field, reason));
            }
        }
        let rings = (l.casing_end_x - l.end_plate_x[0]) / self.axial_step;
        if rings > 1.0e6 {
            return Err(invalid("axial_step", "gives more than 1e6 rings along x"));
        }
        Ok(())
    }
}

/// Free volume per turn of Eq. (7): (pi/4)(Ds^2 - ds^2) ps (4.595e-3 m3 for the paper's screw).
pub fn swept_volume_per_turn(spec: &ScrewFeederSpec) -> Real {
    0.25 * PI * (spec.screw_outer_diameter.powi(2) - spec.shaft_diameter.powi(2)) * spec.pitch
}

/// Points on an arc of radius `r` from angle `a0` to `a1` (inclusive) in the (y, z) plane,
/// with about `per_turn` segments per 2π.
fn arc(r: Real, a0: Real, a1: Real, per_turn: usize) -> Vec<[Real; 2]> {
    let n = ((a1 - a0).abs() / (2.0 * PI) * per_turn as Real)
        .ceil()
        .max(1.0) as usize;
    (0..=n)
        .map(|i| {
            let a = a0 + (a1 - a0) * i as Real / n as Real;
            [r * a.cos(), r * a.sin()]
        })
        .collect()
}

fn circle(r: Real, n: usize) -> Vec<[Real; 2]> {
    let mut c = arc(r, 0.0, 2.0 * PI, n);
    c.pop(); // last point repeats the first
    c
}

/// Half annulus between radii `ri` and `ro`; upper (z >= 0) or lower (z <= 0) half.
fn half_annulus(ri: Real, ro: Real, upper: bool, n: usize) -> Vec<[Real; 2]> {
    let (a0, a1) = if upper { (0.0, PI) } else { (PI, 2.0 * PI) };
    let mut p = arc(ro, a0, a1, n);
    p.extend(arc(ri, a1, a0, n));
    p
}

/// Gable cross-section: rectangle |y| <= ro, 0 <= z <= h minus the upper half of the bore.
fn gable(ri: Real, ro: Real, h: Real, n: usize) -> Vec<[Real; 2]> {
    let mut p = vec![[ri, 0.0], [ro, 0.0], [ro, h], [-ro, h], [-ro, 0.0]];
    let mut inner = arc(ri, PI, 0.0, n);
    inner.pop(); // (ri, 0) is the first vertex
    p.extend(inner);
    p
}

/// The screw: union of the shaft cylinder and the helical flight, each closed and outward
/// oriented (see the module doc).
pub fn screw_mesh(spec: &ScrewFeederSpec) -> TriMesh {
    let l = spec.layout();
    let rs = 0.5 * spec.shaft_diameter;
    let ro = 0.5 * spec.screw_outer_diameter;
    let n_turn = spec.segments_per_turn.max(3);
    let mut mesh = empty();
    append(
        &mut mesh,
        extrude_x(
            &circle(rs, n_turn),
            &stations(l.shaft_x[0], l.shaft_x[1], spec.axial_step),
        ),
    );

    // Flight: rings in the half-plane at angle θ, swept along the helix.
    let e = spec.flight_thickness;
    let r_in = rs - spec.flight_root_embedding;
    let m = spec.radial_segments.max(1);
    let total = 2.0 * PI * spec.flight_turns;
    let n_theta = (spec.flight_turns * n_turn as Real).ceil().max(1.0) as usize;
    let radii: Vec<Real> = (0..=m)
        .map(|j| r_in + (ro - r_in) * j as Real / m as Real)
        .collect();
    let rings: Vec<Vec<Vec3>> = (0..=n_theta)
        .map(|i| {
            let th = total * i as Real / n_theta as Real;
            let xc = 0.5 * e + spec.pitch * th / (2.0 * PI);
            let (s, c) = th.sin_cos();
            let at = |r: Real, x: Real| Vec3::new(x, r * c, r * s);
            // Loop: root->tip on the low-x face, tip->root on the high-x face.
            let mut ring: Vec<Vec3> = radii.iter().map(|&r| at(r, xc - 0.5 * e)).collect();
            ring.extend(radii.iter().rev().map(|&r| at(r, xc + 0.5 * e)));
            ring
        })
        .collect();
    // End caps: strip of quads between the low face (index j) and the high face
    // (index 2m+1-j), wound like the ring loop.
    let hi = |j: usize| 2 * m + 1 - j;
    let cap: Vec<[usize; 3]> = (0..m)
        .flat_map(|j| [[j, j + 1, hi(j + 1)], [j, hi(j + 1), hi(j)]])
        .collect();
    append(&mut mesh, sweep_rings(&rings, &cap, false));
    mesh
}

/// The casing: tube with inlet-side end plate, inlet chute (cheeks and gables) and the two
/// openings, as a union of closed outward-oriented prisms (see the module doc).
pub fn casing_mesh(spec: &ScrewFeederSpec) -> TriMesh {
    let l = spec.layout();
    let (ri, ro, t) = (
        l.bore_radius,
        l.casing_outer_radius,
        spec.casing_wall_thickness,
    );
    let h = l.hopper_bottom_z;
    let n = spec.casing_segments.max(8);
    let dx = spec.axial_step;
    let mut mesh = empty();
    let mut piece = |poly: &[[Real; 2]], x0: Real, x1: Real| {
        if x1 - x0 > 1e-12 {
            append(&mut mesh, extrude_x(poly, &stations(x0, x1, dx)));
        }
    };
    let lower = half_annulus(ri, ro, false, n);
    let upper = half_annulus(ri, ro, true, n);
    let gable = gable(ri, ro, h, n);
    let disk = circle(ro, n);
    let [x_in0, x_in1] = l.inlet_x;
    let [x_out0, x_out1] = l.outlet_x;

    piece(&disk, l.end_plate_x[0], l.end_plate_x[1]);
    piece(&lower, l.end_plate_x[1], x_out0);
    piece(&lower, x_out1, l.casing_end_x);
    piece(&upper, l.end_plate_x[1], x_in0 - t);
    piece(&gable, x_in0 - t, x_in0);
    piece(&gable, x_in1, x_in1 + t);
    piece(&upper, x_in1 + t, l.casing_end_x);
    let cheek = |s: Real| -> Vec<[Real; 2]> {
        // Rectangle |y| in [ri, ro] on side s (= ±1), z in [0, h].
        vec![[s * ri, 0.0], [s * ro, 0.0], [s * ro, h], [s * ri, h]]
    };
    piece(&cheek(1.0), x_in0, x_in1);
    piece(&cheek(-1.0), x_in0, x_in1);
    if spec.discharge_end_plate {
        piece(&disk, l.casing_end_x, l.casing_end_x + t);
    }
    mesh
}

/// Inner rectangle of the hopper at height `z` (linear between bottom and top openings).
pub fn hopper_inner_rect(spec: &ScrewFeederSpec, z: Real) -> RectXY {
    let l = spec.layout();
    let s = ((z - l.hopper_bottom_z) / spec.hopper_height).clamp(0.0, 1.0);
    let xc = 0.5 * (l.inlet_x[0] + l.inlet_x[1]);
    let half_len = 0.5 * (spec.inlet_length + s * (spec.hopper_top_length - spec.inlet_length));
    let half_wid = 0.5
        * (spec.casing_inner_diameter + s * (spec.hopper_top_width - spec.casing_inner_diameter));
    [xc - half_len, xc + half_len, -half_wid, half_wid]
}

/// The hopper: one closed, outward-oriented thick-walled rectangular funnel over the inlet.
pub fn hopper_mesh(spec: &ScrewFeederSpec) -> TriMesh {
    let l = spec.layout();
    let (z0, z1) = (l.hopper_bottom_z, l.hopper_top_z);
    let (ib, it) = (hopper_inner_rect(spec, z0), hopper_inner_rect(spec, z1));
    let t = spec.hopper_wall_thickness;
    let (ibc, itc) = (rect_corners(ib, z0), rect_corners(it, z1));
    let (obc, otc) = (rect_corners(grow(ib, t), z0), rect_corners(grow(it, t), z1));
    // The wall's cross-section (inner bottom, outer bottom, outer top, inner top) swept
    // around the four corners and back to the first: a closed genus-1 solid.
    let rings: Vec<Vec<Vec3>> = (0..4)
        .map(|k| vec![ibc[k], obc[k], otc[k], itc[k]])
        .collect();
    sweep_rings(&rings, &[], true)
}

/// Where particles may be inserted at the start: the inlet chute above the flight tips and
/// the hopper interior, inset by `insertion_margin`; union of two closed pieces.
pub fn insertion_region_mesh(spec: &ScrewFeederSpec) -> TriMesh {
    let l = spec.layout();
    let m = spec.insertion_margin;
    let z_chute = 0.5 * spec.screw_outer_diameter + m;
    let z_mid = l.hopper_bottom_z;
    let z_top = l.hopper_top_z - m;
    let bottom = grow(hopper_inner_rect(spec, z_mid), -m);
    let top = grow(hopper_inner_rect(spec, z_top), -m);
    let mut mesh = empty();
    append(&mut mesh, frustum_z(z_chute, bottom, z_mid, bottom));
    append(&mut mesh, frustum_z(z_mid, bottom, z_top, top));
    mesh
}

/// Writes one mesh as binary STL (f32 coordinates, facet normals from the winding).
pub fn write_stl(mesh: &TriMesh, path: &Path) -> Result<(), ScrewFeederError> {
    let io_err = |source| ScrewFeederError::Io {
        path: path.to_path_buf(),
        source,
    };
    let tris: Vec<stl_io::Triangle> = mesh
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.vertices[i as usize]);
            let normal = (b - a).cross(c - a).normalize_or_zero();
            let f = |v: Vec3| stl_io::Vertex::new(v.as_vec3().to_array());
            stl_io::Triangle {
                normal: f(normal),
                vertices: [f(a), f(b), f(c)],
            }
        })
        .collect();
    let mut file = fs::File::create(path).map_err(io_err)?;
    stl_io::write_stl(&mut file, tris.iter()).map_err(io_err)
}

/// Validates `spec` and writes screw.stl, casing.stl, hopper.stl and insertion.stl into `dir`
/// (created if missing). Returns the paths written.
pub fn write_stl_files(
    spec: &ScrewFeederSpec,
    dir: &Path,
) -> Result<Vec<PathBuf>, ScrewFeederError> {
    spec.validate()?;
    fs::create_dir_all(dir).map_err(|source| ScrewFeederError::Io {
        path: dir.to_path_buf(),
        source,
    })?;
    let meshes = [
        ("screw.stl", screw_mesh(spec)),
        ("casing.stl", casing_mesh(spec)),
        ("hopper.stl", hopper_mesh(spec)),
        ("insertion.stl", insertion_region_mesh(spec)),
    ];
    let mut written = Vec::with_capacity(meshes.len());
    for (name, mesh) in &meshes {
        let path = dir.join(name);
        write_stl(mesh, &path)?;
        written.push(path);
    }
    Ok(written)
}

#[cfg(test)]
mod tests;
