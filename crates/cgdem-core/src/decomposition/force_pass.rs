//! The force pass of one subdomain, a function per job: the sums cleared, the listed pairs
//! (for laws with history, those within reach first), after a list build the walls each
//! particle may reach, then what acts on each particle alone (gravity, the planar walls,
//! the bodies). Every sum runs in list, then particle, order: the same bits on any number
//! of threads or ranks.
//!
//! The helpers take the particle arrays (`ParticleState`, a few slices) by value: passed by
//! reference to a helper the compiler does not inline, their address escapes, and the pair
//! loop then reloads every slice's pointer after each force it stores (the heap bench ran
//! 26% slower so).

use super::step::{ForceSums, Physics};
use super::Subdomain;
use crate::bodies::{BodyLoad, Clearance, NearTriangles};
use crate::contact::{PairHistory, PairLaw};
use crate::force::{larger, pair_force, AloneSlots, FirstParticle, ForceView, ParticleState};
use crate::math::{Real, Vec3};
use crate::neighbor::PairList;
use crate::walls::{WallLaw, WallMask, WallParticle};

/// Forces (and torques) on `sub`'s owned particles: every listed pair evaluated with the
/// lower id first and added to whichever of its particles are owned here (both for an owned
/// pair: a half list without stored reactions), then what acts on each particle alone
/// (gravity, the planar walls and the bodies, with their histories). Returns the deepest
/// pair and wall (or body) overlaps and the bodies' loads summed over the owned particles in
/// order.
#[inline(always)]
pub(super) fn forces<L: PairLaw, W: WallLaw>(
    sub: &mut Subdomain<L::History, W::History>,
    physics: &Physics<'_, L, W>,
    skin: Real,
) -> ForceSums {
    let n = sub.n_owned;
    let ForceView {
        state,
        force,
        torque,
    } = ParticleState::split(&mut sub.particles);
    force[..n].fill(Vec3::ZERO);
    if physics.rotates {
        torque[..n].fill(Vec3::ZERO);
    }
    let deepest_pair = pair_sums(
        &mut sub.list,
        &mut sub.pairs_by_reach,
        state,
        force,
        torque,
        n,
        physics,
    );
    if sub.near_walls.len() != n {
        // After a list build: the walls each particle may reach before the next one.
        sub.near_walls = near_walls(state, n, physics, skin);
        forget_far_wall_histories(&sub.near_walls, &mut sub.wall_history, physics);
    }
    let (n_bodies, n_meshes) = (physics.surroundings.bodies.len(), mesh_bodies(physics));
    // Sized exactly (the reported memory must not depend on the run's history).
    if sub.body_clearances.len() != n * n_bodies {
        sub.body_clearances = vec![Clearance::NONE; n * n_bodies];
    }
    if sub.near_triangles.len() != n * n_meshes {
        sub.near_triangles = vec![NearTriangles::NONE; n * n_meshes];
    }
    let mut body_loads = vec![BodyLoad::default(); n_bodies];
    let alone = AloneArrays {
        near_walls: &sub.near_walls,
        wall_history: &mut sub.wall_history,
        clearances: &mut sub.body_clearances,
        near_triangles: &mut sub.near_triangles,
    };
    let deepest_wall = alone_sums(alone, state, force, torque, &mut body_loads, physics);
    ForceSums {
        deepest_pair,
        deepest_wall,
        finite: true,
        body_loads,
        kinematic_loads: Vec::new(),
    }
}

/// Every listed pair's force (and torques) added to whichever of its two particles are owned
/// (the first `n`); returns the deepest overlap as a fraction of the smaller radius.
#[inline(always)]
fn pair_sums<L: PairLaw, W: WallLaw>(
    list: &mut PairList<L::History>,
    pairs_by_reach: &mut Vec<u32>,
    state: ParticleState<'_>,
    force: &mut [Vec3],
    torque: &mut [Vec3],
    n: usize,
    physics: &Physics<'_, L, W>,
) -> Real {
    let (rotates, dt) = (physics.rotates, physics.surroundings.dt);
    let mut deepest_pair: Real = 0.0;
    // One pair, `b` seen at `position_b`: its force added to whichever of the two are owned
    // (a macro, written once for the direct pairs and those through an image, so that each
    // loop keeps its sums in registers).
    macro_rules! pair {
        ($a:expr, $b:expr, $position_b:expr, $constants:expr, $history:expr) => {{
            let (a, b): (usize, usize) = ($a, $b);
            let first = FirstParticle::at(&state, a, physics.n_species);
            let (result, overlap, smaller_radius) = pair_force(
                physics.law,
                &state,
                &first,
                b,
                $position_b,
                $constants,
                $history,
                dt,
            );
            if overlap > deepest_pair * smaller_radius {
                deepest_pair = overlap / smaller_radius;
            }
            if a < n {
                force[a] += result.force_on_i;
                if rotates {
                    torque[a] += result.torque_on_i;
                }
            }
            if b < n {
                force[b] -= result.force_on_i;
                if rotates {
                    torque[b] += result.torque_on_j;
                }
            }
        }};
    }
    if !compacts_touching_pairs::<L::History>() {
        // A law without contact history (the seed model) is cheap per pair: a filter first
        // would cost more than it spares (the main job 11% slower, reports/PERFORMANCE.md).
        let pairs = list.pairs.iter().zip(&list.constants);
        for ((&[a, b], &constants), history) in pairs.zip(&mut list.history) {
            let b = b as usize;
            pair!(a as usize, b, state.position[b], constants, history);
        }
    } else {
        let count = sort_by_reach(list, pairs_by_reach, state, physics);
        forget_out_of_reach(list, &pairs_by_reach[count..]);
        // Cut to the pairs' length: the check of `pairs[k]` stands for the other two.
        let listed = list.pairs.len();
        let (pairs, constants) = (&list.pairs[..], &list.constants[..listed]);
        let history = &mut list.history[..listed];
        for &k in &pairs_by_reach[..count] {
            let k = k as usize;
            let [a, b] = pairs[k];
            let b = b as usize;
            pair!(
                a as usize,
                b,
                state.position[b],
                constants[k],
                &mut history[k]
            );
        }
    }
    for (image, history) in list.image_pairs.iter().zip(&mut list.image_history) {
        let b = image.pair[1] as usize;
        pair!(
            image.pair[0] as usize,
            b,
            state.position[b] + image.shift,
            image.constants,
            history
        );
    }
    deepest_pair
}

/// Whether the force pass evaluates the pairs within reach apart from the others: for laws
/// with contact history only (the seed model's law is cheaper than the filter;
/// reports/PERFORMANCE.md).
pub(super) fn compacts_touching_pairs<H>() -> bool {
    std::mem::size_of::<H>() > 0
}

/// The listed pairs (by index) sorted by a cheap distance filter, with no branch: those
/// within reach to the front of `order`, in list order, the others to its back. The law then
/// runs over the front only, in list order (every particle's sum is the same as over the
/// whole list), with no branch that half of them take: a settled bed lists about two pairs
/// for each one that touches. Returns how many are within reach.
#[inline(always)]
fn sort_by_reach<L: PairLaw, W: WallLaw>(
    list: &PairList<L::History>,
    order: &mut Vec<u32>,
    state: ParticleState<'_>,
    physics: &Physics<'_, L, W>,
) -> usize {
    let listed = list.pairs.len();
    if order.len() != listed {
        // Sized exactly, not grown (the reported memory must not depend on the run's
        // history: a resumed run reports what the uninterrupted one does).
        *order = vec![0; listed];
    }
    let (mut count, mut back) = (0, listed);
    for (k, &[a, b]) in list.pairs.iter().enumerate() {
        let (a, b) = (a as usize, b as usize);
        let species_pair =
            state.species[a] as usize * physics.n_species + state.species[b] as usize;
        let cutoff = physics
            .law
            .cutoff(species_pair, state.radius[a], state.radius[b]);
        // The same test as `pair_force`'s (a NaN distance is within reach, so the guard
        // sees it).
        let out_of_reach =
            (state.position[a] - state.position[b]).length_squared() >= cutoff * cutoff;
        let at = if out_of_reach { back - 1 } else { count };
        order[at] = k as u32;
        count += usize::from(!out_of_reach);
        back -= usize::from(out_of_reach);
    }
    count
}

/// The pairs `out_of_reach` (by index) lose their history, as the law would reset it had it
/// seen them; written only where it is set.
#[inline(always)]
fn forget_out_of_reach<H: PairHistory>(list: &mut PairList<H>, out_of_reach: &[u32]) {
    for &k in out_of_reach {
        let history = &mut list.history[k as usize];
        if *history != Default::default() {
            *history = Default::default();
        }
    }
}

/// What the wall law reads of owned particle `i`.
#[inline(always)]
fn wall_particle(state: ParticleState<'_>, i: usize) -> WallParticle {
    WallParticle {
        species: state.species[i] as usize,
        position: state.position[i],
        velocity: state.velocity[i],
        radius: state.radius[i],
        mass: state.mass[i],
    }
}

/// Per owned particle (the first `n`), the walls it may reach before the next list build.
fn near_walls<L: PairLaw, W: WallLaw>(
    state: ParticleState<'_>,
    n: usize,
    physics: &Physics<'_, L, W>,
    skin: Real,
) -> Vec<WallMask> {
    let (walls, law) = (physics.surroundings.walls, physics.surroundings.wall_law);
    (0..n)
        .map(|i| walls.near(law, &wall_particle(state, i), skin))
        .collect()
}

/// The wall histories of the walls a particle cannot reach are set at rest now: the pass
/// skips those walls until the next build, where a pass over every wall would reset them.
fn forget_far_wall_histories<L: PairLaw, W: WallLaw>(
    near_walls: &[WallMask],
    wall_history: &mut [W::History],
    physics: &Physics<'_, L, W>,
) {
    if !physics.rotates {
        // Wall histories are kept only for laws that rotate.
        return;
    }
    let (slots, walls) = (physics.wall_slots, physics.surroundings.walls.walls.len());
    for (i, near) in near_walls.iter().enumerate() {
        let history = &mut wall_history[i * slots..][..walls];
        for (k, h) in history.iter_mut().enumerate() {
            if !near.has(k) {
                *h = Default::default();
            }
        }
    }
}

/// A subdomain's per-particle arrays for what acts on its particles alone.
struct AloneArrays<'s, WH> {
    near_walls: &'s [WallMask],
    /// `wall_slots` per particle when particles spin, else empty.
    wall_history: &'s mut [WH],
    /// One per particle and body.
    clearances: &'s mut [Clearance],
    /// One per particle and body met on its triangles.
    near_triangles: &'s mut [NearTriangles],
}

/// How many bodies are met on their triangles (each keeps a list of near triangles per
/// particle).
fn mesh_bodies<L, W>(physics: &Physics<'_, L, W>) -> usize {
    let bodies = physics.surroundings.bodies.iter();
    bodies.filter(|b| b.is_mesh()).count()
}

/// Adds to each owned particle's force (and torque) what acts on it alone: gravity, the
/// walls it may reach and the bodies, with its histories, clearances and lists of near
/// triangles; each body's load into `body_loads`. Returns the deepest wall or body overlap
/// as a fraction of the radius.
#[inline(always)]
fn alone_sums<L: PairLaw, W: WallLaw>(
    arrays: AloneArrays<'_, W::History>,
    state: ParticleState<'_>,
    force: &mut [Vec3],
    torque: &mut [Vec3],
    body_loads: &mut [BodyLoad],
    physics: &Physics<'_, L, W>,
) -> Real {
    let rotates = physics.rotates;
    let (n_bodies, n_meshes) = (physics.surroundings.bodies.len(), mesh_bodies(physics));
    let slots = if rotates { physics.wall_slots } else { 0 };
    let mut deepest_wall: Real = 0.0;
    for (i, &near) in arrays.near_walls.iter().enumerate() {
        let alone = AloneSlots {
            near,
            history: &mut arrays.wall_history[i * slots..(i + 1) * slots],
            clearances: &mut arrays.clearances[i * n_bodies..(i + 1) * n_bodies],
            near_triangles: &mut arrays.near_triangles[i * n_meshes..(i + 1) * n_meshes],
        };
        let omega = state.omega.map_or(Vec3::ZERO, |w| w[i]);
        let mut unused = Vec3::ZERO;
        let spin = if rotates { &mut torque[i] } else { &mut unused };
        let overlap = physics.surroundings.act_on(
            &wall_particle(state, i),
            omega,
            rotates,
            alone,
            body_loads,
            &mut force[i],
            spin,
        );
        deepest_wall = larger(deepest_wall, overlap);
    }
    deepest_wall
}
