//! Which particles a list rebuild removes, and the accounting of what they took with them:
//! a particle that left the box through a bounded face is lost (or kept, when that stops
//! the run: the guard names it), one whose centre entered a delete region is deleted, a
//! non-finite one is the non-finite guard's. The events are gathered over every subdomain
//! (of every rank) in order, so the counts and sums are the same on any number of threads
//! or ranks.

use crate::domain::Domain;
use crate::geometry::aabb::in_delete_region;
use crate::geometry::Aabb;
use crate::math::{Real, Vec3};
use crate::particles::Particles;

/// What decides whether an owned particle stays at a rebuild.
#[derive(Clone, Copy)]
pub struct RemovalRule<'a> {
    pub domain: &'a Domain,
    pub delete_regions: &'a [Aabb],
    /// A particle out of the box stops the run (and stays, for the outputs), instead of
    /// being removed.
    pub stop_on_lost: bool,
    /// A guard has fired this step: no more particles are reported as leaving.
    pub tripped: bool,
    /// Gravity and the corner energy is counted from, for the energy the removed take away.
    pub gravity: Vec3,
    pub origin: Vec3,
}

impl RemovalRule<'_> {
    /// Whether a particle at `x` stays in the box (or is kept there to be reported).
    pub fn stays(&self, x: Vec3) -> bool {
        x.is_finite() && (self.stop_on_lost || self.domain.contains_bounded(x))
    }

    /// Whether a particle at `x` is kept by the rebuild.
    pub fn keeps(&self, x: Vec3) -> bool {
        self.stays(x) && !in_delete_region(self.delete_regions, x)
    }

    /// The event of owned particle `k` of `p`, if the rebuild removes it or it left the box,
    /// appended to `out` as words (see [`Removals::add_words`]).
    pub fn record(&self, p: &Particles, k: usize, out: &mut Vec<Real>) {
        let x = p.position[k];
        let left =
            self.stop_on_lost && x.is_finite() && !self.domain.contains_bounded(x) && !self.tripped;
        let removed = !self.keeps(x);
        if !left && !removed {
            return;
        }
        // In a delete region and not otherwise removed: deleted, not lost.
        let deleted = removed && self.stays(x);
        let energy = 0.5 * p.mass[k] * p.velocity[k].length_squared() + p.spin_energy(k)
            - p.mass[k] * self.gravity.dot(x - self.origin);
        out.push(p.id[k] as Real);
        out.extend_from_slice(&x.to_array());
        out.extend_from_slice(&p.velocity[k].to_array());
        let flag = |b: bool| if b { 1.0 } else { 0.0 };
        out.extend_from_slice(&[energy, flag(left), flag(removed), flag(deleted), p.mass[k]]);
    }
}

/// What a rebuild removed or found outside the box, over all subdomains in order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Removals {
    /// Particles outside the box that stop the run: (id, position, velocity).
    pub left_box: Vec<(u32, Vec3, Vec3)>,
    /// Removed because they left the box through a bounded face (or became non-finite).
    pub lost: u64,
    /// Removed because their centre entered a delete region, and their mass.
    pub deleted: u64,
    pub deleted_mass: Real,
    /// Kinetic plus gravitational energy the removed particles took away (finite ones).
    pub energy: Real,
    /// Ids of removed particles whose energy was not finite.
    pub non_finite: Vec<u32>,
}

impl Removals {
    /// Words per event of [`RemovalRule::record`].
    const WORDS: usize = 12;

    /// Adds the events of one subdomain, as [`RemovalRule::record`] wrote them.
    pub fn add_words(&mut self, words: &[Real]) {
        for w in words.chunks_exact(Self::WORDS) {
            let id = w[0] as u32;
            if w[8] != 0.0 {
                let (x, v) = (Vec3::new(w[1], w[2], w[3]), Vec3::new(w[4], w[5], w[6]));
                self.left_box.push((id, x, v));
            }
            if w[9] == 0.0 {
                continue;
            }
            if w[10] != 0.0 {
                self.deleted += 1;
                self.deleted_mass += w[11];
            } else {
                self.lost += 1;
            }
            if w[7].is_finite() {
                self.energy += w[7];
            } else {
                self.non_finite.push(id);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lost_deleted_and_reported_particles_are_told_apart() {
        let domain = Domain {
            lo: Vec3::ZERO,
            hi: Vec3::ONE,
            periodic: [false; 3],
        };
        let outlet = [Aabb {
            min: Vec3::new(0.0, 0.0, 0.0),
            max: Vec3::new(1.0, 1.0, 0.1),
        }];
        let mut p = Particles::new(false);
        for x in [
            Vec3::splat(0.5),               // stays
            Vec3::new(0.5, 0.5, 0.05),      // deleted
            Vec3::new(1.5, 0.5, 0.5),       // left the box
            Vec3::new(Real::NAN, 0.0, 0.0), // non-finite
        ] {
            p.push(0, x, 0.01, 2.0);
        }
        let rule = |stop_on_lost| RemovalRule {
            domain: &domain,
            delete_regions: &outlet,
            stop_on_lost,
            tripped: false,
            gravity: Vec3::new(0.0, 0.0, -10.0),
            origin: Vec3::ZERO,
        };
        for stop_on_lost in [false, true] {
            let mut words = Vec::new();
            for k in 0..p.len() {
                rule(stop_on_lost).record(&p, k, &mut words);
            }
            let mut removals = Removals::default();
            removals.add_words(&words);
            assert_eq!((removals.deleted, removals.deleted_mass), (1, 2.0));
            assert_eq!(removals.non_finite, vec![3]);
            if stop_on_lost {
                // Kept for the guard to name, not removed.
                assert_eq!(removals.lost, 1);
                assert_eq!(removals.left_box.len(), 1);
                assert_eq!(removals.left_box[0].0, 2);
            } else {
                assert_eq!(removals.lost, 2);
                assert!(removals.left_box.is_empty());
            }
        }
    }
}
