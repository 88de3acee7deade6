//! The codes a case runs with: cgdem itself and the two reference codes, one enum for the
//! suites, the reports and the reference runs alike.

#[derive(
    Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum Code {
    Cgdem,
    /// LAMMPS (`lmp`): the seed's WCA model and the Hertz family.
    Lammps,
    /// LIGGGHTS (`liggghts`): the Hertz family with LIGGGHTS's own keywords.
    Liggghts,
}

impl Code {
    /// The name in suite files, run directories and reports: "cgdem", "lammps", "liggghts".
    pub fn name(self) -> &'static str {
        match self {
            Code::Cgdem => "cgdem",
            Code::Lammps => "lammps",
            Code::Liggghts => "liggghts",
        }
    }

    /// The code a suite file names: "cgdem", "lammps" or "liggghts".
    pub fn from_name(name: &str) -> Option<Code> {
        [Code::Cgdem, Code::Lammps, Code::Liggghts]
            .into_iter()
            .find(|c| c.name() == name)
    }

    /// The code's own spelling, for messages: "cgdem", "LAMMPS", "LIGGGHTS".
    pub fn label(self) -> &'static str {
        match self {
            Code::Cgdem => "cgdem",
            Code::Lammps => "LAMMPS",
            Code::Liggghts => "LIGGGHTS",
        }
    }
}
