//! The scene file as written (TOML), before validation. Unknown keys are errors, so a typo
//! is reported with its name instead of being ignored.

use serde::Deserialize;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawScene {
    pub name: String,
    #[serde(default)]
    pub description: String,
    /// A LAMMPS data file (`atom_style sphere`) whose particles the run starts with.
    pub read_data: Option<String>,
    pub domain: RawDomain,
    pub species: Vec<RawSpecies>,
    pub contact: RawContact,
    pub wall_contact: Option<RawWallContact>,
    #[serde(default, rename = "wall_material")]
    pub wall_materials: Vec<RawWallMaterial>,
    #[serde(default, rename = "wall")]
    pub walls: Vec<RawWall>,
    #[serde(default)]
    pub gravity: Option<[f64; 3]>,
    pub time: RawTime,
    #[serde(default)]
    pub neighbor: Option<RawNeighbor>,
    #[serde(default, rename = "insert")]
    pub insertions: Vec<RawInsertion>,
    #[serde(default, rename = "particle")]
    pub particles: Vec<RawParticle>,
    #[serde(rename = "stage")]
    pub stages: Vec<RawStage>,
    #[serde(default)]
    pub output: Option<RawOutput>,
    #[serde(default)]
    pub repose: Option<RawRepose>,
    #[serde(default, rename = "body")]
    pub bodies: Vec<RawBody>,
    #[serde(default, rename = "delete")]
    pub deletions: Vec<RawDelete>,
    #[serde(default)]
    pub conveying: Option<RawConveying>,
    #[serde(default)]
    pub packing: Option<RawPacking>,
    #[serde(default)]
    pub discharge: Option<RawDischarge>,
    /// The built-in silo's dimensions, for `mesh = "silo:wall"` / `"silo:fill"`.
    #[serde(default)]
    pub silo: Option<RawSilo>,
}

/// `[silo]`: every field defaults to the benchmark silo's (`SiloSpec::default`).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawSilo {
    pub silo_diameter: Option<f64>,
    pub orifice_diameter: Option<f64>,
    pub hopper_half_angle: Option<f64>,
    pub cylinder_height: Option<f64>,
    pub orifice_z: Option<f64>,
    pub wall_thickness: Option<f64>,
    pub segments: Option<u32>,
    pub max_edge: Option<f64>,
    pub fill_height: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawPacking {
    pub stage: String,
    pub floor_margin: Option<f64>,
    pub top_quantile: Option<f64>,
    pub top_margin: Option<f64>,
    pub voxels_per_diameter: Option<u32>,
    pub bin_width_diameters: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawBody {
    pub name: String,
    pub mesh: String,
    pub cell_size: Option<f64>,
    pub padding: Option<f64>,
    pub particles: Option<RawBodyParticles>,
    #[serde(default)]
    pub rpm: f64,
    pub axis: Option<[f64; 3]>,
    pub point: Option<[f64; 3]>,
    pub velocity: Option<[f64; 3]>,
    pub start_stage: Option<String>,
    /// A `[[wall_material]]` name; default: `[wall_contact]`'s material.
    pub material: Option<String>,
    /// `"grid"` (default) or `"mesh"`.
    pub contact: Option<String>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawDelete {
    pub lo: [f64; 3],
    pub hi: [f64; 3],
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawConveying {
    pub stage: String,
    pub body: String,
    pub discard: f64,
    pub blocks: Option<u32>,
    pub outer_diameter: f64,
    pub shaft_diameter: f64,
    pub pitch: f64,
    pub bore_radius: f64,
    pub fill_x: [f64; 2],
    pub flow_x: Option<f64>,
    pub bulk_lo: [f64; 3],
    pub bulk_hi: [f64; 3],
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawDomain {
    pub lo: [f64; 3],
    pub hi: [f64; 3],
    #[serde(default)]
    pub periodic: [bool; 3],
    /// "error" (default) or "warn": what a particle leaving through a bounded face does.
    pub lost: Option<String>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawSpecies {
    pub name: String,
    pub diameter: f64,
    pub density: f64,
    #[serde(default)]
    pub frozen: bool,
    /// Hertz: the species' own material; default: `[contact]`'s.
    pub youngs_modulus: Option<f64>,
    pub poisson_ratio: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawContact {
    pub model: String,
    pub epsilon: Option<f64>,
    pub sigma: Option<f64>,
    pub gamma_n: Option<f64>,
    pub gamma_t: Option<f64>,
    // model = "hertz" (LIGGGHTS/LAMMPS words)
    pub youngs_modulus: Option<f64>,
    pub poisson_ratio: Option<f64>,
    pub restitution: Option<f64>,
    pub friction: Option<f64>,
    pub rolling_friction: Option<f64>,
    pub damping: Option<String>,
    pub gamma_n_yang: Option<f64>,
    pub tangential: Option<String>,
    pub rolling: Option<String>,
    pub cohesion: Option<String>,
    pub hamaker_constant: Option<f64>,
    pub h_min: Option<f64>,
    pub cohesion_cutoff: Option<f64>,
    pub characteristic_velocity: Option<f64>,
    pub limit_force: Option<bool>,
    pub tangential_damping: Option<bool>,
    /// A named combination of the options above (`preset = "chung-ooi"`).
    pub preset: Option<String>,
    /// `[[contact.pair]]`: coefficients of one species pair.
    #[serde(default, rename = "pair")]
    pub pairs: Vec<RawContactPair>,
}

/// `[[contact.pair]] species = ["a", "b"]`: what differs from `[contact]` for one pair.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawContactPair {
    pub species: Vec<String>,
    pub restitution: Option<f64>,
    pub friction: Option<f64>,
    pub rolling_friction: Option<f64>,
    pub hamaker_constant: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawWallContact {
    pub restitution: f64,
    pub friction: f64,
    /// Hertz walls only; default: the particles' material.
    pub youngs_modulus: Option<f64>,
    pub poisson_ratio: Option<f64>,
    pub rolling_friction: Option<f64>,
    /// `[[wall_contact.pair]]`: coefficients of one species against one wall material.
    #[serde(default, rename = "pair")]
    pub pairs: Vec<RawWallPair>,
}

/// `[[wall_contact.pair]] species = "a", material = "steel"`: what differs from
/// `[wall_contact]` for one species against one wall material (default: `[wall_contact]`'s).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawWallPair {
    pub species: String,
    pub material: Option<String>,
    pub restitution: Option<f64>,
    pub friction: Option<f64>,
    pub rolling_friction: Option<f64>,
}

/// `[[wall_material]]`: a material walls and bodies name.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawWallMaterial {
    pub name: String,
    pub youngs_modulus: f64,
    pub poisson_ratio: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawWall {
    pub name: String,
    pub point: [f64; 3],
    pub normal: [f64; 3],
    /// A `[[wall_material]]` name; default: `[wall_contact]`'s material.
    pub material: Option<String>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawTime {
    pub dt_fraction: Option<f64>,
    pub dt: Option<f64>,
    pub integrator: Option<String>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawNeighbor {
    pub skin_fraction: Option<f64>,
    pub resort_every: Option<u32>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawInsertion {
    pub species: String,
    pub lo: [f64; 3],
    pub hi: [f64; 3],
    pub count: Option<u64>,
    pub solid_volume: Option<f64>,
    #[serde(default)]
    pub seed: u64,
    pub mesh: Option<String>,
    pub velocity: Option<[f64; 3]>,
    pub omega: Option<[f64; 3]>,
    pub overlap: Option<f64>,
    pub lattice: Option<String>,
    pub spacing: Option<f64>,
    pub origin: Option<[f64; 3]>,
    pub radius: Option<f64>,
    pub refill: Option<RawRefill>,
}

/// `[[particle]]`: one particle the run starts with.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawParticle {
    pub species: String,
    pub position: [f64; 3],
    /// Checked against the species' diameter (a species has one size).
    pub diameter: Option<f64>,
    pub velocity: Option<[f64; 3]>,
    pub omega: Option<[f64; 3]>,
}

/// `[[body]] particles = { species = "...", lattice = "fcc" }`: a body built of particles.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawBodyParticles {
    pub species: String,
    pub lattice: Option<String>,
}

/// `[[insert]] refill = { interval = 0.1, stage = "..." }`: top the region up.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawRefill {
    pub interval: f64,
    pub stage: String,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawStage {
    pub name: String,
    #[serde(default)]
    pub remove_walls: Vec<String>,
    pub duration: Option<f64>,
    pub until_kinetic_energy_per_mass_below: Option<f64>,
    pub max_duration: Option<f64>,
    pub min_duration: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawOutput {
    pub vtk_interval: Option<f64>,
    pub vtk_contact_network: Option<bool>,
    pub write_data: Option<bool>,
    #[serde(default)]
    pub data_at_stage_ends: Vec<String>,
    pub timeseries_interval: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawRepose {
    pub stage: String,
    pub wall_x: f64,
    #[serde(default)]
    pub at_times: Vec<f64>,
    #[serde(default)]
    pub at_stage_end: bool,
    pub bin_width_diameters: Option<f64>,
    pub exclude_wall_fraction: Option<f64>,
    pub exclude_toe_fraction: Option<f64>,
}

/// `[discharge]`: a hopper or silo emptied through an orifice into `[[delete]]` boxes.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawDischarge {
    pub stage: String,
    pub orifice_diameter: f64,
    pub discard: f64,
    pub blocks: Option<u32>,
    pub bulk_lo: [f64; 3],
    pub bulk_hi: [f64; 3],
}
