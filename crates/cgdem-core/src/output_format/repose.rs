//! The heap of a `[repose]` scene: its surface profile, the angle measured on it by the
//! scene's rule, and `profile.csv` and `repose.csv`.

use serde::{Deserialize, Serialize};

use crate::analysis::heap::{self, HeapProfile};
use crate::io::CsvBuffer;
use crate::math::{Real, Vec3};
use crate::scene::{ReposeSettings, Scene};

/// What took a repose sample: a fixed time after the stage began, or the stage's own end.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum SampleTrigger {
    #[serde(rename = "fixed time")]
    FixedTime,
    #[serde(rename = "stage end")]
    StageEnd,
}

impl std::fmt::Display for SampleTrigger {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            SampleTrigger::FixedTime => "fixed time",
            SampleTrigger::StageEnd => "stage end",
        })
    }
}

/// The angle measured at one time after the repose stage began.
#[derive(Clone, Debug, Serialize, serde::Deserialize)]
pub struct ReposeSample {
    pub time_after_start_s: Real,
    pub trigger: SampleTrigger,
    pub repose_angle_deg: Option<Real>,
    pub repose_fit_r2: Option<Real>,
    /// Why the angle could not be measured, when it could not. Always written (no
    /// `skip_serializing_if`): restart files hold the samples in bincode, which cannot skip.
    #[serde(default)]
    pub not_measured: Option<String>,
    pub runout_m: Real,
    pub wall_height_m: Real,
}

impl ReposeSample {
    /// Measures a heap profile by the scene's repose rule (the same for every code).
    pub fn measure(
        profile: &HeapProfile,
        rule: &ReposeSettings,
        max_diameter: Real,
        time_after_start_s: Real,
        trigger: SampleTrigger,
    ) -> ReposeSample {
        let fit = heap::repose_angle(
            profile,
            2.0 * max_diameter,
            rule.exclude_wall_fraction,
            rule.exclude_toe_fraction,
        );
        ReposeSample {
            time_after_start_s,
            trigger,
            repose_angle_deg: fit.as_ref().ok().map(|f| f.angle_deg),
            repose_fit_r2: fit.as_ref().ok().map(|f| f.r_squared),
            not_measured: fit.as_ref().err().cloned(),
            runout_m: profile.front(2.0 * max_diameter) - profile.wall_x,
            wall_height_m: profile.wall_height(),
        }
    }
}

/// The heap surface of `scene`'s `[repose]` section for particles at `position` of `radius`
/// (None without one).
pub fn heap_profile(scene: &Scene, position: &[Vec3], radius: &[Real]) -> Option<HeapProfile> {
    scene.repose.as_ref().map(|r| {
        heap::profile(
            position,
            radius,
            r.wall_x,
            scene.domain.hi.x,
            scene.domain.lo.z,
            r.bin_width_diameters * scene.max_diameter(),
        )
    })
}

/// `profile.csv`: the heap surface height per bin.
pub fn profile_csv(profile: &HeapProfile) -> std::io::Result<Vec<u8>> {
    let mut csv = CsvBuffer::new(["x_m", "height_m"]);
    for (k, h) in profile.heights.iter().enumerate() {
        csv.row([format!("{:.6e}", profile.bin_centre(k)), format!("{h:.6e}")]);
    }
    csv.bytes().map(<[u8]>::to_vec)
}

/// `repose.csv`: the angle at each measurement.
pub fn repose_csv(samples: &[ReposeSample]) -> std::io::Result<Vec<u8>> {
    let mut csv = CsvBuffer::new([
        "time_after_start_s",
        "trigger",
        "repose_angle_deg",
        "repose_fit_r2",
        "runout_m",
        "wall_height_m",
    ]);
    let opt = |v: Option<Real>| v.map_or(String::new(), |x| format!("{x:.6}"));
    for s in samples {
        csv.row([
            s.time_after_start_s.to_string(),
            s.trigger.to_string(),
            opt(s.repose_angle_deg),
            opt(s.repose_fit_r2),
            format!("{:.6e}", s.runout_m),
            format!("{:.6e}", s.wall_height_m),
        ]);
    }
    csv.bytes().map(<[u8]>::to_vec)
}

/// The headline measurement: the stage-end sample when the scene asks for one, else the last
/// fixed time.
pub fn headline_sample(samples: &[ReposeSample]) -> Option<&ReposeSample> {
    samples
        .iter()
        .rev()
        .find(|s| s.trigger == SampleTrigger::StageEnd)
        .or(samples.last())
}
