//! A VTK XML unstructured grid (`.vtu`) with every array in one appended block of raw
//! little-endian bytes (`format="appended"`, `<AppendedData encoding="raw">`), as ParaView
//! writes by default: no base64 or ASCII conversion, so a frame costs little more than a copy.
//! vtkio 0.6 writes only inline base64, hence this small writer.

use crate::math::{Real, Vec3};

/// A number type a VTK `DataArray` holds.
pub trait VtkNumber: Copy {
    /// The `type` attribute.
    const NAME: &'static str;
    /// Writes the value's little-endian bytes into `out` (exactly its size).
    fn write_le(self, out: &mut [u8]);
}

macro_rules! vtk_number {
    ($t:ty, $name:literal) => {
        impl VtkNumber for $t {
            const NAME: &'static str = $name;
            #[inline(always)]
            fn write_le(self, out: &mut [u8]) {
                out.copy_from_slice(&self.to_le_bytes());
            }
        }
    };
}
vtk_number!(u8, "UInt8");
vtk_number!(u16, "UInt16");
vtk_number!(u32, "UInt32");
vtk_number!(i32, "Int32");
vtk_number!(i64, "Int64");
vtk_number!(f64, "Float64");

/// VTK cell type codes used here.
pub const VTK_VERTEX: u8 = 1;
pub const VTK_LINE: u8 = 3;
pub const VTK_TRIANGLE: u8 = 5;

/// One `.vtu` being assembled: arrays are added by section, then [`Vtu::finish`] gives the
/// file's bytes.
pub struct Vtu {
    n_points: usize,
    n_cells: usize,
    point_data: String,
    cell_data: String,
    points: String,
    cells: String,
    appended: Vec<u8>,
}

impl Vtu {
    /// `appended_bytes`: an estimate of the binary size, to allocate once.
    pub fn new(n_points: usize, n_cells: usize, appended_bytes: usize) -> Vtu {
        Vtu {
            n_points,
            n_cells,
            point_data: String::new(),
            cell_data: String::new(),
            points: String::new(),
            cells: String::new(),
            appended: Vec::with_capacity(appended_bytes),
        }
    }

    /// Appends one array's block (its byte count as UInt64, then the values) and returns
    /// its `DataArray` tag.
    fn array<T: VtkNumber>(
        &mut self,
        name: &str,
        components: usize,
        values: impl Iterator<Item = T>,
    ) -> String {
        let offset = self.appended.len();
        let size = std::mem::size_of::<T>();
        self.appended.extend_from_slice(&0u64.to_le_bytes());
        // Sized once and filled in place when the count is known (the frames' arrays): a
        // tight loop the compiler vectorizes, unlike a push per value.
        let (lower, upper) = values.size_hint();
        let mut values = values.peekable();
        if upper == Some(lower) {
            let start = self.appended.len();
            self.appended.resize(start + lower * size, 0);
            for (out, v) in self.appended[start..]
                .chunks_exact_mut(size)
                .zip(&mut values)
            {
                v.write_le(out);
            }
        }
        let mut buffer = [0u8; 8];
        for v in values {
            v.write_le(&mut buffer[..size]);
            self.appended.extend_from_slice(&buffer[..size]);
        }
        let bytes = (self.appended.len() - offset - 8) as u64;
        self.appended[offset..offset + 8].copy_from_slice(&bytes.to_le_bytes());
        let name = if name.is_empty() {
            String::new()
        } else {
            format!(" Name=\"{name}\"")
        };
        format!(
            "        <DataArray type=\"{}\"{name} NumberOfComponents=\"{components}\" format=\"appended\" offset=\"{offset}\"/>\n",
            T::NAME
        )
    }

    /// Point positions.
    pub fn points(&mut self, positions: impl Iterator<Item = Vec3>) {
        self.points = self.array::<Real>("Points", 3, components(positions));
    }

    /// Cells as VTK's three arrays: every cell's point indices one after another, the end of
    /// each cell in that list, and the cell types. Indices are Int32 unless they need Int64.
    pub fn cells(&mut self, connectivity: &[usize], offsets: &[usize], types: &[u8]) {
        let wide = connectivity.len() > i32::MAX as usize || self.n_points > i32::MAX as usize;
        let (c, o) = if wide {
            (
                self.array("connectivity", 1, connectivity.iter().map(|&k| k as i64)),
                self.array("offsets", 1, offsets.iter().map(|&k| k as i64)),
            )
        } else {
            (
                self.array("connectivity", 1, connectivity.iter().map(|&k| k as i32)),
                self.array("offsets", 1, offsets.iter().map(|&k| k as i32)),
            )
        };
        let t = self.array("types", 1, types.iter().copied());
        self.cells = c + &o + &t;
    }

    /// One vertex cell per point (particles).
    pub fn vertex_cells(&mut self) {
        let n = self.n_points;
        let wide = n > i32::MAX as usize;
        let (c, o) = if wide {
            (
                self.array("connectivity", 1, 0..n as i64),
                self.array("offsets", 1, 1..=n as i64),
            )
        } else {
            (
                self.array("connectivity", 1, 0..n as i32),
                self.array("offsets", 1, 1..=n as i32),
            )
        };
        let t = self.array("types", 1, std::iter::repeat_n(VTK_VERTEX, n));
        self.cells = c + &o + &t;
    }

    /// A per-point array of `components` values each.
    pub fn point_array<T: VtkNumber>(
        &mut self,
        name: &str,
        components: usize,
        values: impl Iterator<Item = T>,
    ) {
        let tag = self.array(name, components, values);
        self.point_data += &tag;
    }

    pub fn point_vectors(&mut self, name: &str, values: impl Iterator<Item = Vec3>) {
        self.point_array(name, 3, components(values));
    }

    /// A per-cell array of `components` values each.
    pub fn cell_array<T: VtkNumber>(
        &mut self,
        name: &str,
        components: usize,
        values: impl Iterator<Item = T>,
    ) {
        let tag = self.array(name, components, values);
        self.cell_data += &tag;
    }

    pub fn cell_vectors(&mut self, name: &str, values: impl Iterator<Item = Vec3>) {
        self.cell_array(name, 3, components(values));
    }

    /// The whole file, as three parts to write one after another (no copy of the data).
    pub fn finish(self) -> [Vec<u8>; 3] {
        let mut xml = format!(
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n  <UnstructuredGrid>\n    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n",
            self.n_points, self.n_cells
        );
        for (tag, body) in [
            ("PointData", &self.point_data),
            ("CellData", &self.cell_data),
            ("Points", &self.points),
            ("Cells", &self.cells),
        ] {
            xml += &format!("      <{tag}>\n{body}      </{tag}>\n");
        }
        xml += "    </Piece>\n  </UnstructuredGrid>\n  <AppendedData encoding=\"raw\">\n   _";
        let tail = "\n  </AppendedData>\n</VTKFile>\n";
        [xml.into_bytes(), self.appended, tail.as_bytes().to_vec()]
    }
}

/// The components of 3-vectors one after another, with an exact size hint when the vectors
/// have one.
fn components(vectors: impl Iterator<Item = Vec3>) -> impl Iterator<Item = Real> {
    let (lower, upper) = vectors.size_hint();
    Exact {
        inner: vectors.flat_map(|v| v.to_array()),
        remaining: (upper == Some(lower)).then_some(3 * lower),
    }
}

/// An iterator with the length it was told.
struct Exact<I> {
    inner: I,
    remaining: Option<usize>,
}

impl<I: Iterator> Iterator for Exact<I> {
    type Item = I::Item;
    #[inline(always)]
    fn next(&mut self) -> Option<I::Item> {
        let v = self.inner.next()?;
        if let Some(r) = &mut self.remaining {
            *r = r.saturating_sub(1);
        }
        Some(v)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        match self.remaining {
            Some(r) => (r, Some(r)),
            None => (0, None),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Reads back the array at `offset` of the appended block: its byte count and bytes.
    fn block(file: &[u8], offset: usize) -> &[u8] {
        let tag = b"<AppendedData encoding=\"raw\">";
        let at = file.windows(tag.len()).position(|w| w == tag).unwrap();
        let underscore = at + file[at..].iter().position(|&b| b == b'_').unwrap();
        let data = &file[underscore + 1..];
        let len = u64::from_le_bytes(data[offset..offset + 8].try_into().unwrap()) as usize;
        &data[offset + 8..offset + 8 + len]
    }

    #[test]
    fn appended_blocks_hold_their_byte_counts_and_little_endian_values_at_the_stated_offsets() {
        let mut vtu = Vtu::new(2, 2, 0);
        vtu.point_array("id", 1, [7u32, 9].into_iter());
        vtu.point_vectors(
            "velocity",
            [Vec3::new(1.0, 2.0, 3.0), Vec3::new(-4.0, 5.5, 6.0)].into_iter(),
        );
        vtu.points([Vec3::ZERO, Vec3::ONE].into_iter());
        vtu.vertex_cells();
        let file = vtu.finish().concat();
        let text = String::from_utf8_lossy(&file);
        let offset = |name: &str| -> usize {
            let at = text.find(&format!("Name=\"{name}\"")).unwrap();
            let rest = &text[at..];
            let o = rest.find("offset=\"").unwrap() + 8;
            rest[o..o + rest[o..].find('"').unwrap()].parse().unwrap()
        };
        assert_eq!(block(&file, offset("id")), [7, 0, 0, 0, 9, 0, 0, 0]);
        let v: Vec<f64> = block(&file, offset("velocity"))
            .chunks(8)
            .map(|b| f64::from_le_bytes(b.try_into().unwrap()))
            .collect();
        assert_eq!(v, [1.0, 2.0, 3.0, -4.0, 5.5, 6.0]);
        let types = block(&file, offset("types"));
        assert_eq!(types, [VTK_VERTEX, VTK_VERTEX]);
        assert!(text.contains("NumberOfPoints=\"2\" NumberOfCells=\"2\""));
        assert!(text.contains("type=\"Int32\" Name=\"offsets\""));
        assert!(file.ends_with(b"\n  </AppendedData>\n</VTKFile>\n"));
    }
}
