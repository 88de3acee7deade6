//! What the solver's arrays hold, for `cgdem bench` and `summary.json`.

/// Bytes the world holds, from its arrays' capacities (what `cgdem bench` reports).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MemoryUse {
    pub particles: usize,
    /// Per-particle arrays: state, forces, wall history, body loads, list offsets.
    pub particle_bytes: usize,
    pub pairs: usize,
    /// Per-pair arrays: the list, its reverse index, the contact history and the results.
    pub pair_bytes: usize,
    /// Contact-history entries (one per listed pair: the store is rebuilt with the list,
    /// so it never outgrows it).
    pub history_entries: usize,
}
