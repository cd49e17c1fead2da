//! What a material's colour can be: one colour, or a procedural pattern of two paints
//! laid out in the painted object's own space.

use std::sync::Arc;

use glam::DVec3;

use crate::span::Span;

/// A surface colour: plain, or a pattern.
#[derive(Clone, Debug, PartialEq)]
pub enum Paint {
    /// One colour, 0–255 per channel.
    Solid(DVec3),
    /// A pattern.
    Pattern(Arc<Pattern>),
}

/// A procedural pattern choosing or blending between two paints at each point of the
/// painted object's space.
#[derive(Clone, Debug, PartialEq)]
pub struct Pattern {
    /// How `a` and `b` are laid out.
    pub kind: PatternKind,
    /// The first paint.
    pub a: Paint,
    /// The second paint.
    pub b: Paint,
    /// The pattern's call.
    pub span: Span,
}

/// The pattern functions. Sizes are > 0 and directions non-zero (the checker's ranges).
#[derive(Clone, Debug, PartialEq)]
pub enum PatternKind {
    /// Cubes of edge `size` alternating `a`, `b` in all three axes; the cube at the
    /// origin's positive corner is `a`.
    Checker {
        /// Edge length.
        size: f64,
    },
    /// Slabs `width` thick across `axis`, alternating `a`, `b`; the slab just above the
    /// origin is `a`.
    Stripes {
        /// Slab thickness.
        width: f64,
        /// The direction the slabs alternate along (not necessarily unit).
        axis: DVec3,
    },
    /// `a` at and before the plane through `from`, `b` at and beyond the plane through
    /// `to` (both normal to `to − from`), mixed linearly in between.
    Gradient {
        /// Where `a` is pure.
        from: DVec3,
        /// Where `b` is pure (never equal to `from`).
        to: DVec3,
    },
    /// `a` and `b` mixed by gradient noise of feature size `size`.
    Noise {
        /// Feature size.
        size: f64,
        /// Which noise field (any whole number).
        seed: u32,
    },
}

impl PatternKind {
    /// The pattern's builtin name.
    pub fn name(&self) -> &'static str {
        match self {
            PatternKind::Checker { .. } => "checker",
            PatternKind::Stripes { .. } => "stripes",
            PatternKind::Gradient { .. } => "gradient",
            PatternKind::Noise { .. } => "noise",
        }
    }
}

impl Paint {
    /// The paint's average colour: the colour a format with one colour per material
    /// (an OBJ `.mtl`, glTF's base colour) gets for a pattern.
    pub fn mean(&self) -> DVec3 {
        match self {
            Paint::Solid(c) => *c,
            // Every pattern covers `a` and `b` equally on average (checker, stripes and
            // noise by symmetry; a gradient is taken at its midpoint).
            Paint::Pattern(p) => (p.a.mean() + p.b.mean()) * 0.5,
        }
    }

    /// Whether a pattern is involved.
    pub fn is_pattern(&self) -> bool {
        matches!(self, Paint::Pattern(_))
    }
}
