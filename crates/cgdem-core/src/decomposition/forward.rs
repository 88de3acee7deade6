//! `forward_comm` (LAMMPS `Comm::forward_comm`): every step between list rebuilds, the
//! ghosts take their owners' new positions (shifted by the image), velocities and spins.

use super::transport::{read_vec3s, write_vec3s, Comm, Wire};
use super::Subdomain;
use crate::contact::PairHistory;
use crate::math::{Real, Vec3};

/// What a ghost needs each step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GhostState {
    pub position: Vec3,
    pub velocity: Vec3,
    /// Zero when particles do not spin.
    pub omega: Vec3,
}

/// One send list's ghost states, as they travel.
#[derive(Clone, Debug, Default)]
pub struct States(pub Vec<GhostState>);

impl Wire for States {
    fn write(&self, out: &mut Vec<Real>) {
        out.push(self.0.len() as Real);
        for g in &self.0 {
            write_vec3s(&[g.position, g.velocity, g.omega], out);
        }
    }

    fn read(input: &mut &[Real]) -> Self {
        let n = input[0] as usize;
        *input = &input[1..];
        let v = read_vec3s(input, 3 * n);
        States(
            v.chunks_exact(3)
                .map(|c| GhostState {
                    position: c[0],
                    velocity: c[1],
                    omega: c[2],
                })
                .collect(),
        )
    }
}

/// First half: `sub`'s owned state per send list into `out` (one buffer per list, reused).
pub fn pack<H: PairHistory, WH: PairHistory>(sub: &Subdomain<H, WH>, out: &mut Vec<States>) {
    let p = &sub.particles;
    out.resize_with(sub.sends.len(), States::default);
    for (list, States(buffer)) in sub.sends.iter().zip(out.iter_mut()) {
        buffer.clear();
        buffer.extend(list.indices.iter().map(|&k| {
            let k = k as usize;
            GhostState {
                position: p.position[k] + list.shift,
                velocity: p.velocity[k],
                omega: p.angular.as_ref().map_or(Vec3::ZERO, |a| a.omega[k]),
            }
        }));
    }
}

/// Second half: `sub`'s ghosts from the buffers of the lists they came from, in order.
pub fn unpack<H: PairHistory, WH: PairHistory>(sub: &mut Subdomain<H, WH>, packed: &[Vec<States>]) {
    let mut k = sub.n_owned;
    let p = &mut sub.particles;
    for &(from, list) in &sub.receives {
        for g in &packed[from][list].0 {
            p.position[k] = g.position;
            p.velocity[k] = g.velocity;
            if let Some(a) = p.angular.as_mut() {
                a.omega[k] = g.omega;
            }
            k += 1;
        }
    }
    debug_assert_eq!(k, p.len(), "ghost count changed without a rebuild");
}

/// Both halves over the subdomains `comm` owns here; `buffers` holds one set per
/// subdomain, reused (under MPI, other ranks' sets hold what they sent here). Returns the
/// bytes sent to other ranks. `counts`: what each rank sends here, known after the first
/// forward following a rebuild (`None` then).
pub fn forward<H: PairHistory, WH: PairHistory>(
    subs: &mut [Subdomain<H, WH>],
    buffers: &mut Vec<Vec<States>>,
    comm: &Comm,
    counts: &mut Option<Vec<usize>>,
) -> u64 {
    buffers.resize_with(subs.len(), Vec::new);
    let mut with_buffers: Vec<_> = subs.iter().zip(buffers.iter_mut()).collect();
    comm.each_owned(&mut with_buffers, |(sub, out)| pack(sub, out));
    let sent = comm.route(buffers, |from, list, _| subs[from].sends[list].to, counts);
    comm.each_owned(subs, |sub| unpack(sub, buffers));
    sent
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::decomposition::borders::{borders, tests::decomposed};
    use crate::domain::Domain;
    use crate::math::Real;

    #[test]
    fn ghosts_follow_their_owners_through_the_image_shift() {
        let domain = Domain {
            lo: Vec3::ZERO,
            hi: Vec3::splat(1.0),
            periodic: [true, false, false],
        };
        let (_, grid, mut subs) = decomposed(&domain, [2, 2, 1], 400, 5);
        borders(&mut subs, &grid, 0.1, &Comm::local());
        let before: Vec<Vec<Vec3>> = subs.iter().map(|s| s.particles.position.clone()).collect();
        // Move every owned particle by an amount that depends on its id.
        let moved = |id: u32| Vec3::new(1e-3 * id as Real, 0.0, -2e-3);
        for sub in subs.iter_mut() {
            for k in 0..sub.n_owned {
                let id = sub.particles.id[k];
                sub.particles.position[k] += moved(id);
                sub.particles.velocity[k] = Vec3::splat(id as Real);
            }
        }
        let mut buffers = Vec::new();
        forward(&mut subs, &mut buffers, &Comm::local(), &mut None);
        let mut ghosts = 0;
        for (sub, old) in subs.iter().zip(&before) {
            for (k, &was) in old.iter().enumerate().skip(sub.n_owned) {
                let id = sub.particles.id[k];
                let expected = was + moved(id);
                assert!((sub.particles.position[k] - expected).length() < 1e-12);
                assert_eq!(sub.particles.velocity[k], Vec3::splat(id as Real));
                ghosts += 1;
            }
        }
        assert!(ghosts > 0);
    }
}
