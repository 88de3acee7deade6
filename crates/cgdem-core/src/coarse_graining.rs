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
    #[error("the {0:?} coarse-graining rule is defined for the seed's WCA model only; use the seed rule for Hertz scenes")]
    RuleNotDefined(CoarseGrainRule),
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

/// Hertz parameters under `phi'(r) = lambda^3 phi(r / lambda)`, i.e. every contact force
/// `F'(x') = lambda^2 F(x' / lambda)` at the same velocities (reference/COARSE_GRAINING_HERTZ.md):
/// Young's modulus, Poisson's ratio, restitution, friction and rolling friction unchanged;
/// Yang's `gamma_n` (s) times lambda; Hamaker constant times lambda^3, `h_min` and the
/// cohesion cut-off times lambda.
pub fn coarse_grain_hertz(h: &HertzSettings, l: f64) -> HertzSettings {
    let mut out = h.clone();
    if let HertzDampingKind::Yang { gamma_n } = h.damping {
        out.damping = HertzDampingKind::Yang {
            gamma_n: gamma_n * l,
        };
    }
    if let CohesionKind::VanDerWaals {
        hamaker_constant,
        h_min,
        cutoff,
    } = h.cohesion
    {
        out.cohesion = CohesionKind::VanDerWaals {
            hamaker_constant: hamaker_constant * l.powi(3),
            h_min: h_min * l,
            cutoff: cutoff.map(|c| c * l),
        };
    }
    out
}

/// Where coarse-graining the scene by `lambda` is not consistent, with the reason (like
/// LIGGGHTS-PFM's model check). Empty for lambda = 1 and for the seed's WCA scenes, whose
/// rule is paper A's.
pub fn coarse_grain_warnings(scene: &Scene, lambda: u32) -> Vec<String> {
    let mut warnings = Vec::new();
    let ContactSettings::Hertz(h) = &scene.contact else {
        return warnings;
    };
    if lambda <= 1 {
        return warnings;
    }
    let l = lambda as f64;
    if scene.gravity.length() > 0.0 {
        warnings.push(format!("gravity: weights scale as lambda^3 but contact forces as lambda^2, so weight/contact-force ratios (overlap under load, Bond number) grow {l}x at lambda = {lambda}"));
    }
    if let CohesionKind::VanDerWaals { .. } = h.cohesion {
        if scene.gravity.length() > 0.0 {
            warnings.push(format!("cohesion: the granular Bond number F_vdw(h_min) / (m g) falls {l}x at lambda = {lambda}; cohesion-controlled structure (porosity of fine powders) is not preserved"));
        }
    }
    if h.rolling != RollingKind::None {
        warnings.push(format!("rolling: the torque mu_r R_eff |F_n| scales like r x F (lambda^3) and is formally consistent, but one parcel stands for lambda^3 = {} real particles whose rolling contacts (and the shape effects mu_r stands for) are not resolved; mu_r calibrated on real particles is unverified for parcels at lambda = {lambda} (LIGGGHTS flags rolling models under coarse-graining)", l.powi(3)));
    }
    warnings
}

/// Returns the scene coarse-grained by `lambda` relative to its current level, by the
/// seed's rule.
pub fn coarse_grain(scene: &Scene, lambda: u32) -> Result<Scene, CoarseGrainError> {
    coarse_grain_by(scene, lambda, CoarseGrainRule::Seed)
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
    let (energy, damping, time) = rule.exponents();
    let mut out = scene.clone();
    out.lambda = scene.lambda * lambda;
    out.cg_rule = rule;
    for s in &mut out.species {
        s.diameter *= l;
    }
    out.contact = match &scene.contact {
        ContactSettings::Wca(w) => ContactSettings::Wca(WcaSettings {
            epsilon: w.epsilon * l.powi(energy),
            sigma: w.sigma * l,
            gamma_n: w.gamma_n * l.powi(damping),
            gamma_t: w.gamma_t * l.powi(damping),
        }),
        ContactSettings::Hertz(_) if rule != CoarseGrainRule::Seed => {
            return Err(CoarseGrainError::RuleNotDefined(rule));
        }
        ContactSettings::Hertz(h) => ContactSettings::Hertz(coarse_grain_hertz(h, l)),
    };
    if let TimeStepRequest::Explicit(dt) = scene.time_step {
        out.time_step = TimeStepRequest::Explicit(dt * l.powi(time));
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

    #[test]
    fn hertz_scenes_warn_where_coarse_graining_is_inconsistent_and_the_seed_does_not() {
        let case = |name: &str| {
            Scene::load(
                &std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
                    .join("validation/cases")
                    .join(name),
            )
            .unwrap()
        };
        let hertz = case("hertz_settle.toml");
        assert!(coarse_grain_warnings(&hertz, 1).is_empty());
        let warnings = coarse_grain_warnings(&hertz, 2);
        assert_eq!(warnings.len(), 2, "{warnings:?}");
        assert!(warnings[0].starts_with("gravity") && warnings[1].starts_with("rolling"));
        assert!(coarse_grain_warnings(&case("aor_collapse.toml"), 8).is_empty());
    }
}
