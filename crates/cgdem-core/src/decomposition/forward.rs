//! `forward_comm` (LAMMPS `Comm::forward_comm`): every step between list rebuilds, the
//! ghosts take their owners' new positions (shifted by the image), velocities and spins.
//!
//! [`Forward`] is the whole update. It rides on the step's two passes over the subdomains
//! instead of adding two of its own (two fork-joins per step instead of four,
//! reports/PERFORMANCE.md): each subdomain packs its owned states at the end of its first
//! half ([`Forward::pack`]), the buffers travel between ranks when the forces are asked for
//! ([`Forward::route`]), and each subdomain unpacks its ghosts at the start of its force
//! pass ([`Forward::unpack`]). A rebuild in between gives the ghosts fresh copies
//! (`borders`): what was packed is dropped ([`Forward::ghosts_rebuilt`]). The test that
//! ghosts follow their owners runs this path, through the step (`step_tests`).

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

/// The ghosts' update of every step: the packed states, where they go, and whether they are
/// still to be unpacked.
#[derive(Clone, Debug, Default)]
pub struct Forward {
    /// Per subdomain, one buffer per send list, reused (under MPI, the sets of other ranks'
    /// subdomains hold what they sent here).
    buffers: Vec<Vec<States>>,
    /// Words each rank sends here, fixed between rebuilds (`None` until the first route after
    /// one).
    counts: Option<Vec<usize>>,
    /// Whether the buffers hold the states of this step's first half, not yet unpacked.
    packed: bool,
}

impl Forward {
    /// Empty buffers with the given capacities (a restored run's, so that it reports the
    /// memory the uninterrupted one does), nothing packed.
    pub(super) fn with_capacities(capacities: Vec<Vec<usize>>) -> Self {
        let buffers = capacities
            .into_iter()
            .map(|lists| {
                lists
                    .into_iter()
                    .map(|c| States(Vec::with_capacity(c)))
                    .collect()
            })
            .collect();
        Forward {
            buffers,
            ..Forward::default()
        }
    }

    /// The buffers' capacities of subdomain `s` (one per send list).
    pub(super) fn capacities(&self, s: usize) -> Vec<usize> {
        self.buffers.get(s).map_or(Vec::new(), |b| {
            b.iter().map(|States(v)| v.capacity()).collect()
        })
    }

    /// Bytes the buffers hold.
    pub(super) fn bytes(&self) -> usize {
        let per_state = std::mem::size_of::<GhostState>();
        self.buffers
            .iter()
            .flatten()
            .map(|States(b)| b.capacity() * per_state)
            .sum()
    }

    /// Each subdomain with its buffers, for the first-half pass to [`Forward::pack`] into;
    /// from now on the buffers count as holding this step's states.
    pub(super) fn start_packing<'a, S>(
        &'a mut self,
        subs: &'a mut [S],
    ) -> Vec<(&'a mut S, &'a mut Vec<States>)> {
        self.buffers.resize_with(subs.len(), Vec::new);
        self.packed = true;
        subs.iter_mut().zip(self.buffers.iter_mut()).collect()
    }

    /// `sub`'s owned states per send list into `out` (one buffer per list).
    pub(super) fn pack<H: PairHistory, WH: PairHistory>(
        sub: &Subdomain<H, WH>,
        out: &mut Vec<States>,
    ) {
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

    /// What was packed for subdomains of other ranks sent there, and what they packed for
    /// this rank's received (nothing moves in one process, or when nothing is packed).
    /// Returns the bytes sent.
    pub(super) fn route<H: PairHistory, WH: PairHistory>(
        &mut self,
        subs: &[Subdomain<H, WH>],
        comm: &Comm,
    ) -> u64 {
        if !self.packed {
            return 0;
        }
        let dest = |from: usize, list: usize, _: &States| subs[from].sends[list].to;
        comm.route(&mut self.buffers, dest, &mut self.counts)
    }

    /// `sub`'s ghosts from the buffers of the lists they came from, in order (nothing when
    /// nothing is packed).
    pub(super) fn unpack<H: PairHistory, WH: PairHistory>(&self, sub: &mut Subdomain<H, WH>) {
        if !self.packed {
            return;
        }
        let mut k = sub.n_owned;
        let p = &mut sub.particles;
        for &(from, list) in &sub.receives {
            for g in &self.buffers[from][list].0 {
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

    /// After the force pass unpacked: nothing more to unpack until the next first half.
    pub(super) fn unpacked(&mut self) {
        self.packed = false;
    }

    /// After `borders`: the ghosts are fresh copies and the send lists new, so what was
    /// packed is dropped and the counts are learnt again.
    pub(super) fn ghosts_rebuilt(&mut self) {
        self.packed = false;
        self.counts = None;
    }
}
