//! Reading the CSV files cgdem and the reference post-processing write (`timeseries.csv`,
//! `profile.csv`, `pore_size.csv`, the published reference points): columns by their header
//! name, values parsed on demand, every error naming the file, the line and the column.

use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;

/// A CSV file read whole: its header and rows, with the line each row started on.
#[derive(Clone, Debug)]
pub struct CsvTable {
    path: PathBuf,
    header: Vec<String>,
    rows: Vec<(u64, csv::StringRecord)>,
}

/// What went wrong reading a table, and where.
#[derive(Clone, Debug, PartialEq)]
pub struct TableError {
    pub path: PathBuf,
    /// 1-based line of the file (None: the file as a whole).
    pub line: Option<u64>,
    pub column: Option<String>,
    pub message: String,
}

impl fmt::Display for TableError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.path.display())?;
        if let Some(line) = self.line {
            write!(f, ":{line}")?;
        }
        if let Some(column) = &self.column {
            write!(f, ": column `{column}`")?;
        }
        write!(f, ": {}", self.message)
    }
}

impl std::error::Error for TableError {}

/// A column found in the header (see [`CsvTable::column`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Column(usize);

impl CsvTable {
    /// Reads `path`; lines starting with `#` are comments, blank lines are skipped.
    pub fn read(path: &Path) -> Result<CsvTable, TableError> {
        let text = std::fs::read(path).map_err(|e| TableError {
            path: path.to_path_buf(),
            line: None,
            column: None,
            message: format!("cannot read: {e}"),
        })?;
        CsvTable::parse(path, &text)
    }

    /// Parses `text` as the contents of `path` (named in errors).
    pub fn parse(path: &Path, text: &[u8]) -> Result<CsvTable, TableError> {
        let error = |line: Option<u64>, message: String| TableError {
            path: path.to_path_buf(),
            line,
            column: None,
            message,
        };
        let mut reader = csv::ReaderBuilder::new()
            .comment(Some(b'#'))
            .flexible(true)
            .from_reader(text);
        let header = reader
            .headers()
            .map_err(|e| error(e.position().map(|p| p.line()), e.to_string()))?
            .iter()
            .map(String::from)
            .collect::<Vec<_>>();
        if header.iter().all(|h| h.is_empty()) {
            return Err(error(None, "no header line".into()));
        }
        // Lines counted from byte offsets: the csv crate's own count passes over blank lines.
        let mut counted = (0, 1);
        let mut line_at = |byte: u64| {
            let (from, line) = counted;
            // A record's position is where the reader began looking for it: before the
            // blank and comment lines it passed over.
            let mut byte = (byte as usize).min(text.len());
            while byte < text.len() {
                match text[byte] {
                    b'\n' | b'\r' => byte += 1,
                    b'#' => {
                        byte = text[byte..]
                            .iter()
                            .position(|&b| b == b'\n')
                            .map_or(text.len(), |k| byte + k + 1)
                    }
                    _ => break,
                }
            }
            counted = (
                byte,
                line + text[from..byte].iter().filter(|&&b| b == b'\n').count() as u64,
            );
            counted.1
        };
        let mut rows = Vec::new();
        for record in reader.records() {
            let record = record.map_err(|e| {
                let line = e.position().map(|p| p.byte());
                error(line.map(&mut line_at), e.to_string())
            })?;
            let line = line_at(record.position().map_or(0, |p| p.byte()));
            rows.push((line, record));
        }
        Ok(CsvTable {
            path: path.to_path_buf(),
            header,
            rows,
        })
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    pub fn header(&self) -> &[String] {
        &self.header
    }

    pub fn len(&self) -> usize {
        self.rows.len()
    }

    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// The column named `name`; an error naming the file and the columns it has otherwise.
    pub fn column(&self, name: &str) -> Result<Column, TableError> {
        self.header
            .iter()
            .position(|h| h == name)
            .map(Column)
            .ok_or_else(|| TableError {
                path: self.path.clone(),
                line: Some(1),
                column: Some(name.to_string()),
                message: format!(
                    "missing from the header (it has: {})",
                    self.header.join(", ")
                ),
            })
    }

    /// The numbers in the columns `names`, one vector per row in the order of `names`.
    pub fn numbers(&self, names: &[&str]) -> Result<Vec<Vec<f64>>, TableError> {
        let columns = names
            .iter()
            .map(|n| self.column(n))
            .collect::<Result<Vec<_>, _>>()?;
        self.rows()
            .map(|row| columns.iter().map(|&c| row.parse(c)).collect())
            .collect()
    }

    pub fn rows(&self) -> impl Iterator<Item = Row<'_>> {
        self.rows.iter().map(move |(line, record)| Row {
            table: self,
            line: *line,
            record,
        })
    }
}

/// One row of a [`CsvTable`].
#[derive(Clone, Copy, Debug)]
pub struct Row<'a> {
    table: &'a CsvTable,
    line: u64,
    record: &'a csv::StringRecord,
}

impl<'a> Row<'a> {
    /// The line of the file this row starts on.
    pub fn line(&self) -> u64 {
        self.line
    }

    fn error(&self, column: Column, message: String) -> TableError {
        TableError {
            path: self.table.path.clone(),
            line: Some(self.line),
            column: Some(self.table.header[column.0].clone()),
            message,
        }
    }

    /// The text of `column` (an error if the row is shorter than the header).
    pub fn text(&self, column: Column) -> Result<&'a str, TableError> {
        self.record.get(column.0).ok_or_else(|| {
            self.error(
                column,
                format!("missing (the row has {} fields)", self.record.len()),
            )
        })
    }

    /// `column` parsed as a `T` (surrounding blanks ignored).
    pub fn parse<T: FromStr>(&self, column: Column) -> Result<T, TableError>
    where
        T::Err: fmt::Display,
    {
        let text = self.text(column)?;
        text.trim()
            .parse()
            .map_err(|e| self.error(column, format!("`{text}` is not a number: {e}")))
    }

    /// `column` parsed as a `T`; None when the field is empty.
    pub fn parse_optional<T: FromStr>(&self, column: Column) -> Result<Option<T>, TableError>
    where
        T::Err: fmt::Display,
    {
        match self.text(column)?.trim() {
            "" => Ok(None),
            _ => self.parse(column).map(Some),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(text: &str) -> Result<CsvTable, TableError> {
        CsvTable::parse(Path::new("run/timeseries.csv"), text.as_bytes())
    }

    #[test]
    fn columns_by_name_with_comments_blank_lines_and_quoted_fields() {
        let t =
            table("# made by a test\nx_m,label,height_m\n1.5e-3,\"a, b\",2\n\n# note\n3,c,4.25\n")
                .unwrap();
        let (x, label, h) = (
            t.column("x_m").unwrap(),
            t.column("label").unwrap(),
            t.column("height_m").unwrap(),
        );
        let rows: Vec<(f64, String, f64)> = t
            .rows()
            .map(|r| {
                (
                    r.parse(x).unwrap(),
                    r.text(label).unwrap().to_string(),
                    r.parse(h).unwrap(),
                )
            })
            .collect();
        assert_eq!(
            rows,
            [(1.5e-3, "a, b".into(), 2.0), (3.0, "c".into(), 4.25)]
        );
        assert_eq!(t.rows().map(|r| r.line()).collect::<Vec<_>>(), [3, 6]);
    }

    #[test]
    fn errors_name_the_file_the_line_and_the_column() {
        let t = table("time_s,stage,n_particles\n0,fill,10\n1e-3,fill,ten\n2e-3,fill\n").unwrap();
        let n = t.column("n_particles").unwrap();
        let rows: Vec<Row> = t.rows().collect();
        assert_eq!(rows[0].parse::<usize>(n), Ok(10));
        assert_eq!(
            rows[1].parse::<usize>(n).unwrap_err().to_string(),
            "run/timeseries.csv:3: column `n_particles`: `ten` is not a number: \
             invalid digit found in string"
        );
        assert_eq!(
            rows[2].parse::<usize>(n).unwrap_err().to_string(),
            "run/timeseries.csv:4: column `n_particles`: missing (the row has 2 fields)"
        );
        assert_eq!(
            t.column("front_m").unwrap_err().to_string(),
            "run/timeseries.csv:1: column `front_m`: missing from the header \
             (it has: time_s, stage, n_particles)"
        );
        let empty = table("").unwrap_err();
        assert_eq!(empty.to_string(), "run/timeseries.csv: no header line");
        let missing = CsvTable::read(Path::new("/nonexistent/profile.csv")).unwrap_err();
        assert!(missing
            .to_string()
            .starts_with("/nonexistent/profile.csv: cannot read: "));
    }

    #[test]
    fn empty_fields_are_none_when_optional() {
        let t = table("a,b\n,2\n").unwrap();
        let row = t.rows().next().unwrap();
        assert_eq!(row.parse_optional::<f64>(t.column("a").unwrap()), Ok(None));
        assert_eq!(
            row.parse_optional::<f64>(t.column("b").unwrap()),
            Ok(Some(2.0))
        );
        assert!(row.parse::<f64>(t.column("a").unwrap()).is_err());
    }
}
