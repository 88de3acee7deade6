//! Bodies built of particles (paper A sec. 4, Fig. 4): particles of a frozen species on an
//! fcc lattice fitted inside a closed mesh, moved each step with the body's prescribed motion
//! (position from the pose, velocity `omega x r + v`), so they meet the grains through the
//! scene's pair law.

use rayon::prelude::*;

use crate::geometry::{Bvh, FastWindingNumber, TriMesh};
use crate::math::{Real, Vec3};

/// The sites of an fcc lattice with nearest-neighbour distance `spacing` (cube edge
/// `sqrt(2) spacing`), one site at `origin`, axes along x, y, z, whose points lie inside
/// `mesh` by the generalized winding number. Ordered by z, then y, then x, then basis site.
pub fn fcc_sites_inside(mesh: &TriMesh, spacing: Real, origin: Vec3) -> Vec<Vec3> {
    let bvh = Bvh::new(mesh);
    let winding = FastWindingNumber::new(&bvh);
    let bounds = mesh.bounding_box();
    let a = spacing * std::f64::consts::SQRT_2;
    let basis = [
        Vec3::ZERO,
        Vec3::new(0.5 * a, 0.5 * a, 0.0),
        Vec3::new(0.5 * a, 0.0, 0.5 * a),
        Vec3::new(0.0, 0.5 * a, 0.5 * a),
    ];
    let range = |lo: Real, hi: Real| ((lo / a).floor() as i64 - 1)..=((hi / a).ceil() as i64);
    let (lo, hi) = (bounds.min - origin, bounds.max - origin);
    let candidates: Vec<Vec3> = range(lo.z, hi.z)
        .flat_map(|k| range(lo.y, hi.y).map(move |j| (j, k)))
        .flat_map(|(j, k)| range(lo.x, hi.x).map(move |i| (i, j, k)))
        .flat_map(|(i, j, k)| {
            let corner = origin + a * Vec3::new(i as Real, j as Real, k as Real);
            basis.map(|b| corner + b)
        })
        .filter(|p| p.cmpge(bounds.min).all() && p.cmple(bounds.max).all())
        .collect();
    let inside: Vec<bool> = candidates
        .par_iter()
        .map(|&p| winding.is_inside(p))
        .collect();
    candidates
        .into_iter()
        .zip(inside)
        .filter_map(|(p, keep)| keep.then_some(p))
        .collect()
}

/// The particles that make up one body: particle ids `first_id .. first_id + reference.len()`
/// with their positions in the body frame (the world positions when the motion starts).
#[derive(Clone, Debug, PartialEq)]
pub struct KinematicParticles {
    /// Index of the driving body in the world's bodies.
    pub body: usize,
    pub first_id: u32,
    pub reference: Vec<Vec3>,
}

impl KinematicParticles {
    /// Body-frame position of the particle with `id`, if it belongs to this body.
    #[inline(always)]
    pub fn reference_of(&self, id: u32) -> Option<Vec3> {
        id.checked_sub(self.first_id)
            .and_then(|k| self.reference.get(k as usize))
            .copied()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{sphere_mesh, winding_number};

    fn cube_mesh(side: Real) -> TriMesh {
        let v: Vec<Vec3> = (0..8)
            .map(|k| {
                side * Vec3::new(
                    (k & 1) as Real,
                    ((k >> 1) & 1) as Real,
                    ((k >> 2) & 1) as Real,
                )
            })
            .collect();
        // Outward-oriented faces of the unit cube (vertex k = x + 2y + 4z).
        let t = vec![
            [0, 2, 1], [1, 2, 3], // z = 0
            [4, 5, 6], [5, 7, 6], // z = 1
            [0, 1, 4], [1, 5, 4], // y = 0
            [2, 6, 3], [3, 6, 7], // y = 1
            [0, 4, 2], [2, 4, 6], // x = 0
            [1, 3, 5], [3, 7, 5], // x = 1
        ];
        TriMesh::new(v, t)
    }

    #[test]
    fn fcc_in_a_cube_has_the_closed_form_count_and_nearest_neighbours_at_the_spacing() {
        // Cube edge a = sqrt(2) s, origin at the cube's corner shifted inside by a/4: in a
        // box of 4 x 4 x 4 cells there are 4 * 4^3 = 256 sites, none on the faces.
        let s = 1e-3;
        let a = s * std::f64::consts::SQRT_2;
        let mesh = cube_mesh(4.0 * a);
        let sites = fcc_sites_inside(&mesh, s, Vec3::splat(0.25 * a));
        assert_eq!(sites.len(), 256);
        let mut nearest = Real::INFINITY;
        for (k, p) in sites.iter().enumerate() {
            for q in &sites[k + 1..] {
                nearest = nearest.min((*p - *q).length());
            }
        }
        assert!((nearest - s).abs() < 1e-12, "{nearest}");
        // Twelve neighbours at the spacing for a site in the middle.
        let centre = sites
            .iter()
            .min_by(|p, q| {
                (**p - Vec3::splat(2.0 * a))
                    .length()
                    .total_cmp(&(**q - Vec3::splat(2.0 * a)).length())
            })
            .unwrap();
        let neighbours = sites
            .iter()
            .filter(|q| ((**q - *centre).length() - s).abs() < 1e-12)
            .count();
        assert_eq!(neighbours, 12);
    }

    #[test]
    fn fcc_in_a_sphere_fills_it_at_the_fcc_density_with_every_centre_inside() {
        let (r, s) = (0.05, 0.004);
        let mesh = sphere_mesh(r, 4);
        let sites = fcc_sites_inside(&mesh, s, Vec3::ZERO);
        // fcc: 4 sites per cube of edge sqrt(2) s, i.e. sqrt(2) / s^3 sites per m^3.
        let expected = mesh.volume() * std::f64::consts::SQRT_2 / s.powi(3);
        assert!(
            (sites.len() as Real / expected - 1.0).abs() < 0.03,
            "{} vs {expected}",
            sites.len()
        );
        for p in &sites {
            assert!(winding_number(&mesh, *p) > 0.5, "{p:?} outside");
        }
    }
}
