//! Linked cells: particles binned by a counting sort into cells at least one cut-off wide.

use crate::domain::Domain;
use crate::math::{Real, Vec3};

/// Cells allowed per particle before cells widen (a dense packing holds one to four
/// particles per cell).
const MAX_CELLS_PER_PARTICLE: usize = 16;
/// Cells always allowed, however few the particles.
const MIN_CELL_CAP: usize = 1 << 15;

/// Particles binned into a regular grid of cells covering the domain.
///
/// Cells are at least `cell_size` wide, so every partner within the cut-off lies in the 27
/// cells around a particle's own. On bounded axes a particle outside the box is clamped into
/// the edge cell; clamping never separates two nearby particles by more than one cell.
#[derive(Clone, Debug, Default)]
pub struct CellGrid {
    pub counts: [usize; 3],
    pub cell_of: Vec<u32>,
    /// Particles of cell `c` are `items[start[c]..start[c + 1]]`, in increasing index order.
    pub start: Vec<u32>,
    pub items: Vec<u32>,
    inv_width: Vec3,
    lo: Vec3,
}

impl CellGrid {
    pub fn build(domain: &Domain, positions: &[Vec3], cell_size: Real) -> CellGrid {
        // Periodic axes span the box (images need whole periods); bounded axes span only the
        // particles, so a large, mostly empty box costs no empty cells.
        let (mut lo, mut length) = (domain.lo, domain.length());
        let bounded: Vec<usize> = (0..3).filter(|&a| !domain.periodic[a]).collect();
        if !bounded.is_empty() && !positions.is_empty() {
            let (mut min, mut max) = (Vec3::splat(Real::INFINITY), Vec3::splat(Real::NEG_INFINITY));
            for &p in positions {
                min = min.min(p);
                max = max.max(p);
            }
            for &axis in &bounded {
                if min[axis].is_finite() && max[axis].is_finite() {
                    lo[axis] = min[axis];
                    length[axis] = (max[axis] - min[axis]).max(cell_size);
                }
            }
        }
        let mut counts = [1usize; 3];
        for axis in 0..3 {
            counts[axis] = ((length[axis] / cell_size).floor() as usize).clamp(1, 1 << 10);
        }
        // One particle far from the rest (a runaway kept for the guard to report) would
        // stretch a bounded axis over 1024 cells and the grid over a billion; past a few
        // cells per particle, wider cells (still at least `cell_size`) lose nothing.
        let most_cells = MAX_CELLS_PER_PARTICLE * positions.len() + MIN_CELL_CAP;
        while counts.iter().product::<usize>() > most_cells {
            let widest = (0..3).max_by_key(|&a| counts[a]).unwrap_or(0);
            counts[widest] = counts[widest].div_ceil(2);
        }
        let mut inv_width = Vec3::ZERO;
        for axis in 0..3 {
            inv_width[axis] = counts[axis] as Real / length[axis];
        }
        let mut grid = CellGrid {
            counts,
            inv_width,
            lo,
            ..Default::default()
        };
        grid.cell_of = positions.iter().map(|&p| grid.cell_index(p)).collect();
        let n_cells = counts[0] * counts[1] * counts[2];
        let mut start = vec![0u32; n_cells + 1];
        for &c in &grid.cell_of {
            start[c as usize + 1] += 1;
        }
        for c in 0..n_cells {
            start[c + 1] += start[c];
        }
        let mut fill = start.clone();
        let mut items = vec![0u32; positions.len()];
        for (i, &c) in grid.cell_of.iter().enumerate() {
            items[fill[c as usize] as usize] = i as u32;
            fill[c as usize] += 1;
        }
        grid.start = start;
        grid.items = items;
        grid
    }

    pub fn cell_coords(&self, p: Vec3) -> [usize; 3] {
        let mut c = [0usize; 3];
        for axis in 0..3 {
            let x = ((p[axis] - self.lo[axis]) * self.inv_width[axis]).floor();
            c[axis] = x.clamp(0.0, (self.counts[axis] - 1) as Real) as usize;
        }
        c
    }

    pub fn cell_index(&self, p: Vec3) -> u32 {
        let c = self.cell_coords(p);
        self.linear(c)
    }

    pub fn linear(&self, c: [usize; 3]) -> u32 {
        ((c[2] * self.counts[1] + c[1]) * self.counts[0] + c[0]) as u32
    }

    pub fn particles_in(&self, cell: u32) -> &[u32] {
        let c = cell as usize;
        &self.items[self.start[c] as usize..self.start[c + 1] as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_runaway_particle_does_not_blow_up_the_grid() {
        let domain = Domain {
            lo: Vec3::ZERO,
            hi: Vec3::splat(1e4),
            periodic: [false; 3],
        };
        // A small cluster at the origin and one particle 9 km away on every axis.
        let mut positions: Vec<Vec3> = (0..1000)
            .map(|k| Vec3::new((k % 10) as Real, ((k / 10) % 10) as Real, (k / 100) as Real) * 1e-3)
            .collect();
        positions.push(Vec3::splat(9e3));
        let grid = CellGrid::build(&domain, &positions, 1e-3);
        let cells: usize = grid.counts.iter().product();
        assert!(
            cells <= MAX_CELLS_PER_PARTICLE * positions.len() + MIN_CELL_CAP,
            "{cells} cells"
        );
        // Still cells at least one cut-off wide, each particle binned once.
        for axis in 0..3 {
            assert!(1.0 / grid.inv_width[axis] >= 1e-3);
        }
        assert_eq!(grid.items.len(), positions.len());
    }
}
