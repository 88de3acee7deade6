//! Top-ups (`[[insert]] refill`): an insertion's region refilled to its count at the stage
//! start, at the refill's interval.

use crate::bodies::Body;
use crate::geometry::{Bvh, FastWindingNumber};
use crate::insertion::insert_random_where;
use crate::math::{Real, Vec3};
use crate::particles::Particles;
use crate::scene::Scene;

use super::RunError;

/// The region of an insertion with `refill`: its box (and mesh), where it is topped up.
pub(crate) struct RefillRegion {
    species: u16,
    radius: Real,
    lo: Vec3,
    hi: Vec3,
    bvh: Option<Bvh>,
    overlap: Real,
}

impl RefillRegion {
    pub(crate) fn new(
        scene: &Scene,
        index: usize,
        ins: &crate::scene::Insertion,
    ) -> Result<Self, RunError> {
        let bvh = match &ins.mesh {
            None => None,
            Some(source) => Some(Bvh::new(&source.load().map_err(|message| {
                RunError::Geometry {
                    file: scene.source.display().to_string(),
                    field: format!("insert[{index}].mesh"),
                    message,
                }
            })?)),
        };
        Ok(RefillRegion {
            species: ins.species as u16,
            radius: scene.species[ins.species].radius(),
            lo: ins.lo,
            hi: ins.hi,
            bvh,
            overlap: ins.overlap,
        })
    }

    /// Whether a centre lies in the region (box, and inside the mesh if there is one).
    fn contains(&self, winding: Option<&FastWindingNumber>, p: Vec3) -> bool {
        p.cmpge(self.lo).all() && p.cmple(self.hi).all() && winding.is_none_or(|w| w.is_inside(p))
    }

    /// Mobile particles of the species with centres in the region.
    pub(crate) fn count(&self, particles: &Particles) -> usize {
        let winding = self.bvh.as_ref().map(FastWindingNumber::new);
        (0..particles.len())
            .filter(|&k| {
                particles.species[k] == self.species
                    && !particles.is_frozen(k)
                    && self.contains(winding.as_ref(), particles.position[k])
            })
            .count()
    }

    /// Positions for as many new particles (up to `target` in the region) as random
    /// sequential addition places without overlap, inside the mesh by one radius and clear of
    /// the bodies, as the first insertion did. New particles start at rest.
    pub(crate) fn top_up(
        &self,
        particles: &Particles,
        bodies: &[Body],
        target: usize,
        seed: u64,
    ) -> Vec<Vec3> {
        let missing = target.saturating_sub(self.count(particles));
        if missing == 0 {
            return Vec::new();
        }
        let winding = self.bvh.as_ref().map(FastWindingNumber::new);
        let radius = self.radius;
        let accept = |p: Vec3| {
            if let (Some(bvh), Some(winding)) = (&self.bvh, &winding) {
                if !winding.is_inside(p) || bvh.nearest_within(p, radius).is_some() {
                    return false;
                }
            }
            bodies
                .iter()
                .all(|b| b.query(p, radius).is_none_or(|(d, _)| d > radius))
        };
        let mut trial = particles.clone();
        let before = trial.len();
        // Fewer than `missing` when the region has no more room: the rest next time.
        let _ = insert_random_where(
            &mut trial,
            self.species,
            radius,
            1.0,
            self.lo,
            self.hi,
            missing as u64,
            seed,
            self.overlap,
            accept,
        );
        trial.position[before..].to_vec()
    }
}

#[cfg(test)]
mod refill_tests {
    use super::*;

    #[test]
    fn top_up_restores_the_count_in_the_region_without_overlap() {
        let (r, m) = (1e-3, 1e-6);
        let region = RefillRegion {
            species: 0,
            radius: r,
            lo: Vec3::ZERO,
            hi: Vec3::splat(0.02),
            bvh: None,
            overlap: 0.0,
        };
        let mut particles = Particles::new(false);
        insert_random_where(
            &mut particles,
            0,
            r,
            m,
            region.lo,
            region.hi,
            60,
            7,
            0.0,
            |_| true,
        )
        .unwrap();
        // One outside the region (not counted) and a frozen one inside (not counted).
        particles.push(0, Vec3::splat(0.03), r, m);
        particles.push(0, Vec3::splat(0.0105), r, m);
        particles.freeze(particles.len() - 1);
        assert_eq!(region.count(&particles), 60);
        // Drain 25 of them, as the screw would.
        let keep: Vec<bool> = (0..particles.len()).map(|k| k >= 25).collect();
        particles.retain(&keep);
        assert_eq!(region.count(&particles), 35);
        let added = region.top_up(&particles, &[], 60, 11);
        assert_eq!(added.len(), 25);
        for (k, a) in added.iter().enumerate() {
            assert!(a.cmpge(region.lo).all() && a.cmple(region.hi).all());
            for b in particles.position.iter().chain(&added[..k]) {
                assert!((*a - *b).length() >= 2.0 * r * (1.0 - 1e-12));
            }
        }
        for &a in &added {
            particles.push(0, a, r, m);
        }
        assert_eq!(region.count(&particles), 60);
        // Full: nothing more.
        assert!(region.top_up(&particles, &[], 60, 12).is_empty());
    }
}
