//! Scene text the collision tests share: glass-like beads (E = 5e6 Pa, the smallest Young's
//! modulus LIGGGHTS takes; nu = 0.3, e = 0.5, mu = 0.5, mu_r = 0.1) under Hertz-Mindlin with
//! tangential history and epsd2 rolling friction, against walls of the same coefficients.
//! Each test writes its own box, species and bodies around these tables, so a change to the
//! beads is made once.

use cgdem_core::math::Real;

/// The beads' `[contact]` table (without `[[contact.pair]]` entries).
pub const BEAD_CONTACT: &str = r#"[contact]
model = "hertz"
youngs_modulus = 5.0e6
poisson_ratio = 0.3
restitution = 0.5
friction = 0.5
rolling_friction = 0.1
damping = "hertz"
tangential = "history"
rolling = "epsd2"
cohesion = "none"
characteristic_velocity = 1.0
"#;

/// The walls' `[wall_contact]` table: the beads' coefficients.
pub const BEAD_WALL_CONTACT: &str = r#"[wall_contact]
restitution = 0.5
friction = 0.5
rolling_friction = 0.1
"#;

/// One stage of `duration` s, every step (`dt`) in the time series, lists never re-sorted.
#[allow(dead_code)] // not every test binary that includes this file runs a collision
pub fn every_step(duration: Real, dt: Real) -> String {
    format!(
        r#"[time]
dt_fraction = 0.05
[neighbor]
skin_fraction = 0.1
resort_every = 0
[[stage]]
name = "collide"
duration = {duration}
[output]
timeseries_interval = {dt}
"#
    )
}
