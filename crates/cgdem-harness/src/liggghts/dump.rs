//! LIGGGHTS `dump custom` files: the same text layout as LAMMPS's (LIGGGHTS is a LAMMPS
//! fork), so the LAMMPS reader parses them; this module pins that with a LIGGGHTS dump.

pub use crate::lammps::dump::{parse_dump, read_dump, DumpError, Frame};

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

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
