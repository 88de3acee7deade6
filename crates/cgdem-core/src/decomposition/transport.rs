//! How the packed buffers of the phases travel between subdomains. In one process every
//! subdomain is here and a phase's unpack reads the other subdomains' buffers in place;
//! under `mpirun` (cargo feature `mpi`) each rank owns a block of subdomains, and
//! [`Comm::route`] sends the buffers meant for another rank's subdomains there (the same
//! buffers, encoded as `f64` words), so that unpack finds them where the threads put them.
//!
//! Every rank takes the same decisions from the same numbers: the reductions here (largest
//! overlap, finiteness, whether any particle moved past half the skin) and the all-gathers
//! in subdomain order give each rank the values one process computes, bit for bit.

use super::team::Team;
use crate::contact::PairHistory;
use crate::math::{Real, Vec3};
use crate::particles::{AngularState, Particles};

/// The processes a decomposed run spans: one (threads only) or the ranks of `MPI_COMM_WORLD`,
/// and the threads of this process that step its subdomains.
#[derive(Clone, Default)]
pub struct Comm {
    #[cfg(feature = "mpi")]
    mpi: Option<std::sync::Arc<mpi_comm::MpiComm>>,
    /// Started at the first phase, with the threads of the rayon pool the run is in
    /// (`--threads`); shared by clones.
    team: std::sync::Arc<std::sync::OnceLock<Team>>,
}

impl std::fmt::Debug for Comm {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Comm {{ rank: {}, size: {} }}", self.rank(), self.size())
    }
}

impl Comm {
    /// One process: every subdomain is stepped here.
    pub fn local() -> Self {
        Comm::default()
    }

    /// The ranks of `MPI_COMM_WORLD` when started by `mpirun` (OpenMPI's or a PMI launcher's
    /// variables are set), otherwise one process. A build without the `mpi` feature started
    /// by `mpirun` on several ranks is refused: each rank would run the whole case and write
    /// the same outputs.
    pub fn from_environment() -> Result<Self, String> {
        let launched = ["OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK"]
            .iter()
            .any(|v| std::env::var_os(v).is_some());
        if !launched {
            return Ok(Comm::local());
        }
        #[cfg(feature = "mpi")]
        {
            mpi_comm::MpiComm::initialize().map(|c| Comm {
                mpi: Some(std::sync::Arc::new(c)),
                team: Default::default(),
            })
        }
        #[cfg(not(feature = "mpi"))]
        {
            let size = std::env::var("OMPI_COMM_WORLD_SIZE")
                .or_else(|_| std::env::var("PMI_SIZE"))
                .ok()
                .and_then(|s| s.parse::<usize>().ok())
                .unwrap_or(1);
            if size > 1 {
                return Err(format!(
                    "started by mpirun on {size} ranks, but this cgdem is built without MPI; build it with `cargo build --release --features mpi` (needs libopenmpi-dev), or run it without mpirun (--threads N --grid ...)"
                ));
            }
            Ok(Comm::local())
        }
    }

    pub fn rank(&self) -> usize {
        #[cfg(feature = "mpi")]
        if let Some(m) = &self.mpi {
            return m.rank;
        }
        0
    }

    pub fn size(&self) -> usize {
        #[cfg(feature = "mpi")]
        if let Some(m) = &self.mpi {
            return m.size;
        }
        1
    }

    /// Rank 0 writes the outputs.
    pub fn is_root(&self) -> bool {
        self.rank() == 0
    }

    /// Whether buffers travel between processes (more than one rank).
    pub fn is_distributed(&self) -> bool {
        self.size() > 1
    }

    /// The rank owning subdomain `sub` of `count`: contiguous blocks, so neighbours along x
    /// (the fastest index) mostly share a rank.
    pub fn owner(&self, sub: usize, count: usize) -> usize {
        sub * self.size() / count.max(1)
    }

    pub fn owns(&self, sub: usize, count: usize) -> bool {
        self.owner(sub, count) == self.rank()
    }

    /// `task` on each subdomain this rank owns (`items[s]` stands for subdomain `s`), each
    /// on the thread of this process whose block it is unless another thread is free first
    /// ([`Team::each_of`]); results by subdomain, `None` where owned elsewhere.
    pub fn each_owned<T: Send, R: Send>(
        &self,
        items: &mut [T],
        task: impl Fn(&mut T) -> R + Sync,
    ) -> Vec<Option<R>> {
        let count = items.len();
        let owned: Vec<usize> = (0..count).filter(|&s| self.owns(s, count)).collect();
        let team = self
            .team
            .get_or_init(|| Team::new(rayon::current_num_threads()));
        team.each_of(items, &owned, task)
    }

    /// Sends every item `packed[from][slot]` of an owned `from` whose destination subdomain
    /// `dest(from, slot, item)` is owned by another rank there, and stores what the other
    /// ranks send here at the same `[from][slot]` (the vectors of subdomains owned elsewhere
    /// grow to hold them, with `T::default()` in slots meant for other ranks). Returns the
    /// bytes this rank sent. Nothing moves in one process. `counts`: the words each rank
    /// sends here, when known (forward between two rebuilds sends the same amounts each
    /// step): then only the ranks that exchange anything meet, point to point; filled in
    /// (by a collective over all ranks) when `None`.
    pub fn route<T: Wire + Default>(
        &self,
        packed: &mut [Vec<T>],
        dest: impl Fn(usize, usize, &T) -> usize,
        counts: &mut Option<Vec<usize>>,
    ) -> u64 {
        if !self.is_distributed() {
            return 0;
        }
        let count = packed.len();
        let mut out: Vec<Vec<Real>> = vec![Vec::new(); self.size()];
        for (from, items) in packed.iter().enumerate() {
            if !self.owns(from, count) {
                continue;
            }
            for (slot, item) in items.iter().enumerate() {
                let to = self.owner(dest(from, slot, item), count);
                if to == self.rank() {
                    continue;
                }
                let buffer = &mut out[to];
                buffer.push(from as Real);
                buffer.push(slot as Real);
                item.write(buffer);
            }
        }
        let sent = out.iter().map(|b| b.len() as u64 * 8).sum();
        for buffer in self.all_to_all(out, counts) {
            let mut input = &buffer[..];
            while !input.is_empty() {
                let from = take_count(&mut input);
                let slot = take_count(&mut input);
                let item = T::read(&mut input);
                let items = &mut packed[from];
                if items.len() <= slot {
                    items.resize_with(slot + 1, T::default);
                }
                items[slot] = item;
            }
        }
        sent
    }

    /// Per rank, what it sent here (`out[r]` goes to rank `r`).
    #[allow(unused_variables)]
    fn all_to_all(&self, out: Vec<Vec<Real>>, counts: &mut Option<Vec<usize>>) -> Vec<Vec<Real>> {
        #[cfg(feature = "mpi")]
        if let Some(m) = &self.mpi {
            return m.all_to_all(out, counts);
        }
        out
    }

    /// The element-wise largest of `v` over the ranks (exact in any order).
    #[allow(unused_variables)]
    pub fn max_each(&self, v: &mut [Real]) {
        #[cfg(feature = "mpi")]
        if let Some(m) = &self.mpi {
            m.all_reduce(v, mpi::collective::SystemOperation::max());
        }
    }

    /// The element-wise sum of `v` over the ranks: exact in any order for integer counts
    /// below 2^53, which is all it is used for.
    #[allow(unused_variables)]
    pub fn sum_each(&self, v: &mut [Real]) {
        #[cfg(feature = "mpi")]
        if let Some(m) = &self.mpi {
            m.all_reduce(v, mpi::collective::SystemOperation::sum());
        }
    }

    /// Every rank's `mine`, in rank order.
    #[allow(unused_variables)]
    pub fn all_gather(&self, mine: Vec<Real>) -> Vec<Vec<Real>> {
        #[cfg(feature = "mpi")]
        if let Some(m) = &self.mpi {
            return m.all_gather(mine);
        }
        vec![mine]
    }

    /// Every rank's `mine` at rank 0, in rank order; the other ranks get nothing back: for
    /// what only rank 0 writes.
    #[allow(unused_variables)]
    pub fn gather_to_root(&self, mine: Vec<Real>) -> Vec<Vec<Real>> {
        #[cfg(feature = "mpi")]
        if let Some(m) = &self.mpi {
            return m.gather_to_root(mine);
        }
        vec![mine]
    }

    /// Per subdomain (index order), the words each owner encoded for it with `encode`
    /// (called for the owned subdomains only), on every rank.
    pub fn gather_by_subdomain(
        &self,
        count: usize,
        encode: impl Fn(usize, &mut Vec<Real>),
    ) -> Vec<Vec<Real>> {
        self.subdomain_words(count, encode, false)
    }

    /// `gather_by_subdomain` at rank 0 only; the other ranks keep the words of their own
    /// subdomains (the others empty).
    pub fn gather_by_subdomain_to_root(
        &self,
        count: usize,
        encode: impl Fn(usize, &mut Vec<Real>),
    ) -> Vec<Vec<Real>> {
        self.subdomain_words(count, encode, true)
    }

    fn subdomain_words(
        &self,
        count: usize,
        encode: impl Fn(usize, &mut Vec<Real>),
        to_root: bool,
    ) -> Vec<Vec<Real>> {
        let mut mine = Vec::new();
        let mut per_sub = vec![Vec::new(); count];
        for (sub, words) in per_sub.iter_mut().enumerate() {
            if self.owns(sub, count) {
                encode(sub, words);
            }
        }
        if !self.is_distributed() {
            return per_sub;
        }
        for (sub, words) in per_sub.iter().enumerate() {
            if self.owns(sub, count) {
                mine.push(sub as Real);
                mine.push(words.len() as Real);
                mine.extend_from_slice(words);
            }
        }
        let gathered = if to_root {
            self.gather_to_root(mine)
        } else {
            self.all_gather(mine)
        };
        for buffer in gathered {
            let mut input = &buffer[..];
            while !input.is_empty() {
                let sub = take_count(&mut input);
                let n = take_count(&mut input);
                per_sub[sub] = input[..n].to_vec();
                input = &input[n..];
            }
        }
        per_sub
    }

    /// The largest `x` over the ranks.
    pub fn max(&self, x: Real) -> Real {
        let mut v = [x];
        self.max_each(&mut v);
        v[0]
    }

    /// Whether `b` holds on every rank.
    pub fn all(&self, b: bool) -> bool {
        !self.any(!b)
    }

    /// Whether `b` holds on some rank.
    pub fn any(&self, b: bool) -> bool {
        self.max(if b { 1.0 } else { 0.0 }) != 0.0
    }

    /// The sum of `n` over the ranks.
    pub fn sum(&self, n: u64) -> u64 {
        #[allow(unused_mut)]
        let mut v = [n as Real];
        #[cfg(feature = "mpi")]
        if let Some(m) = &self.mpi {
            // Counts below 2^53 are exact as f64, in any order.
            m.all_reduce(&mut v, mpi::collective::SystemOperation::sum());
        }
        v[0] as u64
    }
}

fn take_count(input: &mut &[Real]) -> usize {
    let n = input[0] as usize;
    *input = &input[1..];
    n
}

fn take(input: &mut &[Real], n: usize) -> Vec<Real> {
    let (head, rest) = input.split_at(n);
    *input = rest;
    head.to_vec()
}

/// A buffer a phase sends, encoded as `f64` words (ids and counts are exact below 2^53).
pub trait Wire: Sized {
    fn write(&self, out: &mut Vec<Real>);
    fn read(input: &mut &[Real]) -> Self;
}

pub(crate) fn write_vec3s(xs: &[Vec3], out: &mut Vec<Real>) {
    for x in xs {
        out.extend_from_slice(&x.to_array());
    }
}

pub(crate) fn read_vec3s(input: &mut &[Real], n: usize) -> Vec<Vec3> {
    let (head, rest) = input.split_at(3 * n);
    *input = rest;
    head.chunks_exact(3)
        .map(|c| Vec3::new(c[0], c[1], c[2]))
        .collect()
}

/// Histories as words: `H::WORDS` per entry.
pub(crate) fn write_histories<H: PairHistory>(hs: &[H], out: &mut Vec<Real>) {
    out.push(hs.len() as Real);
    for h in hs {
        h.write_words(out);
    }
}

pub(crate) fn read_histories<H: PairHistory>(input: &mut &[Real]) -> Vec<H> {
    let n = take_count(input);
    (0..n)
        .map(|_| {
            let (head, rest) = input.split_at(H::WORDS);
            *input = rest;
            H::read_words(head)
        })
        .collect()
}

impl Wire for Particles {
    fn write(&self, out: &mut Vec<Real>) {
        let n = self.len();
        out.push(n as Real);
        out.push(if self.angular.is_some() { 1.0 } else { 0.0 });
        out.extend(self.id.iter().map(|&v| v as Real));
        out.extend(self.species.iter().map(|&v| v as Real));
        write_vec3s(&self.position, out);
        write_vec3s(&self.velocity, out);
        write_vec3s(&self.force, out);
        out.extend_from_slice(&self.radius);
        out.extend_from_slice(&self.mass);
        out.extend_from_slice(&self.inv_mass);
        if let Some(a) = &self.angular {
            write_vec3s(&a.omega, out);
            write_vec3s(&a.torque, out);
            out.extend_from_slice(&a.inv_inertia);
        }
    }

    fn read(input: &mut &[Real]) -> Self {
        let n = take_count(input);
        let rotation = take_count(input) == 1;
        let id = take(input, n).into_iter().map(|v| v as u32).collect();
        let species = take(input, n).into_iter().map(|v| v as u16).collect();
        let position = read_vec3s(input, n);
        let velocity = read_vec3s(input, n);
        let force = read_vec3s(input, n);
        let radius = take(input, n);
        let mass = take(input, n);
        let inv_mass = take(input, n);
        let angular = rotation.then(|| AngularState {
            omega: read_vec3s(input, n),
            torque: read_vec3s(input, n),
            inv_inertia: take(input, n),
        });
        Particles {
            id,
            species,
            position,
            velocity,
            force,
            radius,
            mass,
            inv_mass,
            angular,
        }
    }
}

#[cfg(feature = "mpi")]
mod mpi_comm {
    use mpi::datatype::{Partition, PartitionMut};
    use mpi::request::WaitGuard;
    use mpi::topology::SimpleCommunicator;
    use mpi::traits::*;
    use mpi::Count;

    use crate::math::Real;

    /// `MPI_COMM_WORLD` and the universe that finalizes MPI when the last handle goes.
    pub(super) struct MpiComm {
        world: SimpleCommunicator,
        _universe: mpi::environment::Universe,
        pub(super) rank: usize,
        pub(super) size: usize,
    }

    // SAFETY: MPI is initialized with MPI_THREAD_SERIALIZED or better, and every call is
    // made by the thread driving the run, between its parallel phases, one at a time.
    unsafe impl Send for MpiComm {}
    unsafe impl Sync for MpiComm {}

    impl MpiComm {
        pub(super) fn initialize() -> Result<Self, String> {
            let (universe, threading) = mpi::initialize_with_threading(mpi::Threading::Serialized)
                .ok_or("MPI is already initialized")?;
            if threading < mpi::Threading::Serialized {
                return Err(format!(
                    "the MPI library offers thread level {threading:?}; cgdem needs Serialized (its ranks call MPI from a worker thread)"
                ));
            }
            let world = universe.world();
            let (rank, size) = (world.rank() as usize, world.size() as usize);
            Ok(MpiComm {
                world,
                _universe: universe,
                rank,
                size,
            })
        }

        fn displacements(counts: &[Count]) -> Vec<Count> {
            counts
                .iter()
                .scan(0, |at, &c| {
                    let d = *at;
                    *at += c;
                    Some(d)
                })
                .collect()
        }

        pub(super) fn all_reduce(&self, v: &mut [Real], op: mpi::collective::SystemOperation) {
            let mine = v.to_vec();
            self.world.all_reduce_into(&mine[..], v, op);
        }

        pub(super) fn all_to_all(
            &self,
            out: Vec<Vec<Real>>,
            known: &mut Option<Vec<usize>>,
        ) -> Vec<Vec<Real>> {
            let send_counts: Vec<Count> = out.iter().map(|b| b.len() as Count).collect();
            if let Some(counts) = known {
                return self.exchange_with_peers(out, counts);
            }
            let mut recv_counts = vec![0 as Count; self.size];
            self.world
                .all_to_all_into(&send_counts[..], &mut recv_counts[..]);
            *known = Some(recv_counts.iter().map(|&c| c as usize).collect());
            let send: Vec<Real> = out.concat();
            let send_displs = Self::displacements(&send_counts);
            let recv_displs = Self::displacements(&recv_counts);
            let total: Count = recv_counts.iter().sum();
            let mut recv = vec![0.0 as Real; total as usize];
            {
                let s = Partition::new(&send[..], &send_counts[..], &send_displs[..]);
                let mut r = PartitionMut::new(&mut recv[..], &recv_counts[..], &recv_displs[..]);
                self.world.all_to_all_varcount_into(&s, &mut r);
            }
            recv_counts
                .iter()
                .zip(&recv_displs)
                .map(|(&c, &d)| recv[d as usize..(d + c) as usize].to_vec())
                .collect()
        }

        /// `all_to_all` once every rank knows what each other rank sends it (the forward
        /// between two rebuilds): one message to and from each rank that sends or receives
        /// anything, the neighbours' ranks, instead of a collective over all ranks (whose
        /// cost grows with their number: see the scale-out estimate in PERFORMANCE.md).
        fn exchange_with_peers(
            &self,
            out: Vec<Vec<Real>>,
            recv_counts: &[usize],
        ) -> Vec<Vec<Real>> {
            let mut received: Vec<Vec<Real>> = recv_counts.iter().map(|&c| vec![0.0; c]).collect();
            mpi::request::scope(|scope| {
                let mut pending = Vec::new();
                for (rank, buffer) in received.iter_mut().enumerate() {
                    if !buffer.is_empty() {
                        let process = self.world.process_at_rank(rank as i32);
                        pending.push(WaitGuard::from(
                            process.immediate_receive_into(scope, &mut buffer[..]),
                        ));
                    }
                }
                for (rank, buffer) in out.iter().enumerate() {
                    if !buffer.is_empty() {
                        let process = self.world.process_at_rank(rank as i32);
                        pending.push(WaitGuard::from(process.immediate_send(scope, &buffer[..])));
                    }
                }
                // Dropping the guards waits for every request.
            });
            received
        }

        pub(super) fn gather_to_root(&self, mine: Vec<Real>) -> Vec<Vec<Real>> {
            let root = self.world.process_at_rank(0);
            let count = mine.len() as Count;
            if self.rank != 0 {
                root.gather_into(&count);
                root.gather_varcount_into(&mine[..]);
                return Vec::new();
            }
            let mut counts = vec![0 as Count; self.size];
            root.gather_into_root(&count, &mut counts[..]);
            let displs = Self::displacements(&counts);
            let total: Count = counts.iter().sum();
            let mut all = vec![0.0 as Real; total as usize];
            {
                let mut r = PartitionMut::new(&mut all[..], &counts[..], &displs[..]);
                root.gather_varcount_into_root(&mine[..], &mut r);
            }
            counts
                .iter()
                .zip(&displs)
                .map(|(&c, &d)| all[d as usize..(d + c) as usize].to_vec())
                .collect()
        }

        pub(super) fn all_gather(&self, mine: Vec<Real>) -> Vec<Vec<Real>> {
            let count = mine.len() as Count;
            let mut counts = vec![0 as Count; self.size];
            self.world.all_gather_into(&count, &mut counts[..]);
            let displs = Self::displacements(&counts);
            let total: Count = counts.iter().sum();
            let mut all = vec![0.0 as Real; total as usize];
            {
                let mut r = PartitionMut::new(&mut all[..], &counts[..], &displs[..]);
                self.world.all_gather_varcount_into(&mine[..], &mut r);
            }
            counts
                .iter()
                .zip(&displs)
                .map(|(&c, &d)| all[d as usize..(d + c) as usize].to_vec())
                .collect()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn particles_travel_as_words_unchanged() {
        for rotation in [false, true] {
            let mut p = Particles::new(rotation);
            p.push(3, Vec3::new(0.1, -2.0, 1e-300), 0.004, 2.5e-7);
            p.push(0, Vec3::new(Real::MAX, 0.0, -0.0), 0.002, 1.0);
            p.id[1] = u32::MAX;
            p.velocity[0] = Vec3::new(1.0, 2.0, 3.0);
            p.force[1] = Vec3::splat(-7.5);
            if let Some(a) = p.angular.as_mut() {
                a.omega[1] = Vec3::new(9.0, 8.0, 7.0);
                a.torque[0] = Vec3::splat(1e-9);
            }
            let mut words = Vec::new();
            p.write(&mut words);
            words.push(42.0);
            let mut input = &words[..];
            let q = Particles::read(&mut input);
            assert_eq!(input, &[42.0]);
            assert_eq!(q.id, p.id);
            assert_eq!(q.species, p.species);
            let bits = |v: &[Vec3]| -> Vec<[u64; 3]> {
                v.iter().map(|x| x.to_array().map(Real::to_bits)).collect()
            };
            assert_eq!(bits(&q.position), bits(&p.position));
            assert_eq!(bits(&q.velocity), bits(&p.velocity));
            assert_eq!(bits(&q.force), bits(&p.force));
            assert_eq!(
                (q.radius, q.mass, q.inv_mass),
                (p.radius, p.mass, p.inv_mass)
            );
            assert_eq!(q.angular.is_some(), rotation);
            if let (Some(a), Some(b)) = (&q.angular, &p.angular) {
                assert_eq!(bits(&a.omega), bits(&b.omega));
                assert_eq!(bits(&a.torque), bits(&b.torque));
                assert_eq!(a.inv_inertia, b.inv_inertia);
            }
        }
    }

    #[test]
    fn histories_travel_as_words_unchanged() {
        let hs: Vec<(Vec3, Real)> = vec![(Vec3::new(1.0, -2.0, 3.5), 0.25), Default::default()];
        let mut words = Vec::new();
        write_histories(&hs, &mut words);
        assert_eq!(words.len(), 1 + 2 * 4);
        let mut input = &words[..];
        assert_eq!(read_histories::<(Vec3, Real)>(&mut input), hs);
        let units = vec![(); 5];
        let mut words = Vec::new();
        write_histories(&units, &mut words);
        assert_eq!(read_histories::<()>(&mut &words[..]), units);
    }

    #[test]
    fn one_process_owns_every_subdomain_and_routes_nothing() {
        let comm = Comm::local();
        assert_eq!((comm.rank(), comm.size()), (0, 1));
        assert!((0..7).all(|s| comm.owns(s, 7)));
        let mut packed = vec![vec![Particles::new(false)], Vec::new()];
        packed[0][0].push(0, Vec3::ZERO, 1.0, 1.0);
        assert_eq!(comm.route(&mut packed, |_, _, _| 1, &mut None), 0);
        assert_eq!((packed[0][0].len(), packed[1].len()), (1, 0));
        assert_eq!(comm.max(2.0), 2.0);
        assert!(comm.any(true) && !comm.any(false) && comm.all(true));
        assert_eq!(comm.sum(5), 5);
        let per = comm.gather_by_subdomain(3, |s, w| w.push(s as Real));
        assert_eq!(per, vec![vec![0.0], vec![1.0], vec![2.0]]);
    }
}
