//! The contact properties of every pair of a Hertz scene, resolved once from its defaults
//! (`[contact]`, `[wall_contact]`) and its tables (a species' own material, `[[contact.pair]]`,
//! `[[wall_material]]`, `[[wall_contact.pair]]`), as LIGGGHTS's `fix property/global ...
//! peratomtype` and `peratomtypepair` give them per atom type (walls having their own types).
//! The laws (`run::laws`) and the reference decks are made from these tables.
//!
//! Effective values of a pair of materials 1 and 2 (LIGGGHTS `createYeff`, `createGeff`):
//! `1/Y* = (1 - nu_1^2)/E_1 + (1 - nu_2^2)/E_2`,
//! `1/G* = 2 (2 - nu_1)(1 + nu_1)/E_1 + 2 (2 - nu_2)(1 + nu_2)/E_2`
//! (`contact::normal::Material`); restitution, friction, rolling friction and the Hamaker
//! constant are the pair's own, not mixed.

use super::{CohesionKind, ContactSettings, HertzSettings, Scene};
use crate::contact::normal::Material;
use crate::math::Real;

/// The coefficients of one pair, a species pair or a species against a wall material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairProperties {
    pub restitution: Real,
    pub friction: Real,
    pub rolling_friction: Real,
    /// Van der Waals, J; 0 without cohesion and against walls.
    pub hamaker_constant: Real,
}

/// Materials and pair coefficients of a Hertz scene, every pair resolved.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactTables {
    /// Per species.
    pub species: Vec<Material>,
    /// Per wall material: 0 is `[wall_contact]`'s, k is `[[wall_material]]` k - 1.
    pub wall_materials: Vec<Material>,
    /// Per species pair `a * n_species + b` (the same both ways round).
    pub pairs: Vec<PairProperties>,
    /// Per species and wall material, `a * n_wall_materials + k`.
    pub wall_pairs: Vec<PairProperties>,
}

impl ContactTables {
    /// The tables of a Hertz scene; None for the seed's WCA model (one law for all pairs).
    pub fn of(scene: &Scene) -> Option<ContactTables> {
        match &scene.contact {
            ContactSettings::Hertz(h) => Some(ContactTables::of_hertz(scene, h)),
            ContactSettings::Wca(_) => None,
        }
    }

    /// The tables of `scene` with its Hertz settings `h`.
    pub fn of_hertz(scene: &Scene, h: &HertzSettings) -> ContactTables {
        let n = scene.species.len();
        let species = scene
            .species
            .iter()
            .map(|s| Material {
                youngs_modulus: s.youngs_modulus.unwrap_or(h.youngs_modulus),
                poisson_ratio: s.poisson_ratio.unwrap_or(h.poisson_ratio),
            })
            .collect();
        let w = &scene.wall_contact;
        let mut wall_materials = vec![Material {
            youngs_modulus: w.youngs_modulus.unwrap_or(h.youngs_modulus),
            poisson_ratio: w.poisson_ratio.unwrap_or(h.poisson_ratio),
        }];
        wall_materials.extend(w.materials.iter().map(|m| Material {
            youngs_modulus: m.youngs_modulus,
            poisson_ratio: m.poisson_ratio,
        }));
        let hamaker_constant = match h.cohesion {
            CohesionKind::VanDerWaals {
                hamaker_constant, ..
            } => hamaker_constant,
            CohesionKind::None => 0.0,
        };
        let mut pairs = vec![
            PairProperties {
                restitution: h.restitution,
                friction: h.friction,
                rolling_friction: h.rolling_friction,
                hamaker_constant,
            };
            n * n
        ];
        for p in &h.pairs {
            let [a, b] = p.species;
            for ab in [a * n + b, b * n + a] {
                let q = &mut pairs[ab];
                q.restitution = p.restitution.unwrap_or(q.restitution);
                q.friction = p.friction.unwrap_or(q.friction);
                q.rolling_friction = p.rolling_friction.unwrap_or(q.rolling_friction);
                q.hamaker_constant = p.hamaker_constant.unwrap_or(q.hamaker_constant);
            }
        }
        let n_wall = wall_materials.len();
        let mut wall_pairs = vec![
            PairProperties {
                restitution: w.restitution,
                friction: w.friction,
                rolling_friction: w.rolling_friction,
                hamaker_constant: 0.0,
            };
            n * n_wall
        ];
        for p in &w.pairs {
            let q = &mut wall_pairs[p.species * n_wall + p.material];
            q.restitution = p.restitution.unwrap_or(q.restitution);
            q.friction = p.friction.unwrap_or(q.friction);
            q.rolling_friction = p.rolling_friction.unwrap_or(q.rolling_friction);
        }
        ContactTables {
            species,
            wall_materials,
            pairs,
            wall_pairs,
        }
    }

    pub fn n_species(&self) -> usize {
        self.species.len()
    }

    pub fn n_wall_materials(&self) -> usize {
        self.wall_materials.len()
    }

    /// Whether the scene has one particle material and one set of pair coefficients, and
    /// one wall material with one set of coefficients against every species: what the
    /// scene-wide `[contact]` and `[wall_contact]` alone describe.
    pub fn is_uniform(&self) -> bool {
        let same = |v: &[PairProperties]| v.iter().all(|p| *p == v[0]);
        self.species.iter().all(|m| *m == self.species[0])
            && self.wall_materials.len() == 1
            && same(&self.pairs)
            && same(&self.wall_pairs)
    }

    /// Species pair `(a, b)`.
    pub fn pair(&self, a: usize, b: usize) -> &PairProperties {
        &self.pairs[a * self.n_species() + b]
    }

    /// Species `a` against wall material `k`.
    pub fn wall_pair(&self, a: usize, k: usize) -> &PairProperties {
        &self.wall_pairs[a * self.n_wall_materials() + k]
    }

    /// `Y*` of species `a` and `b`.
    pub fn y_eff(&self, a: usize, b: usize) -> Real {
        Material::y_eff(self.species[a], self.species[b])
    }

    /// `G*` of species `a` and `b`.
    pub fn g_eff(&self, a: usize, b: usize) -> Real {
        Material::g_eff(self.species[a], self.species[b])
    }

    /// `Y*` of species `a` against wall material `k`.
    pub fn wall_y_eff(&self, a: usize, k: usize) -> Real {
        Material::y_eff(self.species[a], self.wall_materials[k])
    }

    /// `G*` of species `a` against wall material `k`.
    pub fn wall_g_eff(&self, a: usize, k: usize) -> Real {
        Material::g_eff(self.species[a], self.wall_materials[k])
    }

    /// `f(a, b)` for every species pair, in the laws' order `a * n + b`.
    pub fn pair_table(&self, f: impl Fn(usize, usize) -> Real) -> Vec<Real> {
        let n = self.n_species();
        (0..n * n).map(|ab| f(ab / n, ab % n)).collect()
    }

    /// `f(a, k)` for every species and wall material, in the order `a * n_wall + k`.
    pub fn wall_table(&self, f: impl Fn(usize, usize) -> Real) -> Vec<Real> {
        let n_wall = self.n_wall_materials();
        (0..self.n_species() * n_wall)
            .map(|ak| f(ak / n_wall, ak % n_wall))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    const TWO: &str = r#"name = "two"
[domain]
lo = [0.0, 0.0, 0.0]
hi = [0.01, 0.01, 0.01]
[[species]]
name = "soft"
diameter = 1e-3
density = 1000.0
[[species]]
name = "hard"
diameter = 1e-3
density = 2500.0
youngs_modulus = 7e7
poisson_ratio = 0.2
[contact]
model = "hertz"
youngs_modulus = 5e6
poisson_ratio = 0.3
restitution = 0.5
friction = 0.5
[[contact.pair]]
species = ["hard", "soft"]
restitution = 0.3
[wall_contact]
restitution = 0.6
friction = 0.4
[[wall_material]]
name = "steel"
youngs_modulus = 2e11
poisson_ratio = 0.29
[[wall_contact.pair]]
species = "soft"
material = "steel"
friction = 0.2
[[wall]]
name = "floor"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
material = "steel"
[time]
dt = 1e-7
[[stage]]
name = "s"
duration = 1e-6
"#;

    #[test]
    fn tables_take_each_pair_from_its_own_table_else_the_default() {
        let scene = Scene::parse(TWO, Path::new("two.toml")).unwrap();
        let t = ContactTables::of(&scene).unwrap();
        assert!(!t.is_uniform());
        let (soft, hard) = (
            Material {
                youngs_modulus: 5e6,
                poisson_ratio: 0.3,
            },
            Material {
                youngs_modulus: 7e7,
                poisson_ratio: 0.2,
            },
        );
        assert_eq!(t.species, vec![soft, hard]);
        assert_eq!(t.pair(0, 1).restitution, 0.3);
        assert_eq!(t.pair(1, 0).restitution, 0.3);
        assert_eq!(t.pair(0, 0).restitution, 0.5);
        assert_eq!(t.pair(1, 1).friction, 0.5);
        // 1/Y* = (1 - 0.09)/5e6 + (1 - 0.04)/7e7, 1/G* = 2 (1.7)(1.3)/5e6 + 2 (1.8)(1.2)/7e7.
        let y = 1.0 / (0.91 / 5e6 + 0.96 / 7e7);
        let g = 1.0 / (2.0 * 1.7 * 1.3 / 5e6 + 2.0 * 1.8 * 1.2 / 7e7);
        assert!((t.y_eff(0, 1) / y - 1.0).abs() < 1e-15);
        assert!((t.g_eff(1, 0) / g - 1.0).abs() < 1e-15);
        assert_eq!(t.y_eff(0, 1), t.y_eff(1, 0));
        // The default wall material is the particles' default; `steel` is material 1.
        assert_eq!(t.wall_materials[0], soft);
        assert_eq!(t.wall_materials.len(), 2);
        assert_eq!(t.wall_pair(0, 1).friction, 0.2);
        assert_eq!(t.wall_pair(0, 1).restitution, 0.6);
        assert_eq!(t.wall_pair(1, 1).friction, 0.4);
        assert_eq!(scene.walls[0].material, 1);
    }
}
