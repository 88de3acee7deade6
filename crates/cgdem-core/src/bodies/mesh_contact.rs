//! A mesh body on one particle, triangle by triangle (`contact = "mesh"`), as LIGGGHTS's
//! mesh walls (`fix_wall_gran.cpp`, `fix_contact_history_mesh`):
//!
//! - the triangles near the particle's point in the body frame are visited in index order,
//!   each giving the closest point of the feature it owns ([`MeshSurface::resolve`]);
//! - a contact is kept per triangle, with its own history (tangential and rolling springs).
//!   A new contact on a face, where a triangle of the same smooth patch sharing a vertex has
//!   already been counted at this step, is not counted (one patch, one contact); otherwise
//!   it starts with the history of such a triangle from the last step, so the spring goes
//!   on as the contact point moves from one triangle to the next;
//! - contacts not met again are dropped with their history.
//!
//! A particle keeps [`MESH_CONTACTS`] contacts per mesh body, each in two slots of its
//! wall-history row: the triangle (as a tag, [`PairHistory::tagged`]) and the history. The
//! triangles are found through the surface's BVH when the particle's clearance (as for grid
//! bodies, a ball free of the surface) does not already rule them out.

use std::cell::RefCell;

use super::{Body, BodyLoad, Clearance};
use crate::contact::PairHistory;
use crate::geometry::MeshSurface;
use crate::guard::overlap_fraction;
use crate::math::{Real, Vec3};
use crate::walls::{WallContact, WallLaw, WallParticle};

/// Contacts a particle keeps at once with one mesh body (LIGGGHTS's limit is the number of
/// triangles in its list). A further contact acts without history.
pub const MESH_CONTACTS: usize = 4;

/// How far beyond its reach a particle's triangle search looks, in reaches: the clearance
/// ball then lets the particle move that far before the next search.
const SEARCH_REACH: Real = 2.0;

thread_local! {
    /// The triangles near the particle of the moment (the search's scratch).
    static NEAR: RefCell<Vec<u32>> = const { RefCell::new(Vec::new()) };
}

/// Force and torque of a mesh body on one particle, the particle's load on the body and its
/// deepest overlap with a triangle as a fraction of its radius. `slots`: the particle's
/// `2 * MESH_CONTACTS` history slots for this body (tags, then histories); empty when
/// particles do not spin (then contacts keep no history and give no torque).
#[allow(clippy::too_many_arguments)]
pub(crate) fn mesh_contacts<W: WallLaw>(
    body: &Body,
    mesh: &MeshSurface,
    law: &W,
    particle: &WallParticle,
    omega: Vec3,
    slots: &mut [W::History],
    clearance: &mut Clearance,
    dt: Real,
) -> (Vec3, Vec3, BodyLoad, Real) {
    let reach = law.reach(particle.species, particle.radius);
    let beyond = reach.max(particle.radius);
    let (tags, histories) = slots.split_at_mut(slots.len() / 2);
    let mut out = (Vec3::ZERO, Vec3::ZERO, BodyLoad::default(), 0.0);
    let q = body.to_body(particle.position);
    if !body.within_reach(particle.position, reach) || clearance.contains(q, beyond) {
        forget(tags, histories, &[false; MESH_CONTACTS]);
        return out;
    }
    let search = SEARCH_REACH * beyond;
    let mut keep = [false; MESH_CONTACTS];
    // Without history: the triangles counted at this step, for the one-patch rule.
    let mut counted = [u32::MAX; MESH_CONTACTS];
    let mut nearest = search;
    NEAR.with_borrow_mut(|near| {
        mesh.triangles_near(q, search, near);
        for &t in near.iter() {
            let Some(hit) = mesh.resolve(t as usize, q) else {
                continue;
            };
            nearest = nearest.min(hit.distance);
            if hit.distance >= beyond {
                continue;
            }
            let overlap = overlap_fraction(hit.distance, particle.radius);
            if overlap > out.3 {
                out.3 = overlap;
            }
            // A centre on or past the surface has no normal: no force (as for grids).
            if hit.distance >= reach || hit.distance <= 0.0 {
                continue;
            }
            let tag = t as Real + 1.0;
            let same_patch =
                |other: Real| other != 0.0 && other != tag && mesh.coplanar(other as u32 - 1, t);
            let mut spare = W::History::default();
            let history = if tags.is_empty() || W::History::WORDS == 0 {
                let seen = |c: &u32| *c != u32::MAX && same_patch(*c as Real + 1.0);
                if hit.face && counted.iter().any(seen) {
                    continue;
                }
                if let Some(free) = counted.iter_mut().find(|c| **c == u32::MAX) {
                    *free = t;
                }
                &mut spare
            } else if let Some(s) = tags.iter().position(|h| h.tag() == tag) {
                keep[s] = true;
                &mut histories[s]
            } else {
                let patch_counted = (0..tags.len()).any(|s| keep[s] && same_patch(tags[s].tag()));
                if hit.face && patch_counted {
                    continue;
                }
                match tags.iter().position(|h| h.tag() == 0.0) {
                    Some(s) => {
                        tags[s] = W::History::tagged(tag);
                        keep[s] = true;
                        histories[s] = W::History::default();
                        if hit.face {
                            for o in 0..tags.len() {
                                if o != s && same_patch(tags[o].tag()) {
                                    histories[s] = histories[o];
                                }
                            }
                        }
                        &mut histories[s]
                    }
                    None => &mut spare,
                }
            };
            let point = body.to_world(hit.point);
            let contact = WallContact {
                species: particle.species,
                material: body.material,
                normal: body.rotate((q - hit.point) / hit.distance),
                distance: hit.distance,
                relative_velocity: particle.velocity - body.surface_velocity(point),
                radius: particle.radius,
                mass: particle.mass,
            };
            let (force, torque) = if W::NEEDS_ROTATION && !tags.is_empty() {
                law.force_and_torque_with_history(&contact, omega, history, dt)
            } else {
                (law.force(&contact, dt), Vec3::ZERO)
            };
            out.0 += force;
            out.1 += torque;
            out.2 += BodyLoad {
                force: -force,
                torque: (point - body.center()).cross(-force),
            };
        }
    });
    forget(tags, histories, &keep);
    // No triangle nearer than `nearest` (the exact distance is 1-Lipschitz); the margin
    // covers the tolerances of the feature tests.
    clearance.set(q, beyond, nearest - beyond * (1.0 + 1e-6));
    out
}

/// Drops the contacts not met at this step, with their history.
fn forget<H: PairHistory>(tags: &mut [H], histories: &mut [H], keep: &[bool; MESH_CONTACTS]) {
    for (s, tag) in tags.iter_mut().enumerate() {
        if !keep[s] && *tag != H::default() {
            *tag = H::default();
            histories[s] = H::default();
        }
    }
}
