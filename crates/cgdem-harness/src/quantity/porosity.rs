//! A packing's porosity and mean pore size (a scene with `[packing]`): the core's analysis
//! measures them into each run's `summary.json` (`packing.porosity`,
//! `packing.mean_pore_diameter_m`), the same for every code; here they are read, the pore
//! size in the run's particle (parcel) diameters, since the pores of a similar packing
//! scale with its particles.

use cgdem_core::scene::Scene;

/// The run's porosity, when it measured one.
pub fn porosity(summary: &serde_json::Value) -> Option<f64> {
    summary["packing"]["porosity"]
        .as_f64()
        .filter(|v| v.is_finite())
}

/// The run's mean pore diameter over the diameter of its particles (`scene` coarse-grained
/// by `lambda`), when it measured one.
pub fn pore_diameter_in_diameters(
    summary: &serde_json::Value,
    scene: &Scene,
    lambda: u32,
) -> Option<f64> {
    summary["packing"]["mean_pore_diameter_m"]
        .as_f64()
        .map(|pore| pore / (scene.max_diameter() * lambda as f64))
        .filter(|v| v.is_finite() && *v > 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_pore_size_is_in_the_diameters_of_the_runs_parcels() {
        crate::at_repo_root();
        let scene = Scene::load(std::path::Path::new("tests/data/tiny_drop.toml")).unwrap();
        let d = scene.max_diameter();
        let summary =
            serde_json::json!({ "packing": { "porosity": 0.4, "mean_pore_diameter_m": 0.6 * d } });
        assert_eq!(porosity(&summary), Some(0.4));
        let at_2 = pore_diameter_in_diameters(&summary, &scene, 2).unwrap();
        assert!((at_2 - 0.3).abs() < 1e-12, "{at_2}");
        let none = serde_json::json!({ "packing": null });
        assert_eq!(porosity(&none), None);
        assert_eq!(pore_diameter_in_diameters(&none, &scene, 1), None);
    }
}
