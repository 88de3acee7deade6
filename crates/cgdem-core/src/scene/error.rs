//! Errors a user can act on: which file, which field, what value, what is allowed.

use std::path::PathBuf;

#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    #[error("{file}: cannot read the scene file: {source}")]
    Unreadable {
        file: PathBuf,
        source: std::io::Error,
    },
    #[error("{file}: not a valid scene file: {message}")]
    Syntax { file: PathBuf, message: String },
    #[error("{file}: field `{field}` = {value} is not allowed: {allowed}")]
    Invalid {
        file: PathBuf,
        field: String,
        value: String,
        allowed: String,
    },
    /// A bad line of the scene's `read_data` file (which names its file, line and field).
    #[error("{}: read_data: {source}", .scene.display())]
    DataFile {
        scene: PathBuf,
        source: Box<crate::lammps_data::DataFileError>,
    },
}
