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
//! bodies, a ball free of the surface) does not already rule them out, and kept in the
//! particle's [`NearTriangles`] (LIGGGHTS's per-particle triangle list): while its point stays
//! within the skin of where they were searched, it visits them without searching again.

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

/// How far a particle's triangle search looks, in reaches: the clearance ball and the list of
/// triangles then let the particle move half a reach (the list's skin) before the next
/// search. A wider skin searches less often but lists more triangles, each tested every step.
const SEARCH_REACH: Real = 1.5;

thread_local! {
    /// The triangles near the particle of the moment (the search's scratch).
    static NEAR: RefCell<Vec<u32>> = const { RefCell::new(Vec::new()) };
}

/// Triangles a particle's list holds at most; a search that finds more is not kept (the
/// particle searches again at its next step, as it would without a list).
const NEAR_CAPACITY: usize = 48;

/// The triangles of one mesh body within the search radius of a body-frame point `at`: a
/// particle's list, as LIGGGHTS keeps one per particle and mesh. For any point within
/// `skin` of `at`, every triangle nearer than `beyond` is in it, so the contacts found from it
/// are those a new search would give, in the same (index) order: the outputs do not change.
/// Like [`Clearance`], it states a fact about the body, not about a particle, so a slot
/// handed to another particle after a re-sort is still right for it.
#[derive(Clone, Copy, Debug)]
pub struct NearTriangles {
    at: Vec3,
    /// Squared radius of the ball of points the list serves; negative: none.
    skin_squared: Real,
    /// The distance below which the list holds every triangle (a particle's reach or radius).
    beyond: Real,
    count: u32,
    triangles: [u32; NEAR_CAPACITY],
}

impl NearTriangles {
    pub const NONE: NearTriangles = NearTriangles {
        at: Vec3::ZERO,
        skin_squared: -1.0,
        beyond: Real::NAN,
        count: 0,
        triangles: [0; NEAR_CAPACITY],
    };

    /// How far `q` is from where the list was searched, if it serves `q` for `beyond`.
    #[inline(always)]
    fn serves(&self, q: Vec3, beyond: Real) -> Option<Real> {
        let moved_squared = (q - self.at).length_squared();
        (self.beyond == beyond && moved_squared < self.skin_squared).then(|| moved_squared.sqrt())
    }

    /// Keeps `triangles` (every one within `beyond + skin` of `at`), if they fit.
    fn keep(&mut self, at: Vec3, beyond: Real, skin: Real, triangles: &[u32]) {
        if triangles.len() > NEAR_CAPACITY {
            *self = NearTriangles::NONE;
            return;
        }
        self.at = at;
        self.beyond = beyond;
        self.skin_squared = skin * skin;
        self.count = triangles.len() as u32;
        self.triangles[..triangles.len()].copy_from_slice(triangles);
    }

    fn triangles(&self) -> &[u32] {
        &self.triangles[..self.count as usize]
    }
}

/// Force and torque of a mesh body on one particle, the particle's load on the body and its
/// deepest overlap with a triangle as a fraction of its radius. `slots`: the particle's
/// `2 * MESH_CONTACTS` history slots for this body (tags, then histories); empty when
/// particles do not spin (then contacts keep no history and give no torque). `clearance`
/// and `near`: the particle's ball free of the surface and its list of triangles.
#[allow(clippy::too_many_arguments)]
pub(crate) fn mesh_contacts<W: WallLaw>(
    body: &Body,
    mesh: &MeshSurface,
    law: &W,
    particle: &WallParticle,
    omega: Vec3,
    slots: &mut [W::History],
    clearance: &mut Clearance,
    near: &mut NearTriangles,
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
    // No triangle outside the ones visited is nearer than this.
    let mut nearest = search;
    NEAR.with_borrow_mut(|found| {
        let listed = match near.serves(q, beyond) {
            Some(moved) => {
                nearest = search - moved;
                near.triangles()
            }
            None => {
                mesh.triangles_near(q, search, found);
                near.keep(q, beyond, search - beyond, found);
                found.as_slice()
            }
        };
        for &t in listed {
            let at_least = mesh.distance_at_least(t as usize, q);
            if at_least >= beyond {
                nearest = nearest.min(at_least);
                continue;
            }
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
