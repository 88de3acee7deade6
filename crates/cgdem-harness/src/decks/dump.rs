//! Reader for `dump custom` text files: LAMMPS's layout, which LIGGGHTS (a LAMMPS fork)
//! writes too.

use std::path::{Path, PathBuf};

use cgdem_core::math::Real;

/// One snapshot: time step, box and per-atom columns by name.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    pub step: u64,
    /// Boundary flags as written (e.g. `pp pp ff`).
    pub boundary: String,
    /// (lo, hi) per axis.
    pub bounds: [[Real; 2]; 3],
    pub columns: Vec<String>,
    /// `values[c][atom]`.
    pub values: Vec<Vec<Real>>,
}

impl Frame {
    pub fn len(&self) -> usize {
        self.values.first().map_or(0, Vec::len)
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    pub fn column(&self, name: &str) -> Option<&[Real]> {
        self.columns
            .iter()
            .position(|c| c == name)
            .map(|k| self.values[k].as_slice())
    }
}

#[derive(Debug, thiserror::Error, PartialEq)]
#[error("{file}:{line}: {message}")]
pub struct DumpError {
    pub file: PathBuf,
    /// 1-based line number (the line after the last one for a truncated file).
    pub line: usize,
    pub message: String,
}

/// All frames of a dump file; a frame repeated at the same step (LAMMPS writes one at the
/// start of each `run`) is kept once.
pub fn read_dump(path: &Path) -> Result<Vec<Frame>, DumpError> {
    let text = std::fs::read_to_string(path).map_err(|e| DumpError {
        file: path.to_path_buf(),
        line: 0,
        message: format!("cannot read: {e}"),
    })?;
    parse_dump(&text, path)
}

/// Parses dump text; `path` is used in messages.
pub fn parse_dump(text: &str, path: &Path) -> Result<Vec<Frame>, DumpError> {
    let mut cursor = Cursor {
        lines: text.lines().collect(),
        at: 0,
        path,
    };
    let mut frames: Vec<Frame> = Vec::new();
    while let Some(first) = cursor.lines.get(cursor.at) {
        if first.trim().is_empty() {
            cursor.at += 1;
            continue;
        }
        let frame = cursor.frame()?;
        match frames.last() {
            Some(last) if last.step == frame.step => {}
            _ => frames.push(frame),
        }
    }
    Ok(frames)
}

/// The dump's lines and the next one to read.
struct Cursor<'a> {
    lines: Vec<&'a str>,
    at: usize,
    path: &'a Path,
}

impl<'a> Cursor<'a> {
    fn err(&self, line: usize, message: String) -> DumpError {
        DumpError {
            file: self.path.to_path_buf(),
            line,
            message,
        }
    }

    /// The line at `at` (advancing) with its 1-based number, or a truncation error naming
    /// what was expected.
    fn next(&mut self, what: &str) -> Result<(usize, &'a str), DumpError> {
        let k = self.at;
        self.at += 1;
        match self.lines.get(k) {
            Some(l) => Ok((k + 1, *l)),
            None => Err(self.err(k + 1, format!("file ends early: expected {what}"))),
        }
    }

    /// One frame, from its `ITEM: TIMESTEP` line to its last atom.
    fn frame(&mut self) -> Result<Frame, DumpError> {
        let (n, l) = self.next("ITEM: TIMESTEP")?;
        if l.trim() != "ITEM: TIMESTEP" {
            return Err(self.err(n, format!("expected `ITEM: TIMESTEP`, found `{l}`")));
        }
        let (n, l) = self.next("the time step")?;
        let step: u64 = l
            .trim()
            .parse()
            .map_err(|_| self.err(n, format!("time step `{l}` is not a non-negative integer")))?;
        let (n, l) = self.next("ITEM: NUMBER OF ATOMS")?;
        if l.trim() != "ITEM: NUMBER OF ATOMS" {
            return Err(self.err(n, format!("expected `ITEM: NUMBER OF ATOMS`, found `{l}`")));
        }
        let (n, l) = self.next("the number of atoms")?;
        let n_atoms: usize = l.trim().parse().map_err(|_| {
            self.err(
                n,
                format!("number of atoms `{l}` is not a non-negative integer"),
            )
        })?;
        let (boundary, bounds) = self.bounds()?;
        let (n, l) = self.next("ITEM: ATOMS")?;
        let Some(names) = l.trim().strip_prefix("ITEM: ATOMS") else {
            return Err(self.err(n, format!("expected `ITEM: ATOMS <columns>`, found `{l}`")));
        };
        let columns: Vec<String> = names.split_whitespace().map(String::from).collect();
        if columns.is_empty() {
            return Err(self.err(n, "`ITEM: ATOMS` names no columns".into()));
        }
        let values = self.atoms(&columns, n_atoms, step)?;
        Ok(Frame {
            step,
            boundary,
            bounds,
            columns,
            values,
        })
    }

    /// `ITEM: BOX BOUNDS <flags>` and its three lines: the flags and (lo, hi) per axis.
    fn bounds(&mut self) -> Result<(String, [[Real; 2]; 3]), DumpError> {
        let (n, l) = self.next("ITEM: BOX BOUNDS")?;
        let Some(boundary) = l.trim().strip_prefix("ITEM: BOX BOUNDS") else {
            return Err(self.err(n, format!("expected `ITEM: BOX BOUNDS ...`, found `{l}`")));
        };
        let boundary = boundary.trim().to_string();
        let mut bounds = [[0.0; 2]; 3];
        for (axis, b) in bounds.iter_mut().enumerate() {
            let (n, l) = self.next("a box bounds line")?;
            let v: Vec<Real> = l
                .split_whitespace()
                .map(str::parse)
                .collect::<Result<_, _>>()
                .map_err(|_| {
                    self.err(
                        n,
                        format!("box bounds of axis {axis}: `{l}` is not numbers"),
                    )
                })?;
            if v.len() < 2 {
                return Err(self.err(
                    n,
                    format!("box bounds of axis {axis}: expected lo hi, found `{l}`"),
                ));
            }
            *b = [v[0], v[1]];
        }
        Ok((boundary, bounds))
    }

    /// The `n_atoms` atom lines of a frame, as `values[column][atom]`.
    fn atoms(
        &mut self,
        columns: &[String],
        n_atoms: usize,
        step: u64,
    ) -> Result<Vec<Vec<Real>>, DumpError> {
        let mut values = vec![Vec::with_capacity(n_atoms); columns.len()];
        for atom in 0..n_atoms {
            let (n, l) = self.next(&format!(
                "atom line {} of {n_atoms} (step {step})",
                atom + 1
            ))?;
            let fields: Vec<&str> = l.split_whitespace().collect();
            if fields.len() != columns.len() {
                return Err(self.err(
                    n,
                    format!(
                        "atom line has {} values, the header names {} columns ({})",
                        fields.len(),
                        columns.len(),
                        columns.join(" ")
                    ),
                ));
            }
            for (c, f) in fields.iter().enumerate() {
                let v: Real = f.parse().map_err(|_| {
                    self.err(n, format!("column `{}`: `{f}` is not a number", columns[c]))
                })?;
                values[c].push(v);
            }
        }
        Ok(values)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TWO_FRAMES: &str = "ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS ff pp ff\n0 1\n0 2\n0 3\nITEM: ATOMS id type x y z\n1 1 0.1 0.2 0.3\n2 1 0.4 0.5 0.6\nITEM: TIMESTEP\n10\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS ff pp ff\n0 1\n0 2\n0 3\nITEM: ATOMS id type x y z\n1 1 0.15 0.2 0.3\n2 1 0.4 0.5 0.65\n";

    #[test]
    fn reads_frames_and_columns_by_name() {
        let frames = parse_dump(TWO_FRAMES, Path::new("t.dump")).unwrap();
        assert_eq!(frames.len(), 2);
        assert_eq!(frames[1].step, 10);
        assert_eq!(frames[1].column("x").unwrap(), &[0.15, 0.4]);
        assert_eq!(frames[0].bounds[2], [0.0, 3.0]);
        assert_eq!(frames[0].boundary, "ff pp ff");
    }

    #[test]
    fn truncated_dump_names_file_line_and_what_is_missing() {
        let cut = &TWO_FRAMES[..TWO_FRAMES.rfind("2 1 0.4").unwrap()];
        let e = parse_dump(cut, Path::new("run/traj.dump")).unwrap_err();
        assert_eq!(e.line, 22);
        let message = e.to_string();
        assert!(
            message.starts_with("run/traj.dump:22: file ends early"),
            "{message}"
        );
        assert!(message.contains("atom line 2 of 2 (step 10)"), "{message}");
    }

    #[test]
    fn malformed_values_are_reported_with_their_column() {
        let bad = TWO_FRAMES.replace("0.15", "0.1.5");
        let e = parse_dump(&bad, Path::new("t.dump")).unwrap_err();
        assert_eq!(e.line, 21);
        assert!(e.to_string().contains("column `x`: `0.1.5`"), "{e}");
        let short = TWO_FRAMES.replace("1 1 0.15 0.2 0.3", "1 1 0.15 0.2");
        assert!(parse_dump(&short, Path::new("t.dump"))
            .unwrap_err()
            .to_string()
            .contains("4 values, the header names 5"));
    }

    /// The first frame of a dump written by LIGGGHTS 3.8.0 (tests/hertz_golden.rs, oblique
    /// pair): trailing spaces, `-0`, and 17 significant digits.
    const LIGGGHTS_DUMP: &str = "ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS ff ff ff\n-0.01 0.01\n-0.01 0.01\n-0.01 0.01\nITEM: ATOMS id type x y z vx vy vz omegax omegay omegaz radius \n1 1 -0.00086645841648633085 -0.00050025000000000004 -0 0.5 0 0 0 0 300 0.001 \n2 1 0.00086645841648633085 0.00050025000000000004 0 -0.5 0 0 0 0 0 0.001 \n";

    #[test]
    fn reads_a_liggghts_dump_with_spins() {
        let frames = parse_dump(LIGGGHTS_DUMP, Path::new("traj.dump")).unwrap();
        assert_eq!(frames.len(), 1);
        assert_eq!(frames[0].column("omegaz").unwrap(), &[300.0, 0.0]);
        assert_eq!(frames[0].column("y").unwrap()[1], 0.000_500_25); // 17 digits of the same double
        assert_eq!(frames[0].column("z").unwrap(), &[0.0, 0.0]);
        assert_eq!(frames[0].boundary, "ff ff ff");
    }
}
