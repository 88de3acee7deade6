//! A ParaView collection (`.pvd`): the frames of one series, by simulated time.

use std::path::{Path, PathBuf};

pub struct PvdSeries {
    path: PathBuf,
    /// (time, file name relative to the `.pvd`)
    frames: Vec<(f64, String)>,
}

impl PvdSeries {
    pub fn new(path: PathBuf) -> PvdSeries {
        PvdSeries {
            path,
            frames: Vec::new(),
        }
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The frames so far: (time, file).
    pub fn frames(&self) -> &[(f64, String)] {
        &self.frames
    }

    /// Replaces the frames (a resumed run's, as at its checkpoint) and rewrites the index
    /// when there is one to write.
    pub fn set_frames(&mut self, frames: Vec<(f64, String)>) -> std::io::Result<()> {
        self.frames = frames;
        match self.frames.pop() {
            Some((time, file)) => self.push(time, file),
            None => Ok(()),
        }
    }

    /// Adds a frame and rewrites the index (through a rename), so the series stays readable
    /// if the run stops early.
    pub fn push(&mut self, time: f64, file: String) -> std::io::Result<()> {
        self.frames.push((time, file));
        let mut pvd = String::from("<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n");
        for (t, file) in &self.frames {
            pvd +=
                &format!("    <DataSet timestep=\"{t}\" group=\"\" part=\"0\" file=\"{file}\"/>\n");
        }
        pvd += "  </Collection>\n</VTKFile>\n";
        crate::io::write_atomic(&self.path, pvd.as_bytes())
    }
}
