//! The coarse-graining rule a scene was built with (the transform is `coarse_graining`).

/// Which quantities a coarse-graining keeps. Both scale diameters by `lambda` and masses by
/// `lambda^3` and keep the damping ratio (hence each contact's restitution); they differ in
/// how the contact energy and the dashpots scale (derivation: reference/COARSE_GRAINING.md).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum CoarseGrainRule {
    /// Paper A: `phi'(r) = lambda^3 phi(r/lambda)`, `gamma' = lambda^2 gamma`,
    /// `dt' = lambda dt`. Keeps each contact's restitution and the overlap per diameter under
    /// the same velocity; the bulk viscosity `~ gamma/d` grows by `lambda`, so viscous flows
    /// run `lambda` times slower.
    #[default]
    Seed,
    /// `phi'(r) = lambda phi(r/lambda)`, `gamma' = lambda gamma`, `dt' = lambda^2 dt`. Keeps
    /// each contact's restitution and the bulk viscosity `~ gamma/d`, so viscous flows run at
    /// the same speed; contacts are softer (period `lambda^2` longer).
    BulkViscosity,
}

impl CoarseGrainRule {
    /// The rule's name in scene files, run directories and `--cg-rule`.
    pub fn name(self) -> &'static str {
        match self {
            CoarseGrainRule::Seed => "seed",
            CoarseGrainRule::BulkViscosity => "bulk-viscosity",
        }
    }

    /// Every rule, in the order the documentation lists them.
    pub const ALL: [CoarseGrainRule; 2] = [CoarseGrainRule::Seed, CoarseGrainRule::BulkViscosity];

    /// The rule named `name` (its [`name`](Self::name)), if any.
    pub fn from_name(name: &str) -> Option<CoarseGrainRule> {
        Self::ALL.into_iter().find(|r| r.name() == name)
    }

    /// Exponents of lambda for (WCA energy, dashpots, explicit time step).
    pub(crate) fn exponents(self) -> (i32, i32, i32) {
        match self {
            CoarseGrainRule::Seed => (3, 2, 1),
            CoarseGrainRule::BulkViscosity => (1, 1, 2),
        }
    }
}
