//! Parameters that are valid but far outside any physical range: a scene with a friction of
//! 1e308 or a box a light-year tall runs, and a user's own case meets such typos first, so
//! each is named with a warning (the run goes on: a thought experiment may want one).

use super::{ContactSettings, Scene};
use crate::math::Real;

/// One plausible range: the field, its value, and the range that covers real powders.
struct Range {
    field: String,
    value: Real,
    lo: Real,
    hi: Real,
    what: &'static str,
}

impl Scene {
    /// Warnings, one per field far outside the range of real granular materials and
    /// equipment, each naming the field, its value and that range.
    pub fn implausible_parameters(&self) -> Vec<String> {
        let mut ranges = Vec::new();
        let mut check = |field: String, value: Real, lo: Real, hi: Real, what| {
            ranges.push(Range {
                field,
                value,
                lo,
                hi,
                what,
            })
        };
        let size = self.domain.hi - self.domain.lo;
        for (axis, extent) in [size.x, size.y, size.z].into_iter().enumerate() {
            let field = format!("domain.hi[{axis}] - domain.lo[{axis}]");
            check(
                field,
                extent,
                1e-6,
                1e3,
                "m, from a micro-channel to a silo",
            );
        }
        for (k, s) in self.species.iter().enumerate() {
            let field = |f| format!("species[{k}].{f}");
            check(
                field("diameter"),
                s.diameter,
                1e-8,
                1.0,
                "m, nanopowders to boulders",
            );
            check(
                field("density"),
                s.density,
                1.0,
                3e4,
                "kg/m^3, aerogel to osmium",
            );
            if let Some(e) = s.youngs_modulus {
                check(field("youngs_modulus"), e, 1e3, 1e13, "Pa");
            }
        }
        check(
            "gravity (magnitude)".into(),
            self.gravity.length(),
            0.0,
            1e4,
            "m/s^2 (a centrifuge at most)",
        );
        let friction = "a friction coefficient (measured powders: 0 to about 1.5)";
        let rolling = "a rolling-friction coefficient (measured: 0 to about 0.5)";
        if let ContactSettings::Hertz(h) = &self.contact {
            check("contact.friction".into(), h.friction, 0.0, 10.0, friction);
            check(
                "contact.rolling_friction".into(),
                h.rolling_friction,
                0.0,
                10.0,
                rolling,
            );
            check(
                "contact.youngs_modulus".into(),
                h.youngs_modulus,
                1e3,
                1e13,
                "Pa",
            );
            for (k, p) in h.pairs.iter().enumerate() {
                if let Some(mu) = p.friction {
                    check(
                        format!("contact.pair[{k}].friction"),
                        mu,
                        0.0,
                        10.0,
                        friction,
                    );
                }
                if let Some(mu) = p.rolling_friction {
                    let field = format!("contact.pair[{k}].rolling_friction");
                    check(field, mu, 0.0, 10.0, rolling);
                }
            }
        }
        let w = &self.wall_contact;
        check(
            "wall_contact.friction".into(),
            w.friction,
            0.0,
            10.0,
            friction,
        );
        check(
            "wall_contact.rolling_friction".into(),
            w.rolling_friction,
            0.0,
            10.0,
            rolling,
        );
        if let Some(e) = w.youngs_modulus {
            check("wall_contact.youngs_modulus".into(), e, 1e3, 1e13, "Pa");
        }
        ranges
            .into_iter()
            .filter(|r| !(r.value >= r.lo && r.value <= r.hi))
            .map(|r| {
                format!(
                    "{}: {} = {:e} is far outside {:e} ..= {:e} ({}); measurements of this run may mean nothing",
                    self.source.display(),
                    r.field,
                    r.value,
                    r.lo,
                    r.hi,
                    r.what
                )
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_huge_friction_and_a_huge_box_are_named_and_the_shipped_case_is_not() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../validation/cases/aor_hertz.toml");
        let scene = Scene::load(&path).unwrap();
        assert!(
            scene.implausible_parameters().is_empty(),
            "{:?}",
            scene.implausible_parameters()
        );
        let mut odd = scene.clone();
        odd.wall_contact.friction = 1e308;
        odd.domain.hi.z = 1e300;
        let warnings = odd.implausible_parameters();
        assert_eq!(warnings.len(), 2, "{warnings:?}");
        assert!(warnings[0].contains("domain.hi[2]"), "{warnings:?}");
        assert!(
            warnings[1].contains("wall_contact.friction = 1e308"),
            "{warnings:?}"
        );
    }
}
