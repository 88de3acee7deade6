//! LAMMPS data files for `atom_style sphere` (LIGGGHTS `granular`: the same columns), read
//! (`read_data`) and written: a title line, the header (`N atoms`, `M atom types`, `lo hi
//! xlo xhi` and likewise y, z), `Atoms # sphere` with one line `atom-ID atom-type diameter
//! density x y z` per atom (three image flags may follow; they are ignored, positions are
//! taken as they stand) and an optional `Velocities` section, `atom-ID vx vy vz wx wy wz`.
//! `Masses` and `Pair Coeffs` sections are skipped: the scene's species and `[contact]` say
//! what they would. Text after `#` is a comment (on the `Atoms` line it names the style).

use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::math::{Real, Vec3};
use crate::particles::Particles;

/// One line of the `Atoms` section.
#[derive(Clone, Debug, PartialEq)]
pub struct DataAtom {
    /// 1-based line in the file, for messages.
    pub line: usize,
    pub id: u64,
    pub atom_type: u64,
    pub diameter: Real,
    pub density: Real,
    pub position: Vec3,
}

/// One line of the `Velocities` section (m/s, rad/s).
#[derive(Clone, Debug, PartialEq)]
pub struct DataVelocity {
    pub line: usize,
    pub velocity: Vec3,
    pub omega: Vec3,
}

/// A data file as read: atoms in file order, each with its velocity line (if the file has a
/// `Velocities` section, every atom has one).
#[derive(Clone, Debug, PartialEq)]
pub struct DataFile {
    pub atom_types: u64,
    pub lo: Vec3,
    pub hi: Vec3,
    pub atoms: Vec<DataAtom>,
    pub velocities: Option<Vec<DataVelocity>>,
}

/// What is wrong, where: the file, the line (none: the file as a whole), the field (section
/// and column, or header keyword), the value and what is allowed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}{}: field `{field}` = {value} is not allowed: {allowed}", .file.display(), .line.map(|l| format!(":{l}")).unwrap_or_default())]
pub struct DataFileError {
    pub file: PathBuf,
    pub line: Option<usize>,
    pub field: String,
    pub value: String,
    pub allowed: String,
}

const ATOM_COLUMNS: [&str; 7] = ["atom-ID", "atom-type", "diameter", "density", "x", "y", "z"];
const VELOCITY_COLUMNS: [&str; 7] = ["atom-ID", "vx", "vy", "vz", "wx", "wy", "wz"];
/// Sections read past: what they hold comes from the scene.
const SKIPPED_SECTIONS: [&str; 3] = ["Masses", "Pair Coeffs", "PairIJ Coeffs"];

struct Reader<'a> {
    file: &'a Path,
}

impl Reader<'_> {
    fn error(
        &self,
        line: Option<usize>,
        field: impl Into<String>,
        value: impl std::fmt::Display,
        allowed: impl Into<String>,
    ) -> DataFileError {
        DataFileError {
            file: self.file.to_path_buf(),
            line,
            field: field.into(),
            value: value.to_string(),
            allowed: allowed.into(),
        }
    }

    fn real(&self, line: usize, field: String, token: &str) -> Result<Real, DataFileError> {
        match token.parse::<Real>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(self.error(Some(line), field, token, "a finite number")),
        }
    }

    fn positive(&self, line: usize, field: String, token: &str) -> Result<Real, DataFileError> {
        match self.real(line, field.clone(), token)? {
            v if v > 0.0 => Ok(v),
            _ => Err(self.error(Some(line), field, token, "a finite number > 0")),
        }
    }

    fn count(&self, line: usize, field: String, token: &str) -> Result<u64, DataFileError> {
        token
            .parse::<u64>()
            .map_err(|_| self.error(Some(line), field, token, "a whole number >= 0"))
    }
}

/// Whether a line (comment removed) starts a section: its first character is a letter.
fn is_keyword(content: &str) -> bool {
    content
        .chars()
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic())
}

/// Reads a data file's text; `file` is named in errors.
pub fn parse_data(text: &str, file: &Path) -> Result<DataFile, DataFileError> {
    let r = Reader { file };
    let lines: Vec<Line> = text
        .lines()
        .enumerate()
        .skip(1) // the title line, as LAMMPS skips it
        .map(|(k, l)| {
            let (content, comment) = l.split_once('#').unwrap_or((l, ""));
            (k + 1, content.trim(), comment.trim())
        })
        .collect();
    let (n_atoms, atom_types, lo, hi, mut k) = parse_header(&r, &lines)?;

    let mut atoms: Option<Vec<DataAtom>> = None;
    // (section line, rows)
    let mut velocity_rows: Option<(usize, Vec<VelocityRow>)> = None;
    let mut skipped_seen: Vec<&str> = Vec::new();
    while k < lines.len() {
        let (line, keyword, comment) = lines[k];
        k += 1;
        let start = k;
        while k < lines.len() && !is_keyword(lines[k].1) {
            k += 1;
        }
        let rows = lines[start..k]
            .iter()
            .filter(|(_, content, _)| !content.is_empty());
        match keyword {
            "Atoms" => {
                if atoms.is_some() {
                    return Err(r.error(Some(line), "Atoms", "a second section", "one"));
                }
                atoms = Some(parse_atoms(&r, line, comment, rows, n_atoms, atom_types)?);
            }
            "Velocities" => {
                if velocity_rows.is_some() {
                    return Err(r.error(Some(line), "Velocities", "a second section", "one"));
                }
                velocity_rows = Some((line, parse_velocity_rows(&r, rows)?));
            }
            name if SKIPPED_SECTIONS.contains(&name) && !skipped_seen.contains(&name) => {
                skipped_seen.push(name);
            }
            other => return Err(r.error(
                Some(line),
                "section",
                format!("\"{other}\""),
                "`Atoms # sphere`, `Velocities` (and `Masses`, `Pair Coeffs`, skipped), each once",
            )),
        }
    }
    let atoms = match atoms {
        Some(a) => a,
        None if n_atoms == 0 => Vec::new(),
        None => {
            return Err(r.error(
                None,
                "Atoms",
                "missing",
                "an `Atoms # sphere` section: atom-ID atom-type diameter density x y z",
            ))
        }
    };
    let velocities = match velocity_rows {
        None => None,
        Some((header, rows)) => Some(match_velocities(&r, &atoms, header, rows)?),
    };
    Ok(DataFile {
        atom_types,
        lo,
        hi,
        atoms,
        velocities,
    })
}

/// A `Velocities` row: (line, atom-ID, vx vy vz wx wy wz).
type VelocityRow = (usize, u64, [Real; 6]);

/// A line of the file: (line number, content without comment, comment).
type Line<'a> = (usize, &'a str, &'a str);

/// The header before the first section: (atoms, atom types, box lo, box hi, index of the
/// first section's line).
fn parse_header(
    r: &Reader,
    lines: &[Line],
) -> Result<(u64, u64, Vec3, Vec3, usize), DataFileError> {
    let mut n_atoms = None;
    let mut atom_types = None;
    let mut bounds: [Option<(Real, Real)>; 3] = [None; 3];
    let mut k = 0;
    while k < lines.len() && !is_keyword(lines[k].1) {
        let (line, content, _) = lines[k];
        k += 1;
        if content.is_empty() {
            continue;
        }
        let tokens: Vec<&str> = content.split_whitespace().collect();
        match tokens.as_slice() {
            [n, "atoms"] => n_atoms = Some(r.count(line, "atoms".into(), n)?),
            [n, "atom", "types"] => {
                let n = r.count(line, "atom types".into(), n)?;
                if n == 0 {
                    return Err(r.error(Some(line), "atom types", n, "at least 1"));
                }
                atom_types = Some(n);
            }
            [lo, hi, name_lo, name_hi]
                if ["x", "y", "z"]
                    .iter()
                    .any(|a| *name_lo == format!("{a}lo") && *name_hi == format!("{a}hi")) =>
            {
                let axis = usize::from(name_lo.as_bytes()[0] - b'x');
                let field = format!("{name_lo} {name_hi}");
                let (lo, hi) = (
                    r.real(line, field.clone(), lo)?,
                    r.real(line, field.clone(), hi)?,
                );
                if hi <= lo {
                    return Err(r.error(Some(line), field, format!("{lo} {hi}"), "lo < hi"));
                }
                bounds[axis] = Some((lo, hi));
            }
            _ => {
                return Err(r.error(
                    Some(line),
                    "header",
                    format!("\"{content}\""),
                    "`N atoms`, `M atom types` or `lo hi xlo xhi` (ylo yhi, zlo zhi): cgdem reads atom_style sphere data (no bonds, no triclinic box)",
                ))
            }
        }
    }
    let n_atoms = n_atoms.ok_or_else(|| {
        r.error(
            None,
            "atoms",
            "missing",
            "a header line `N atoms` before the first section",
        )
    })?;
    let atom_types = atom_types.ok_or_else(|| {
        r.error(
            None,
            "atom types",
            "missing",
            "a header line `M atom types` before the first section",
        )
    })?;
    let mut lo = Vec3::ZERO;
    let mut hi = Vec3::ZERO;
    for (axis, b) in bounds.iter().enumerate() {
        let name = ["x", "y", "z"][axis];
        let (l, h) = b.ok_or_else(|| {
            r.error(
                None,
                format!("{name}lo {name}hi"),
                "missing",
                "the box in the header, `lo hi xlo xhi` and likewise for y and z",
            )
        })?;
        lo[axis] = l;
        hi[axis] = h;
    }

    Ok((n_atoms, atom_types, lo, hi, k))
}

/// The `Atoms # sphere` section starting on `line` (its comment `comment`), with its `rows`.
fn parse_atoms<'a>(
    r: &Reader,
    line: usize,
    comment: &str,
    rows: impl Iterator<Item = &'a Line<'a>>,
    n_atoms: u64,
    atom_types: u64,
) -> Result<Vec<DataAtom>, DataFileError> {
    if !["", "sphere", "granular"].contains(&comment) {
        return Err(r.error(
            Some(line),
            "Atoms",
            format!("\"Atoms # {comment}\""),
            "`Atoms # sphere` (LIGGGHTS: `# granular`): atom-ID atom-type diameter density x y z",
        ));
    }
    let mut list = Vec::new();
    let mut first_line: HashMap<u64, usize> = HashMap::new();
    for &(row, content, _) in rows {
        let t: Vec<&str> = content.split_whitespace().collect();
        if t.len() != 7 && t.len() != 10 {
            return Err(r.error(
                Some(row),
                "Atoms",
                format!("{} columns", t.len()),
                "7 columns, atom-ID atom-type diameter density x y z (and optionally 3 image flags)",
            ));
        }
        let field = |c: usize| format!("Atoms {}", ATOM_COLUMNS[c]);
        let id = r.count(row, field(0), t[0])?;
        if id == 0 {
            return Err(r.error(Some(row), field(0), 0, "a whole number >= 1"));
        }
        if let Some(previous) = first_line.insert(id, row) {
            return Err(r.error(
                Some(row),
                field(0),
                id,
                format!("each atom-ID once (this one is also on line {previous})"),
            ));
        }
        let atom_type = r.count(row, field(1), t[1])?;
        if atom_type == 0 || atom_type > atom_types {
            return Err(r.error(
                Some(row),
                field(1),
                atom_type,
                format!("1 to {atom_types} (the header's `atom types`)"),
            ));
        }
        for (c, flag) in t.iter().enumerate().skip(7) {
            if flag.parse::<i64>().is_err() {
                return Err(r.error(
                    Some(row),
                    format!("Atoms image flag {}", c - 6),
                    flag,
                    "an integer",
                ));
            }
        }
        list.push(DataAtom {
            line: row,
            id,
            atom_type,
            diameter: r.positive(row, field(2), t[2])?,
            density: r.positive(row, field(3), t[3])?,
            position: Vec3::new(
                r.real(row, field(4), t[4])?,
                r.real(row, field(5), t[5])?,
                r.real(row, field(6), t[6])?,
            ),
        });
    }
    if list.len() as u64 != n_atoms {
        return Err(r.error(
            Some(line),
            "Atoms",
            format!("{} lines", list.len()),
            format!("one line per atom: {n_atoms} (the header's `atoms`)"),
        ));
    }
    Ok(list)
}

/// The `Velocities` section's rows: (line, atom-ID, vx vy vz wx wy wz).
fn parse_velocity_rows<'a>(
    r: &Reader,
    rows: impl Iterator<Item = &'a Line<'a>>,
) -> Result<Vec<VelocityRow>, DataFileError> {
    let mut list = Vec::new();
    for &(row, content, _) in rows {
        let t: Vec<&str> = content.split_whitespace().collect();
        if t.len() != 7 {
            return Err(r.error(
                Some(row),
                "Velocities",
                format!("{} columns", t.len()),
                "7 columns, atom-ID vx vy vz wx wy wz",
            ));
        }
        let field = |c: usize| format!("Velocities {}", VELOCITY_COLUMNS[c]);
        let id = r.count(row, field(0), t[0])?;
        let mut values = [0.0; 6];
        for (c, v) in values.iter_mut().enumerate() {
            *v = r.real(row, field(c + 1), t[c + 1])?;
        }
        list.push((row, id, values));
    }
    Ok(list)
}

/// Each atom's velocity and spin from the `Velocities` rows (section on line `header`):
/// every atom once, no other atom-ID.
fn match_velocities(
    r: &Reader,
    atoms: &[DataAtom],
    header: usize,
    rows: Vec<VelocityRow>,
) -> Result<Vec<DataVelocity>, DataFileError> {
    let index: HashMap<u64, usize> = atoms.iter().enumerate().map(|(k, a)| (a.id, k)).collect();
    let mut out: Vec<Option<DataVelocity>> = vec![None; atoms.len()];
    for (row, id, v) in rows {
        let Some(&k) = index.get(&id) else {
            return Err(r.error(
                Some(row),
                "Velocities atom-ID",
                id,
                "an atom-ID of the `Atoms` section",
            ));
        };
        if let Some(previous) = &out[k] {
            return Err(r.error(
                Some(row),
                "Velocities atom-ID",
                id,
                format!(
                    "each atom-ID once (this one is also on line {})",
                    previous.line
                ),
            ));
        }
        out[k] = Some(DataVelocity {
            line: row,
            velocity: Vec3::new(v[0], v[1], v[2]),
            omega: Vec3::new(v[3], v[4], v[5]),
        });
    }
    if let Some(k) = out.iter().position(Option::is_none) {
        return Err(r.error(
            Some(header),
            "Velocities",
            format!("no line for atom-ID {}", atoms[k].id),
            "one line per atom of the `Atoms` section",
        ));
    }
    Ok(out.into_iter().flatten().collect())
}

fn g(x: Real) -> String {
    format!("{x:.17e}")
}

/// A data file for `atom_style sphere` (LAMMPS) or `granular` (LIGGGHTS, same columns):
/// `title` on the first line, `n_types` atom types, per species the diameter and density
/// given, the particles' positions, velocities and spins (zero without angular state). Ids
/// are `id + 1`, types `species + 1`. Numbers in `%.17e`, so reading it back is exact.
pub fn data_text(
    title: &str,
    lo: Vec3,
    hi: Vec3,
    particles: &Particles,
    diameters: &[Real],
    densities: &[Real],
    n_types: usize,
) -> String {
    let mut data = format!(
        "{title}\n\n{} atoms\n{} atom types\n\n",
        particles.len(),
        n_types
    );
    for (axis, name) in ["x", "y", "z"].iter().enumerate() {
        let _ = writeln!(data, "{} {} {name}lo {name}hi", g(lo[axis]), g(hi[axis]));
    }
    data += "\nAtoms # sphere\n\n";
    for k in 0..particles.len() {
        let species = particles.species[k] as usize;
        let p = particles.position[k];
        let _ = writeln!(
            data,
            "{} {} {} {} {} {} {}",
            particles.id[k] + 1,
            species + 1,
            g(diameters[species]),
            g(densities[species]),
            g(p.x),
            g(p.y),
            g(p.z)
        );
    }
    data += "\nVelocities\n\n";
    for k in 0..particles.len() {
        let v = particles.velocity[k];
        let w = particles
            .angular
            .as_ref()
            .map_or(Vec3::ZERO, |a| a.omega[k]);
        let _ = writeln!(
            data,
            "{} {} {} {} {} {} {}",
            particles.id[k] + 1,
            g(v.x),
            g(v.y),
            g(v.z),
            g(w.x),
            g(w.y),
            g(w.z)
        );
    }
    data
}

#[cfg(test)]
mod tests {
    use super::*;

    const FILE: &str = "start.data";

    const GOOD: &str = "LAMMPS data file
# comment

3 atoms
2 atom types

0.0 1.0 xlo xhi
0.0 1.0 ylo yhi
0.0 2.0 zlo zhi

Atoms # sphere

3 2 0.1 2500 0.5 0.5 0.5
1 1 0.1 2500 0.2 0.2 0.2 0 0 0
2 1 0.1 2500 0.8 0.8 0.8

Velocities

2 0 0 -1 0 0 0
1 1 0 0 0 5 0
3 0 0 0 0 0 -7
";

    fn err(text: &str) -> String {
        parse_data(text, Path::new(FILE)).unwrap_err().to_string()
    }

    #[test]
    fn a_sphere_data_file_is_read_with_each_velocity_beside_its_atom() {
        let d = parse_data(GOOD, Path::new(FILE)).unwrap();
        assert_eq!(d.atom_types, 2);
        assert_eq!(d.hi, Vec3::new(1.0, 1.0, 2.0));
        assert_eq!(
            d.atoms.iter().map(|a| a.id).collect::<Vec<_>>(),
            vec![3, 1, 2]
        );
        assert_eq!(d.atoms[0].atom_type, 2);
        assert_eq!(d.atoms[1].line, 14);
        let v = d.velocities.unwrap();
        assert_eq!(v[0].omega, Vec3::new(0.0, 0.0, -7.0));
        assert_eq!(v[1].velocity, Vec3::new(1.0, 0.0, 0.0));
        assert_eq!(v[1].omega, Vec3::new(0.0, 5.0, 0.0));
        assert_eq!(v[2].velocity, Vec3::new(0.0, 0.0, -1.0));
    }

    #[test]
    fn bad_data_files_name_the_file_line_and_field() {
        let cases = [
            (
                GOOD.replace("Atoms # sphere", "Atoms # atomic"),
                ":11: field `Atoms`",
                "sphere",
            ),
            (
                GOOD.replace("3 2 0.1 2500 0.5 0.5 0.5", "3 2 0.1 2500 0.5 0.5"),
                ":13: field `Atoms` = 6 columns",
                "7 columns",
            ),
            (
                GOOD.replace("3 2 0.1", "3 4 0.1"),
                ":13: field `Atoms atom-type` = 4",
                "1 to 2",
            ),
            (
                GOOD.replace("0.8 0.8 0.8", "0.8 nan 0.8"),
                ":15: field `Atoms y` = nan",
                "finite",
            ),
            (
                GOOD.replace("2 1 0.1", "1 1 0.1"),
                ":15: field `Atoms atom-ID` = 1",
                "line 14",
            ),
            (
                GOOD.replace("2 1 0.1 2500", "2 1 -0.1 2500"),
                ":15: field `Atoms diameter`",
                "> 0",
            ),
            (
                GOOD.replace("3 0 0 0 0 0 -7", "4 0 0 0 0 0 -7"),
                ":21: field `Velocities atom-ID` = 4",
                "Atoms",
            ),
            (
                GOOD.replace("3 0 0 0 0 0 -7", "1 0 0 0 0 0 -7"),
                ":21: field `Velocities atom-ID` = 1",
                "line 20",
            ),
            (
                GOOD.replace("1 1 0 0 0 5 0", "1 1 0 0 0 inf 0"),
                ":20: field `Velocities wy` = inf",
                "finite",
            ),
            (
                GOOD.replace("3 atoms", "4 atoms"),
                ":11: field `Atoms` = 3 lines",
                "4",
            ),
            (
                GOOD.replace("Atoms # sphere", "Bonds"),
                ":11: field `section`",
                "Atoms",
            ),
            (
                GOOD.replace("2 atom types", "2 bond types"),
                ":5: field `header`",
                "atom types",
            ),
            (
                GOOD.replace("0.0 2.0 zlo zhi", ""),
                ": field `zlo zhi` = missing",
                "box",
            ),
        ];
        for (text, at, allowed) in cases {
            let m = err(&text);
            assert!(
                m.starts_with(FILE) && m.contains(at) && m.contains(allowed),
                "{m}"
            );
        }
        let m = err(&GOOD[..GOOD.find("Atoms").unwrap()]);
        assert!(m.contains("field `Atoms` = missing"), "{m}");
    }

    #[test]
    fn written_particles_read_back_exactly() {
        let mut p = Particles::new(true);
        p.push(0, Vec3::new(0.1, 0.2, 0.3), 0.05, 1.0);
        p.push(1, Vec3::new(1.0 / 3.0, 0.7, 1e-9), 0.05, 1.0);
        p.velocity[1] = Vec3::new(-0.1, 2.0 / 3.0, 0.0);
        p.angular.as_mut().unwrap().omega[0] = Vec3::new(0.0, 1.0 / 7.0, 3.0);
        let text = data_text(
            "t",
            Vec3::ZERO,
            Vec3::ONE,
            &p,
            &[0.1, 0.1],
            &[2500.0, 2.5],
            3,
        );
        let d = parse_data(&text, Path::new(FILE)).unwrap();
        let v = d.velocities.unwrap();
        for (k, (a, v)) in d.atoms.iter().zip(&v).enumerate() {
            assert_eq!(a.id, k as u64 + 1);
            assert_eq!(a.atom_type, k as u64 + 1);
            assert_eq!(a.position, p.position[k]);
            assert_eq!(v.velocity, p.velocity[k]);
            assert_eq!(v.omega, p.angular.as_ref().unwrap().omega[k]);
        }
        assert_eq!(d.atoms.len(), 2);
        assert_eq!(d.atoms[1].density, 2.5);
    }
}
