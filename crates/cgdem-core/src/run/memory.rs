//! What a run will allocate, estimated from the scene before anything is allocated, against
//! the memory the machine has free (`MemAvailable` in /proc/meminfo): a scene that cannot fit
//! is refused with both numbers instead of being killed part-way.

use crate::math::Real;
use crate::scene::{BodyContact, InsertAmount, LatticeKind, Scene};

/// Bytes per particle of the solver's arrays (state, forces, wall history, body loads, list
/// offsets): `MemoryUse::particle_bytes / particles` measured 478 (screw, 4974 particles) and
/// 497 (tiny collapse, 40); rounded up.
const PARTICLE_BYTES: Real = 512.0;
/// Bytes per listed pair (list, reverse index, contact history, results): measured 88 to 152.
const PAIR_BYTES: Real = 160.0;
/// Listed pairs per particle in a dense packing with the skin (half of ~12 neighbours, plus
/// the skin's shell); runs measured 1.2 to 3.1.
const PAIRS_PER_PARTICLE: Real = 6.0;
/// Cell grid: at most 16 cells per particle (its cap), 8 bytes each.
const CELL_BYTES_PER_PARTICLE: Real = 16.0 * 8.0;
/// Per particle and body: its clearance (`bodies::Clearance`), not in the figures above.
const CLEARANCE_BYTES: Real = std::mem::size_of::<crate::bodies::Clearance>() as Real;
/// Per particle and body met on its triangles: its list of them (`bodies::NearTriangles`).
const NEAR_TRIANGLES_BYTES: Real = std::mem::size_of::<crate::bodies::NearTriangles>() as Real;

#[derive(Clone, Debug, PartialEq)]
pub struct MemoryEstimate {
    pub particles: Real,
    pub particle_bytes: Real,
    pub pair_bytes: Real,
    pub sdf_bytes: Real,
}

impl MemoryEstimate {
    pub fn total(&self) -> Real {
        self.particle_bytes + self.pair_bytes + self.sdf_bytes
    }

    pub fn describe(&self) -> String {
        format!(
            "{} ({:.3e} particles: {} for particles and cells, {} for pairs and contact history; {} for SDF grids)",
            bytes(self.total()),
            self.particles,
            bytes(self.particle_bytes),
            bytes(self.pair_bytes),
            bytes(self.sdf_bytes)
        )
    }
}

pub fn bytes(b: Real) -> String {
    if b >= 1e9 {
        format!("{:.3} GB", b / 1e9)
    } else {
        format!("{:.1} MB", b / 1e6)
    }
}

/// The particles given (`read_data`, `[[particle]]`), those the insertions will make (an upper
/// bound for lattices and meshes), plus what top-ups may add (at most the region's count again
/// per insertion).
fn particle_count(scene: &Scene) -> Real {
    let mut n = scene.particles.len() as Real;
    for ins in &scene.insertions {
        let d = scene.species[ins.species].diameter;
        let box_volume = (ins.hi - ins.lo).max(crate::math::Vec3::ZERO);
        let box_volume = box_volume.x * box_volume.y * box_volume.z;
        let count = match &ins.amount {
            InsertAmount::Count(c) => *c as Real,
            InsertAmount::SolidVolume(v) => v / (std::f64::consts::PI / 6.0 * d * d * d),
            InsertAmount::Lattice(l) => {
                let per_site = match l.kind {
                    LatticeKind::Cubic => l.spacing.powi(3),
                    // Hexagonal layers: sqrt(3)/2 s^2 per site, layers s apart.
                    _ => 3.0f64.sqrt() / 2.0 * l.spacing.powi(3),
                };
                box_volume / per_site
            }
        };
        n += if ins.refill.is_some() {
            2.0 * count
        } else {
            count
        };
    }
    n
}

/// Bytes per triangle of a body met on its triangles (`geometry::MeshSurface`: corners,
/// edges, normal, flags, patch neighbours and its BVH's share), rounded up.
const TRIANGLE_BYTES: Real = 400.0;

/// SDF grid nodes of the scene's grid bodies (8 bytes each), from each mesh's bounding box;
/// the triangles of bodies met on their triangles.
fn sdf_bytes(scene: &Scene) -> Real {
    let mut total = 0.0;
    for body in scene.bodies.iter().filter(|b| b.particles.is_none()) {
        let Ok(mesh) = body.load_mesh() else {
            continue; // the run reports the unreadable mesh itself
        };
        if body.contact == BodyContact::Mesh {
            total += TRIANGLE_BYTES * mesh.triangles.len() as Real;
            continue;
        }
        let b = mesh.bounding_box();
        let padding = body
            .padding
            .unwrap_or(3.0 * body.cell_size + scene.max_diameter());
        let nodes: Real = (0..3)
            .map(|a| ((b.max[a] - b.min[a] + 2.0 * padding) / body.cell_size).ceil() + 1.0)
            .product();
        total += 8.0 * nodes;
    }
    total
}

/// The estimate for `scene`, or for `particles` when the run starts from a given state.
pub fn estimate(scene: &Scene, particles: Option<usize>) -> MemoryEstimate {
    let particles = particles.map_or_else(|| particle_count(scene), |n| n as Real);
    let meshes = scene
        .bodies
        .iter()
        .filter(|b| b.contact == BodyContact::Mesh && b.particles.is_none());
    MemoryEstimate {
        particles,
        particle_bytes: particles
            * (PARTICLE_BYTES
                + CELL_BYTES_PER_PARTICLE
                + scene.bodies.len() as Real * CLEARANCE_BYTES
                + meshes.count() as Real * NEAR_TRIANGLES_BYTES),
        pair_bytes: particles * PAIRS_PER_PARTICLE * PAIR_BYTES,
        sdf_bytes: sdf_bytes(scene),
    }
}

/// `MemAvailable` from /proc/meminfo, bytes; None where there is no such file.
pub fn mem_available() -> Option<Real> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    parse_mem_available(&text)
}

fn parse_mem_available(meminfo: &str) -> Option<Real> {
    let line = meminfo.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: Real = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mem_available_is_read_in_bytes() {
        let text = "MemTotal:       16318412 kB\nMemFree:  1 kB\nMemAvailable:    8000000 kB\n";
        assert_eq!(parse_mem_available(text), Some(8000000.0 * 1024.0));
        assert_eq!(parse_mem_available("MemTotal: 5 kB\n"), None);
    }
}
