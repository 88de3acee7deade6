//! A decomposed world's state for restart files (LAMMPS restart files hold the whole
//! system, not one rank's piece): the grid as it stands, the balance's record, and each
//! subdomain's arrays as they are between two steps (owned particles and ghosts, wall
//! histories, send lists, the list with its histories and reference positions), gathered
//! from every rank. A run on the same grid takes each subdomain back as it was, on any
//! number of threads or ranks, and steps on bit for bit; another grid deals the owned
//! particles out again with their histories (as a rebuild would).

use serde::{Deserialize, Serialize};

use super::balance::Balance;
use super::borders::SendList;
use super::forward::Forward;
use super::step::Decomposition;
use super::{Comm, Grid, HistoryRows, Subdomain};
use crate::contact::PairHistory;
use crate::math::Real;
use crate::neighbor::PairList;
use crate::particles::Particles;

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct DecomposedState {
    pub grid: Grid,
    pub balance: Balance,
    pub builds: u64,
    /// Bytes sent between ranks since the start, over all ranks.
    pub bytes_sent: u64,
    /// Ghost layer, list reach and skin of the run (fixed at its start).
    pub width: Real,
    pub extra: Real,
    pub skin: Real,
    /// Per subdomain, a `SubdomainState` in bincode.
    pub subdomains: Vec<Vec<u8>>,
}

/// One subdomain's arrays between two steps, with the capacities `MemoryUse` counts (given
/// back on restore, so that summary.json's memory is the uninterrupted run's).
#[derive(Serialize)]
struct SubdomainOut<'a, H: Serialize, WH: Serialize> {
    particles: &'a Particles,
    n_owned: usize,
    wall_history: &'a [WH],
    sends: &'a [SendList],
    receives: &'a [(usize, usize)],
    list: &'a PairList<H>,
    capacities: Vec<usize>,
    /// The subdomain's forward buffers (one per send list).
    buffers: Vec<usize>,
}

#[derive(Deserialize)]
#[serde(bound = "H: PairHistory, WH: PairHistory")]
struct SubdomainState<H, WH> {
    particles: Particles,
    n_owned: usize,
    wall_history: Vec<WH>,
    sends: Vec<SendList>,
    receives: Vec<(usize, usize)>,
    list: PairList<H>,
    capacities: Vec<usize>,
    buffers: Vec<usize>,
}

/// Applies `$m!` to each array of a subdomain whose capacity `MemoryUse` counts, in a fixed
/// order (spin arrays last, when there are any).
macro_rules! subdomain_arrays {
    ($s:expr, $m:ident, $angular:ident) => {{
        $m!($s.particles.id);
        $m!($s.particles.species);
        $m!($s.particles.position);
        $m!($s.particles.velocity);
        $m!($s.particles.force);
        $m!($s.particles.radius);
        $m!($s.particles.mass);
        $m!($s.particles.inv_mass);
        $m!($s.wall_history);
        $m!($s.receives);
        $m!($s.list.pairs);
        $m!($s.list.constants);
        $m!($s.list.history);
        $m!($s.list.image_pairs);
        $m!($s.list.image_history);
        $m!($s.list.reference);
        if let Some(a) = $s.particles.angular.$angular() {
            $m!(a.omega);
            $m!(a.torque);
            $m!(a.inv_inertia);
        }
    }};
}

/// Bytes as `f64` words (bit patterns, length first), the unit the transport gathers.
fn bytes_to_words(bytes: &[u8], out: &mut Vec<Real>) {
    out.push(bytes.len() as Real);
    for chunk in bytes.chunks(8) {
        let mut word = [0u8; 8];
        word[..chunk.len()].copy_from_slice(chunk);
        out.push(Real::from_bits(u64::from_le_bytes(word)));
    }
}

fn words_to_bytes(words: &[Real]) -> Vec<u8> {
    let Some((&len, words)) = words.split_first() else {
        return Vec::new();
    };
    let mut bytes: Vec<u8> = words
        .iter()
        .flat_map(|w| w.to_bits().to_le_bytes())
        .collect();
    bytes.truncate(len as usize);
    bytes
}

impl<H: PairHistory, WH: PairHistory> Decomposition<H, WH> {
    /// The state of every subdomain (of every rank, gathered to each: collective).
    pub fn state(&self) -> DecomposedState {
        let per_sub = self
            .comm
            .gather_by_subdomain(self.subdomains.len(), |s, out| {
                let sub = &self.subdomains[s];
                let mut capacities = Vec::new();
                macro_rules! record {
                    ($v:expr) => {
                        capacities.push($v.capacity())
                    };
                }
                subdomain_arrays!(sub, record, as_ref);
                capacities.extend(sub.sends.iter().map(|l| l.indices.capacity()));
                let buffers = self.forward.capacities(s);
                let state = SubdomainOut {
                    particles: &sub.particles,
                    n_owned: sub.n_owned,
                    wall_history: &sub.wall_history,
                    sends: &sub.sends,
                    receives: &sub.receives,
                    list: &sub.list,
                    capacities,
                    buffers,
                };
                let bytes = bincode::serialize(&state).expect("in-memory bincode of plain data");
                bytes_to_words(&bytes, out);
            });
        DecomposedState {
            grid: self.grid.clone(),
            balance: self.balance.clone(),
            builds: self.builds,
            bytes_sent: self.comm.sum(self.bytes_sent),
            width: self.width,
            extra: self.extra,
            skin: self.skin,
            subdomains: per_sub.iter().map(|w| words_to_bytes(w)).collect(),
        }
    }

    /// The subdomains of `state` as they were, those `comm` owns here filled in; the cut
    /// planes move at `threshold` from now on. An error when the state does not fit
    /// (`wall_slots` wall histories per particle, indices within the subdomain).
    pub fn from_state(
        state: DecomposedState,
        comm: Comm,
        threshold: Option<Real>,
        rotation: bool,
        wall_slots: usize,
    ) -> Result<Self, String> {
        let grid = state.grid;
        let count = grid.len();
        if state.subdomains.len() != count {
            return Err(format!(
                "{} subdomain states for a grid of {count}",
                state.subdomains.len()
            ));
        }
        let mut subdomains: Vec<Subdomain<H, WH>> = (0..count)
            .map(|s| Subdomain::new(s, &grid, rotation))
            .collect();
        let mut buffers: Vec<Vec<usize>> = vec![Vec::new(); count];
        let mut total = 0;
        for (s, bytes) in state.subdomains.iter().enumerate() {
            let stored: SubdomainState<H, WH> = bincode::deserialize(bytes)
                .map_err(|e| format!("subdomain {s} does not decode: {e}"))?;
            check(&stored, s, count, wall_slots)?;
            total += stored.n_owned;
            if !comm.owns(s, count) {
                continue;
            }
            let sub = &mut subdomains[s];
            sub.particles = stored.particles;
            sub.n_owned = stored.n_owned;
            sub.wall_history = stored.wall_history;
            sub.sends = stored.sends;
            sub.receives = stored.receives;
            sub.list = stored.list;
            let mut capacities = stored.capacities.into_iter();
            macro_rules! reserve {
                ($v:expr) => {
                    if let Some(c) = capacities.next() {
                        if c > $v.capacity() {
                            $v.reserve_exact(c - $v.len());
                        }
                    }
                };
            }
            subdomain_arrays!(sub, reserve, as_mut);
            for list in &mut sub.sends {
                reserve!(list.indices);
            }
            buffers[s] = stored.buffers;
        }
        let mut balance = state.balance;
        balance.threshold = threshold;
        let bytes_sent = if comm.is_root() { state.bytes_sent } else { 0 };
        Ok(Decomposition {
            grid,
            subdomains,
            width: state.width,
            extra: state.extra,
            skin: state.skin,
            builds: state.builds,
            comm,
            total,
            bytes_sent,
            balance,
            forward: Forward::with_capacities(buffers),
        })
    }

    /// The owned particles of every subdomain of `state` side by side, their wall histories
    /// and contact-history rows: what another grid deals out again.
    pub fn gathered_from_state(
        state: &DecomposedState,
        rotation: bool,
        wall_slots: usize,
    ) -> Result<(Particles, Vec<WH>, HistoryRows<H>), String> {
        let count = state.subdomains.len();
        let mut all = Particles::new(rotation);
        let mut wall = Vec::new();
        let mut rows = HistoryRows::default();
        for (s, bytes) in state.subdomains.iter().enumerate() {
            let stored: SubdomainState<H, WH> = bincode::deserialize(bytes)
                .map_err(|e| format!("subdomain {s} does not decode: {e}"))?;
            check(&stored, s, count, wall_slots)?;
            let own = stored.list.rows(&stored.particles.id, stored.n_owned);
            for k in 0..stored.n_owned {
                all.push_copy(&stored.particles, k);
                rows.push(own.of(k));
            }
            wall.extend_from_slice(&stored.wall_history);
        }
        Ok((all, wall, rows))
    }
}

/// Refuses a subdomain state whose arrays do not fit together (so that no index panics).
fn check<H, WH>(
    s: &SubdomainState<H, WH>,
    index: usize,
    count: usize,
    wall_slots: usize,
) -> Result<(), String> {
    let n = s.particles.len();
    let owned = s.n_owned;
    let bad = |what: &str| Err(format!("subdomain {index}: {what}"));
    let p = &s.particles;
    let lengths = [
        p.id.len(),
        p.species.len(),
        p.velocity.len(),
        p.force.len(),
        p.radius.len(),
        p.mass.len(),
        p.inv_mass.len(),
    ];
    if lengths.iter().any(|&l| l != n)
        || p.angular
            .as_ref()
            .is_some_and(|a| a.omega.len() != n || a.torque.len() != n || a.inv_inertia.len() != n)
    {
        return bad("particle arrays of different lengths");
    }
    if owned > n || s.wall_history.len() != owned * wall_slots {
        return bad("owned particles and wall histories do not match");
    }
    let l = &s.list;
    if l.reference.len() != owned
        || l.history.len() != l.pairs.len()
        || l.constants.len() != l.pairs.len()
        || l.image_history.len() != l.image_pairs.len()
        || l.each()
            .any(|([i, j], _, _)| i as usize >= n || j as usize >= n)
    {
        return bad("its pair list does not match its particles");
    }
    if s.sends
        .iter()
        .any(|list| list.to >= count || list.indices.iter().any(|&k| k as usize >= owned))
        || s.receives.iter().any(|&(from, _)| from >= count)
    {
        return bad("its ghost lists name particles or subdomains that do not exist");
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bytes_travel_as_words_unchanged() {
        for n in [0, 1, 7, 8, 9, 100] {
            let bytes: Vec<u8> = (0..n).map(|k| (k * 37 + 255) as u8).collect();
            let mut words = Vec::new();
            bytes_to_words(&bytes, &mut words);
            assert_eq!(words_to_bytes(&words), bytes);
        }
    }
}
