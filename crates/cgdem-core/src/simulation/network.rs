//! The particle-particle contacts of the present state, for output: what LIGGGHTS's
//! `compute pair/gran/local` (pairs with force and overlap, for `dump local`) and
//! `compute contact/atom` (coordination number) give.

use rayon::prelude::*;

use super::World;
use crate::contact::PairLaw;
use crate::force::{pair_force, FirstParticle, ParticleState};
use crate::math::{Real, Vec3};
use crate::neighbor::{pairs_within, PairConstants};
use crate::walls::WallLaw;

/// One pair the law acts on now (centre distance below its cut-off).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairContact {
    /// Particle indices (not ids) of the pair.
    pub i: u32,
    pub j: u32,
    /// Add to `position[j]` for the image `i` interacts with (periodic boxes).
    pub image_shift: Vec3,
    /// Normal force on `i` along the unit vector from `j` to `i`, N (positive pushes apart).
    pub normal_force: Real,
    /// `r_i + r_j - distance`, m (negative when apart and a cohesion slot still acts).
    pub overlap: Real,
}

/// Interacting pairs and, per particle, the number of particles it touches.
#[derive(Clone, Debug, Default)]
pub struct ContactNetwork {
    pub pairs: Vec<PairContact>,
    /// Per particle (index order), the particles it interacts with (centre distance below the
    /// law's cut-off): for Hertz the particles it overlaps, as LIGGGHTS's `contact/atom`; for
    /// WCA those within its repulsion range (`2^(1/6) sigma`, a little beyond touching, where
    /// particles at rest sit); with cohesion also pairs held across a gap. Walls and bodies
    /// are not counted.
    pub coordination: Vec<u32>,
}

impl<L: PairLaw, W: WallLaw> World<L, W> {
    /// The pair contacts of the gathered particles (`particles`, as of the last
    /// `sync_particles`), evaluated by the scene's law. Read after a step, the elastic part
    /// of each normal force is the one the step applied; the damping part sees the
    /// velocities after the step's closing kick, where the step saw them half a step
    /// earlier (a difference of order `dt` / contact time). The subdomains' lists hold
    /// their pairs by subdomain, with ghosts: a pair search over the gathered particles
    /// finds them for the output, evaluated without their tangential history, which the
    /// reported normal force does not depend on (the tangential force is perpendicular to
    /// the normal). The run itself is untouched.
    pub fn contact_network(&self) -> ContactNetwork {
        let mut p = self.particles().clone();
        for x in p.position.iter_mut() {
            *x = self.domain.wrap(*x);
        }
        let p = &p;
        let list = pairs_within(p, &self.domain, self.law.reach() + self.neighbor.skin);
        let state = ParticleState::of(p);
        let pairs: Vec<PairContact> = list
            .par_iter()
            .with_min_len(4096)
            .filter_map(|&pair| {
                let (i, j) = (pair.i as usize, pair.j as usize);
                let first = FirstParticle::at(&state, i, self.n_species);
                let shift = self.domain.image_shift(pair.image);
                let mut history = L::History::default();
                let (result, overlap, _) = pair_force(
                    &self.law,
                    &state,
                    &first,
                    j,
                    p.position[j] + shift,
                    PairConstants::of(p, i, j),
                    &mut history,
                    self.dt,
                );
                let d = p.position[i] - (p.position[j] + shift);
                let within = d.length()
                    < self.law.cutoff(
                        first.species_row + p.species[j] as usize,
                        p.radius[i],
                        p.radius[j],
                    );
                within.then(|| PairContact {
                    i: pair.i,
                    j: pair.j,
                    image_shift: shift,
                    normal_force: result.force_on_i.dot(d.normalize_or_zero()),
                    overlap,
                })
            })
            .collect();
        let mut coordination = vec![0u32; p.len()];
        for c in &pairs {
            coordination[c.i as usize] += 1;
            coordination[c.j as usize] += 1;
        }
        ContactNetwork {
            pairs,
            coordination,
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::contact::cohesion::NoCohesion;
    use crate::contact::damping::{liggghts_damping_factor, HertzDamping};
    use crate::contact::normal::{Hertz, Material};
    use crate::contact::rolling::NoRolling;
    use crate::contact::tangential::Mindlin;
    use crate::contact::ContactLaw;
    use crate::decomposition::GridSpec;
    use crate::domain::Domain;
    use crate::particles::Particles;
    use crate::simulation::{Decompose, NeighborSettings, WorldSetup};
    use crate::walls::HertzWall;

    pub(crate) const R: Real = 1e-3;

    type HertzWorld =
        World<ContactLaw<Hertz, HertzDamping, Mindlin, NoRolling, NoCohesion>, HertzWall>;

    /// Spheres of radius `R` (Hertz, Mindlin, no gravity) in a box of half-width `half`.
    pub(crate) fn hertz_world(
        positions: &[Vec3],
        velocities: &[Vec3],
        half: Real,
        periodic: bool,
        restitution: Real,
    ) -> HertzWorld {
        let decompose = Decompose::default();
        hertz_world_on(
            positions,
            velocities,
            half,
            periodic,
            restitution,
            decompose,
        )
    }

    /// [`hertz_world`] on the grid `decompose` gives.
    pub(crate) fn hertz_world_on(
        positions: &[Vec3],
        velocities: &[Vec3],
        half: Real,
        periodic: bool,
        restitution: Real,
        decompose: Decompose,
    ) -> HertzWorld {
        let material = Material {
            youngs_modulus: 5e6,
            poisson_ratio: 0.3,
        };
        let law = ContactLaw::new(
            Hertz {
                y_eff: vec![Material::y_eff(material, material)],
                characteristic_velocity: 1.0,
            },
            HertzDamping::from_restitution(&[restitution]),
            Mindlin {
                g_eff: vec![Material::g_eff(material, material)],
                damping_factor: vec![liggghts_damping_factor(restitution)],
                friction: vec![0.5],
            },
            NoRolling,
            NoCohesion,
        );
        let wall = HertzWall::new(
            &[Material::y_eff(material, material)],
            restitution,
            0.5,
            0.0,
            1.0,
        );
        let mut particles = Particles::new(true);
        for (&x, &v) in positions.iter().zip(velocities) {
            particles.push(0, x, R, 1e-5);
            *particles.velocity.last_mut().unwrap() = v;
        }
        let domain = Domain {
            lo: Vec3::splat(-half),
            hi: Vec3::splat(half),
            periodic: [periodic, false, false],
        };
        let neighbor = NeighborSettings {
            skin: 0.5 * R,
            resort_every: 0,
        };
        let setup = WorldSetup::new(particles, domain, law, wall, 1, Vec3::ZERO, 1e-7, neighbor);
        World::new(setup, &decompose).expect("the particles fit the box")
    }

    #[test]
    fn network_holds_the_overlapping_pairs_with_the_force_the_step_applied_and_counts_them() {
        // 0 touches 1 (overlap 0.1 R, approaching), 1 touches 2 (0.05 R); 0 and 2 are apart.
        let x = [
            Vec3::new(-1.9 * R, 0.0, 0.0),
            Vec3::ZERO,
            Vec3::new(1.95 * R, 0.2 * R, 0.0),
        ];
        let v = [Vec3::new(0.1, 0.02, 0.0), Vec3::ZERO, Vec3::ZERO];
        // Undamped, so that the whole normal force is the one the step applied.
        let mut w = hertz_world(&x, &v, 0.01, false, 1.0);
        w.step();
        w.sync_particles();
        let network = w.contact_network();
        assert_eq!(network.coordination, [1, 2, 1]);
        assert_eq!(network.pairs.len(), 2);
        let p = w.particles();
        // Particle 0 has one contact: its normal force is its force along the line of centres.
        let c = network
            .pairs
            .iter()
            .find(|c| c.i == 0 || c.j == 0)
            .expect("pair 0-1");
        let n = (p.position[0] - p.position[1]).normalize();
        let on_0 = if c.i == 0 { 1.0 } else { -1.0 } * c.normal_force;
        assert!(c.normal_force > 0.0);
        assert!((p.force[0].dot(n) - on_0).abs() <= 1e-12 * c.normal_force);
        let distance = (p.position[0] - p.position[1]).length();
        assert_eq!(c.overlap, 2.0 * R - distance);
        // Reading the network leaves the run as it was.
        let before = (p.force.clone(), w.pair_histories());
        let _ = w.contact_network();
        assert_eq!((w.particles().force.clone(), w.pair_histories()), before);
    }

    #[test]
    fn a_world_on_two_subdomains_reports_the_contacts_it_reports_on_one() {
        // The network comes from the gathered particles, whatever the grid: the same
        // contacts with the same normal forces (they do not depend on tangential history).
        let x = [
            Vec3::new(-1.9 * R, 0.0, 0.0),
            Vec3::ZERO,
            Vec3::new(1.95 * R, 0.2 * R, 0.0),
        ];
        let v = [Vec3::new(0.1, 0.02, 0.0), Vec3::ZERO, Vec3::ZERO];
        let whole = hertz_world(&x, &v, 0.01, false, 1.0);
        let split = hertz_world_on(
            &x,
            &v,
            0.01,
            false,
            1.0,
            Decompose {
                grid: Some(GridSpec::Given([2, 1, 1])),
                ..Decompose::default()
            },
        );
        assert_eq!(split.grid(), [2, 1, 1]);
        let (a, b) = (whole.contact_network(), split.contact_network());
        assert_eq!(b.coordination, [1, 2, 1]);
        assert_eq!(a.coordination, b.coordination);
        let force = |n: &ContactNetwork| {
            let mut f: Vec<Real> = n.pairs.iter().map(|c| c.normal_force).collect();
            f.sort_by(Real::total_cmp);
            f
        };
        assert_eq!(force(&a), force(&b));
    }

    #[test]
    fn a_pair_across_a_periodic_face_ends_at_the_image_its_partner_meets() {
        let x = [
            Vec3::new(-0.01 + 0.95 * R, 0.0, 0.0),
            Vec3::new(0.01 - 0.95 * R, 0.0, 0.0),
        ];
        let w = hertz_world(&x, &[Vec3::ZERO; 2], 0.01, true, 0.5);
        let network = w.contact_network();
        assert_eq!(network.pairs.len(), 1);
        let c = network.pairs[0];
        let p = w.particles();
        let line = p.position[c.i as usize] - (p.position[c.j as usize] + c.image_shift);
        assert!((line.length() - 1.9 * R).abs() < 1e-12);
        assert!((c.overlap - 0.1 * R).abs() < 1e-12);
    }
}
