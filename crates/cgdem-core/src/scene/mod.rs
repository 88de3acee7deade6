//! Scene files: TOML read into raw structs, then validated once into typed settings.

mod cg_rule;
mod error;
mod materials;
mod overrides;
mod plausibility;
mod raw;
mod validate;

pub use cg_rule::CoarseGrainRule;
pub use error::SceneError;
pub use materials::{ContactTables, PairProperties};
pub use overrides::{apply_overrides, Override};
pub use validate::given_particles_from_data;

use std::path::{Path, PathBuf};

use crate::domain::Domain;
use crate::integrate::Integrator;
use crate::math::{Real, Vec3};
use crate::timestep::TimeStepRequest;

#[derive(Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Species {
    pub name: String,
    pub diameter: Real,
    pub density: Real,
    /// Particles of a frozen species never move (LIGGGHTS/LAMMPS `fix freeze`): they are
    /// not integrated, act with infinite mass in their contacts, and pairs of two frozen
    /// particles are never listed.
    pub frozen: bool,
    /// Hertz: the species' own material (LIGGGHTS `youngsModulus peratomtype`), Pa; None:
    /// `[contact]`'s.
    #[serde(default)]
    pub youngs_modulus: Option<Real>,
    /// Hertz: the species' own Poisson's ratio; None: `[contact]`'s.
    #[serde(default)]
    pub poisson_ratio: Option<Real>,
}

/// The fields as before materials per species, the material only when the species has its
/// own: the scene digest (`Scene::digest`) of a one-material scene stays what it was.
impl std::fmt::Debug for Species {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut s = f.debug_struct("Species");
        s.field("name", &self.name)
            .field("diameter", &self.diameter)
            .field("density", &self.density)
            .field("frozen", &self.frozen);
        optional_field(&mut s, "youngs_modulus", &self.youngs_modulus);
        optional_field(&mut s, "poisson_ratio", &self.poisson_ratio);
        s.finish()
    }
}

/// Adds `value` to a debug text unless it is the default (absent, empty, zero): fields added
/// for materials leave the debug text, hence the digest, of scenes without them unchanged.
fn optional_field<T: std::fmt::Debug + Default + PartialEq>(
    s: &mut std::fmt::DebugStruct<'_, '_>,
    name: &str,
    value: &T,
) {
    if *value != T::default() {
        s.field(name, value);
    }
}

impl Species {
    pub fn radius(&self) -> Real {
        0.5 * self.diameter
    }

    pub fn mass(&self) -> Real {
        self.density * std::f64::consts::PI / 6.0 * self.diameter.powi(3)
    }
}

/// The seed's WCA model's parameters (`model = "wca"`): the energy `epsilon` and length
/// `sigma` of the repulsion, the normal and tangential damping `gamma_n`, `gamma_t`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct WcaSettings {
    pub epsilon: Real,
    pub sigma: Real,
    pub gamma_n: Real,
    pub gamma_t: Real,
}

/// The particle-particle contact law and its parameters (one set for all species pairs).
#[derive(Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum ContactSettings {
    /// The seed's model, paper A Eq. (1)-(2): WCA repulsion plus normal and tangential
    /// viscous damping.
    Wca(WcaSettings),
    /// Hertz contact with LIGGGHTS/LAMMPS-style sub-models (paper B).
    Hertz(HertzSettings),
}

/// Written as when `Wca` was a struct variant: the scene digest (`Scene::digest`, by which
/// `--reuse` recognises a finished run) hashes this text.
impl std::fmt::Debug for ContactSettings {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ContactSettings::Wca(w) => f
                .debug_struct("Wca")
                .field("epsilon", &w.epsilon)
                .field("sigma", &w.sigma)
                .field("gamma_n", &w.gamma_n)
                .field("gamma_t", &w.gamma_t)
                .finish(),
            ContactSettings::Hertz(h) => f.debug_tuple("Hertz").field(h).finish(),
        }
    }
}

/// `damping = "hertz" | "yang"`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum HertzDampingKind {
    /// LIGGGHTS `model hertz`: restitution-based, `2 sqrt(5/6) |beta(e)| sqrt(S_n m_eff)`.
    Restitution,
    /// Paper B Eq. (4): `gamma_n E sqrt(R xi_n)`, `gamma_n` in s (`gamma_n_yang`).
    Yang { gamma_n: Real },
}

/// `tangential = "history" | "coulomb" | "yang"`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum TangentialKind {
    /// LIGGGHTS `tangential history`, to the last bit: the spring alone is capped at
    /// `mu |F_n|`, the dashpot is added uncapped below the cap (reference/MAPPING.md).
    History,
    /// The same spring and dashpot with Coulomb's bound on their sum, `mu max(F_n, 0)`
    /// (`contact::tangential::CoulombMindlin`).
    Coulomb,
    Yang,
}

impl TangentialKind {
    /// The scene file's word for the law.
    pub fn name(self) -> &'static str {
        match self {
            TangentialKind::History => "history",
            TangentialKind::Coulomb => "coulomb",
            TangentialKind::Yang => "yang",
        }
    }
}

/// `rolling = "none" | "constant_torque" | "epsd2"`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum RollingKind {
    None,
    ConstantTorque,
    Epsd2,
}

/// `cohesion = "none" | "vdw"`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum CohesionKind {
    None,
    /// Paper B Eq. (7)-(8); `cutoff` is the gap beyond touching where it stops (default:
    /// where the force falls to 1e-3 of its value at `h_min`).
    VanDerWaals {
        hamaker_constant: Real,
        h_min: Real,
        cutoff: Option<Real>,
    },
}

/// `[contact] model = "hertz"`. The material and pair coefficients here are the defaults:
/// a species may have its own material (`Species::youngs_modulus`), a species pair its own
/// coefficients (`pairs`); [`ContactTables`] resolves them.
#[derive(Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct HertzSettings {
    pub youngs_modulus: Real,
    pub poisson_ratio: Real,
    pub restitution: Real,
    pub friction: Real,
    /// The default of the species pairs; 0 also when `[contact]` gives none.
    pub rolling_friction: Real,
    pub damping: HertzDampingKind,
    pub tangential: TangentialKind,
    pub rolling: RollingKind,
    pub cohesion: CohesionKind,
    /// Impact speed (m/s) at which Hertz contacts are linearized for the time step.
    pub characteristic_velocity: Real,
    /// `limit_force = true` (LIGGGHTS `limitForce on`): the normal force of particles and
    /// walls is clamped at zero, so the dashpot never pulls at the end of a contact.
    #[serde(default, skip_serializing_if = "is_false")]
    pub limit_force: bool,
    /// `tangential_damping = false` (LIGGGHTS `tangential_damping off`): the Mindlin spring
    /// without its dashpot, for particles and walls.
    #[serde(default = "yes", skip_serializing_if = "is_true")]
    pub tangential_damping: bool,
    /// `[[contact.pair]]`: species pairs whose coefficients are not the defaults above (each
    /// unordered pair at most once).
    #[serde(default)]
    pub pairs: Vec<SpeciesPair>,
}

/// The derived text of the fields as before, `pairs` only when given (see `Species`).
impl std::fmt::Debug for HertzSettings {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut s = f.debug_struct("HertzSettings");
        s.field("youngs_modulus", &self.youngs_modulus)
            .field("poisson_ratio", &self.poisson_ratio)
            .field("restitution", &self.restitution)
            .field("friction", &self.friction)
            .field("rolling_friction", &self.rolling_friction)
            .field("damping", &self.damping)
            .field("tangential", &self.tangential)
            .field("rolling", &self.rolling)
            .field("cohesion", &self.cohesion)
            .field("characteristic_velocity", &self.characteristic_velocity);
        optional_field(&mut s, "limit_force", &self.limit_force);
        if !self.tangential_damping {
            s.field("tangential_damping", &false);
        }
        optional_field(&mut s, "pairs", &self.pairs);
        s.finish()
    }
}

fn is_false(b: &bool) -> bool {
    !*b
}

fn is_true(b: &bool) -> bool {
    *b
}

fn yes() -> bool {
    true
}

/// `[[contact.pair]] species = ["a", "b"]`: the coefficients of one species pair (LIGGGHTS
/// `peratomtypepair` entries); None: the `[contact]` default.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SpeciesPair {
    /// Indices into `Scene::species`, in the order given.
    pub species: [usize; 2],
    pub restitution: Option<Real>,
    pub friction: Option<Real>,
    pub rolling_friction: Option<Real>,
    /// Van der Waals Hamaker constant, J (`cohesion = "vdw"` only).
    pub hamaker_constant: Option<Real>,
}

/// `[wall_contact]`: the particle-wall contact of walls and bodies. Its material and
/// coefficients are the defaults; `materials` are further wall materials that walls and
/// bodies name (LIGGGHTS gives each its own atom type), `pairs` the coefficients of a species
/// against a wall material that differ from the defaults.
#[derive(Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct WallContactSettings {
    pub restitution: Real,
    pub friction: Real,
    /// Hertz walls: the default wall material (None = `[contact]`'s) and rolling friction.
    pub youngs_modulus: Option<Real>,
    pub poisson_ratio: Option<Real>,
    pub rolling_friction: Real,
    /// `[[wall_material]]`: material `k + 1` (material 0 is the default above).
    #[serde(default)]
    pub materials: Vec<WallMaterial>,
    /// `[[wall_contact.pair]]`, each (species, material) at most once.
    #[serde(default)]
    pub pairs: Vec<WallPair>,
}

/// The derived text of the fields as before, the material tables only when given.
impl std::fmt::Debug for WallContactSettings {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut s = f.debug_struct("WallContactSettings");
        s.field("restitution", &self.restitution)
            .field("friction", &self.friction)
            .field("youngs_modulus", &self.youngs_modulus)
            .field("poisson_ratio", &self.poisson_ratio)
            .field("rolling_friction", &self.rolling_friction);
        optional_field(&mut s, "materials", &self.materials);
        optional_field(&mut s, "pairs", &self.pairs);
        s.finish()
    }
}

/// `[[wall_material]]`: a material that walls and bodies name (`material = "steel"`).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct WallMaterial {
    pub name: String,
    pub youngs_modulus: Real,
    pub poisson_ratio: Real,
}

/// `[[wall_contact.pair]] species = "grain", material = "steel"`: the coefficients of one
/// species against one wall material; None: the `[wall_contact]` default.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct WallPair {
    pub species: usize,
    /// 0: the default material of `[wall_contact]`; k: `WallContactSettings::materials[k - 1]`.
    pub material: usize,
    pub restitution: Option<Real>,
    pub friction: Option<Real>,
    pub rolling_friction: Option<Real>,
}

#[derive(Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct WallSettings {
    pub name: String,
    pub point: Vec3,
    pub normal: Vec3,
    /// 0: the default material of `[wall_contact]`; k: `WallContactSettings::materials[k - 1]`.
    #[serde(default)]
    pub material: usize,
}

/// The derived text of the fields as before, `material` only when not the default.
impl std::fmt::Debug for WallSettings {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut s = f.debug_struct("WallSettings");
        s.field("name", &self.name)
            .field("point", &self.point)
            .field("normal", &self.normal);
        optional_field(&mut s, "material", &self.material);
        s.finish()
    }
}

#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum InsertAmount {
    Count(u64),
    /// Total solid volume, m^3: the count follows from the particle size, so coarse-graining
    /// keeps the mass.
    SolidVolume(Real),
    /// Every site of a lattice inside the box (and within `radius`, if given).
    Lattice(Lattice),
}

/// `lattice = "cubic" | "hexagonal"`: hexagonal layers (close-packed rows in x, rows
/// `spacing sqrt(3)/2` apart in y, every other row shifted by half a spacing) stacked
/// `spacing` apart in z.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum LatticeKind {
    Cubic,
    Hexagonal,
}

#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Lattice {
    pub kind: LatticeKind,
    /// Distance between nearest sites, m.
    pub spacing: Real,
    /// A site of the lattice; sites are kept where the whole sphere lies inside the box.
    /// Default: the box corner `lo` plus one particle radius.
    pub origin: Option<Vec3>,
    /// Keep only sites within this distance of `origin` in the x-y plane (a disk), m.
    pub radius: Option<Real>,
}

/// A particle the run starts with, from `read_data` or a `[[particle]]` table; its size and
/// density are its species'.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct GivenParticle {
    pub species: usize,
    pub position: Vec3,
    /// m/s.
    pub velocity: Vec3,
    /// rad/s; zero unless the contact law rotates particles.
    pub omega: Vec3,
}

#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Insertion {
    pub species: usize,
    /// The box sampled; with `mesh`, only positions inside the mesh (by at least one radius)
    /// are kept.
    pub lo: Vec3,
    pub hi: Vec3,
    pub mesh: Option<MeshSource>,
    pub amount: InsertAmount,
    pub seed: u64,
    /// Initial velocity of every particle inserted, m/s.
    pub velocity: Vec3,
    /// Initial angular velocity of every particle inserted, rad/s (LIGGGHTS `set ... omega`);
    /// only with a contact law that rotates particles (Hertz).
    pub omega: Vec3,
    /// Overlap allowed between inserted particles, as a fraction of the sum of their radii
    /// (0: none; stability tests use it to start from a compressed packing).
    pub overlap: Real,
    /// Keep the region topped up (e.g. a hopper, so the feed stays flooded).
    pub refill: Option<Refill>,
}

/// Top-up of an insertion region: from the start of `stage`, every `interval` seconds, new
/// particles are inserted at random (no overlap) in the region until it again holds as many
/// particles of the species as it did when the stage began.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Refill {
    /// s of simulated time between top-ups.
    pub interval: Real,
    pub stage: String,
}

/// A body built of particles of a frozen species on an fcc lattice fitted inside its mesh
/// (paper A sec. 4), moving with the body's prescribed motion.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BodyParticles {
    /// Index into `Scene::species` (a frozen species).
    pub species: usize,
}

/// Where a triangle mesh comes from: an STL file (path relative to the scene file) or, with
/// the prefix `screw-feeder:`, one part of the seed's screw feeder generated with the default
/// [`ScrewFeederSpec`](crate::geometry::screw_feeder::ScrewFeederSpec): `screw`, `casing`,
/// `hopper` or `insertion`, or with the prefix `silo:`, the scene's `[silo]`
/// ([`SiloSpec`](crate::geometry::silo::SiloSpec)): its `wall` or its `fill` region.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum MeshSource {
    Stl(PathBuf),
    ScrewFeeder(String),
    Silo(SiloPart, crate::geometry::silo::SiloSpec),
}

/// A part of the built-in silo (`silo:wall`, `silo:fill`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum SiloPart {
    Wall,
    Fill,
}

impl MeshSource {
    pub fn load(&self) -> Result<crate::geometry::TriMesh, String> {
        use crate::geometry::screw_feeder as sf;
        use crate::geometry::stl::StlError;
        match self {
            // The STL errors name the file.
            MeshSource::Stl(path) => crate::geometry::read_stl(path).map_err(|e| match e {
                StlError::OpenEdges { .. } | StlError::BadOrientation { .. } => format!(
                    "{e}\n  an SDF grid needs a closed, consistently oriented surface; \
                     contact = \"mesh\" meets an open one on its triangles"
                ),
                e => e.to_string(),
            }),
            MeshSource::ScrewFeeder(part) => {
                let spec = sf::ScrewFeederSpec::default();
                Ok(match part.as_str() {
                    "screw" => sf::screw_mesh(&spec),
                    "casing" => sf::casing_mesh(&spec),
                    "hopper" => sf::hopper_mesh(&spec),
                    "insertion" => sf::insertion_region_mesh(&spec),
                    other => return Err(format!("no screw-feeder part `{other}`")),
                })
            }
            MeshSource::Silo(SiloPart::Wall, spec) => Ok(crate::geometry::silo::wall_mesh(spec)),
            MeshSource::Silo(SiloPart::Fill, spec) => crate::geometry::silo::fill_mesh(spec)
                .ok_or_else(|| "silo:fill needs [silo] fill_height".to_string()),
        }
    }
}

/// A rigid body from a mesh, turned into an SDF grid, with prescribed motion.
#[derive(Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BodySettings {
    pub name: String,
    pub mesh: MeshSource,
    /// SDF grid spacing, m (unused for a body built of particles).
    pub cell_size: Real,
    /// `Some`: the body is built of particles instead of an SDF grid.
    pub particles: Option<BodyParticles>,
    /// Grid padding around the mesh; `None`: 3 cells plus the largest particle diameter.
    pub padding: Option<Real>,
    pub rpm: Real,
    pub axis: Vec3,
    pub point: Vec3,
    pub velocity: Vec3,
    /// The stage at whose start the motion begins; `None`: from the start of the run.
    pub start_stage: Option<String>,
    /// The surface's material (an SDF body), as `WallSettings::material`.
    #[serde(default)]
    pub material: usize,
    /// How particles meet the mesh: its SDF grid or its triangles.
    #[serde(default)]
    pub contact: BodyContact,
}

/// How particles meet a body's mesh (`[[body]] contact`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum BodyContact {
    /// A signed-distance grid of `cell_size` built from the closed mesh.
    #[default]
    Grid,
    /// The triangles themselves, as LIGGGHTS's mesh walls: exact, open meshes allowed.
    Mesh,
}

impl BodySettings {
    /// The body's mesh: a closed, outward-oriented surface for a grid, any surface (open
    /// or closed, as given) for mesh contact.
    pub fn load_mesh(&self) -> Result<crate::geometry::TriMesh, String> {
        match (self.contact, &self.mesh) {
            (BodyContact::Mesh, MeshSource::Stl(path)) => {
                crate::geometry::stl::read_stl_unchecked(path)
                    .map(|(mesh, _)| mesh)
                    .map_err(|e| e.to_string())
            }
            _ => self.mesh.load(),
        }
    }
}

/// The derived text of the fields as before, `material` only when not the default.
impl std::fmt::Debug for BodySettings {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut s = f.debug_struct("BodySettings");
        s.field("name", &self.name)
            .field("mesh", &self.mesh)
            .field("cell_size", &self.cell_size)
            .field("particles", &self.particles)
            .field("padding", &self.padding)
            .field("rpm", &self.rpm)
            .field("axis", &self.axis)
            .field("point", &self.point)
            .field("velocity", &self.velocity)
            .field("start_stage", &self.start_stage);
        optional_field(&mut s, "material", &self.material);
        optional_field(&mut s, "contact", &self.contact);
        s.finish()
    }
}

/// Rule choosing the measurement region of a poured bed (lateral periodic, floor below, top
/// open), in units of the mean particle diameter `d`.
///
/// Bottom: `floor_z + floor_margin * d`. Near a flat wall spheres order in layers (the local
/// porosity oscillates with period about `d`, largest in the first layer, and has decayed to a
/// few percent of its amplitude after about two diameters), so the first two layers are left out.
///
/// Top: `bed_height - top_margin * d`, where `bed_height` is the `top_quantile` quantile
/// (nearest rank) of the particle-centre heights. A quantile instead of the maximum keeps a few
/// particles perched on (or still bouncing above) the surface from setting the height; the
/// 0.99 quantile of a 10 d x 10 d bed sits in its topmost layer. The free surface is rough over
/// one to two diameters and looser below it, hence the two-diameter margin.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BedRegionRule {
    pub floor_margin: Real,
    pub top_quantile: Real,
    pub top_margin: Real,
}

impl Default for BedRegionRule {
    fn default() -> Self {
        Self {
            floor_margin: 2.0,
            top_quantile: 0.99,
            top_margin: 2.0,
        }
    }
}

/// Screw-conveyor measurements (paper A Eq. 7) during one stage.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ConveyingSettings {
    pub stage: String,
    /// The screw body (its rpm gives n_s).
    pub body: String,
    /// Start-up time discarded at the beginning of the stage, s.
    pub discard: Real,
    /// Blocks for the standard error of the mass flow.
    pub blocks: u32,
    pub outer_diameter: Real,
    pub shaft_diameter: Real,
    pub pitch: Real,
    /// Casing bore radius: particles with centres inside it count for the fill ratio.
    pub bore_radius: Real,
    /// Axial range (along x, the screw axis) where the fill ratio is measured.
    pub fill_x: [Real; 2],
    /// Axial position of the plane the mass flow is measured through (inside the screw
    /// section, downstream of the inlet); `None`: at the outlet, from the deleted mass alone.
    pub flow_x: Option<Real>,
    /// Box where the bulk density is measured (centres inside count).
    pub bulk_lo: Vec3,
    pub bulk_hi: Vec3,
}

/// Porosity and pore sizes of a poured bed (paper B sec. 3), measured when `stage` ends.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PackingSettings {
    pub stage: String,
    /// The measurement region, in diameters (see [`BedRegionRule`]).
    pub rule: BedRegionRule,
    /// Pore-size voxels per particle diameter (the lateral period must hold a whole number).
    pub voxels_per_diameter: u32,
    /// Width of the pore-size histogram bins, in diameters.
    pub bin_width_diameters: Real,
}

/// A discharge through an orifice (a silo, a hopper): the mass deleted in the scene's
/// `[[delete]]` boxes against time gives the discharge rate, its slope over the stage after
/// `discard` (measured by the validation harness from `timeseries.csv`).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct DischargeSettings {
    /// The stage that opens the orifice; times count from its start.
    pub stage: String,
    /// The orifice's diameter, m (Beverloo's law; the smallest opening grains pass).
    pub orifice_diameter: Real,
    /// Start-up left out after the stage starts, s.
    pub discard: Real,
    /// Blocks of the steady window for the rate's standard error.
    pub blocks: u32,
    /// The box whose grains give the fill's bulk density when the stage starts, m.
    pub bulk_lo: [Real; 3],
    pub bulk_hi: [Real; 3],
}

#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum StageEnd {
    /// Run for this long.
    Duration(Real),
    /// Run for at least `min_duration`, then until the kinetic energy per unit mass (J/kg,
    /// invariant under coarse-graining) falls below the threshold, for at most `max_duration`.
    Settled {
        kinetic_energy_per_mass: Real,
        min_duration: Real,
        max_duration: Real,
    },
}

#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Stage {
    pub name: String,
    pub remove_walls: Vec<String>,
    pub end: StageEnd,
}

#[derive(Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct OutputSettings {
    /// Simulated seconds between VTK frames; 0 = none.
    pub vtk_interval: Real,
    /// Also write the pair contacts as lines (`vtk/contacts.pvd`) with each VTK frame.
    pub vtk_contact_network: bool,
    /// Also write each VTK frame's particles as a LAMMPS data file
    /// (`vtk/particles_NNNNNN.data`), from which a scene can start (`read_data`).
    pub write_data: bool,
    /// Stages at whose end the particles are written as a LAMMPS data file
    /// (`stage_<name>_end.data`).
    #[serde(default)]
    pub data_at_stage_ends: Vec<String>,
    /// Simulated seconds between time-series rows.
    pub timeseries_interval: Real,
}

/// The derived text of the fields as before (the scene digest), `data_at_stage_ends` only
/// when not empty.
impl std::fmt::Debug for OutputSettings {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut s = f.debug_struct("OutputSettings");
        s.field("vtk_interval", &self.vtk_interval)
            .field("vtk_contact_network", &self.vtk_contact_network)
            .field("write_data", &self.write_data);
        optional_field(&mut s, "data_at_stage_ends", &self.data_at_stage_ends);
        s.field("timeseries_interval", &self.timeseries_interval);
        s.finish()
    }
}

/// How and when the repose angle of a collapsed heap is measured (see `analysis::heap`).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ReposeSettings {
    /// The stage after whose start the `at_times` count.
    pub stage: String,
    /// x of the wall that stays; the heap runs out towards +x.
    pub wall_x: Real,
    /// Times after the stage start at which the angle is also measured.
    pub at_times: Vec<Real>,
    /// Measure when the stage ends by its own condition (e.g. the heap has come to rest);
    /// this is then the headline angle. Otherwise the last of `at_times` is.
    pub at_stage_end: bool,
    pub bin_width_diameters: Real,
    pub exclude_wall_fraction: Real,
    pub exclude_toe_fraction: Real,
}

#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Scene {
    pub name: String,
    pub description: String,
    pub source: PathBuf,
    pub domain: Domain,
    /// Whether a particle leaving the box through a bounded face stops the run
    /// (`[domain] lost = "error"`, the default, as LAMMPS's `thermo_modify lost error`) or is
    /// removed with a warning (`lost = "warn"`).
    pub stop_on_lost: bool,
    pub species: Vec<Species>,
    pub contact: ContactSettings,
    pub wall_contact: WallContactSettings,
    pub walls: Vec<WallSettings>,
    pub gravity: Vec3,
    pub time_step: TimeStepRequest,
    pub integrator: Integrator,
    /// Neighbour skin as a fraction of the largest diameter (scales with coarse-graining).
    pub skin_fraction: Real,
    pub resort_every: u32,
    pub insertions: Vec<Insertion>,
    /// Particles given one by one: those of `read_data` (by atom-ID), then the `[[particle]]`
    /// tables; placed before the insertions, after the particles of bodies.
    pub particles: Vec<GivenParticle>,
    pub stages: Vec<Stage>,
    pub output: OutputSettings,
    pub repose: Option<ReposeSettings>,
    /// Coarse-graining level already applied (1 = the original system).
    pub lambda: u32,
    /// The rule by which it was coarse-grained.
    pub cg_rule: CoarseGrainRule,
    pub bodies: Vec<BodySettings>,
    /// Particles whose centre enters one of these boxes (lo, hi) are deleted.
    pub deletions: Vec<(Vec3, Vec3)>,
    pub conveying: Option<ConveyingSettings>,
    pub packing: Option<PackingSettings>,
    pub discharge: Option<DischargeSettings>,
}

/// What [`Scene::to_json`] writes.
#[derive(serde::Serialize, serde::Deserialize)]
struct WrittenScene {
    format: String,
    digest: String,
    scene: Scene,
}

const WRITTEN_SCENE_FORMAT: &str = "cgdem-scene-1";

impl Scene {
    /// Reads and validates a scene file: TOML, or a scene cgdem wrote (`.json`, see
    /// [`Scene::to_json`]).
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        Scene::load_with_overrides(path, &[])
    }

    /// Reads a scene file, applies `KEY=VALUE` overrides to its text, then validates it.
    pub fn load_with_overrides(path: &Path, overrides: &[Override]) -> Result<Scene, SceneError> {
        let text = std::fs::read_to_string(path).map_err(|source| SceneError::Unreadable {
            file: path.to_path_buf(),
            source,
        })?;
        if path.extension().is_some_and(|e| e == "json") {
            if let Some(o) = overrides.first() {
                return Err(SceneError::Invalid {
                    file: path.to_path_buf(),
                    field: o.key.clone(),
                    value: "(given with --set)".into(),
                    allowed: "no overrides: a scene cgdem wrote (.json) runs as written; override the TOML case it came from".into(),
                });
            }
            return Scene::from_written_json(&text, path);
        }
        Scene::parse(&overrides::apply_overrides(&text, path, overrides)?, path)
    }

    /// The scene, exactly as it is (every number to the last bit), as the text of a
    /// `scene.json` for another cgdem process to run: the harness hands a coarse-grained,
    /// re-seeded scene to `mpirun -np N cgdem run DIR/scene.json`. Not an input format: the
    /// text carries the scene's digest, and [`Scene::load`] refuses a file whose content no
    /// longer matches it, since a scene read this way skips the checks a TOML scene goes
    /// through.
    pub fn to_json(&self) -> String {
        let written = WrittenScene {
            format: WRITTEN_SCENE_FORMAT.into(),
            digest: self.digest(),
            scene: self.clone(),
        };
        serde_json::to_string_pretty(&written).expect("a scene is plain data")
    }

    fn from_written_json(text: &str, path: &Path) -> Result<Scene, SceneError> {
        let invalid = |field: &str, value: String, allowed: &str| SceneError::Invalid {
            file: path.to_path_buf(),
            field: field.into(),
            value,
            allowed: allowed.into(),
        };
        let written: WrittenScene = serde_json::from_str(text).map_err(|e| SceneError::Syntax {
            file: path.to_path_buf(),
            message: format!("not a scene written by this cgdem ({e}); scene files are TOML"),
        })?;
        if written.format != WRITTEN_SCENE_FORMAT {
            return Err(invalid(
                "format",
                written.format,
                &format!("`{WRITTEN_SCENE_FORMAT}` (a scene written by this cgdem)"),
            ));
        }
        let mut scene = written.scene;
        scene.source = path.to_path_buf();
        if scene.digest() != written.digest {
            return Err(invalid(
                "digest",
                written.digest,
                &format!("the digest of the scene it holds ({}): the file was edited or written by another cgdem version; edit the TOML case instead", scene.digest()),
            ));
        }
        Ok(scene)
    }

    /// Validates scene text; `path` is used in messages.
    pub fn parse(text: &str, path: &Path) -> Result<Scene, SceneError> {
        let raw: raw::RawScene = toml::from_str(text).map_err(|e| SceneError::Syntax {
            file: path.to_path_buf(),
            message: e.to_string().trim_end().replace('\n', "\n  "),
        })?;
        validate::scene(raw, path)
    }

    /// The same scene with insertion `k` seeded by `seed + k` (a different random packing).
    pub fn with_insertion_seed(&self, seed: u64) -> Scene {
        let mut out = self.clone();
        for (k, ins) in out.insertions.iter_mut().enumerate() {
            ins.seed = seed.wrapping_add(k as u64);
        }
        out
    }

    /// A fingerprint of everything that decides a run (parameters, coarse-graining, seeds; not
    /// the file's path): equal digests mean the same simulation, so a finished run can be
    /// reused instead of repeated (`cgdem validate --reuse`). FNV-1a over the settings' debug
    /// text, so it changes whenever a setting or the settings' layout changes.
    pub fn digest(&self) -> String {
        let mut settings = self.clone();
        settings.source = PathBuf::new();
        let text = format!("{settings:?}");
        let hash = text.bytes().fold(0xcbf2_9ce4_8422_2325_u64, |h, b| {
            (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
        });
        format!("{hash:016x}")
    }

    /// Whether the scene gives materials or coefficients beyond `[contact]` and
    /// `[wall_contact]`: a species' own material, `[[contact.pair]]`, `[[wall_material]]` or
    /// `[[wall_contact.pair]]` (see [`ContactTables`]).
    pub fn gives_material_tables(&self) -> bool {
        let own = |s: &Species| s.youngs_modulus.is_some() || s.poisson_ratio.is_some();
        let pairs = match &self.contact {
            ContactSettings::Hertz(h) => !h.pairs.is_empty(),
            ContactSettings::Wca(_) => false,
        };
        self.species.iter().any(own)
            || pairs
            || !self.wall_contact.materials.is_empty()
            || !self.wall_contact.pairs.is_empty()
    }

    pub fn max_diameter(&self) -> Real {
        self.species.iter().map(|s| s.diameter).fold(0.0, Real::max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wca_settings_print_as_the_struct_variant_the_scene_digests_were_taken_of() {
        let contact = ContactSettings::Wca(WcaSettings {
            epsilon: 1.5,
            sigma: 2e-3,
            gamma_n: 0.25,
            gamma_t: 0.125,
        });
        assert_eq!(
            format!("{contact:?}"),
            "Wca { epsilon: 1.5, sigma: 0.002, gamma_n: 0.25, gamma_t: 0.125 }"
        );
    }

    /// The tables of materials appear in the debug text only when given, so a scene without
    /// them keeps the digest it had before them (a finished run stays reusable).
    #[test]
    fn settings_without_materials_print_as_before_materials() {
        let species = Species {
            name: "bead".into(),
            diameter: 0.01,
            density: 2500.0,
            frozen: false,
            youngs_modulus: None,
            poisson_ratio: None,
        };
        assert_eq!(
            format!("{species:?}"),
            "Species { name: \"bead\", diameter: 0.01, density: 2500.0, frozen: false }"
        );
        let wall = WallSettings {
            name: "floor".into(),
            point: Vec3::ZERO,
            normal: Vec3::Z,
            material: 0,
        };
        assert_eq!(
            format!("{wall:?}"),
            "WallSettings { name: \"floor\", point: DVec3(0.0, 0.0, 0.0), normal: DVec3(0.0, 0.0, 1.0) }"
        );
        let w = WallContactSettings {
            restitution: 0.5,
            friction: 0.25,
            youngs_modulus: None,
            poisson_ratio: Some(0.3),
            rolling_friction: 0.0,
            materials: Vec::new(),
            pairs: Vec::new(),
        };
        assert_eq!(
            format!("{w:?}"),
            "WallContactSettings { restitution: 0.5, friction: 0.25, youngs_modulus: None, poisson_ratio: Some(0.3), rolling_friction: 0.0 }"
        );
        let h = HertzSettings {
            youngs_modulus: 5e6,
            poisson_ratio: 0.3,
            restitution: 0.5,
            friction: 0.5,
            rolling_friction: 0.1,
            damping: HertzDampingKind::Restitution,
            tangential: TangentialKind::History,
            rolling: RollingKind::Epsd2,
            cohesion: CohesionKind::None,
            characteristic_velocity: 1.0,
            limit_force: false,
            tangential_damping: true,
            pairs: Vec::new(),
        };
        assert_eq!(
            format!("{h:?}"),
            "HertzSettings { youngs_modulus: 5000000.0, poisson_ratio: 0.3, restitution: 0.5, friction: 0.5, rolling_friction: 0.1, damping: Restitution, tangential: History, rolling: Epsd2, cohesion: None, characteristic_velocity: 1.0 }"
        );
        let body = BodySettings {
            name: "screw".into(),
            mesh: MeshSource::ScrewFeeder("screw".into()),
            cell_size: 0.004,
            particles: None,
            padding: None,
            rpm: 10.0,
            axis: Vec3::X,
            point: Vec3::ZERO,
            velocity: Vec3::ZERO,
            start_stage: None,
            material: 0,
            contact: BodyContact::Grid,
        };
        assert_eq!(
            format!("{body:?}"),
            "BodySettings { name: \"screw\", mesh: ScrewFeeder(\"screw\"), cell_size: 0.004, particles: None, padding: None, rpm: 10.0, axis: DVec3(1.0, 0.0, 0.0), point: DVec3(0.0, 0.0, 0.0), velocity: DVec3(0.0, 0.0, 0.0), start_stage: None }"
        );
        // Given, they are part of it.
        let own = Species {
            youngs_modulus: Some(1e7),
            ..species
        };
        assert!(format!("{own:?}").ends_with("frozen: false, youngs_modulus: Some(10000000.0) }"));
    }
}
