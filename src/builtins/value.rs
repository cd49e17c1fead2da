//! Values of the evaluator: what an expression evaluates to at compile time.

use std::rc::Rc;
use std::sync::Arc;

use glam::DVec3;

use super::Ty;
use crate::ir;
use crate::span::Span;

/// A field literal's value: its body, evaluated with the point unknown.
#[derive(Debug)]
pub struct FieldLit {
    /// The body.
    pub body: Arc<ir::field::FieldExpr>,
    /// The body's span, to blame for what it computes.
    pub span: Span,
}

/// A compile-time value. `Error` is poison: an expression that already failed, which
/// every operation passes through silently so one mistake is reported once.
#[derive(Clone, Debug)]
pub enum Value {
    /// A number.
    Num(f64),
    /// A boolean.
    Bool(bool),
    /// A string.
    Str(Rc<str>),
    /// A vector.
    Vec3(DVec3),
    /// A colour, 0–255 per channel.
    Color(DVec3),
    /// A material.
    Material(Arc<ir::Material>),
    /// A pattern.
    Pattern(Arc<ir::Pattern>),
    /// A shape tree.
    Shape(Arc<ir::Shape>),
    /// A mesh.
    Mesh(Arc<ir::Mesh>),
    /// A light.
    Light(Arc<ir::Light>),
    /// A list.
    List(Rc<Vec<Value>>),
    /// A number, vector or truth value that depends on a field's point: inside a field
    /// literal's body, what the point flows into.
    Sym(Arc<ir::field::FieldExpr>),
    /// A field literal `p => …`, its body evaluated.
    Field(Rc<FieldLit>),
    /// A 2D profile.
    Profile(Arc<Profile>),
    /// Poison.
    Error,
}

impl Value {
    /// The value's type; `None` for poison.
    pub fn ty(&self) -> Option<Ty> {
        Some(match self {
            Value::Num(x) if x.fract() == 0.0 => Ty::Int,
            Value::Num(_) => Ty::Num,
            Value::Bool(_) => Ty::Bool,
            Value::Str(_) => Ty::Str,
            Value::Vec3(_) => Ty::Vec3,
            Value::Color(_) => Ty::Color,
            Value::Material(_) => Ty::Material,
            Value::Pattern(_) => Ty::Pattern,
            Value::Shape(_) => Ty::Shape,
            Value::Mesh(_) => Ty::Mesh,
            Value::Light(_) => Ty::Light,
            Value::List(_) => Ty::List,
            Value::Sym(e) => match e.ty {
                ir::field::FieldTy::Num => Ty::Num,
                ir::field::FieldTy::Vec3 => Ty::Vec3,
                ir::field::FieldTy::Bool => Ty::Bool,
            },
            Value::Field(f) if f.body.ty == ir::field::FieldTy::Vec3 => Ty::FieldVec,
            Value::Field(_) => Ty::FieldNum,
            Value::Profile(_) => Ty::Profile,
            Value::Error => return None,
        })
    }

    /// The label under a value of the wrong type: "this is a `T`".
    pub fn this_is(&self) -> String {
        format!("this is a `{}`", self.ty_name())
    }

    /// The type as users read it (`num` for any number).
    pub fn ty_name(&self) -> String {
        match self {
            Value::Num(_) => "num".into(),
            Value::Sym(e) => format!("{} (depends on the point)", e.ty.name()),
            Value::List(items) => match items.first().and_then(Value::ty) {
                Some(Ty::Int) => "list<num>".into(),
                Some(t) => format!("list<{t}>"),
                None => "list".into(),
            },
            v => v.ty().map_or("?".into(), |t| t.to_string()),
        }
    }

    /// Whether two values have the same type as users read it ([`Value::ty_name`]),
    /// without formatting either. The empty list is a list of any element type, so
    /// `if c then [sphere(1)] else []` and `[[1], []]` are well typed.
    pub fn same_type(&self, other: &Value) -> bool {
        fn key(v: &Value) -> (Option<Ty>, Option<Ty>) {
            let num = |t: Option<Ty>| if t == Some(Ty::Int) { Some(Ty::Num) } else { t };
            match v {
                Value::List(items) => (Some(Ty::List), num(items.first().and_then(Value::ty))),
                v => (num(v.ty()), None),
            }
        }
        match (key(self), key(other)) {
            ((Some(Ty::List), None), (Some(Ty::List), _)) | ((Some(Ty::List), _), (Some(Ty::List), None)) => true,
            (a, b) => a == b,
        }
    }

    /// A vector's three numbers as a list, as `for` and list parameters read `[x, y, z]`.
    pub fn numbers(v: DVec3) -> Rc<Vec<Value>> {
        Rc::new(v.to_array().map(Value::Num).to_vec())
    }

    /// False when a number in it is infinite or NaN.
    pub fn is_finite(&self) -> bool {
        match self {
            Value::Num(x) => x.is_finite(),
            Value::Vec3(v) | Value::Color(v) => v.is_finite(),
            _ => true,
        }
    }

    /// The value as a field expression, if it is a number, vector or truth value
    /// (known, or depending on the point).
    pub fn as_field(&self) -> Option<Arc<ir::field::FieldExpr>> {
        use ir::field::{FieldExpr, FieldKind, FieldTy};
        Some(match self {
            Value::Num(x) => FieldExpr::num(*x),
            Value::Vec3(v) => FieldExpr::vec(*v),
            Value::Bool(b) => FieldExpr::new(FieldKind::Num(f64::from(*b)), FieldTy::Bool),
            Value::Sym(e) => e.clone(),
            _ => return None,
        })
    }

    /// True for poison.
    pub fn is_error(&self) -> bool {
        matches!(self, Value::Error)
    }
}

/// A 2D shape: its signed distance as an expression of the point `[u, v, 0]`, and its box.
#[derive(Clone, Debug, PartialEq)]
pub struct Profile {
    /// The signed distance: exact for a circle, rectangle or polygon, moved or not; a
    /// bound after `union`, `intersect`, `subtract`, `round` or `shell`.
    pub body: Arc<ir::field::FieldExpr>,
    /// The region it covers when that is made of polygons and circles by sharp CSG
    /// (moved or not): what an extrusion's mesh is made from, and a lathe's when it is one
    /// polygon. `None` after `round` or `shell` of anything but a circle, or a smooth CSG.
    pub region: Option<Arc<crate::geom::region::Region>>,
    /// Smallest corner `[u, v]`.
    pub min: glam::DVec2,
    /// Largest corner `[u, v]`.
    pub max: glam::DVec2,
}
