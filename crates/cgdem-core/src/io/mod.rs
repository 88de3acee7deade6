//! Files a run writes: VTK for ParaView, CSV tables, the JSON summary.

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

/// A CSV table built in memory and then written whole (with [`write_atomic`]): quoting by the
/// `csv` crate (RFC 4180, only where a field needs it), fields formatted by the caller. A
/// row whose length differs from the header's is an error, reported by [`CsvBuffer::bytes`].
pub struct CsvBuffer {
    writer: csv::Writer<Vec<u8>>,
    error: Option<csv::Error>,
}

impl CsvBuffer {
    /// A table with the header line `header`.
    pub fn new<I, F>(header: I) -> CsvBuffer
    where
        I: IntoIterator<Item = F>,
        F: AsRef<[u8]>,
    {
        let mut table = CsvBuffer {
            writer: csv::Writer::from_writer(Vec::new()),
            error: None,
        };
        table.row(header);
        table
    }

    /// Appends one row.
    pub fn row<I, F>(&mut self, fields: I)
    where
        I: IntoIterator<Item = F>,
        F: AsRef<[u8]>,
    {
        if self.error.is_none() {
            self.error = self.writer.write_record(fields).err();
        }
    }

    /// The table so far (header and rows), or the first error of a row.
    pub fn bytes(&mut self) -> std::io::Result<&[u8]> {
        if let Some(e) = &self.error {
            return Err(std::io::Error::other(e.to_string()));
        }
        self.writer.flush()?;
        Ok(self.writer.get_ref())
    }
}

#[cfg(test)]
mod tests {
    use super::CsvBuffer;

    #[test]
    fn csv_buffer_quotes_only_where_needed_and_refuses_ragged_rows() {
        let mut t = CsvBuffer::new(["case", "value", "message"]);
        t.row(["heap", "1.5e-3", "plain"]);
        t.row(["screw, short", "", "said \"no\""]);
        assert_eq!(
            t.bytes().unwrap(),
            b"case,value,message\nheap,1.5e-3,plain\n\"screw, short\",,\"said \"\"no\"\"\"\n"
        );
        t.row(["only two", "fields"]);
        let e = t.bytes().unwrap_err();
        assert!(e.to_string().contains("found record with 2 fields"), "{e}");
    }
}
