//! Per-pair contact history, the state a slot keeps for one contact.

use crate::math::{Real, Vec3};

/// Contact history of a particle pair or of a particle and a wall (e.g. a tangential
/// spring). A pair's is stored once per listed pair and kept across list rebuilds, always
/// seen from the particle of lower id: a re-sort, which changes the particles' indices but
/// not their ids, leaves it as it is (it is never mirrored).
pub trait PairHistory:
    Copy + Default + Send + Sync + PartialEq + serde::Serialize + serde::de::DeserializeOwned
{
    /// `f64` words of one history, for the MPI transport of the decomposed step.
    const WORDS: usize;
    fn write_words(&self, out: &mut Vec<Real>);
    /// From exactly `WORDS` words.
    fn read_words(words: &[Real]) -> Self;
    /// A history holding only `tag` (not 0) in its first word: a mesh contact keeps the
    /// triangle it is on in a slot beside its history (`bodies::mesh_contact`). Zero-sized
    /// histories hold no tag.
    fn tagged(tag: Real) -> Self;
    /// The tag of [`PairHistory::tagged`]; 0 for the default history.
    fn tag(&self) -> Real;
}

/// The seed's model keeps no history: a zero-sized type, so its store costs nothing.
impl PairHistory for () {
    const WORDS: usize = 0;
    fn write_words(&self, _: &mut Vec<Real>) {}
    fn read_words(_: &[Real]) -> Self {}
    fn tagged(_: Real) -> Self {}
    fn tag(&self) -> Real {
        0.0
    }
}

/// A displacement of `i` relative to `j` (e.g. a tangential spring): `j` sees it negated.
impl PairHistory for Vec3 {
    const WORDS: usize = 3;
    fn write_words(&self, out: &mut Vec<Real>) {
        out.extend_from_slice(&self.to_array());
    }
    fn read_words(w: &[Real]) -> Self {
        Vec3::new(w[0], w[1], w[2])
    }
    fn tagged(tag: Real) -> Self {
        Vec3::new(tag, 0.0, 0.0)
    }
    fn tag(&self) -> Real {
        self.x
    }
}

/// Two histories side by side (e.g. tangential and rolling).
impl<A: PairHistory, B: PairHistory> PairHistory for (A, B) {
    const WORDS: usize = A::WORDS + B::WORDS;
    fn write_words(&self, out: &mut Vec<Real>) {
        self.0.write_words(out);
        self.1.write_words(out);
    }
    fn read_words(w: &[Real]) -> Self {
        (A::read_words(&w[..A::WORDS]), B::read_words(&w[A::WORDS..]))
    }
    fn tagged(tag: Real) -> Self {
        if A::WORDS > 0 {
            (A::tagged(tag), B::default())
        } else {
            (A::default(), B::tagged(tag))
        }
    }
    fn tag(&self) -> Real {
        if A::WORDS > 0 {
            self.0.tag()
        } else {
            self.1.tag()
        }
    }
}

/// A magnitude (e.g. accumulated slip length): the same from either side.
impl PairHistory for Real {
    const WORDS: usize = 1;
    fn write_words(&self, out: &mut Vec<Real>) {
        out.push(*self);
    }
    fn read_words(w: &[Real]) -> Self {
        w[0]
    }
    fn tagged(tag: Real) -> Self {
        tag
    }
    fn tag(&self) -> Real {
        *self
    }
}
