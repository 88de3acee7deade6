//! Contact laws composed from slots: normal, damping, tangential, rolling, cohesion.
//!
//! Each slot is a generic parameter of [`ContactLaw`]; an absent slot is a zero-sized `No*`
//! type whose methods are empty and inline away, so a scene pays only for the physics it
//! uses. The combination is chosen once, when the scene is read (see `simulation`), never
//! per contact. Parameters are tables indexed by species pair, `si * n_species + sj`.

mod cap;
pub mod cohesion;
pub mod damping;
mod history;
pub mod normal;
pub mod rolling;
pub mod tangential;

pub use cap::exceeds;
pub use history::PairHistory;

use crate::math::{Real, Vec3};

/// Geometry and kinematics of one interacting pair, seen from particle `i`.
#[derive(Clone, Copy, Debug)]
pub struct Contact {
    /// Species-pair index into the slots' parameter tables.
    pub species_pair: usize,
    /// Unit vector from `j` to `i`.
    pub normal: Vec3,
    pub distance: Real,
    /// `r_i + r_j - distance`; negative when apart (cohesion may still act).
    pub overlap: Real,
    pub radius_i: Real,
    pub radius_j: Real,
    /// Effective radius `r_i r_j / (r_i + r_j)`.
    pub r_eff: Real,
    /// Inverse masses, 1/kg; zero for a frozen particle (infinite mass).
    pub inv_mass_i: Real,
    pub inv_mass_j: Real,
    /// Effective mass `1 / (1/m_i + 1/m_j)`: the mobile particle's mass against a frozen one.
    pub m_eff: Real,
    /// Relative velocity `v_i - v_j` at the contact point (spins included when rotating).
    pub relative_velocity: Vec3,
    /// Normal component `relative_velocity . normal` (negative while approaching).
    pub normal_speed: Real,
    /// Tangential part of the relative velocity.
    pub tangential_velocity: Vec3,
}

/// Force and torques one pair exerts; the force on `j` is `-force_on_i`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PairResult {
    pub force_on_i: Vec3,
    pub torque_on_i: Vec3,
    pub torque_on_j: Vec3,
}

/// The elastic normal response: force magnitude (positive pushes apart) and the local
/// stiffness dF/d(overlap), which restitution-based damping needs.
#[derive(Clone, Copy, Debug, Default)]
pub struct NormalResponse {
    pub force: Real,
    pub stiffness: Real,
}

pub trait NormalModel: Send + Sync {
    /// Centre distance below which the pair interacts.
    fn cutoff(&self, species_pair: usize, radius_i: Real, radius_j: Real) -> Real;
    /// Elastic force at `contact`; only called when `distance < cutoff`.
    fn response(&self, contact: &Contact) -> NormalResponse;
    /// Stiffness of the linearized contact at its stiffest, for the time step.
    fn linear_stiffness(
        &self,
        species_pair: usize,
        radius_i: Real,
        radius_j: Real,
        m_eff: Real,
    ) -> Real;
    /// Elastic energy stored in the pair at centre distance `distance` (zero when apart).
    fn elastic_energy(
        &self,
        species_pair: usize,
        radius_i: Real,
        radius_j: Real,
        distance: Real,
    ) -> Real;
}

pub trait DampingModel: Send + Sync {
    /// Normal damping force (positive pushes apart).
    fn force(&self, contact: &Contact, elastic: &NormalResponse) -> Real;
    /// Damping coefficient of the linearized contact (kg/s), for the time-step limit.
    fn linear_coefficient(&self, species_pair: usize, stiffness: Real, m_eff: Real) -> Real;
}

pub trait TangentialModel: Send + Sync {
    type History: PairHistory;
    /// Whether the model needs particle spin (contact-point velocity, torques).
    const NEEDS_ROTATION: bool;
    /// The normal load the law's Coulomb bounds take from the normal force `F_n` (elastic
    /// plus dashpot), for its own cap and the rolling torque's: `|F_n|`, as LIGGGHTS, unless
    /// the law says otherwise.
    #[inline(always)]
    fn cap_load(normal_force: Real) -> Real {
        normal_force.abs()
    }
    /// Tangential force on `i`; `normal_force` is the total normal force magnitude.
    fn force(
        &self,
        contact: &Contact,
        normal_force: Real,
        history: &mut Self::History,
        dt: Real,
    ) -> Vec3;
}

pub trait RollingModel: Send + Sync {
    /// Per-pair state (e.g. a rolling spring); `()` when the model has none.
    type History: PairHistory;
    const NEEDS_ROTATION: bool;
    /// Rolling-resistance torque on `i` (the torque on `j` is its negative).
    fn torque(
        &self,
        contact: &Contact,
        normal_force: Real,
        omega_i: Vec3,
        omega_j: Vec3,
        history: &mut Self::History,
        dt: Real,
    ) -> Vec3;
}

pub trait CohesionModel: Send + Sync {
    /// Whether the slot attracts: then kinetic plus gravitational energy may rise by the
    /// binding energy, and the energy guard does not apply.
    const ATTRACTS: bool = true;
    /// How far beyond touching (`r_i + r_j`) the attraction reaches; the neighbour search
    /// adds it to its cut-off.
    fn reach(&self) -> Real;
    /// Attractive force magnitude (positive pulls together).
    fn force(&self, contact: &Contact) -> Real;
}

/// What the force loop needs from a law.
pub trait PairLaw: Send + Sync {
    type History: PairHistory;
    const NEEDS_ROTATION: bool;
    /// Whether any part of the law attracts (cohesion).
    const ATTRACTS: bool = false;
    /// Largest distance beyond `r_i + r_j` at which any pair still interacts.
    fn reach(&self) -> Real;
    fn cutoff(&self, species_pair: usize, radius_i: Real, radius_j: Real) -> Real;
    fn evaluate(
        &self,
        contact: &Contact,
        history: &mut Self::History,
        omega: (Vec3, Vec3),
        dt: Real,
    ) -> PairResult;
    /// (stiffness, damping coefficient) of the linearized contact of two particles.
    fn linearized(
        &self,
        species_pair: usize,
        radius_i: Real,
        radius_j: Real,
        m_eff: Real,
    ) -> (Real, Real);
    /// Elastic energy of the repulsion stored at centre distance `distance` (the energy
    /// guard counts it, so that particles placed overlapping may push apart).
    fn elastic_energy(
        &self,
        species_pair: usize,
        radius_i: Real,
        radius_j: Real,
        distance: Real,
    ) -> Real;
}

/// Elastic plus damping normal force (positive pushes apart): the normal and damping slots
/// together, for pairs and for walls (a wall being a partner of infinite radius and mass).
#[inline(always)]
pub fn normal_force<N: NormalModel, D: DampingModel>(
    normal: &N,
    damping: &D,
    contact: &Contact,
) -> Real {
    let elastic = normal.response(contact);
    elastic.force + damping.force(contact, &elastic)
}

/// A contact law assembled from five slots.
#[derive(Clone, Debug)]
pub struct ContactLaw<N, D, T, R, C> {
    pub normal: N,
    pub damping: D,
    pub tangential: T,
    pub rolling: R,
    pub cohesion: C,
    /// Largest `cutoff - (r_i + r_j)` over the species pairs, from the normal slot.
    pub normal_reach: Real,
}

impl<N, D, T, R, C> PairLaw for ContactLaw<N, D, T, R, C>
where
    N: NormalModel,
    D: DampingModel,
    T: TangentialModel,
    R: RollingModel,
    C: CohesionModel,
{
    /// Tangential and rolling history side by side; `((), ())` (no storage) for the seed.
    type History = (T::History, R::History);
    const NEEDS_ROTATION: bool = T::NEEDS_ROTATION || R::NEEDS_ROTATION;
    const ATTRACTS: bool = C::ATTRACTS;

    fn reach(&self) -> Real {
        self.normal_reach.max(self.cohesion.reach())
    }

    fn cutoff(&self, species_pair: usize, radius_i: Real, radius_j: Real) -> Real {
        self.normal
            .cutoff(species_pair, radius_i, radius_j)
            .max(radius_i + radius_j + self.cohesion.reach())
    }

    #[inline(always)]
    fn evaluate(
        &self,
        contact: &Contact,
        history: &mut Self::History,
        omega: (Vec3, Vec3),
        dt: Real,
    ) -> PairResult {
        let touching = contact.distance
            < self
                .normal
                .cutoff(contact.species_pair, contact.radius_i, contact.radius_j);
        if !touching {
            // A separated pair loses its history; cohesion may still pull.
            *history = Default::default();
            let pull = self.cohesion.force(contact);
            return PairResult {
                force_on_i: -pull * contact.normal,
                ..Default::default()
            };
        }
        // The normal part first: friction and rolling need |F_n|.
        let normal_force = normal_force(&self.normal, &self.damping, contact);
        let tangential = self
            .tangential
            .force(contact, normal_force, &mut history.0, dt);
        let pull = self.cohesion.force(contact);
        let force_on_i = (normal_force - pull) * contact.normal + tangential;
        if !Self::NEEDS_ROTATION {
            return PairResult {
                force_on_i,
                ..Default::default()
            };
        }
        // Torque of the tangential force about each centre (contact point on the line of
        // centres), plus rolling resistance.
        let arm_i = -contact.normal * (contact.radius_i - 0.5 * contact.overlap);
        let arm_j = contact.normal * (contact.radius_j - 0.5 * contact.overlap);
        let rolling = self.rolling.torque(
            contact,
            T::cap_load(normal_force),
            omega.0,
            omega.1,
            &mut history.1,
            dt,
        );
        PairResult {
            force_on_i,
            torque_on_i: arm_i.cross(tangential) + rolling,
            torque_on_j: arm_j.cross(-tangential) - rolling,
        }
    }

    fn linearized(
        &self,
        species_pair: usize,
        radius_i: Real,
        radius_j: Real,
        m_eff: Real,
    ) -> (Real, Real) {
        let k = self
            .normal
            .linear_stiffness(species_pair, radius_i, radius_j, m_eff);
        let gamma = self.damping.linear_coefficient(species_pair, k, m_eff);
        (k, gamma)
    }

    fn elastic_energy(
        &self,
        species_pair: usize,
        radius_i: Real,
        radius_j: Real,
        distance: Real,
    ) -> Real {
        self.normal
            .elastic_energy(species_pair, radius_i, radius_j, distance)
    }
}

/// The seed's model, paper A Eq. (1)-(2): WCA repulsion, normal and tangential dashpots; no
/// rotation, no history, no cohesion.
pub type SeedModel = ContactLaw<
    normal::Wca,
    damping::ViscousNormal,
    tangential::ViscousTangential,
    rolling::NoRolling,
    cohesion::NoCohesion,
>;

impl SeedModel {
    /// Tables are indexed by species pair `si * n + sj`.
    pub fn seed(wca: Vec<normal::WcaCoefficients>, gamma_n: Vec<Real>, gamma_t: Vec<Real>) -> Self {
        let normal_reach = 0.0; // r_c = 2^(1/6) sigma is the diameter; cutoff() takes the max
        ContactLaw {
            normal: normal::Wca { table: wca },
            damping: damping::ViscousNormal { gamma_n },
            tangential: tangential::ViscousTangential { gamma_t },
            rolling: rolling::NoRolling,
            cohesion: cohesion::NoCohesion,
            normal_reach,
        }
    }
}

/// The Hertz family (LIGGGHTS `model hertz`, paper B). Each scene picks one of these
/// concrete combinations (see `run`), so it pays only for its slots.
pub type HertzHistory = ContactLaw<
    normal::Hertz,
    damping::HertzDamping,
    tangential::Mindlin,
    rolling::NoRolling,
    cohesion::NoCohesion,
>;
/// `HertzHistory` plus constant-torque rolling resistance.
pub type HertzHistoryRolling = ContactLaw<
    normal::Hertz,
    damping::HertzDamping,
    tangential::Mindlin,
    rolling::ConstantTorque,
    cohesion::NoCohesion,
>;
/// `HertzHistoryRolling` plus van der Waals attraction.
pub type HertzHistoryRollingVdw = ContactLaw<
    normal::Hertz,
    damping::HertzDamping,
    tangential::Mindlin,
    rolling::ConstantTorque,
    cohesion::VanDerWaals,
>;
/// Paper B as written: Hertz, Yang dashpot and tangential law, rolling, van der Waals.
pub type PaperB = ContactLaw<
    normal::Hertz,
    damping::YangDamping,
    tangential::YangTangential,
    rolling::ConstantTorque,
    cohesion::VanDerWaals,
>;
/// Paper B without rolling resistance and cohesion.
pub type YangHertz = ContactLaw<
    normal::Hertz,
    damping::YangDamping,
    tangential::YangTangential,
    rolling::NoRolling,
    cohesion::NoCohesion,
>;

impl<N: NormalModel, D, T, R, C> ContactLaw<N, D, T, R, C> {
    /// Assembles a law; the normal slot touches exactly at `r_i + r_j`.
    pub fn new(normal: N, damping: D, tangential: T, rolling: R, cohesion: C) -> Self {
        ContactLaw {
            normal,
            damping,
            tangential,
            rolling,
            cohesion,
            normal_reach: 0.0,
        }
    }
}

#[cfg(test)]
mod coulomb_tests;
#[cfg(test)]
mod physics_tests;

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Two 1 g spheres of effective radius `r_eff` (radii `2 r_eff`) overlapping by `delta`
    /// along x, at rest.
    pub fn contact_at(delta: Real, r_eff: Real) -> Contact {
        let r = 2.0 * r_eff;
        Contact {
            species_pair: 0,
            normal: Vec3::X,
            distance: 2.0 * r - delta,
            overlap: delta,
            radius_i: r,
            radius_j: r,
            r_eff,
            inv_mass_i: 500.0,
            inv_mass_j: 500.0,
            m_eff: 1e-3,
            relative_velocity: Vec3::ZERO,
            normal_speed: 0.0,
            tangential_velocity: Vec3::ZERO,
        }
    }
}
