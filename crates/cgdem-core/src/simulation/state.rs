//! A world's changing state, for restart files (`run::restart`): what a world built from the
//! same scene needs to step on bit for bit from where the state was taken.

use super::World;
use crate::bodies::BodyState;
use crate::contact::{PairHistory, PairLaw};
use crate::decomposition::{DecomposedState, GridSpec};
use crate::guard::GuardState;
use crate::math::Real;
use crate::walls::WallLaw;

/// Everything a world carries from one step to the next that its scene does not give: the
/// clock and counters, which walls are still there, the bodies' poses and loads, the guards'
/// state, and the subdomains (their particles with the forces the next step's first half
/// uses, their pair lists with the contact histories, in the order that is the force
/// summation order). A world built from the same scene and given this state on the same grid
/// steps on bit for bit, on any number of threads or ranks.
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(bound = "")]
pub struct WorldState<H: PairHistory, WH: PairHistory> {
    time: Real,
    steps: u64,
    lost: u64,
    deleted: u64,
    deleted_mass: Real,
    wall_active: Vec<bool>,
    bodies: Vec<BodyState>,
    guard: GuardState,
    subdomains: DecomposedState,
    /// Why the grid is what it is (kept by a run resumed on it).
    grid_reason: String,
    #[serde(skip)]
    histories: std::marker::PhantomData<(H, WH)>,
}

impl<H: PairHistory, WH: PairHistory> WorldState<H, WH> {
    /// The grid the state's subdomains are on.
    pub fn grid(&self) -> [usize; 3] {
        self.subdomains.grid.counts
    }
}

impl<L: PairLaw, W: WallLaw> World<L, W> {
    /// The world's changing state, for a restart file; the subdomains' state is gathered
    /// from every rank (collective).
    pub fn state(&self) -> WorldState<L::History, W::History> {
        WorldState {
            time: self.time,
            steps: self.steps,
            lost: self.lost,
            deleted: self.deleted,
            deleted_mass: self.deleted_mass,
            wall_active: self.walls.walls.iter().map(|w| w.active).collect(),
            bodies: self.bodies.iter().map(|b| b.state()).collect(),
            guard: self.guard.clone(),
            subdomains: self.subdomains.state(),
            grid_reason: self.grid_reason.clone(),
            histories: std::marker::PhantomData,
        }
    }

    /// Puts back a state taken by [`World::state`] from a world built from the same scene
    /// (the guard settings and the balance threshold stay this world's): on the stored grid
    /// unless `grid` names another, which deals the stored particles out again with their
    /// histories (as a rebuild would). An error when the walls, bodies or grid do not fit.
    pub fn set_state(
        &mut self,
        state: WorldState<L::History, W::History>,
        grid: Option<GridSpec>,
    ) -> Result<(), String> {
        if state.wall_active.len() != self.walls.walls.len()
            || state.bodies.len() != self.bodies.len()
        {
            return Err(format!(
                "the stored state has {} walls and {} bodies, the scene {} and {}",
                state.wall_active.len(),
                state.bodies.len(),
                self.walls.walls.len(),
                self.bodies.len()
            ));
        }
        for (wall, &active) in self.walls.walls.iter_mut().zip(&state.wall_active) {
            wall.active = active;
        }
        for (body, s) in self.bodies.iter_mut().zip(&state.bodies) {
            body.set_state(s);
        }
        let settings = std::mem::take(&mut self.guard.settings);
        self.time = state.time;
        self.steps = state.steps;
        self.lost = state.lost;
        self.deleted = state.deleted;
        self.deleted_mass = state.deleted_mass;
        self.guard = state.guard;
        self.guard.settings = settings;
        self.grid_reason = state.grid_reason;
        self.restore_subdomains(state.subdomains, grid)
    }
}
