//! What the guards say when they fire: which particles, what was measured and the likely
//! cause. Run only when a guard fires, on the particles gathered from every subdomain.

use super::World;
use crate::contact::{Contact, PairLaw};
use crate::guard::{
    forced_step_cause, overlap_cause, overlap_fraction, undamped_limit, GuardKind, GuardTrip,
};
use crate::math::{Real, Vec3};
use crate::neighbor::pairs_within;
use crate::walls::{WallContact, WallLaw, WallParticle};

impl<L: PairLaw, W: WallLaw> World<L, W> {
    fn trip(
        &self,
        kind: GuardKind,
        particles: Vec<u32>,
        detail: String,
        cause: String,
    ) -> GuardTrip {
        GuardTrip {
            kind,
            step: self.steps,
            time: self.time,
            particles,
            detail,
            cause,
            dt: self.dt,
            stable_dt: self.guard.settings.stable_dt,
        }
    }

    pub(super) fn diagnose_non_finite(&mut self) -> GuardTrip {
        let p = &self.particles;
        let mut ids = std::mem::take(&mut self.guard.removed_non_finite);
        let bad: Vec<usize> = (0..p.len())
            .filter(|&k| {
                let spin_ok = p
                    .angular
                    .as_ref()
                    .is_none_or(|a| a.omega[k].is_finite() && a.torque[k].is_finite());
                !(p.position[k].is_finite()
                    && p.velocity[k].is_finite()
                    && p.force[k].is_finite()
                    && spin_ok)
            })
            .collect();
        let cause = forced_step_cause(self.dt, self.guard.settings.stable_dt).unwrap_or_else(|| {
            "a force too large for the step: a contact far stiffer than the step was chosen for (an impact faster than the scene's contact time scale, or particles placed overlapping)".into()
        });
        let count = ids.len() + bad.len();
        ids.extend(bad.iter().map(|&k| p.id[k]));
        ids.truncate(5);
        self.trip(
            GuardKind::NonFinite,
            ids,
            format!("{count} particle(s) with a non-finite position, velocity, force or spin"),
            cause,
        )
    }

    /// Names the deepest contact (pair, wall or body) and the step its stiffness at that
    /// overlap allows.
    pub(super) fn diagnose_overlap(&self) -> GuardTrip {
        let p = &self.particles;
        let s = self.guard.settings;
        let images: [Vec3; 27] = std::array::from_fn(|k| self.domain.image_shift(k as u8));
        // (fraction, ids, relative normal speed, local stable step, what)
        let mut worst: (Real, Vec<u32>, Real, Real, String) =
            (0.0, Vec::new(), 0.0, Real::NAN, String::new());
        for pair in pairs_within(p, &self.domain, self.law.reach()) {
            let (i, j) = (pair.i as usize, pair.j as usize);
            let d = self.domain.wrap(p.position[i])
                - (self.domain.wrap(p.position[j]) + images[pair.image as usize]);
            let distance = d.length();
            let (r_i, r_j) = (p.radius[i], p.radius[j]);
            let fraction = (r_i + r_j - distance) / r_i.min(r_j);
            if fraction > worst.0 {
                let normal = d / distance;
                let speed = (p.velocity[i] - p.velocity[j]).dot(normal);
                let m_eff = 1.0 / (p.inv_mass[i] + p.inv_mass[j]);
                let species_pair = p.species[i] as usize * self.n_species + p.species[j] as usize;
                let force_at = |distance: Real| {
                    let contact = Contact {
                        species_pair,
                        normal: Vec3::Z,
                        distance,
                        overlap: r_i + r_j - distance,
                        radius_i: r_i,
                        radius_j: r_j,
                        r_eff: r_i * r_j / (r_i + r_j),
                        inv_mass_i: p.inv_mass[i],
                        inv_mass_j: p.inv_mass[j],
                        m_eff,
                        relative_velocity: Vec3::ZERO,
                        normal_speed: 0.0,
                        tangential_velocity: Vec3::ZERO,
                    };
                    let mut history = L::History::default();
                    self.law
                        .evaluate(&contact, &mut history, (Vec3::ZERO, Vec3::ZERO), self.dt)
                        .force_on_i
                        .z
                };
                let h = 1e-6 * (r_i + r_j);
                let stiffness = (force_at(distance - h) - force_at(distance)) / h;
                worst = (
                    fraction,
                    vec![p.id[i], p.id[j]],
                    -speed,
                    undamped_limit(stiffness, m_eff),
                    "pair".into(),
                );
            }
        }
        for k in 0..p.len() {
            let particle = WallParticle {
                species: p.species[k] as usize,
                position: p.position[k],
                velocity: p.velocity[k],
                radius: p.radius[k],
                mass: p.mass[k],
            };
            for wall in self.walls.walls.iter().filter(|w| w.active) {
                let Some(distance) = wall.plane.distance(particle.position) else {
                    continue;
                };
                let fraction = overlap_fraction(distance, particle.radius);
                if fraction > worst.0 {
                    let force_at = |distance: Real| {
                        let contact = WallContact {
                            species: particle.species,
                            normal: Vec3::Z,
                            distance,
                            relative_velocity: Vec3::ZERO,
                            radius: particle.radius,
                            mass: particle.mass,
                        };
                        self.wall_law.force(&contact, self.dt).z
                    };
                    let h = 1e-6 * particle.radius;
                    let stiffness = if distance > h {
                        (force_at(distance - h) - force_at(distance)) / h
                    } else {
                        Real::NAN // the centre has passed the wall
                    };
                    worst = (
                        fraction,
                        vec![p.id[k]],
                        -particle.velocity.dot(wall.plane.normal),
                        undamped_limit(stiffness, particle.mass),
                        format!("wall `{}`", wall.name),
                    );
                }
            }
            for body in &self.bodies {
                let reach = self.wall_law.reach(particle.species, particle.radius);
                if let Some((distance, normal)) = body.query(particle.position, reach) {
                    let fraction = overlap_fraction(distance, particle.radius);
                    if fraction > worst.0 {
                        let surface = body.surface_velocity(particle.position - distance * normal);
                        worst = (
                            fraction,
                            vec![p.id[k]],
                            -(particle.velocity - surface).dot(normal),
                            Real::NAN,
                            format!("body `{}`", body.name),
                        );
                    }
                }
            }
        }
        let (fraction, ids, speed, local_limit, what) = worst;
        let initial = self.guard.initial_overlap.unwrap_or(0.0);
        let cause = if initial > s.max_overlap_fraction {
            format!("the particles were placed overlapping (largest overlap {:.0}% of the radius before the first step)", 100.0 * initial)
        } else if let Some(forced) = forced_step_cause(self.dt, s.stable_dt) {
            forced
        } else {
            let smallest_radius = p.radius.iter().cloned().fold(Real::INFINITY, Real::min);
            overlap_cause(fraction, speed, self.dt, local_limit, smallest_radius)
        };
        let mut trip = self.trip(
            GuardKind::Overlap,
            ids,
            format!(
                "{what} overlap {:.1}% of the radius exceeds the limit of {:.1}%{}",
                100.0 * fraction,
                100.0 * s.max_overlap_fraction,
                if local_limit.is_finite() {
                    format!("; at this overlap the contact allows dt <= {local_limit:.3e} s (undamped 2/omega)")
                } else {
                    String::new()
                }
            ),
            cause,
        );
        if local_limit.is_finite() {
            trip.stable_dt = trip.stable_dt.min(local_limit);
        }
        trip
    }

    pub(super) fn diagnose_lost(&self, left: &[(u32, Vec3, Vec3)]) -> GuardTrip {
        let (id, x, v) = left
            .iter()
            .copied()
            .max_by(|a, b| a.2.length_squared().total_cmp(&b.2.length_squared()))
            .expect("called with at least one particle");
        let (lo, hi) = (self.domain.lo, self.domain.hi);
        let face = (0..3)
            .find_map(|a| {
                if self.domain.periodic[a] {
                    None
                } else if x[a] < lo[a] {
                    Some(format!("{}lo", ["x", "y", "z"][a]))
                } else if x[a] > hi[a] {
                    Some(format!("{}hi", ["x", "y", "z"][a]))
                } else {
                    None
                }
            })
            .unwrap_or_else(|| "a bounded face".into());
        let initial = self.guard.initial_overlap.unwrap_or(0.0);
        let cause = if let Some(forced) = forced_step_cause(self.dt, self.guard.settings.stable_dt)
        {
            forced
        } else if initial > 0.01 && self.time < 0.1 {
            format!("the particles were placed overlapping (largest overlap {:.0}% of the radius before the first step) and the elastic energy released threw them out", 100.0 * initial)
        } else {
            "the box does not hold the motion: enlarge it, close it with walls, or catch such particles with a [[delete]] region (or set [domain] lost = \"warn\" to remove them with a warning)".into()
        };
        self.trip(
            GuardKind::LostParticles,
            left.iter().map(|l| l.0).collect(),
            format!(
                "{} particle(s) left the box through a bounded face; the fastest, id {id}, crossed {face} at ({:.4e}, {:.4e}, {:.4e}) m moving at {:.3} m/s",
                left.len(),
                x.x,
                x.y,
                x.z,
                v.length()
            ),
            cause,
        )
    }

    pub(super) fn diagnose_energy(&self, energy: Real, reference: Real) -> GuardTrip {
        let p = &self.particles;
        let s = self.guard.settings;
        let mut by_energy: Vec<(Real, u32)> = (0..p.len())
            .map(|k| (p.mass[k] * p.velocity[k].length_squared(), p.id[k]))
            .collect();
        by_energy.sort_by(|a, b| b.0.total_cmp(&a.0));
        let initial = self.guard.initial_overlap.unwrap_or(0.0);
        let cause = if let Some(forced) = forced_step_cause(self.dt, s.stable_dt) {
            forced
        } else if initial > 0.01 {
            format!("the particles were placed overlapping (largest overlap {:.0}% of the radius before the first step) and their elastic energy was released", 100.0 * initial)
        } else {
            "energy created at contacts the step does not resolve (a contact stiffer or an impact faster than the step was chosen for)".into()
        };
        self.trip(
            GuardKind::EnergyGrowth,
            by_energy.iter().take(3).map(|e| e.1).collect(),
            format!(
                "kinetic plus gravitational energy rose to {energy:.4e} J, above the {reference:.4e} J held at the start of the run or stage (kinetic, gravitational and elastic in overlapping pairs; allowed: +{:.0}%), with no work done on the particles; the particles named move fastest",
                100.0 * s.energy_growth
            ),
            cause,
        )
    }
}
