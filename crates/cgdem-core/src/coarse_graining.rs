//! Coarse-graining as a transform of the scene, paper A Eq. (3)-(6).
//!
//! With `lambda = 2^n`: diameters `lambda d` (same density, so `m' = lambda^3 m`),
//! `phi'(r) = lambda^3 phi(r / lambda)` (so `sigma' = lambda sigma`, `eps' = lambda^3 eps`),
//! `gamma' = lambda^2 gamma`, an explicit `dt' = lambda dt`, the same box, and
//! `N' ~ N / lambda^3`. Positions and velocities are not scaled. Applied once, before the
//! world is built; the force loop never sees lambda.
//!
//! Consequences (tested below): contact stiffness `k = 72 eps / r_c^2` becomes `lambda k`;
//! the period `2 pi sqrt(m_eff / k)` becomes `lambda` times longer; the damping ratio
//! `gamma / (2 sqrt(k m_eff))` and hence the restitution are unchanged. Wall damping is set
//! from the restitution, so it follows the same rule by construction.

pub use crate::scene::CoarseGrainRule;
use crate::scene::{
    CohesionKind, ContactSettings, HertzDampingKind, HertzSettings, InsertAmount, RollingKind,
    Scene, WcaSettings,
};
use crate::timestep::TimeStepRequest;

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum CoarseGrainError {
    #[error("lambda = {0} is not allowed: lambda must be a power of two (1, 2, 4, 8, ...)")]
    NotPowerOfTwo(u32),
    #[error("the {} coarse-graining rule is not defined for model = \"{model}\" scenes; use {allowed} (reference/COARSE_GRAINING.md)", .rule.name())]
    RuleNotDefined {
        rule: CoarseGrainRule,
        model: &'static str,
        allowed: String,
    },
    #[error(
        "{file}: at lambda = {lambda} the particles ({diameter:.4e} m) no longer fit: {reason}"
    )]
    TooCoarse {
        file: String,
        lambda: u32,
        diameter: f64,
        reason: String,
    },
    #[error("{file}: lambda = {lambda} is not allowed with given particles (`read_data`, `[[particle]]`): a prepared state has no coarser counterpart; coarse-grain the scene that prepared it")]
    GivenParticles { file: String, lambda: u32 },
}

/// Hertz parameters under the seed's rule, `phi'(r) = lambda^3 phi(r / lambda)`, i.e. every
/// contact force `F'(x') = lambda^2 F(x' / lambda)` at the same velocities
/// (reference/COARSE_GRAINING_HERTZ.md): Young's modulus, Poisson's ratio, restitution,
/// friction and rolling friction unchanged; Yang's `gamma_n` (s) times lambda; Hamaker
/// constant times lambda^3, `h_min` and the cohesion cut-off times lambda.
pub fn coarse_grain_hertz(h: &HertzSettings, l: f64) -> HertzSettings {
    coarse_grain_hertz_by(h, l, CoarseGrainRule::RelativeOverlap)
}

/// Hertz parameters under `rule` (reference/COARSE_GRAINING.md, "Hertz-Mindlin rules"). The
/// elastic constants, restitution, friction and rolling friction are kept by every rule (each
/// species' material and each pair's coefficients alike); they differ in Yang's `gamma_n` and
/// in the van der Waals cohesion (the default Hamaker constant and each pair's own):
///
/// | rule | `gamma_n` (Yang) | Hamaker constant | `h_min`, cut-off | vdW force at the scaled gap |
/// |---|---|---|---|---|
/// | seed | x lambda | x lambda^3 | x lambda | x lambda^2 (like the contact forces) |
/// | scaled-particle | unchanged | unchanged | unchanged | same material: x lambda near contact |
/// | liggghts-pfm | x lambda | x lambda^4 | x lambda | x lambda^3 (like the weight) |
///
/// Rules other than these three are not defined for Hertz: the scene is returned unchanged
/// (`coarse_grain_by` refuses them first).
pub fn coarse_grain_hertz_by(h: &HertzSettings, l: f64, rule: CoarseGrainRule) -> HertzSettings {
    let (damping, hamaker) = match rule {
        CoarseGrainRule::RelativeOverlap => (1, 3),
        CoarseGrainRule::LiggghtsPfm => (1, 4),
        CoarseGrainRule::ScaledParticle | CoarseGrainRule::BulkViscosity => return h.clone(),
    };
    let mut out = h.clone();
    if let HertzDampingKind::Yang { gamma_n } = h.damping {
        out.damping = HertzDampingKind::Yang {
            gamma_n: gamma_n * l.powi(damping),
        };
    }
    if let CohesionKind::VanDerWaals {
        hamaker_constant,
        h_min,
        cutoff,
    } = h.cohesion
    {
        out.cohesion = CohesionKind::VanDerWaals {
            hamaker_constant: hamaker_constant * l.powi(hamaker),
            h_min: h_min * l,
            cutoff: cutoff.map(|c| c * l),
        };
        // Every species pair's own constant by the same rule.
        for p in &mut out.pairs {
            p.hamaker_constant = p.hamaker_constant.map(|a| a * l.powi(hamaker));
        }
    }
    out
}

/// How far a rule departs from what it keeps for a parameter of the scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CgSeverity {
    /// A known cost of every Hertz rule, stated in the documentation: a warning.
    Note,
    /// The rule cannot keep what it states for this parameter: a warning, an error under
    /// `cgdem run --strict`.
    Inconsistent,
}

/// One finding of [`coarse_grain_checks`]: the rule, the scene parameter and why.
#[derive(Clone, Debug, PartialEq)]
pub struct CgCheck {
    pub rule: CoarseGrainRule,
    /// The scene's name of the parameter (`hamaker_constant`, `gamma_n_yang`, `gravity`,
    /// `rolling_friction`).
    pub parameter: &'static str,
    pub severity: CgSeverity,
    pub message: String,
}

impl std::fmt::Display for CgCheck {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} rule, {}: {}",
            self.rule.name(),
            self.parameter,
            self.message
        )
    }
}

/// Where coarse-graining the scene by `lambda` under `rule` is not consistent, like
/// LIGGGHTS-PFM's `model_check`. Empty for lambda = 1, for the seed's WCA scenes (whose rules
/// are exact similarities) and for a rule not defined for the scene's model (refused by
/// `coarse_grain_by`).
pub fn coarse_grain_checks(scene: &Scene, lambda: u32, rule: CoarseGrainRule) -> Vec<CgCheck> {
    let mut checks = Vec::new();
    let ContactSettings::Hertz(h) = &scene.contact else {
        return checks;
    };
    if lambda <= 1 || !rule.defined_for("hertz") {
        return checks;
    }
    let l = lambda as f64;
    let gravity = scene.gravity.length() > 0.0;
    let mut push = |parameter, severity, message: String| {
        checks.push(CgCheck {
            rule,
            parameter,
            severity,
            message,
        })
    };
    if gravity {
        push("gravity", CgSeverity::Note, format!("weights scale as lambda^3 but Hertz contact forces at the scaled overlap as lambda^2 (Young's modulus is kept), so a contact under load overlaps lambda^(2/3) = {:.2} times more of its diameter at lambda = {lambda}", l.powf(2.0 / 3.0)));
    }
    if h.rolling != RollingKind::None {
        push("rolling_friction", CgSeverity::Note, format!("mu_r is kept: the rolling torque mu_r R_eff |F_n| keeps its ratio to r x F and, where contact forces carry the weight, to the weight's torque m g R; but one parcel stands for lambda^3 = {} real particles whose rolling contacts (and the shapes mu_r stands for) are not resolved, so mu_r calibrated on real particles is unverified for parcels (LIGGGHTS-PFM flags every rolling model under coarsegraining)", l.powi(3)));
    }
    if let CohesionKind::VanDerWaals { .. } = h.cohesion {
        match (rule, gravity) {
            (CoarseGrainRule::RelativeOverlap, true) => push("hamaker_constant", CgSeverity::Inconsistent, format!("the Hamaker constant scales as lambda^3 so the cohesion follows the contact forces (lambda^2), not the weight (lambda^3): the Bond number F_vdw(h_min) / (m g) falls {l}x at lambda = {lambda}, and cohesion-controlled structure (the porosity of fine powders) is not kept; the liggghts-pfm rule keeps it")),
            (CoarseGrainRule::ScaledParticle, _) => push("hamaker_constant", CgSeverity::Inconsistent, format!("same material: the van der Waals force near contact grows only as R (lambda) while contact forces grow as lambda^2 and weights as lambda^3: the Bond number F_vdw(h_min) / (m g) falls {}x at lambda = {lambda}", l * l)),
            (CoarseGrainRule::LiggghtsPfm, false) => push("hamaker_constant", CgSeverity::Inconsistent, format!("the rule scales the cohesion like the weight (Hamaker constant x lambda^4) to keep the Bond number; without gravity there is no weight, and the cohesion only grows {l}x relative to the contact forces at lambda = {lambda}")),
            (CoarseGrainRule::LiggghtsPfm, true) => push("hamaker_constant", CgSeverity::Note, format!("the Bond number is kept (Hamaker constant x lambda^4, h_min x lambda), but the cohesion, like the weight, grows lambda times relative to the unchanged elastic stiffness: cohesive overlaps per diameter grow lambda^(2/3) = {:.2} times at lambda = {lambda}", l.powf(2.0 / 3.0))),
            _ => {}
        }
    }
    if let (CoarseGrainRule::ScaledParticle, HertzDampingKind::Yang { .. }) = (rule, h.damping) {
        push("gamma_n_yang", CgSeverity::Inconsistent, format!("same material: Yang's gamma_n is kept, so the dashpot force at the same velocity grows lambda times while a similar collision needs lambda^2: the restitution of a parcel pair differs from the fine pair's at lambda = {lambda} (seed and liggghts-pfm scale gamma_n by lambda)"));
    }
    checks
}

/// Returns the scene coarse-grained by `lambda` relative to its current level, by the
/// seed's rule.
pub fn coarse_grain(scene: &Scene, lambda: u32) -> Result<Scene, CoarseGrainError> {
    coarse_grain_by(scene, lambda, CoarseGrainRule::RelativeOverlap)
}

/// Returns the scene coarse-grained by `lambda` relative to its current level.
pub fn coarse_grain_by(
    scene: &Scene,
    lambda: u32,
    rule: CoarseGrainRule,
) -> Result<Scene, CoarseGrainError> {
    if lambda == 0 || !lambda.is_power_of_two() {
        return Err(CoarseGrainError::NotPowerOfTwo(lambda));
    }
    if lambda > 1 && !scene.particles.is_empty() {
        return Err(CoarseGrainError::GivenParticles {
            file: scene.source.display().to_string(),
            lambda,
        });
    }
    let l = lambda as f64;
    let model = match &scene.contact {
        ContactSettings::Wca(_) => "wca",
        ContactSettings::Hertz(_) => "hertz",
    };
    if !rule.defined_for(model) {
        return Err(CoarseGrainError::RuleNotDefined {
            rule,
            model,
            allowed: CoarseGrainRule::names_for(model),
        });
    }
    let mut out = scene.clone();
    out.lambda = scene.lambda * lambda;
    out.cg_rule = rule;
    for s in &mut out.species {
        s.diameter *= l;
    }
    out.contact = match &scene.contact {
        ContactSettings::Wca(w) => {
            let (energy, damping) = rule.wca_exponents().expect("a WCA rule");
            ContactSettings::Wca(WcaSettings {
                epsilon: w.epsilon * l.powi(energy),
                sigma: w.sigma * l,
                gamma_n: w.gamma_n * l.powi(damping),
                gamma_t: w.gamma_t * l.powi(damping),
            })
        }
        ContactSettings::Hertz(h) => ContactSettings::Hertz(coarse_grain_hertz_by(h, l, rule)),
    };
    if let TimeStepRequest::Explicit(dt) = scene.time_step {
        out.time_step = TimeStepRequest::Explicit(dt * l.powi(rule.time_exponent()));
    }
    for ins in &mut out.insertions {
        if let InsertAmount::Lattice(lattice) = &mut ins.amount {
            // Sites one coarse diameter apart where there were sites one diameter apart.
            lattice.spacing *= l;
        }
        if let InsertAmount::Count(n) = ins.amount {
            ins.amount = InsertAmount::Count(((n as f64 / l.powi(3)).round() as u64).max(1));
        }
    }
    let diameter = out.max_diameter();
    let length = out.domain.length();
    let too_coarse = |reason: String| CoarseGrainError::TooCoarse {
        file: scene.source.display().to_string(),
        lambda: out.lambda,
        diameter,
        reason,
    };
    for axis in 0..3 {
        if diameter >= length[axis] {
            return Err(too_coarse(format!(
                "the box is only {:.4e} m along axis {axis}",
                length[axis]
            )));
        }
        let needed = (2.0 + out.skin_fraction) * diameter;
        if out.domain.periodic[axis] && length[axis] < needed {
            return Err(too_coarse(format!("the periodic side along axis {axis} ({:.4e} m) must be at least (2 + skin) diameters = {needed:.4e} m", length[axis])));
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::normal::WcaCoefficients;
    use std::path::Path;

    fn collapse_scene() -> Scene {
        let path = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
            .join("validation/cases/aor_collapse.toml");
        Scene::load(&path).unwrap()
    }

    /// (stiffness, effective mass, damping) of the particle-particle contact.
    fn linear_pair(scene: &Scene) -> (f64, f64, f64) {
        let ContactSettings::Wca(w) = scene.contact else {
            panic!("the collapse case uses the WCA model")
        };
        let k = WcaCoefficients {
            epsilon: w.epsilon,
            sigma: w.sigma,
        }
        .contact_stiffness();
        (k, 0.5 * scene.species[0].mass(), w.gamma_n)
    }

    #[test]
    fn damping_ratio_is_invariant_and_the_period_grows_by_lambda() {
        let original = collapse_scene();
        let (k1, m1, g1) = linear_pair(&original);
        let zeta1 = g1 / (2.0 * (k1 * m1).sqrt());
        let period1 = (m1 / k1).sqrt();
        for lambda in [2u32, 4, 8] {
            let coarse = coarse_grain(&original, lambda).unwrap();
            let (k, m, g) = linear_pair(&coarse);
            let l = lambda as f64;
            assert!((k / (l * k1) - 1.0).abs() < 1e-12, "k' = lambda k");
            assert!(
                (m / (l.powi(3) * m1) - 1.0).abs() < 1e-12,
                "m' = lambda^3 m"
            );
            assert!(
                ((g / (2.0 * (k * m).sqrt())) / zeta1 - 1.0).abs() < 1e-12,
                "damping ratio"
            );
            assert!(
                ((m / k).sqrt() / (l * period1) - 1.0).abs() < 1e-12,
                "period x lambda"
            );
            assert_eq!(
                coarse.wall_contact, original.wall_contact,
                "restitution and friction kept"
            );
            assert_eq!(coarse.domain, original.domain, "same box");
        }
    }

    #[test]
    fn bulk_viscosity_rule_keeps_damping_ratio_and_gamma_over_d_and_stretches_the_period_by_lambda_squared(
    ) {
        let original = collapse_scene();
        let (k1, m1, g1) = linear_pair(&original);
        let d1 = original.species[0].diameter;
        for lambda in [2u32, 4, 8] {
            let coarse =
                coarse_grain_by(&original, lambda, CoarseGrainRule::BulkViscosity).unwrap();
            let (k, m, g) = linear_pair(&coarse);
            let l = lambda as f64;
            let d = coarse.species[0].diameter;
            assert!(
                ((g / (2.0 * (k * m).sqrt())) / (g1 / (2.0 * (k1 * m1).sqrt())) - 1.0).abs()
                    < 1e-12
            );
            assert!(
                ((g / d) / (g1 / d1) - 1.0).abs() < 1e-12,
                "bulk viscosity gamma/d kept"
            );
            assert!(((m / k).sqrt() / (l * l * (m1 / k1).sqrt()) - 1.0).abs() < 1e-12);
            assert_eq!(coarse.cg_rule, CoarseGrainRule::BulkViscosity);
        }
    }

    #[test]
    fn particle_count_falls_by_lambda_cubed() {
        let mut scene = collapse_scene();
        scene.insertions[0].amount = InsertAmount::Count(80_000);
        for lambda in [2u32, 4, 8] {
            let coarse = coarse_grain(&scene, lambda).unwrap();
            assert_eq!(
                coarse.insertions[0].amount,
                InsertAmount::Count(80_000 / (lambda as u64).pow(3))
            );
        }
    }

    #[test]
    fn explicit_time_step_grows_by_lambda_and_lambda_must_be_a_power_of_two() {
        let mut scene = collapse_scene();
        scene.time_step = TimeStepRequest::Explicit(1e-8);
        let coarse = coarse_grain(&scene, 4).unwrap();
        assert_eq!(coarse.time_step, TimeStepRequest::Explicit(4e-8));
        assert_eq!(
            coarse_grain(&scene, 3).unwrap_err(),
            CoarseGrainError::NotPowerOfTwo(3)
        );
        assert!(matches!(
            coarse_grain(&scene, 64),
            Err(CoarseGrainError::TooCoarse { .. })
        ));
    }
}

#[cfg(test)]
mod hertz_tests {
    use super::*;
    use crate::scene::{HertzSettings, TangentialKind};

    fn paper_b() -> HertzSettings {
        HertzSettings {
            youngs_modulus: 1e7,
            poisson_ratio: 0.29,
            restitution: 1.0,
            friction: 0.3,
            rolling_friction: 0.002,
            damping: HertzDampingKind::Yang { gamma_n: 1e-5 },
            tangential: TangentialKind::Yang,
            rolling: RollingKind::ConstantTorque,
            cohesion: CohesionKind::VanDerWaals {
                hamaker_constant: 6.5e-20,
                h_min: 4e-10,
                cutoff: None,
            },
            characteristic_velocity: 1.0,
            limit_force: false,
            tangential_damping: true,
            pairs: Vec::new(),
        }
    }

    #[test]
    fn hertz_parameters_scale_so_every_contact_force_is_lambda_squared_at_the_scaled_state() {
        use crate::contact::cohesion::vdw_force;
        let l = 4.0;
        let h = paper_b();
        let g = coarse_grain_hertz(&h, l);
        assert_eq!(
            (
                g.youngs_modulus,
                g.poisson_ratio,
                g.friction,
                g.rolling_friction
            ),
            (
                h.youngs_modulus,
                h.poisson_ratio,
                h.friction,
                h.rolling_friction
            )
        );
        assert_eq!(g.damping, HertzDampingKind::Yang { gamma_n: 4e-5 });
        let (
            CohesionKind::VanDerWaals {
                hamaker_constant: a0,
                h_min: h0,
                ..
            },
            CohesionKind::VanDerWaals {
                hamaker_constant: a1,
                h_min: h1,
                ..
            },
        ) = (h.cohesion, g.cohesion)
        else {
            panic!("vdw lost")
        };
        // F'(lambda x) = lambda^2 F(x): Hertz (Y unchanged), Yang dashpot, van der Waals.
        let (r, delta, v) = (2.5e-5, 1e-8, 0.01);
        let hertz = |y: f64, r: f64, d: f64| 4.0 / 3.0 * y * (r * d).sqrt() * d;
        let yang = |gamma: f64, y: f64, r: f64, d: f64| gamma * 2.0 * y * (r * d).sqrt() * v;
        let ratio = |a: f64, b: f64| a / b / (l * l) - 1.0;
        assert!(
            ratio(
                hertz(g.youngs_modulus, l * r, l * delta),
                hertz(h.youngs_modulus, r, delta)
            )
            .abs()
                < 1e-12
        );
        assert!(ratio(yang(4e-5, 1e7, l * r, l * delta), yang(1e-5, 1e7, r, delta)).abs() < 1e-12);
        for gap in [h0, 3.0 * h0, 30.0 * h0] {
            assert!(
                ratio(
                    vdw_force(a1, l * r, l * r, l * gap),
                    vdw_force(a0, r, r, gap)
                )
                .abs()
                    < 1e-12
            );
        }
        assert!((h1 / h0 - l).abs() < 1e-12);
    }

    fn case(name: &str) -> Scene {
        Scene::load(
            &std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
                .join("validation/cases")
                .join(name),
        )
        .unwrap()
    }

    fn vdw(h: &HertzSettings) -> (f64, f64, Option<f64>) {
        match h.cohesion {
            CohesionKind::VanDerWaals {
                hamaker_constant,
                h_min,
                cutoff,
            } => (hamaker_constant, h_min, cutoff),
            CohesionKind::None => panic!("vdw lost"),
        }
    }

    fn yang(h: &HertzSettings) -> f64 {
        match h.damping {
            HertzDampingKind::Yang { gamma_n } => gamma_n,
            HertzDampingKind::Restitution => panic!("yang lost"),
        }
    }

    /// The exact factor of each parameter under each Hertz rule at lambda = 2 and 4.
    #[test]
    fn each_hertz_rule_scales_each_parameter_by_its_stated_power_of_lambda() {
        let mut h = paper_b();
        h.cohesion = CohesionKind::VanDerWaals {
            hamaker_constant: 6.5e-20,
            h_min: 4e-10,
            cutoff: Some(1e-8),
        };
        // (rule, lambda, gamma_n, Hamaker, h_min and cut-off factors)
        let expected = [
            (CoarseGrainRule::RelativeOverlap, 2.0, 2.0, 8.0, 2.0),
            (CoarseGrainRule::RelativeOverlap, 4.0, 4.0, 64.0, 4.0),
            (CoarseGrainRule::ScaledParticle, 2.0, 1.0, 1.0, 1.0),
            (CoarseGrainRule::ScaledParticle, 4.0, 1.0, 1.0, 1.0),
            (CoarseGrainRule::LiggghtsPfm, 2.0, 2.0, 16.0, 2.0),
            (CoarseGrainRule::LiggghtsPfm, 4.0, 4.0, 256.0, 4.0),
        ];
        let (a0, h0, c0) = vdw(&h);
        for (rule, l, gamma, hamaker, length) in expected {
            let g = coarse_grain_hertz_by(&h, l, rule);
            let kept = |g: &HertzSettings| {
                (
                    g.youngs_modulus,
                    g.poisson_ratio,
                    g.restitution,
                    g.friction,
                    g.rolling_friction,
                    g.rolling,
                    g.tangential,
                )
            };
            assert_eq!(
                kept(&g),
                kept(&h),
                "{rule:?}: elastic, friction, rolling kept"
            );
            let (a1, h1, c1) = vdw(&g);
            assert_eq!(yang(&g), yang(&h) * gamma, "{rule:?} lambda {l}: gamma_n");
            assert_eq!(a1, a0 * hamaker, "{rule:?} lambda {l}: Hamaker constant");
            assert_eq!(h1, h0 * length, "{rule:?} lambda {l}: h_min");
            assert_eq!(c1, c0.map(|c| c * length), "{rule:?} lambda {l}: cut-off");
        }
    }

    /// What each rule keeps, at the scaled state x' = lambda x: the seed's rule every contact
    /// force x lambda^2; liggghts-pfm the van der Waals force x lambda^3, like the weight (the
    /// Bond number); scaled-particle the material (vdW force x lambda near contact only).
    #[test]
    fn the_vdw_force_at_the_scaled_gap_follows_the_contact_forces_the_weight_or_the_material() {
        use crate::contact::cohesion::vdw_force;
        let h = paper_b();
        let (a0, h0, _) = vdw(&h);
        let r = 2.5e-5;
        for l in [2.0, 4.0] {
            for (rule, power) in [
                (CoarseGrainRule::RelativeOverlap, 2),
                (CoarseGrainRule::LiggghtsPfm, 3),
            ] {
                let (a1, h1, _) = vdw(&coarse_grain_hertz_by(&h, l, rule));
                for gap in [h0, 3.0 * h0, 30.0 * h0] {
                    let ratio = vdw_force(a1, l * r, l * r, l * gap) / vdw_force(a0, r, r, gap);
                    assert!((ratio / l.powi(power) - 1.0).abs() < 1e-12, "{rule:?}");
                }
                assert!((h1 / h0 - l).abs() < 1e-15);
            }
            let (a1, h1, _) = vdw(&coarse_grain_hertz_by(
                &h,
                l,
                CoarseGrainRule::ScaledParticle,
            ));
            let ratio = vdw_force(a1, l * r, l * r, h1) / vdw_force(a0, r, r, h0);
            assert!(
                (ratio / l - 1.0).abs() < 1e-4,
                "near contact F ~ A R / h^2: {ratio}"
            );
        }
    }

    #[test]
    fn rules_are_refused_for_the_model_they_are_not_defined_for() {
        let wca = case("aor_collapse.toml");
        let hertz = case("hertz_settle.toml");
        for rule in [
            CoarseGrainRule::ScaledParticle,
            CoarseGrainRule::LiggghtsPfm,
        ] {
            let e = coarse_grain_by(&wca, 2, rule).unwrap_err().to_string();
            assert!(
                e.contains(rule.name()) && e.contains("\"wca\"") && e.contains("bulk-viscosity"),
                "{e}"
            );
            assert!(coarse_grain_by(&hertz, 2, rule).is_ok());
        }
        let e = coarse_grain_by(&hertz, 2, CoarseGrainRule::BulkViscosity)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("bulk-viscosity") && e.contains("liggghts-pfm"),
            "{e}"
        );
    }

    /// The collapse's scene (restitution dashpot, no cohesion) gets the same parameters under
    /// every Hertz rule, so the fidelity suite runs it under one.
    #[test]
    fn without_yang_damping_or_cohesion_the_hertz_rules_coincide() {
        let scene = case("aor_hertz.toml");
        let seed = coarse_grain_by(&scene, 4, CoarseGrainRule::RelativeOverlap).unwrap();
        for rule in [
            CoarseGrainRule::ScaledParticle,
            CoarseGrainRule::LiggghtsPfm,
        ] {
            let other = coarse_grain_by(&scene, 4, rule).unwrap();
            assert_eq!(other.contact, seed.contact);
            assert_eq!(other.species, seed.species);
            assert_eq!(other.time_step, seed.time_step);
        }
    }

    #[test]
    fn checks_name_the_rule_and_the_parameter_and_strict_refuses_only_inconsistencies() {
        let settle = case("hertz_settle.toml");
        assert!(coarse_grain_checks(&settle, 1, CoarseGrainRule::RelativeOverlap).is_empty());
        let notes = coarse_grain_checks(&settle, 2, CoarseGrainRule::RelativeOverlap);
        let names: Vec<_> = notes.iter().map(|c| (c.parameter, c.severity)).collect();
        assert_eq!(
            names,
            [
                ("gravity", CgSeverity::Note),
                ("rolling_friction", CgSeverity::Note)
            ]
        );
        assert!(coarse_grain_checks(
            &case("aor_collapse.toml"),
            8,
            CoarseGrainRule::RelativeOverlap
        )
        .is_empty());
        let packing = case("packing_vdw.toml");
        let inconsistent = |rule| {
            coarse_grain_checks(&packing, 4, rule)
                .into_iter()
                .filter(|c| c.severity == CgSeverity::Inconsistent)
                .map(|c| c.parameter)
                .collect::<Vec<_>>()
        };
        assert_eq!(
            inconsistent(CoarseGrainRule::RelativeOverlap),
            ["hamaker_constant"]
        );
        assert_eq!(
            inconsistent(CoarseGrainRule::ScaledParticle),
            ["hamaker_constant", "gamma_n_yang"]
        );
        assert!(inconsistent(CoarseGrainRule::LiggghtsPfm).is_empty());
        let c = &coarse_grain_checks(&packing, 4, CoarseGrainRule::RelativeOverlap)
            .into_iter()
            .find(|c| c.severity == CgSeverity::Inconsistent)
            .unwrap();
        let text = c.to_string();
        assert!(
            text.starts_with("relative-overlap rule, hamaker_constant:") && text.contains("4x"),
            "{text}"
        );
        // Without gravity the Bond-number law has no weight to follow.
        let mut weightless = packing.clone();
        weightless.gravity = crate::math::Vec3::ZERO;
        assert_eq!(
            inconsistent_of(&weightless, CoarseGrainRule::LiggghtsPfm),
            ["hamaker_constant"]
        );
        assert!(inconsistent_of(&weightless, CoarseGrainRule::RelativeOverlap).is_empty());
    }

    fn inconsistent_of(scene: &Scene, rule: CoarseGrainRule) -> Vec<&'static str> {
        coarse_grain_checks(scene, 4, rule)
            .into_iter()
            .filter(|c| c.severity == CgSeverity::Inconsistent)
            .map(|c| c.parameter)
            .collect()
    }
}
