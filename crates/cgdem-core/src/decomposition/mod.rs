//! Spatial domain decomposition (LAMMPS `Comm`, comm_brick.cpp): the box is cut into a grid
//! of subdomains, each owning the particles inside it in its own arrays, plus a layer of
//! ghost copies of its neighbours' particles, `width` = largest diameter + contact reach +
//! skin thick. The cut, then the three phases that move data between subdomains (LAMMPS's
//! fourth, `reverse_comm`, is not needed: see below), one file each:
//!
//! - [`grid`]: the subdomain grid and its cut planes (by particle count);
//! - [`balance`] and [`rebalance`]: at a list rebuild, the cut planes move by count when
//!   the imbalance passes a threshold (LAMMPS `fix balance ... shift`): when, and how;
//! - [`exchange`]: at a list rebuild, particles that left their subdomain move to the new
//!   owner with every per-particle array that must travel (wall history, contact history
//!   rows);
//! - [`borders`]: at a list rebuild, which owned particles each neighbour needs as ghosts
//!   (periodic faces through shifted images);
//! - [`forward`]: every step, the ghosts' positions, velocities and spins.
//!
//! The step itself is [`step`] (what the world asks for) and `force_pass` (the forces of one
//! subdomain). Pairs that cross a boundary are evaluated by both owners (newton off, as
//! LIGGGHTS's granular pair styles), so no forces travel back; each pair is evaluated with
//! the particle of lower id first, so both sides compute the same numbers and keep the same
//! history, except across a periodic face cut into subdomains: there each side sees the
//! other particle through its image, whose position is rounded once more (`x + L`), so the
//! two copies agree to that rounding only (see `step_tests`). Each phase packs what travels
//! into buffers and unpacks them on the other side: threads in one process read them in
//! place, MPI ranks send the same buffers ([`transport`]). The threads of a process form a
//! [`team`] that gives each subdomain to the same thread, unless another is free first.

pub mod balance;
pub mod borders;
pub mod exchange;
mod force_pass;
pub mod forward;
pub mod grid;
pub mod placement;
pub mod rebalance;
pub mod removal;
pub mod state;
pub mod step;
#[cfg(test)]
mod step_tests;
pub mod team;
pub mod transport;

pub use balance::BalanceSpec;
pub use grid::{choose_counts, Grid, GridSpec};
pub use state::DecomposedState;
pub use transport::Comm;

use crate::contact::PairHistory;
use crate::math::{Real, Vec3};
pub use crate::neighbor::HistoryRows;
use crate::neighbor::PairList;
use crate::particles::Particles;

/// What `summary.json` says of a run's subdomains.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct DecompositionSummary {
    /// Subdomains along x, y, z.
    pub grid: [usize; 3],
    /// Why: `--grid` given, or chosen from the scene (and by which rule).
    #[serde(default)]
    pub grid_reason: String,
    /// MPI ranks (1: threads in one process).
    pub ranks: usize,
    /// Owned particles per subdomain at the end.
    pub subdomain_particles: Vec<usize>,
    /// Most particles in one subdomain over the mean, at the end (1 is perfect balance), by
    /// owner: the owners are those of the last rebuild.
    pub imbalance: Real,
    /// `--balance`: the imbalance past which the cut planes moved at a rebuild (none: off).
    #[serde(default)]
    pub balance_threshold: Option<Real>,
    /// Rebuilds at which the cut planes moved.
    #[serde(default)]
    pub shifts: u64,
    /// The largest imbalance the subdomains had after a rebuild, from the first shift on.
    #[serde(default)]
    pub imbalance_max_after_first_shift: Option<Real>,
    /// The imbalance the start's cut planes (by count, never moved) would give at the end, by
    /// position: particles that crossed a plane since the last rebuild count on their new
    /// side, so between rebuilds this can differ from `imbalance` even when no plane moved.
    #[serde(default)]
    pub static_imbalance: Real,
    /// The largest imbalance the start's cut planes gave or would have given at a rebuild,
    /// or at the end (by position, as `static_imbalance`).
    #[serde(default)]
    pub static_imbalance_max: Real,
    /// Bytes the ranks sent each other per step, averaged over the run (exchange, borders,
    /// forward; 0 in one process, where the threads read the buffers in place).
    pub bytes_sent_between_ranks_per_step: Real,
}

/// One subdomain: its bounds, its owned particles (first `n_owned` entries of `particles`)
/// followed by its ghosts, and what it needs to rebuild and step.
#[derive(Clone, Debug)]
pub struct Subdomain<H, WH> {
    pub index: usize,
    pub lo: Vec3,
    pub hi: Vec3,
    pub particles: Particles,
    pub n_owned: usize,
    /// Per owned particle, `wall_slots` wall-contact histories (particle-major).
    pub wall_history: Vec<WH>,
    /// Contact histories by partner, valid from the exchange to the list build.
    pub rows: HistoryRows<H>,
    /// Owned particles each neighbour keeps as ghosts (built by `borders`).
    pub sends: Vec<borders::SendList>,
    /// The send lists this subdomain's ghosts come from, in ghost order: (subdomain, list).
    pub receives: Vec<(usize, usize)>,
    pub list: PairList<H>,
    /// Per owned particle, per body: where it needs no SDF lookup (as the world's; not
    /// stored in restart files).
    pub body_clearances: Vec<crate::bodies::Clearance>,
    /// Per owned particle and body met on its triangles: the triangles near it.
    pub near_triangles: Vec<crate::bodies::NearTriangles>,
    /// Per owned particle, the walls it may reach before the next list build; made by the
    /// first force pass after a build (not stored in restart files: any pass makes them
    /// right, they only spare looking at walls out of reach).
    pub near_walls: Vec<crate::walls::WallMask>,
    /// Scratch of the force pass: the listed (direct) pairs by index, those within reach
    /// this step first, sized as the list (laws with history only).
    pub pairs_by_reach: Vec<u32>,
}

impl<H: PairHistory, WH: PairHistory> Subdomain<H, WH> {
    pub fn new(index: usize, grid: &Grid, with_rotation: bool) -> Self {
        let (lo, hi) = grid.bounds(index);
        Subdomain {
            index,
            lo,
            hi,
            particles: Particles::new(with_rotation),
            n_owned: 0,
            wall_history: Vec::new(),
            rows: HistoryRows::default(),
            sends: Vec::new(),
            receives: Vec::new(),
            list: PairList::default(),
            body_clearances: Vec::new(),
            near_triangles: Vec::new(),
            near_walls: Vec::new(),
            pairs_by_reach: Vec::new(),
        }
    }

    pub fn ghosts(&self) -> usize {
        self.particles.len() - self.n_owned
    }
}
