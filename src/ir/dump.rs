//! A stable, readable text form of the IR, for `scnc ir` and golden tests.

use std::fmt::Write as _;

use glam::{DAffine3, DVec3};

use super::{
    Body, ColorSpace, LightKind, Material, Mesh, MeshSource, Paint, PatternKind, Primitive, Scene, Shape, ShapeKind,
};
use crate::source::SourceMap;
use crate::span::Span;

pub(crate) use crate::sig::{num, vec};

fn color(c: DVec3) -> String {
    format!("rgb({}, {}, {})", num(c.x), num(c.y), num(c.z))
}

/// A colour or a pattern, patterns written as calls with their paints last.
fn paint(p: &Paint) -> String {
    match p {
        Paint::Solid(c) => color(*c),
        Paint::Pattern(pat) => {
            let args = match &pat.kind {
                PatternKind::Checker { size } => format!("size {}", num(*size)),
                PatternKind::Stripes { width, axis } => format!("width {} axis {}", num(*width), vec(*axis)),
                PatternKind::Gradient { from, to } => format!("from {} to {}", vec(*from), vec(*to)),
                PatternKind::Noise { size, seed } => format!("size {} seed {seed}", num(*size)),
            };
            format!("{}({args}, {}, {})", pat.kind.name(), paint(&pat.a), paint(&pat.b))
        }
    }
}

struct Dumper<'a> {
    out: String,
    map: &'a SourceMap,
}

impl Dumper<'_> {
    fn at(&self, span: Span) -> String {
        let (id, r) = self.map.local_range(span);
        let (line, col) = self.map.line_col(id, r.start);
        format!("@{}:{line}:{col}", self.map.file(id).name)
    }

    fn line(&mut self, indent: usize, text: &str, span: Option<Span>) {
        let _ = write!(self.out, "{:indent$}{text}", "", indent = indent * 2);
        if let Some(span) = span {
            let _ = write!(self.out, "  {}", self.at(span));
        }
        self.out.push('\n');
    }

    fn material(m: &Material) -> String {
        let spec = m.specular.map_or("none".to_string(), num);
        let mut s = format!("{} specular {} reflective {}", paint(&m.color), spec, num(m.reflective));
        // Only transparent materials show the medium, so opaque scenes dump as before.
        if m.is_transparent() {
            let _ =
                write!(s, " transparency {} ior {} absorption {}", num(m.transparency), num(m.ior), vec(m.absorption));
        }
        if m.emits() {
            let _ = write!(s, " emission {} strength {}", vec(m.emission), num(m.emission_strength));
        }
        // Only a density given shows, so scenes without one dump as before.
        if m.density != 1.0 {
            let _ = write!(s, " density {}", num(m.density));
        }
        s
    }

    fn xf(xf: &DAffine3) -> String {
        let mut s = format!("at {}", vec(xf.translation));
        let m = xf.matrix3;
        if m != glam::DMat3::IDENTITY {
            let rows = (0..3).map(|r| vec(m.row(r))).collect::<Vec<_>>().join(", ");
            let _ = write!(s, " linear [{rows}]");
        }
        s
    }

    fn shape(&mut self, indent: usize, shape: &Shape) {
        let children = |this: &mut Self, kids: &[std::sync::Arc<Shape>]| {
            for kid in kids {
                this.shape(indent + 1, kid);
            }
        };
        let span = Some(shape.span);
        match &shape.kind {
            ShapeKind::Primitive(p) => self.line(indent, &primitive(p), span),
            ShapeKind::Csg { op, children: kids, smooth } => {
                let op = op.name();
                let text = if *smooth > 0.0 { format!("{op} smooth {}", num(*smooth)) } else { op.to_string() };
                self.line(indent, &text, span);
                children(self, kids);
            }
            ShapeKind::Round { child, radius } => {
                self.line(indent, &format!("round radius {}", num(*radius)), span);
                self.shape(indent + 1, child);
            }
            ShapeKind::Shell { child, thickness } => {
                self.line(indent, &format!("shell thickness {}", num(*thickness)), span);
                self.shape(indent + 1, child);
            }
            ShapeKind::Repeat { child, period, count } => {
                self.line(
                    indent,
                    &format!("repeat period {} count [{}, {}, {}]", vec(*period), count[0], count[1], count[2]),
                    span,
                );
                self.shape(indent + 1, child);
            }
            ShapeKind::Transform { child, xf } => {
                self.line(indent, &format!("transform {}", Self::xf(xf)), span);
                self.shape(indent + 1, child);
            }
            ShapeKind::Paint { child, material } => {
                self.line(indent, &format!("paint {}", Self::material(material)), Some(material.span));
                self.shape(indent + 1, child);
            }
            ShapeKind::Field { body, bounds, lipschitz, .. } => {
                // Said because it changes how the field is marched and shadowed.
                let convex = if super::convex::is_convex(body) { " convex" } else { "" };
                let head = format!("field{}{}{convex}", Self::bounds(bounds), Self::lipschitz(lipschitz));
                self.line(indent, &head, span);
                self.body(indent + 1, body);
            }
            ShapeKind::Warp { child, map, bounds, lipschitz, .. } => {
                self.line(indent, &format!("warp{}{}", Self::bounds(bounds), Self::lipschitz(lipschitz)), span);
                self.body(indent + 1, map);
                self.shape(indent + 1, child);
            }
            ShapeKind::Displace { child, by, bounds, lipschitz, reach } => {
                let reach = format!(" reach {}", num(*reach));
                let head = format!("displace{}{}{reach}", Self::bounds(bounds), Self::lipschitz(lipschitz));
                self.line(indent, &head, span);
                self.body(indent + 1, by);
                self.shape(indent + 1, child);
            }
        }
    }

    fn bounds(b: &Option<super::DAabb>) -> String {
        b.map_or(String::new(), |b| format!(" bounds [{}, {}]", vec(b.min), vec(b.max)))
    }

    fn lipschitz(l: &super::Lipschitz) -> String {
        format!(" lipschitz {} ({})", num(l.value), if l.given { "given" } else { "estimated" })
    }

    /// A field body as source, then each shape its `dist` calls read.
    fn body(&mut self, indent: usize, body: &std::sync::Arc<super::field::FieldExpr>) {
        self.line(indent, &format!("p => {}", body.source(2000)), None);
        for (i, s) in body.shapes().iter().enumerate() {
            self.line(indent, &format!("shape#{i}"), None);
            self.shape(indent + 1, s);
        }
    }

    fn mesh(&mut self, indent: usize, mesh: &Mesh) {
        let src = match &mesh.source {
            MeshSource::UvSphere { radius, rings, segments } => {
                format!("uvsphere radius {} rings {rings} segments {segments}", num(*radius))
            }
            MeshSource::IcoSphere { radius, subdivisions } => {
                format!("icosphere radius {} subdivisions {subdivisions}", num(*radius))
            }
            MeshSource::Box { half } => format!("box half {}", vec(*half)),
            MeshSource::Cylinder { radius, half_height, segments } => {
                format!("cylinder radius {} half_height {} segments {segments}", num(*radius), num(*half_height))
            }
            MeshSource::Torus { major, minor, segments, sides } => {
                format!("torus major {} minor {} segments {segments} sides {sides}", num(*major), num(*minor))
            }
            MeshSource::Plane { size } => format!("plane size {}", num(*size)),
            MeshSource::Isosurface { cell, .. } => format!("isosurface cell {}", num(*cell)),
            MeshSource::File { written, .. } => format!("file {written:?}"),
        };
        let shading = if mesh.smooth { "smooth" } else { "flat" };
        self.line(indent, &format!("mesh {src} {shading} {}", Self::xf(&mesh.xf)), Some(mesh.span));
        if let Some(m) = &mesh.material {
            self.line(indent + 1, &format!("material {}", Self::material(m)), Some(m.span));
        }
        if let MeshSource::Isosurface { shape, .. } = &mesh.source {
            self.shape(indent + 1, shape);
        }
    }
}

/// The IR as text: one line per node, children indented, each with its source location.
pub fn dump(scene: &Scene, map: &SourceMap) -> String {
    let mut d = Dumper { out: String::new(), map };
    let c = &scene.camera;
    d.line(
        0,
        &format!(
            "camera position {} look_at {} up {} fov {}{}",
            vec(c.position),
            vec(c.look_at),
            vec(c.up),
            num(c.fov),
            if c.aperture > 0.0 {
                format!(
                    " aperture {} focus_distance {}",
                    num(c.aperture),
                    c.focus_distance.map_or("look_at".to_string(), num)
                )
            } else {
                String::new()
            }
        ),
        c.span,
    );
    let s = &scene.settings;
    d.line(
        0,
        &format!(
            "render {}x{} depth {} background {} epsilon {} max_steps {} max_distance {} samples {}{}{}{}{}{}{}{}",
            s.width,
            s.height,
            s.depth,
            color(s.background),
            num(s.epsilon),
            s.max_steps,
            num(s.max_distance),
            s.samples,
            if s.ambient_occlusion > 0.0 {
                format!(" ambient_occlusion {}", num(s.ambient_occlusion))
            } else {
                String::new()
            },
            if s.color == ColorSpace::Linear { String::new() } else { format!(" color {}", s.color.name()) },
            if s.frames > 1 {
                format!(" frames {} fps {}{}", s.frames, num(s.fps), if s.cyclic { " cyclic" } else { "" })
            } else {
                String::new()
            },
            s.bounces.map_or(String::new(), |b| format!(" bounces {b}")),
            if s.exposure != 0.0 { format!(" exposure {}", num(s.exposure)) } else { String::new() },
            s.noise.map_or(String::new(), |e| format!(" noise {}", num(e))),
            s.clamp.map_or(String::new(), |c| format!(" clamp {}", num(c))),
        ),
        s.span,
    );
    for light in &scene.lights {
        let kind = match &light.kind {
            LightKind::Ambient => "ambient".to_string(),
            LightKind::Point { position } => format!("point at {}", vec(*position)),
            LightKind::Directional { towards } => format!("directional towards {}", vec(*towards)),
            LightKind::Area { centre, u, v } => format!("area at {} u {} v {}", vec(*centre), vec(*u), vec(*v)),
            LightKind::Environment => "environment".to_string(),
        };
        let mut text = format!("light {kind} intensity {}", num(light.intensity));
        if !matches!(light.kind, LightKind::Ambient | LightKind::Environment) {
            text.push_str(if light.shadows { " shadows" } else { " no_shadows" });
        }
        if light.radius > 0.0 {
            let _ = write!(text, " radius {}", num(light.radius));
        }
        d.line(0, &text, Some(light.span));
    }
    for (i, obj) in scene.objects.iter().enumerate() {
        d.line(0, &format!("object {i}"), Some(obj.span));
        match &obj.geometry {
            Body::Shape(shape) => d.shape(1, shape),
            Body::Mesh(mesh) => d.mesh(1, mesh),
        }
    }
    d.out
}

/// A primitive's dump line: its name and its parameters.
fn primitive(p: &Primitive) -> String {
    let fields: Vec<String> = p.fields().into_iter().map(|(name, value)| format!("{name} {value}")).collect();
    format!("{} {}", p.name(), fields.join(" "))
}
