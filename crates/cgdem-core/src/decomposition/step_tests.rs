//! The step of a decomposed world seen from its subdomains: the ghosts' update and the two
//! copies of a pair across a boundary.

use super::step::{Decomposition, Drive, Physics};
use super::{Comm, Grid, HistoryRows};
use crate::contact::{normal::WcaCoefficients, PairLaw, SeedModel};
use crate::domain::Domain;
use crate::force::Surroundings;
use crate::integrate::Integrator;
use crate::math::{Real, Vec3};
use crate::particles::Particles;
use crate::walls::{WallLaw, WallSet, WcaWall};
use rand::{Rng, SeedableRng};

/// The seed's laws for particles of radius up to 0.03 (WCA reach 0.045), no walls.
struct Laws {
    law: SeedModel,
    wall_law: WcaWall,
    walls: WallSet,
}

impl Laws {
    fn new() -> Self {
        let wca = WcaCoefficients {
            epsilon: 1e-6,
            sigma: 0.04,
        };
        Laws {
            law: SeedModel::seed(vec![wca], vec![0.0], vec![0.0]),
            wall_law: WcaWall::new(&[(wca, 1.0)], 0.5, 0.0),
            walls: WallSet::default(),
        }
    }

    fn physics(&self) -> Physics<'_, SeedModel, WcaWall> {
        Physics {
            law: &self.law,
            surroundings: Surroundings {
                wall_law: &self.wall_law,
                walls: &self.walls,
                bodies: &[],
                gravity: Vec3::ZERO,
                dt: 1e-3,
            },
            kinematic: &[],
            n_species: 1,
            wall_slots: 0,
            rotates: false,
        }
    }
}

/// The unit box, periodic along x.
fn periodic_x() -> Domain {
    Domain {
        lo: Vec3::ZERO,
        hi: Vec3::ONE,
        periodic: [true, false, false],
    }
}

/// The subdomains of a world under the seed's laws.
type SeedSubdomains = Decomposition<<SeedModel as PairLaw>::History, <WcaWall as WallLaw>::History>;

/// `p` dealt out over `grid`, ghost layer 0.1 thick, skin 0.2.
fn decomposed(p: &Particles, grid: Grid, domain: &Domain) -> SeedSubdomains {
    let rows = HistoryRows::none(p.len());
    Decomposition::new(grid, p, &[], &rows, domain, 0, 0.1, 0.2, 0.2, Comm::local())
}

/// The step's own path: the first half packs, the force pass unpacks. Every ghost must then
/// hold its owner's new state, bit for bit, its position through the image shift.
#[test]
fn ghosts_follow_their_owners_through_the_image_shift() {
    let domain = periodic_x();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(5);
    let mut p = Particles::new(false);
    for _ in 0..400 {
        let u = Vec3::new(rng.gen(), rng.gen(), rng.gen());
        p.push(0, u, rng.gen_range(0.01..=0.03), 1.0);
    }
    for k in 0..p.len() {
        // A velocity that depends on the id, so that every ghost moves its own way.
        p.velocity[k] = Vec3::new(1e-3 * p.id[k] as Real, 0.5, -2.0);
    }
    let mut d = decomposed(&p, Grid::balanced([2, 2, 1], &domain, &p.position), &domain);
    let before: Vec<Vec<Vec3>> = d
        .subdomains
        .iter()
        .map(|s| s.particles.position.clone())
        .collect();
    let drive = Drive {
        bodies: &[],
        kinematic: &[],
        delete_regions: &[],
        rotates: false,
    };
    // 1 ms at up to 2 m/s: within half the skin, so no rebuild.
    assert!(!d.advance(1e-3, Integrator::VelocityVerlet, &drive));
    d.forces(&Laws::new().physics(), None);
    let mut ghosts = 0;
    for (sub, old) in d.subdomains.iter().zip(&before) {
        let mut k = sub.n_owned;
        for &(from, list) in &sub.receives {
            let (owner, list) = (&d.subdomains[from], &d.subdomains[from].sends[list]);
            for &i in &list.indices {
                let x = sub.particles.position[k];
                assert_eq!(x, owner.particles.position[i as usize] + list.shift);
                assert_ne!(x, old[k], "the ghost must have moved");
                assert_eq!(
                    sub.particles.velocity[k],
                    owner.particles.velocity[i as usize]
                );
                (k, ghosts) = (k + 1, ghosts + 1);
            }
        }
        assert_eq!(k, sub.particles.len());
    }
    assert!(ghosts > 0);
}

/// Both copies of a pair across an interior face compute the same numbers: the forces on
/// its two particles cancel exactly. Across the periodic face of an axis cut into
/// subdomains, each side sees the other particle through its image, whose position is
/// rounded once more (`x + 1` of a particle near `x = 0`): the two forces cancel only to
/// that rounding. This pins the documented behaviour; a change that makes the periodic
/// copies identical should update the docs (decomposition, docs/architecture.md).
#[test]
fn copies_of_a_pair_agree_exactly_inside_and_to_a_rounding_across_a_periodic_face() {
    let domain = periodic_x();
    let mut p = Particles::new(false);
    // Ids 0 and 1 across the periodic face (0.0412 apart, touching), 2 and 3 across the
    // interior plane x = 0.5 (0.0398 apart).
    for x in [
        Vec3::new(0.012_345_678_9, 0.5, 0.5),
        Vec3::new(0.971_123_456_7, 0.5, 0.5),
        Vec3::new(0.480_123_456_7, 0.2, 0.5),
        Vec3::new(0.519_923_456_7, 0.2, 0.5),
    ] {
        p.push(0, x, 0.02, 1.0);
    }
    let grid = Grid {
        counts: [2, 1, 1],
        planes: [vec![0.5], Vec::new(), Vec::new()],
        lo: domain.lo,
        hi: domain.hi,
        periodic: domain.periodic,
    };
    let mut d = decomposed(&p, grid, &domain);
    d.forces(&Laws::new().physics(), None);
    let (p, _) = d.gathered();
    let force = |id: u32| p.force[p.id.iter().position(|&i| i == id).expect("kept")];
    let (inside, across) = (force(2) + force(3), force(0) + force(1));
    assert!(
        force(2).x != 0.0 && force(0).x != 0.0,
        "both pairs must touch"
    );
    assert_eq!(inside, Vec3::ZERO, "the interior copies must agree bitwise");
    assert_ne!(
        across,
        Vec3::ZERO,
        "these positions round differently on the two sides"
    );
    assert!(
        across.length() < 1e-12 * force(0).length(),
        "the periodic copies must agree to a rounding: {across:?} of {:?}",
        force(0)
    );
}
