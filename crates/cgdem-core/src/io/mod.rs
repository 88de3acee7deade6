//! Files a run writes: VTK for ParaView, CSV tables, the JSON summary.

pub mod lammps_data;
pub mod vtk;

use std::io::Write;
use std::path::Path;

/// Writes `contents` to `path` through a temporary file and a rename, so a reader never
/// sees half a file and an interrupted write leaves the old one intact. A failed write (a
/// full disk) removes its temporary file and leaves `path` as it was.
pub fn write_atomic(path: &Path, contents: &[u8]) -> std::io::Result<()> {
    let tmp = path.with_extension(format!(
        "{}.tmp",
        path.extension().and_then(|e| e.to_str()).unwrap_or("")
    ));
    let written = (|| {
        let mut file = std::fs::File::create(&tmp)?;
        file.write_all(contents)?;
        file.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if written.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    written
}
