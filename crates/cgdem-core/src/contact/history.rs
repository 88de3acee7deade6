//! Per-pair contact history, the state a slot keeps for one contact.

use crate::math::{Real, Vec3};

/// Per-pair contact history (e.g. a tangential spring). Stored once per pair, kept across
/// list rebuilds, mirrored when a re-sort swaps which particle of the pair comes first.
pub trait PairHistory:
    Copy + Default + Send + Sync + PartialEq + serde::Serialize + serde::de::DeserializeOwned
{
    /// The same history seen from the other particle.
    fn mirrored(self) -> Self;
}

/// The seed's model keeps no history: a zero-sized type, so its store costs nothing.
impl PairHistory for () {
    fn mirrored(self) -> Self {}
}

/// A displacement of `i` relative to `j` (e.g. a tangential spring): `j` sees it negated.
impl PairHistory for Vec3 {
    fn mirrored(self) -> Self {
        -self
    }
}

/// Two histories side by side (e.g. tangential and rolling).
impl<A: PairHistory, B: PairHistory> PairHistory for (A, B) {
    fn mirrored(self) -> Self {
        (self.0.mirrored(), self.1.mirrored())
    }
}

/// A magnitude (e.g. accumulated slip length): the same from either side.
impl PairHistory for Real {
    fn mirrored(self) -> Self {
        self
    }
}
