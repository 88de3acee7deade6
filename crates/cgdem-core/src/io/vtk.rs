//! ParaView-readable particle output: one `.vtu` (VTK XML unstructured grid of vertices,
//! with radius, velocity and id) per frame, and a `.pvd` collection indexing the frames by
//! simulated time.

use std::path::{Path, PathBuf};
use vtkio::model::*;

use crate::particles::Particles;

pub struct VtkSeries {
    dir: PathBuf,
    stem: String,
    frames: Vec<(f64, String)>,
}

impl VtkSeries {
    pub fn new(dir: &Path, stem: &str) -> std::io::Result<Self> {
        std::fs::create_dir_all(dir)?;
        Ok(VtkSeries {
            dir: dir.to_path_buf(),
            stem: stem.to_string(),
            frames: Vec::new(),
        })
    }

    /// Writes one frame and rewrites the `.pvd` index, so the series is readable even if
    /// the run stops early.
    pub fn write_frame(&mut self, particles: &Particles, time: f64) -> Result<(), String> {
        let name = format!("{}_{:06}.vtu", self.stem, self.frames.len());
        let path = self.dir.join(&name);
        let n = particles.len() as u64;
        let points: Vec<f64> = particles
            .position
            .iter()
            .flat_map(|p| p.to_array())
            .collect();
        let velocity: Vec<f64> = particles
            .velocity
            .iter()
            .flat_map(|v| v.to_array())
            .collect();
        let vtk = Vtk {
            version: Version::new((1, 0)),
            title: format!("cgdem particles at t = {time} s"),
            byte_order: ByteOrder::LittleEndian,
            file_path: None,
            data: DataSet::inline(UnstructuredGridPiece {
                points: IOBuffer::F64(points),
                cells: Cells {
                    cell_verts: VertexNumbers::XML {
                        connectivity: (0..n).collect(),
                        offsets: (1..=n).collect(),
                    },
                    types: vec![CellType::Vertex; n as usize],
                },
                data: Attributes {
                    point: vec![
                        Attribute::scalars("radius", 1).with_data(particles.radius.clone()),
                        Attribute::vectors("velocity").with_data(velocity),
                        Attribute::scalars("id", 1).with_data(particles.id.clone()),
                    ],
                    cell: vec![],
                },
            }),
        };
        vtk.export(&path)
            .map_err(|e| format!("{}: {e}", path.display()))?;
        self.frames.push((time, name));
        let mut pvd = String::from("<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n");
        for (t, file) in &self.frames {
            pvd +=
                &format!("    <DataSet timestep=\"{t}\" group=\"\" part=\"0\" file=\"{file}\"/>\n");
        }
        pvd += "  </Collection>\n</VTKFile>\n";
        let index = self.dir.join(format!("{}.pvd", self.stem));
        super::write_atomic(&index, pvd.as_bytes()).map_err(|e| format!("{}: {e}", index.display()))
    }
}
