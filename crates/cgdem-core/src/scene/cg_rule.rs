//! The coarse-graining rule a scene was built with (the transform is `coarse_graining`).

/// Which quantities a coarse-graining keeps. Every rule scales diameters by `lambda` and
/// masses by `lambda^3` and keeps each contact's restitution; they differ in how the contact
/// energy, the dashpots and the cohesion scale (derivations: reference/COARSE_GRAINING.md).
/// `RelativeOverlap` and `BulkViscosity` are defined for the WCA model of Hirose,
/// `RelativeOverlap`, `ScaledParticle` and `LiggghtsPfm` for Hertz-Mindlin.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum CoarseGrainRule {
    /// Hirose's rule: `phi'(r) = lambda^3 phi(r/lambda)`, `gamma' = lambda^2 gamma`,
    /// `dt' = lambda dt`. Keeps each contact's restitution and the overlap per diameter under
    /// the same velocity; the bulk viscosity `~ gamma/d` grows by `lambda`, so viscous flows
    /// run `lambda` times slower. For Hertz: every contact force `F'(lambda x) = lambda^2 F(x)`
    /// (Yang's `gamma_n` times lambda, Hamaker constant times lambda^3, `h_min` times lambda).
    /// Named after what it keeps: `k' = lambda k` and `m' = lambda^3 m` give
    /// `overlap' = lambda overlap` at the same impact velocity. Its first name, `seed`, is
    /// still read (suite files, `--cg-rule`, stored `summary.json` and restart files).
    #[default]
    #[serde(alias = "seed")]
    RelativeOverlap,
    /// `phi'(r) = lambda phi(r/lambda)`, `gamma' = lambda gamma`, `dt' = lambda^2 dt`. Keeps
    /// each contact's restitution and the bulk viscosity `~ gamma/d`, so viscous flows run at
    /// the same speed; contacts are softer (period `lambda^2` longer). WCA only.
    BulkViscosity,
    /// Hertz only: the same material in larger particles. Every material constant unchanged
    /// (Young's modulus, Poisson's ratio, restitution, friction, rolling friction, Yang's
    /// `gamma_n`, Hamaker constant, `h_min`, the cohesion cut-off).
    ScaledParticle,
    /// Hertz only: LIGGGHTS-PFM's `coarsegraining` (radius times the factor, Young's modulus,
    /// Poisson's ratio, restitution and friction unchanged, the neighbour skin in diameters)
    /// with a stated law for what it leaves unscaled: rolling friction unchanged, the van der
    /// Waals cohesion scaled like the weight (Hamaker constant times lambda^4, `h_min` and the
    /// cut-off times lambda: the Bond number `F_vdw / (m g)` is kept at every scaled gap) and
    /// Yang's `gamma_n` times lambda (restitution kept).
    LiggghtsPfm,
}

impl CoarseGrainRule {
    /// The rule's name in scene files, run directories and `--cg-rule`.
    pub fn name(self) -> &'static str {
        match self {
            CoarseGrainRule::RelativeOverlap => "relative-overlap",
            CoarseGrainRule::BulkViscosity => "bulk-viscosity",
            CoarseGrainRule::ScaledParticle => "scaled-particle",
            CoarseGrainRule::LiggghtsPfm => "liggghts-pfm",
        }
    }

    /// Every rule, in the order the documentation lists them.
    pub const ALL: [CoarseGrainRule; 4] = [
        CoarseGrainRule::RelativeOverlap,
        CoarseGrainRule::BulkViscosity,
        CoarseGrainRule::ScaledParticle,
        CoarseGrainRule::LiggghtsPfm,
    ];

    /// The rule named `name` (its [`name`](Self::name), or the first name `seed` of
    /// `relative-overlap`), if any.
    pub fn from_name(name: &str) -> Option<CoarseGrainRule> {
        match name {
            Self::OLD_RELATIVE_OVERLAP => Some(CoarseGrainRule::RelativeOverlap),
            _ => Self::ALL.into_iter().find(|r| r.name() == name),
        }
    }

    /// The first name of `relative-overlap`, as older suite files, `summary.json`,
    /// `history.json` and comparison names hold it.
    pub const OLD_RELATIVE_OVERLAP: &'static str = "seed";

    /// Whether the rule is defined for the WCA model of Hirose (`wca`) or for Hertz (`hertz`).
    pub fn defined_for(self, model: &str) -> bool {
        use CoarseGrainRule::*;
        match model {
            "wca" => matches!(self, RelativeOverlap | BulkViscosity),
            "hertz" => matches!(self, RelativeOverlap | ScaledParticle | LiggghtsPfm),
            _ => false,
        }
    }

    /// The rules defined for `model`, as words for messages (`"relative-overlap" or "bulk-viscosity"`).
    pub fn names_for(model: &str) -> String {
        Self::ALL
            .into_iter()
            .filter(|r| r.defined_for(model))
            .map(|r| format!("\"{}\"", r.name()))
            .collect::<Vec<_>>()
            .join(" or ")
    }

    /// Exponents of lambda for the WCA energy and dashpots (None for the Hertz-only rules).
    pub(crate) fn wca_exponents(self) -> Option<(i32, i32)> {
        match self {
            CoarseGrainRule::RelativeOverlap => Some((3, 2)),
            CoarseGrainRule::BulkViscosity => Some((1, 1)),
            CoarseGrainRule::ScaledParticle | CoarseGrainRule::LiggghtsPfm => None,
        }
    }

    /// Exponent of lambda for an explicit time step: the contact period grows by lambda
    /// under every rule but bulk-viscosity's (lambda^2). For Hertz with Young's modulus
    /// unchanged the contact time `~ (m^2 / (R Y^2 v))^(1/5)` grows by lambda.
    pub(crate) fn time_exponent(self) -> i32 {
        match self {
            CoarseGrainRule::BulkViscosity => 2,
            _ => 1,
        }
    }
}
