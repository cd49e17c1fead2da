//! The one mapping between scnc's space and a mesh file's, used by export and import
//! alike, so a model exported and read back lands where it was.
//!
//! scnc is left-handed (x right, y up, z forward, away from a default camera). STL, OBJ,
//! PLY, 3MF and glTF are read as right-handed, so a file's frame is a reflection of
//! scnc's: with y up, `(x, y, z)` in scnc is `(x, y, −z)` in the file; with z up (slicers,
//! CAD), `(x, z, y)`. A reflection turns every triangle inside out, so each mapping also
//! reverses the winding ([`REVERSES_WINDING`]): a part keeps its shape and stays wound
//! outward both ways.

use glam::DVec3;

/// Which axis of a file is up.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Up {
    /// Y up, as in glTF, OBJ and PLY viewers (and scnc).
    Y,
    /// Z up, as slicers and CAD tools expect.
    Z,
}

/// STL has no units and every slicer reads millimetres, while for printing a scene unit
/// is a centimetre (a unit sphere a 2 cm ball): STL export writes this many file units
/// per scene unit unless told otherwise, and STL import divides by it.
pub const STL_PER_UNIT: f64 = 10.0;

/// Whether a triangle's corners must be reversed when it crosses between the frames
/// (both mappings are reflections).
pub const REVERSES_WINDING: bool = true;

/// A triangle wound for the other frame, placed by a map that mirrors (`mirrored`,
/// a negative determinant) or not: reversed when exactly one of the two reflects.
pub fn wound(t: [u32; 3], mirrored: bool) -> [u32; 3] {
    if REVERSES_WINDING != mirrored {
        [t[0], t[2], t[1]]
    } else {
        t
    }
}

/// A point of scnc's space in a file's frame.
pub fn to_file(p: DVec3, up: Up) -> DVec3 {
    match up {
        Up::Y => DVec3::new(p.x, p.y, -p.z),
        Up::Z => DVec3::new(p.x, p.z, p.y),
    }
}

/// A point of a file's frame in scnc's space: the inverse of [`to_file`].
pub fn from_file(p: DVec3, up: Up) -> DVec3 {
    match up {
        Up::Y => DVec3::new(p.x, p.y, -p.z),
        Up::Z => DVec3::new(p.x, p.z, p.y),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each mapping undoes the other, and is a reflection (determinant −1), which is
    /// why triangles are reversed.
    #[test]
    fn the_mappings_are_inverse_reflections() {
        for up in [Up::Y, Up::Z] {
            let p = DVec3::new(1.0, 2.0, 3.0);
            assert_eq!(from_file(to_file(p, up), up), p);
            let m = glam::DMat3::from_cols(to_file(DVec3::X, up), to_file(DVec3::Y, up), to_file(DVec3::Z, up));
            assert_eq!(m.determinant() < 0.0, REVERSES_WINDING);
        }
    }
}
