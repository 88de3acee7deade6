//! One rigid body with prescribed motion, and the load particles put on it.

use glam::{DMat3, DQuat};

use super::shape::ShapeSample;
use super::{BodyShape, Motion};
use crate::geometry::Aabb;
use crate::math::{Real, Vec3};

/// Force on a body and torque about its axis point, from one particle or summed.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BodyLoad {
    pub force: Vec3,
    pub torque: Vec3,
}

impl std::ops::AddAssign for BodyLoad {
    fn add_assign(&mut self, other: BodyLoad) {
        self.force += other.force;
        self.torque += other.torque;
    }
}

/// The changing part of a body (see [`Body::state`]).
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct BodyState {
    pub started_at: Option<Real>,
    pub rotation: DMat3,
    pub center: Vec3,
    pub world_bounds: (Vec3, Vec3),
    pub load: BodyLoad,
}

/// A rigid body. The pose is a function of time (no accumulated rotation error): at time
/// `t`, after the motion started at `t0`, a body-frame point `q` is at
/// `c(t) + R(omega (t - t0)) (q - point)` with `c(t) = point + v (t - t0)`.
#[derive(Clone, Debug)]
pub struct Body {
    pub name: String,
    pub shape: BodyShape,
    pub motion: Motion,
    /// When the motion started; `None`: not started, the body rests in its initial pose.
    pub started_at: Option<Real>,
    /// Body-to-world rotation at the current time.
    rotation: DMat3,
    /// Axis point at the current time.
    center: Vec3,
    /// World box of the shape's bounds at the current time.
    world_bounds: Aabb,
    /// Load of the particles on the body at the last force evaluation.
    pub load: BodyLoad,
    /// The surface's wall material (`walls::WallContact::material`); 0 the default.
    pub material: usize,
}

impl Body {
    pub fn new(name: impl Into<String>, shape: BodyShape, motion: Motion) -> Body {
        let mut body = Body {
            name: name.into(),
            shape,
            motion,
            started_at: None,
            rotation: DMat3::IDENTITY,
            center: motion.point,
            world_bounds: Aabb {
                min: Vec3::ZERO,
                max: Vec3::ZERO,
            },
            load: BodyLoad::default(),
            material: 0,
        };
        body.set_time(0.0);
        body
    }

    /// Starts the prescribed motion at `time` (a body built with motion but never started
    /// stays put, e.g. during a settling stage).
    pub fn start(&mut self, time: Real) {
        if self.started_at.is_none() {
            self.started_at = Some(time);
            self.set_time(time);
        }
    }

    /// Moves the body to its pose at `time`.
    pub fn set_time(&mut self, time: Real) {
        let elapsed = self.started_at.map_or(0.0, |t0| time - t0);
        let m = &self.motion;
        self.rotation = DMat3::from_quat(DQuat::from_axis_angle(m.axis, m.angular_speed * elapsed));
        self.center = m.point + m.velocity * elapsed;
        let local = self.shape.bounds();
        let mut bounds = Aabb {
            min: Vec3::splat(Real::INFINITY),
            max: Vec3::splat(Real::NEG_INFINITY),
        };
        for k in 0..8 {
            let corner = Vec3::new(
                if k & 1 == 0 { local.min.x } else { local.max.x },
                if k & 2 == 0 { local.min.y } else { local.max.y },
                if k & 4 == 0 { local.min.z } else { local.max.z },
            );
            bounds = bounds.grown(self.to_world(corner));
        }
        self.world_bounds = bounds;
    }

    /// What changes as the body moves, for a restart file (the shape and motion come from
    /// the scene).
    pub fn state(&self) -> BodyState {
        BodyState {
            started_at: self.started_at,
            rotation: self.rotation,
            center: self.center,
            world_bounds: (self.world_bounds.min, self.world_bounds.max),
            load: self.load,
        }
    }

    /// Puts the body back where [`Body::state`] found it, bit for bit.
    pub fn set_state(&mut self, state: &BodyState) {
        self.started_at = state.started_at;
        self.rotation = state.rotation;
        self.center = state.center;
        self.world_bounds = Aabb {
            min: state.world_bounds.0,
            max: state.world_bounds.1,
        };
        self.load = state.load;
    }

    /// Whether the motion is running.
    pub fn is_moving(&self) -> bool {
        self.started_at.is_some() && !self.motion.is_fixed()
    }

    /// Axis point at the current time (the torque reference).
    pub fn center(&self) -> Vec3 {
        self.center
    }

    pub fn world_bounds(&self) -> Aabb {
        self.world_bounds
    }

    /// Body-frame point to world.
    pub fn to_world(&self, q: Vec3) -> Vec3 {
        self.center + self.rotation * (q - self.motion.point)
    }

    /// World point to body frame.
    pub fn to_body(&self, p: Vec3) -> Vec3 {
        self.motion.point + self.rotation.transpose() * (p - self.center)
    }

    /// Whether `p` lies within `reach` of the body's box: outside it no lookup is made.
    #[inline(always)]
    pub(super) fn within_reach(&self, p: Vec3, reach: Real) -> bool {
        let b = &self.world_bounds;
        !(p.cmplt(b.min - Vec3::splat(reach)).any() || p.cmpgt(b.max + Vec3::splat(reach)).any())
    }

    /// Signed distance and world normal at world point `p`, if `p` lies within `reach` of the
    /// body's box and the shape has data there. A body met on its triangles is searched no
    /// farther than `reach` (the whole mesh otherwise): `None` where no triangle is that near.
    #[inline(always)]
    pub fn query(&self, p: Vec3, reach: Real) -> Option<(Real, Vec3)> {
        if !self.within_reach(p, reach) {
            return None;
        }
        let q = self.to_body(p);
        let (distance, normal) = match &self.shape {
            BodyShape::Mesh(mesh) => mesh.nearest_within(q, reach).map(|(d, c)| {
                let normal = if d > 0.0 { (q - c) / d } else { Vec3::Z };
                (d, normal)
            })?,
            shape => shape.query(q)?,
        };
        Some((distance, self.rotation * normal))
    }

    /// As [`Body::query`], the normal computed only when asked for ([`BodySample::normal`]):
    /// the plain lookup that [`Body::sample_near`] spares (the force loop calls that one).
    #[cfg(test)]
    pub fn sample(&self, p: Vec3, reach: Real) -> Option<BodySample<'_>> {
        if !self.within_reach(p, reach) {
            return None;
        }
        Some(BodySample {
            shape: self.shape.sample(self.to_body(p))?,
            rotation: &self.rotation,
        })
    }

    /// The distance (and the normal on demand) at world point `p` for a particle whose
    /// sample counts only below `beyond` (where its force and overlap start), skipping the
    /// lookup while the particle's point in the body frame stays inside its `clearance`:
    /// `None` then, as when out of reach. Each lookup sets the clearance anew, so the
    /// answers that matter are those of the plain lookup, bit for bit.
    #[inline(always)]
    pub fn sample_near(
        &self,
        p: Vec3,
        reach: Real,
        beyond: Real,
        clearance: &mut Clearance,
    ) -> Option<BodySample<'_>> {
        if !self.within_reach(p, reach) {
            return None;
        }
        let q = self.to_body(p);
        // The ball was made for this `beyond`: any particle with the same one inside it is
        // out of reach (entries are per array slot, and slots change hands at list builds).
        if clearance.beyond == beyond
            && (q - clearance.at).length_squared() < clearance.free_squared
        {
            return None;
        }
        let Some(shape) = self.shape.sample(q) else {
            clearance.free_squared = -1.0;
            return None;
        };
        clearance.at = q;
        clearance.beyond = beyond;
        // Rounding in the interpolation is far below this margin (1e-9 of `beyond`).
        let free = self
            .shape
            .lipschitz()
            .map_or(-1.0, |l| (shape.distance() - beyond * (1.0 + 1e-9)) / l);
        clearance.free_squared = if free > 0.0 { free * free } else { -1.0 };
        Some(BodySample {
            shape,
            rotation: &self.rotation,
        })
    }

    /// Whether the body is met on its triangles (`contact = "mesh"`).
    pub fn is_mesh(&self) -> bool {
        matches!(self.shape, BodyShape::Mesh(_))
    }

    /// A body-frame direction in the world frame.
    #[inline(always)]
    pub(super) fn rotate(&self, v: Vec3) -> Vec3 {
        self.rotation * v
    }

    /// History slots a particle keeps for this body in its wall-history row: one, or for a
    /// mesh body a tag and a history per contact it may have at once.
    pub fn history_slots(&self) -> usize {
        match self.shape {
            BodyShape::Mesh(_) => 2 * super::MESH_CONTACTS,
            _ => 1,
        }
    }

    /// Velocity of the body's material at world point `p`: `v + omega x (p - c)`.
    #[inline(always)]
    pub fn surface_velocity(&self, p: Vec3) -> Vec3 {
        if self.started_at.is_none() {
            return Vec3::ZERO;
        }
        self.motion.velocity + self.motion.omega().cross(p - self.center)
    }

    /// Angular velocity of the body's material (zero before the motion starts).
    pub fn angular_velocity(&self) -> Vec3 {
        if self.started_at.is_none() {
            return Vec3::ZERO;
        }
        self.motion.omega()
    }

    /// Torque of the particles about the axis, N m (component of `load.torque` along it).
    pub fn axial_torque(&self) -> Real {
        self.load.torque.dot(self.motion.axis)
    }

    /// Power the drive must supply to keep the prescribed motion against the particles, W.
    pub fn drive_power(&self) -> Real {
        if self.started_at.is_none() {
            return 0.0;
        }
        -(self.load.torque.dot(self.motion.omega()) + self.load.force.dot(self.motion.velocity))
    }
}

/// Per particle and body: a ball in the body's frame inside which a particle is out of the
/// body's reach, so that it needs no SDF lookup ([`Body::sample_near`]). Grid lookups were
/// about half of a screw feeder's step (8 scattered reads and a trilinear interpolation per
/// particle and body); most particles sit between the flights, more than a few diameters
/// from any surface, and a ball of radius (distance - beyond) / lipschitz around their last
/// lookup lets them skip it for many steps. Exact: a skip happens only where the lookup
/// would have found the particle beyond contact, whichever particle holds the slot.
#[derive(Clone, Copy, Debug)]
pub struct Clearance {
    at: Vec3,
    /// Radius squared; negative: none.
    free_squared: Real,
    /// The distance beyond which the ball was made (a particle's reach or radius).
    beyond: Real,
}

impl Clearance {
    pub const NONE: Clearance = Clearance {
        at: Vec3::ZERO,
        free_squared: -1.0,
        beyond: Real::NAN,
    };

    /// Whether body-frame point `q` of a particle whose contacts start below `beyond` is
    /// inside the ball.
    #[inline(always)]
    pub(super) fn contains(&self, q: Vec3, beyond: Real) -> bool {
        self.beyond == beyond && (q - self.at).length_squared() < self.free_squared
    }

    /// A ball of radius `free` (none when not positive) around `q`, for `beyond`.
    #[inline(always)]
    pub(super) fn set(&mut self, q: Vec3, beyond: Real, free: Real) {
        self.at = q;
        self.beyond = beyond;
        self.free_squared = if free > 0.0 { free * free } else { -1.0 };
    }
}

/// A body's signed distance at a world point, and its world normal there on demand.
#[derive(Clone, Copy, Debug)]
pub struct BodySample<'b> {
    shape: ShapeSample,
    /// The body's, borrowed: the sample is taken per particle and body every step.
    rotation: &'b DMat3,
}

impl BodySample<'_> {
    pub fn distance(&self) -> Real {
        self.shape.distance()
    }

    /// The outward unit normal in the world frame.
    pub fn normal(&self) -> Vec3 {
        *self.rotation * self.shape.normal()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Sphere;

    #[test]
    fn body_frame_round_trip_and_surface_velocity_of_a_turning_body() {
        let shape = BodyShape::Sphere(Sphere {
            center: Vec3::new(1.0, 0.0, 0.0),
            radius: 0.5,
        });
        let motion = Motion::rotation_rpm(Vec3::Z, Vec3::ZERO, 60.0);
        let mut body = Body::new("ball", shape, motion);
        body.start(0.0);
        body.set_time(0.25); // a quarter turn: the ball is now on +y
        let q = Vec3::new(1.0, 0.0, 0.0);
        let p = body.to_world(q);
        assert!((p - Vec3::new(0.0, 1.0, 0.0)).length() < 1e-12);
        assert!((body.to_body(p) - q).length() < 1e-12);
        let (d, n) = body.query(Vec3::new(0.0, 1.55, 0.0), 0.1).unwrap();
        assert!((d - 0.05).abs() < 1e-12 && (n - Vec3::Y).length() < 1e-12);
        // omega = 2 pi rad/s about z: at (0, 1, 0) the material moves along -x at 2 pi m/s.
        let v = body.surface_velocity(p);
        assert!((v - Vec3::new(-std::f64::consts::TAU, 0.0, 0.0)).length() < 1e-12);
        assert!(body.query(Vec3::new(3.0, 0.0, 0.0), 0.1).is_none());
    }

    /// A particle wandering around a turning grid body: where `sample_near` looks up, its
    /// distance is `sample`'s to the bit; where it skips, `sample` finds nothing or a
    /// distance beyond contact. And it does skip, most of the time far from the surface.
    #[test]
    fn clearances_skip_only_lookups_beyond_contact() {
        use crate::geometry::{Aabb, Cylinder, SdfGrid};
        // A blade off the axis, so that turning moves its surface.
        let blade = Cylinder::new(Vec3::new(0.0, 0.3, 0.0), Vec3::X, 0.1, 0.8);
        let bounds = Aabb {
            min: Vec3::new(-0.4, 0.2, -0.1),
            max: Vec3::new(0.4, 0.4, 0.1),
        };
        let grid = SdfGrid::from_sdf(&blade, bounds, 0.02, 0.3).unwrap();
        assert!(
            (0.99..=1.74).contains(&grid.lipschitz()),
            "{}",
            grid.lipschitz()
        );
        let motion = Motion::rotation_rpm(Vec3::X, Vec3::ZERO, 120.0);
        let mut body = Body::new("blade", BodyShape::Grid(grid), motion);
        body.start(0.0);
        let (reach, beyond) = (0.01, 0.012);
        let mut clearance = Clearance::NONE;
        let mut rng = 12345u64;
        let mut next = move || {
            rng = rng
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (rng >> 11) as Real / (1u64 << 53) as Real - 0.5
        };
        let mut p = Vec3::new(0.0, 0.3, 0.25);
        let (mut skipped, mut near) = (0, 0);
        for step in 0..20_000 {
            body.set_time(step as Real * 1e-4);
            p += 0.002 * Vec3::new(next(), next(), next());
            p = p.clamp(Vec3::splat(-0.45), Vec3::splat(0.45));
            let exact = body.sample(p, reach).map(|s| s.distance());
            match body.sample_near(p, reach, beyond, &mut clearance) {
                Some(s) => {
                    assert_eq!(Some(s.distance().to_bits()), exact.map(Real::to_bits));
                }
                None => {
                    if let Some(d) = exact {
                        assert!(d >= beyond, "skipped at distance {d} (step {step})");
                        skipped += 1;
                    }
                }
            }
            if exact.is_some_and(|d| d < 0.05) {
                near += 1;
            }
        }
        assert!(skipped > 5_000, "{skipped} lookups skipped of 20000");
        assert!(
            near > 100,
            "the walk stayed away from the blade ({near} steps near it)"
        );
        // A particle with another reach in the slot: the ball is not used.
        let mut far = Clearance::NONE;
        body.sample_near(Vec3::new(0.0, 0.3, 0.25), reach, beyond, &mut far);
        assert!(far.free_squared > 0.0);
        assert!(body
            .sample_near(Vec3::new(0.0, 0.3, 0.25), reach, 0.2, &mut far)
            .is_some_and(|s| s.distance() < 0.2));
    }
}
