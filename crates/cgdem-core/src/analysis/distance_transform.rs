//! Exact Euclidean distance transform of a 3D voxel grid.
//!
//! Separable algorithm of Felzenszwalb & Huttenlocher, "Distance transforms of sampled
//! functions", Theory of Computing 8 (2012) 415: one 1D pass per axis, each computing
//! `d(p) = min_q [ s^2 (p - q)^2 + f(q) ]` as the lower envelope of parabolas in O(n).
//! The squared Euclidean distance is a sum of per-axis squares, so three 1D passes give the
//! exact 3D result.
//!
//! Layout: `index = x + nx * (y + ny * z)` (x fastest), the same as
//! [`crate::analysis::VoxelGrid`].
//!
//! Periodic axes: on a torus the squared distance to the nearest image is the sum over axes
//! of the per-axis nearest-image squares (the image lattice is a product), so periodicity is
//! handled inside each 1D pass: the line is tripled (sites `q - n`, `q`, `q + n`) and the
//! envelope is evaluated on the middle copy. For `p, q` in `0..n` the nearest image of `q` is
//! always one of those three, so this is exact, at three times the cost of that pass.
//!
//! Every pass runs in parallel over lines with rayon. Lines along y and z are strided in
//! memory; they are gathered into a line-major buffer, transformed, and scattered back, both
//! steps parallel and free of shared mutable state.

use crate::math::Real;
use rayon::prelude::*;

/// Squared Euclidean distance from every voxel centre to the nearest feature voxel centre.
///
/// `features[i] == true` marks a feature (distance 0). `spacing` is the voxel edge length per
/// axis (use `[1.0; 3]` to get integer squared distances in voxel units, exact in `f64`).
/// Voxels with no feature anywhere (an empty `features`) get `Real::INFINITY`.
///
/// # Panics
/// If `features.len() != dims[0] * dims[1] * dims[2]`.
pub fn squared_distance_transform(
    features: &[bool],
    dims: [usize; 3],
    spacing: [Real; 3],
    periodic: [bool; 3],
) -> Vec<Real> {
    let n = dims[0] * dims[1] * dims[2];
    assert_eq!(
        features.len(),
        n,
        "features.len() must equal the number of voxels"
    );
    let mut f: Vec<Real> = features
        .par_iter()
        .map(|&b| if b { 0.0 } else { Real::INFINITY })
        .collect();
    if n == 0 {
        return f;
    }
    for axis in 0..3 {
        transform_axis(
            &mut f,
            dims,
            axis,
            spacing[axis] * spacing[axis],
            periodic[axis],
        );
    }
    f
}

/// Reusable buffers of one 1D transform.
#[derive(Default)]
struct LineScratch {
    input: Vec<Real>,
    /// Sites (possibly image positions, outside `0..n`) of the envelope's parabolas.
    sites: Vec<i64>,
    /// Value `f(q) + s2 q^2` of each site, cached.
    lifted: Vec<Real>,
    /// Left boundary of each parabola's interval in the envelope.
    bounds: Vec<Real>,
}

fn transform_axis(f: &mut [Real], dims: [usize; 3], axis: usize, s2: Real, periodic: bool) {
    let n_along = dims[axis];
    if axis == 0 {
        f.par_chunks_mut(n_along)
            .for_each_init(LineScratch::default, |s, line| {
                s.input.clear();
                s.input.extend_from_slice(line);
                transform_line(s, line, s2, periodic);
            });
        return;
    }
    // Strided lines: line `l` starts at `base(l)` and steps by `stride`.
    let stride: usize = dims[..axis].iter().product();
    let base = |l: usize| (l % stride) + (l / stride) * stride * n_along;
    let mut lines = vec![0.0; f.len()];
    {
        let src: &[Real] = f;
        lines.par_chunks_mut(n_along).enumerate().for_each_init(
            LineScratch::default,
            |s, (l, out)| {
                let b = base(l);
                s.input.clear();
                s.input.extend((0..n_along).map(|k| src[b + k * stride]));
                transform_line(s, out, s2, periodic);
            },
        );
    }
    let nx = dims[0];
    f.par_chunks_mut(nx).enumerate().for_each(|(row, dst)| {
        // Voxel (x, row) has flat index x + nx * row; find its line and position.
        for (x, d) in dst.iter_mut().enumerate() {
            let idx = x + nx * row;
            let k = (idx / stride) % n_along;
            let l = (idx % stride) + (idx / (stride * n_along)) * stride;
            *d = lines[l * n_along + k];
        }
    });
}

/// 1D transform of `s.input` into `out`: `out[p] = min_q s2 (p - q)^2 + input[q]`.
fn transform_line(s: &mut LineScratch, out: &mut [Real], s2: Real, periodic: bool) {
    let n = s.input.len() as i64;
    let (q_lo, q_hi) = if periodic { (-n, 2 * n) } else { (0, n) };
    s.sites.clear();
    s.lifted.clear();
    s.bounds.clear();
    for q in q_lo..q_hi {
        let fq = s.input[q.rem_euclid(n) as usize];
        if !fq.is_finite() {
            continue;
        }
        let qf = q as Real;
        let lifted = fq + s2 * qf * qf;
        loop {
            match (s.sites.last(), s.lifted.last(), s.bounds.last()) {
                (Some(&v), Some(&lv), Some(&zv)) => {
                    // Abscissa where the parabola of q overtakes the one of v.
                    let x = (lifted - lv) / (2.0 * s2 * (qf - v as Real));
                    if x <= zv {
                        s.sites.pop();
                        s.lifted.pop();
                        s.bounds.pop();
                    } else {
                        s.sites.push(q);
                        s.lifted.push(lifted);
                        s.bounds.push(x);
                        break;
                    }
                }
                _ => {
                    s.sites.push(q);
                    s.lifted.push(lifted);
                    s.bounds.push(Real::NEG_INFINITY);
                    break;
                }
            }
        }
    }
    if s.sites.is_empty() {
        out.fill(Real::INFINITY);
        return;
    }
    let mut k = 0;
    for (p, o) in out.iter_mut().enumerate() {
        let pf = p as Real;
        while k + 1 < s.sites.len() && s.bounds[k + 1] < pf {
            k += 1;
        }
        let v = s.sites[k];
        let d = pf - v as Real;
        *o = s2 * d * d + s.input[v.rem_euclid(n) as usize];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> u64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            self.0
        }
        fn unit(&mut self) -> Real {
            (self.next() >> 11) as Real / (1u64 << 53) as Real
        }
    }

    fn brute_force(
        features: &[bool],
        dims: [usize; 3],
        spacing: [Real; 3],
        periodic: [bool; 3],
    ) -> Vec<Real> {
        let [nx, ny, nz] = dims;
        let axis_d2 = |a: usize, i: usize, j: usize| {
            let mut d = i.abs_diff(j);
            if periodic[a] {
                d = d.min(dims[a] - d);
            }
            let d = d as Real * spacing[a];
            d * d
        };
        let mut out = vec![Real::INFINITY; features.len()];
        for z in 0..nz {
            for y in 0..ny {
                for x in 0..nx {
                    let mut best = Real::INFINITY;
                    for fz in 0..nz {
                        for fy in 0..ny {
                            for fx in 0..nx {
                                if features[fx + nx * (fy + ny * fz)] {
                                    let d =
                                        axis_d2(0, x, fx) + axis_d2(1, y, fy) + axis_d2(2, z, fz);
                                    best = best.min(d);
                                }
                            }
                        }
                    }
                    out[x + nx * (y + ny * z)] = best;
                }
            }
        }
        out
    }

    fn check_random(
        seed: u64,
        dims: [usize; 3],
        spacing: [Real; 3],
        periodic: [bool; 3],
        density: Real,
    ) {
        let mut rng = Rng(seed);
        let n = dims.iter().product();
        let features: Vec<bool> = (0..n).map(|_| rng.unit() < density).collect();
        let fast = squared_distance_transform(&features, dims, spacing, periodic);
        let slow = brute_force(&features, dims, spacing, periodic);
        for (i, (a, b)) in fast.iter().zip(&slow).enumerate() {
            assert!(
                (a == b) || (a - b).abs() <= 1e-9 * b.max(1.0),
                "voxel {i}: fast {a} brute {b} (dims {dims:?}, periodic {periodic:?})"
            );
        }
    }

    #[test]
    fn edt_matches_brute_force_on_random_grids() {
        for (seed, density) in [(1u64, 0.02), (2, 0.1), (3, 0.4), (4, 0.005)] {
            check_random(seed, [9, 7, 11], [1.0; 3], [false; 3], density);
        }
    }

    #[test]
    fn periodic_edt_matches_brute_force() {
        for (seed, periodic) in [
            (5u64, [true, true, true]),
            (6, [true, false, true]),
            (7, [false, true, false]),
            (8, [true, true, false]),
        ] {
            check_random(seed, [8, 10, 7], [1.0; 3], periodic, 0.01);
            check_random(seed + 100, [8, 10, 7], [1.0; 3], periodic, 0.15);
        }
    }

    #[test]
    fn anisotropic_spacing_matches_brute_force() {
        check_random(9, [7, 8, 9], [0.5, 1.3, 2.0], [true, false, true], 0.03);
    }

    #[test]
    fn integer_distances_are_exact_in_voxel_units() {
        let mut rng = Rng(11);
        let dims = [12, 12, 12];
        let features: Vec<bool> = (0..1728).map(|_| rng.unit() < 0.01).collect();
        let d2 = squared_distance_transform(&features, dims, [1.0; 3], [true; 3]);
        assert!(d2.iter().all(|v| v.fract() == 0.0));
    }

    #[test]
    fn no_feature_gives_infinity() {
        let d2 = squared_distance_transform(&[false; 27], [3, 3, 3], [1.0; 3], [true; 3]);
        assert!(d2.iter().all(|v| v.is_infinite()));
    }
}
