//! The scene an evaluation assembles: each `object` statement's geometry, within the
//! scene's limits on objects and shape nodes, and at the end the scene-wide warnings
//! (unused names, no objects or lights, useless lights, objects behind the camera).

use super::{Ctx, Value, MAX_OBJECTS, MAX_SCENE_NODES};
use crate::diag::{codes, Diagnostic};
use crate::ir::{self, Camera, Scene};
use crate::span::Span;
use crate::syntax::ast;
use std::path::Path;

impl Ctx<'_> {
    /// Adds the value of an `object` statement to the scene.
    pub(super) fn object(&mut self, v: Value, expr: &ast::Expr, stmt_span: Span) {
        let expr_span = expr.span;
        let geometry = match v {
            Value::Shape(s) => ir::Body::Shape(s),
            Value::Mesh(m) => ir::Body::Mesh(m),
            Value::Error => return,
            other => {
                let mut d = Diagnostic::error(
                    codes::NOT_AN_OBJECT,
                    expr_span,
                    format!("expected a shape or a mesh, found `{}`", other.ty_name()),
                    other.this_is(),
                );
                if matches!(other, Value::Light(_)) {
                    d = d.with_hint("lights are added with `light …`, not `object …`");
                }
                self.report(d);
                return;
            }
        };
        if self.dry > 0 {
            return;
        }
        if self.objects.len() >= MAX_OBJECTS {
            if !self.too_many_objects {
                self.too_many_objects = true;
                self.report(
                    Diagnostic::error(
                        codes::TOO_MANY_OBJECTS,
                        stmt_span,
                        "too many objects",
                        format!("object number {} is one too many", MAX_OBJECTS + 1),
                    )
                    .with_note(format!(
                        "a scene may have at most {MAX_OBJECTS} objects; `repeat(…)` draws many copies as one object"
                    )),
                );
            }
            return;
        }
        let nodes = match &geometry {
            ir::Body::Shape(s) => s.nodes,
            ir::Body::Mesh(m) => match &m.source {
                ir::MeshSource::Isosurface { shape, .. } => shape.nodes,
                ir::MeshSource::UvSphere { .. }
                | ir::MeshSource::IcoSphere { .. }
                | ir::MeshSource::Box { .. }
                | ir::MeshSource::Cylinder { .. }
                | ir::MeshSource::Torus { .. }
                | ir::MeshSource::Plane { .. }
                | ir::MeshSource::File { .. } => 0,
            },
        };
        self.scene_nodes = self.scene_nodes.saturating_add(nodes);
        if self.scene_nodes > MAX_SCENE_NODES {
            self.too_many_objects = true;
            self.report(
                Diagnostic::error(
                    codes::SHAPE_TOO_LARGE,
                    stmt_span,
                    "the scene's shapes are too large in total",
                    format!("with this object they have {} nodes", self.scene_nodes),
                )
                .with_note(format!(
                    "a scene's shapes may have at most {MAX_SCENE_NODES} nodes in all, counting a shared part each time it is used"
                )),
            );
            return;
        }
        if !self.affordable(&geometry, stmt_span) {
            return;
        }
        let name = self.unique_name(base_name(expr));
        self.objects.push(ir::Object { geometry, span: stmt_span, name });
    }

    /// Whether one distance evaluation of the object's shape is within the work
    /// ceiling ([`crate::field::evaluation_cost`]); past it an error, past the warning
    /// band a warning, each naming the estimate.
    fn affordable(&mut self, geometry: &ir::Body, span: Span) -> bool {
        use crate::field::{evaluation_cost, MAX_WORK, WARN_WORK};
        let shape = match geometry {
            ir::Body::Shape(s) => s,
            ir::Body::Mesh(m) => match &m.source {
                ir::MeshSource::Isosurface { shape, .. } => shape,
                _ => return true,
            },
        };
        let cost = evaluation_cost(shape);
        let work = cost.work();
        if work <= WARN_WORK {
            return true;
        }
        let label = format!(
            "one distance evaluation of this shape is estimated at {} primitive evaluations and {} field instructions",
            cost.leaves, cost.ops
        );
        let note = "work multiplies where a body reads `dist` of a shape that itself reads `dist`, where `polar` \
                    measures every copy of a part crossing its sector, and where `repeat` evaluates neighbouring \
                    copies: each level multiplies what the levels below it cost";
        let hint = "nest fewer levels of bodies reading `dist`, or keep `polar` parts within their sectors";
        if work > MAX_WORK {
            self.report(
                Diagnostic::error(codes::TOO_COSTLY, span, "this shape is too costly to evaluate", label)
                    .with_note(format!("{note}; a shape may cost at most {MAX_WORK} per evaluation (docs/limits.md)"))
                    .with_hint(hint),
            );
            return false;
        }
        self.report(
            Diagnostic::warning(codes::COSTLY, span, "this shape is costly to evaluate", label)
                .with_note(format!("{note}; every step of every ray does this work (from {WARN_WORK} this warns)"))
                .with_hint(hint),
        );
        true
    }

    /// The scene and every diagnostic, with the scene-wide warnings added.
    ///
    /// Long because it adds the scene-wide warnings, each its own check over the finished
    /// scene, in the order they are reported.
    pub(super) fn finish(mut self) -> (Option<Scene>, Vec<Diagnostic>) {
        let mut unused: Vec<(Span, String)> = self
            .lets
            .iter()
            .filter(|(_, (name, used))| !used && !name.starts_with('_'))
            .map(|(s, (n, _))| (*s, n.clone()))
            .collect();
        unused.sort();
        for (span, name) in unused {
            self.report(
                Diagnostic::warning(codes::UNUSED, span, format!("`{name}` is never used"), "defined here")
                    .with_hint(format!("if this is intentional, try naming it `_{name}`")),
            );
        }
        let end = self.file_start();
        let has_errors = self.diags.iter().any(Diagnostic::is_error);
        if has_errors {
            // Objects and lights were dropped with their errors; do not warn about their absence.
        } else if self.objects.is_empty() {
            self.report(
                Diagnostic::warning(
                    codes::NO_OBJECTS,
                    end,
                    "the scene has no objects",
                    "the image will show only the background",
                )
                .with_hint("try `object sphere(1) at [0, 0, 5]`"),
            );
        } else if self.lights.is_empty()
            && !self.objects.iter().any(|o| crate::ir::materials_of(&o.geometry).iter().any(crate::ir::Material::emits))
        {
            self.report(
                Diagnostic::warning(codes::NO_LIGHTS, end, "the scene has no lights", "every object will be black")
                    .with_hint("try `light ambient(0.2)` and `light point(0.6) at [2, 1, 0]`"),
            );
        }
        for light in &self.lights.clone() {
            if light.intensity == 0.0 {
                self.report(
                    Diagnostic::warning(
                        codes::USELESS_LIGHT,
                        light.span,
                        "this light has intensity 0",
                        "it lights nothing",
                    )
                    .with_hint("try removing it, or giving it an intensity above 0"),
                );
            }
        }
        let camera = self.camera.clone().unwrap_or_default();
        self.check_range(&camera);
        for obj in &self.objects.clone() {
            if let Some(dist) = behind_camera(obj, &camera) {
                self.report(
                    Diagnostic::warning(
                        codes::BEHIND_CAMERA,
                        obj.span,
                        "this object is behind the camera",
                        format!("its bounds end {} units behind the eye", ir::dump_num(dist)),
                    )
                    .with_note("it can still show in reflections"),
                );
            }
        }
        let mut diags: Vec<Diagnostic> = self
            .diags
            .into_iter()
            .zip(self.repeats)
            .map(|(d, more)| match more {
                0 => d,
                n => d.with_note(format!("and {n} more {} here", if n == 1 { "time" } else { "times" })),
            })
            .collect();
        diags.sort_by_key(|d| (d.span().start, d.severity));
        if diags.iter().any(Diagnostic::is_error) {
            return (None, diags);
        }
        let mut material_names: Vec<(Span, String)> = self.material_names.into_iter().collect();
        material_names.sort();
        let scene = Scene {
            camera,
            settings: self.settings.unwrap_or_default(),
            lights: self.lights,
            objects: self.objects,
            material_names,
            params: self.params,
        };
        (Some(scene), diags)
    }
}

impl Ctx<'_> {
    /// An empty span at the start of the root file: where scene-wide diagnostics point.
    pub(super) fn file_start(&self) -> Span {
        self.map.files().next().map_or(Span::default(), |(_, f)| Span::new(f.base as usize, f.base as usize))
    }

    /// `base`, or `base_2`, `base_3`, … if an earlier object has it. Each base
    /// remembers its next number, so 100,000 `sphere`s take linear time.
    fn unique_name(&mut self, base: String) -> String {
        let next = self.name_counts.entry(base.clone()).or_insert(1);
        let mut name = if *next == 1 { base.clone() } else { format!("{base}_{next}") };
        while !self.object_names.insert(name.clone()) {
            *next += 1;
            name = format!("{base}_{next}");
        }
        *next += 1;
        name
    }
}

/// The name an object's expression starts from: `wheel at p` is `wheel`, `bead(0.2)` is
/// `bead`, `mesh file("scan.obj")` is `scan`; anything else (an `if`, a list) `object`.
fn base_name(e: &ast::Expr) -> String {
    match &e.kind {
        ast::ExprKind::Transform { target, .. } => base_name(target),
        ast::ExprKind::Ident(id) => id.name.clone(),
        ast::ExprKind::Call { callee, .. } => callee.name.clone(),
        ast::ExprKind::Mesh { generator, args } => {
            let file = args.first().and_then(|a| match &a.value.kind {
                ast::ExprKind::Str(s) if generator.name == "file" => Path::new(s).file_stem()?.to_str(),
                _ => None,
            });
            // Names are written into OBJ lines and XML attributes: a file name keeps
            // only the characters every format takes as they are.
            file.map_or_else(|| generator.name.clone(), crate::source::file_safe)
        }
        _ => "object".to_string(),
    }
}

/// How far behind the camera plane an object's bounding sphere lies, if entirely behind it.
fn behind_camera(obj: &ir::Object, camera: &Camera) -> Option<f64> {
    let (centre, radius) = ir::bounding_sphere(&obj.geometry)?;
    let forward = (camera.look_at - camera.position).normalize();
    let depth = (centre - camera.position).dot(forward);
    (depth + radius < 0.0).then_some(-(depth + radius))
}
