//! The drum's three measures of one frame (reference/DRUM.md, "Measurement"): the grains of
//! each species in MercuryDPM's two zones, the free surface's angle by a stated rule, and
//! Lacey's mixing index of the large grains' volume fraction. The drum's axis is the y axis
//! through the origin and gravity points along -z, as in the benchmark's frame.

/// One grain of a frame: centre (m), diameter (m), and whether it is of the large species
/// (the benchmark's M2, d = 4 mm; the small one is M1, d = 2 mm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grain {
    pub position: [f64; 3],
    pub diameter: f64,
    pub large: bool,
}

/// The grains of each species whose centre lies in zone 1 (x > 0 and z > 0: the upper
/// quadrant on the side where MercuryDPM's drum wall rises) and in zone 2 (x < 0 and z < 0),
/// as MercuryDPM's `OSDrum.cpp` counts them; a centre on an axis is in neither.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ZoneCounts {
    pub zone1_m1: usize,
    pub zone1_m2: usize,
    pub zone2_m1: usize,
    pub zone2_m2: usize,
}

impl ZoneCounts {
    /// The four counts in the benchmark's order of its columns here: zone 1 M1, zone 1 M2,
    /// zone 2 M1, zone 2 M2.
    pub fn as_array(&self) -> [usize; 4] {
        [self.zone1_m1, self.zone1_m2, self.zone2_m1, self.zone2_m2]
    }
}

pub fn zone_counts(grains: &[Grain]) -> ZoneCounts {
    let mut c = ZoneCounts::default();
    for g in grains {
        let [x, _, z] = g.position;
        let slot = match (x > 0.0 && z > 0.0, x < 0.0 && z < 0.0, g.large) {
            (true, _, false) => &mut c.zone1_m1,
            (true, _, true) => &mut c.zone1_m2,
            (_, true, false) => &mut c.zone2_m1,
            (_, true, true) => &mut c.zone2_m2,
            _ => continue,
        };
        *slot += 1;
    }
    c
}

/// The free surface's line: its angle to the horizontal (positive when it rises towards
/// +x, the side where the wall rises), the R^2 of the fit and the bins it went through.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceLine {
    pub angle_deg: f64,
    pub r2: f64,
    pub bins: usize,
}

/// The dynamic angle of repose of one frame, by this rule: bins of `bin_width` along x
/// (edges at multiples of it); in each, the height of the highest grain top (z + radius); a
/// least-squares line through the bins whose centres lie between 20% and 80% of the
/// occupied span of x (the two ends are where the surface meets the wall); the angle is
/// atan of its slope. None with fewer than three such bins.
pub fn surface_angle(grains: &[Grain], bin_width: f64) -> Option<SurfaceLine> {
    let mut tops: std::collections::BTreeMap<i64, f64> = Default::default();
    for g in grains {
        let bin = (g.position[0] / bin_width).floor() as i64;
        let top = g.position[2] + 0.5 * g.diameter;
        let h = tops.entry(bin).or_insert(f64::NEG_INFINITY);
        *h = h.max(top);
    }
    let (&lo, &hi) = (tops.keys().next()?, tops.keys().next_back()?);
    let span = (hi + 1 - lo) as f64;
    let (from, to) = (lo as f64 + 0.2 * span, lo as f64 + 0.8 * span);
    let points: Vec<(f64, f64)> = tops
        .iter()
        .filter(|(&b, _)| (from..=to).contains(&(b as f64 + 0.5)))
        .map(|(&b, &h)| ((b as f64 + 0.5) * bin_width, h))
        .collect();
    let (slope, r2) = cgdem_core::analysis::heap::least_squares(&points)?;
    Some(SurfaceLine {
        angle_deg: slope.atan().to_degrees(),
        r2,
        bins: points.len(),
    })
}

/// Lacey's mixing index and the cells it used.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lacey {
    pub index: f64,
    pub cells: usize,
}

/// Lacey's index of the large grains' volume fraction (the two sizes differ by 8 in volume,
/// so counts would weight the small grains eight times): cubic cells of edge `cell` (edges
/// at multiples of it), each grain in the cell of its centre, cells with at least
/// `min_grains` kept; c_i the large grains' share of a kept cell's solid volume, p the share
/// over all kept cells, S^2 the variance of c_i weighted by the cells' solid volume,
/// S0^2 = p (1 - p) (segregated), Sr^2 = S0^2 / n (random, n the mean number of grains per
/// kept cell); M = (S0^2 - S^2) / (S0^2 - Sr^2): 0 for segregated layers, 1 for a random
/// mixture. None with fewer than two kept cells, or one species only.
pub fn lacey_index(grains: &[Grain], cell: f64, min_grains: usize) -> Option<Lacey> {
    // (solid volume, large grains' volume, grains) per cell
    let mut cells: std::collections::HashMap<[i64; 3], (f64, f64, usize)> = Default::default();
    for g in grains {
        let key = g.position.map(|x| (x / cell).floor() as i64);
        let v = std::f64::consts::PI / 6.0 * g.diameter.powi(3);
        let e = cells.entry(key).or_default();
        e.0 += v;
        e.1 += if g.large { v } else { 0.0 };
        e.2 += 1;
    }
    let kept: Vec<(f64, f64, usize)> = cells
        .into_values()
        .filter(|c| c.2 >= min_grains.max(1))
        .collect();
    if kept.len() < 2 {
        return None;
    }
    let total: f64 = kept.iter().map(|c| c.0).sum();
    let p = kept.iter().map(|c| c.1).sum::<f64>() / total;
    let s2 = kept
        .iter()
        .map(|&(v, vl, _)| v * (vl / v - p).powi(2))
        .sum::<f64>()
        / total;
    let s0 = p * (1.0 - p);
    let n = kept.iter().map(|c| c.2 as f64).sum::<f64>() / kept.len() as f64;
    let sr = s0 / n;
    (s0 - sr > 0.0).then(|| Lacey {
        index: (s0 - s2) / (s0 - sr),
        cells: kept.len(),
    })
}
