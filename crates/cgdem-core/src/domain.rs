//! The simulation box: its bounds and which axes are periodic.

use crate::math::{Real, Vec3};

#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Domain {
    pub lo: Vec3,
    pub hi: Vec3,
    pub periodic: [bool; 3],
}

/// Index of the zero image in the 27-entry image table.
pub const NO_IMAGE: u8 = 13;

impl Domain {
    pub fn length(&self) -> Vec3 {
        self.hi - self.lo
    }

    pub fn any_periodic(&self) -> bool {
        self.periodic.iter().any(|&p| p)
    }

    /// Image `k` in 0..27 encodes offsets (a, b, c) in {-1, 0, 1}^3 as
    /// `k = (a+1)*9 + (b+1)*3 + (c+1)`; the returned vector is added to particle j's position.
    pub fn image_shift(&self, image: u8) -> Vec3 {
        let k = image as i32;
        let offset = Vec3::new(
            (k / 9 - 1) as Real,
            ((k / 3) % 3 - 1) as Real,
            (k % 3 - 1) as Real,
        );
        offset * self.length()
    }

    /// The offsets (a, b, c) of image `k` (the inverse of `image_index`).
    pub fn image_offset(image: u8) -> [i32; 3] {
        let k = image as i32;
        [k / 9 - 1, (k / 3) % 3 - 1, k % 3 - 1]
    }

    /// How many box lengths `wrap` subtracts from `p` along each periodic axis (0 elsewhere).
    pub fn wrap_count(&self, p: Vec3) -> [i32; 3] {
        let length = self.length();
        let wrapped = self.wrap(p);
        std::array::from_fn(|axis| {
            if self.periodic[axis] {
                ((p[axis] - wrapped[axis]) / length[axis]).round() as i32
            } else {
                0
            }
        })
    }

    pub fn image_index(offset: [i32; 3]) -> u8 {
        ((offset[0] + 1) * 9 + (offset[1] + 1) * 3 + (offset[2] + 1)) as u8
    }

    /// Maps a position on periodic axes back into [lo, hi).
    pub fn wrap(&self, p: Vec3) -> Vec3 {
        let mut q = p;
        let length = self.length();
        for axis in 0..3 {
            if self.periodic[axis] {
                let relative = (q[axis] - self.lo[axis]).rem_euclid(length[axis]);
                // rem_euclid can round up to exactly `length`.
                q[axis] = self.lo[axis]
                    + if relative >= length[axis] {
                        0.0
                    } else {
                        relative
                    };
            }
        }
        q
    }

    /// Whether a point lies inside the box on the non-periodic axes.
    pub fn contains_bounded(&self, p: Vec3) -> bool {
        (0..3).all(|a| self.periodic[a] || (p[a] >= self.lo[a] && p[a] <= self.hi[a]))
    }
}

/// The corner of the box `lo..hi` lowest along `gravity`: gravitational energy `-m g.(x - o)`
/// is counted from it (cgdem's energy guard, and the energy balance of every code's outputs).
pub fn potential_origin(gravity: Vec3, lo: Vec3, hi: Vec3) -> Vec3 {
    Vec3::new(
        if gravity.x < 0.0 { lo.x } else { hi.x },
        if gravity.y < 0.0 { lo.y } else { hi.y },
        if gravity.z < 0.0 { lo.z } else { hi.z },
    )
}
