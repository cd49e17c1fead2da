//! Checking and evaluation: a [`File`](crate::syntax::ast::File) (and everything it
//! includes) to an [`ir::Scene`] plus diagnostics.
//!
//! The language is pure and evaluated at compile time, so the checker *is* an evaluator
//! over typed values: names are resolved in lexical scopes, every operation checks the
//! types of its operands, every builtin checks arity, named arguments, types and ranges.
//! Errors evaluate to a poison value that later operations pass through silently, so
//! one run reports every independent mistake once. Function bodies are also evaluated
//! once at their definition with poisoned parameters, and empty loops once with a
//! poisoned variable, so mistakes in code that never runs are still reported.
//!
//! **Invariant:** a `Scene` is returned only when no error was reported, and then it
//! satisfies the invariants stated in [`ir`].

mod call;
mod control;
mod env;
mod expr;
mod field;
mod include;
pub mod index;
mod param;
mod range;
mod scene;
mod time;
mod transform;

use std::cell::Cell;
use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::rc::Rc;

use crate::builtins::{self, BoundArgs, Host};
pub use crate::builtins::{
    Value, EPSILON_RANGE, MAX_DEPTH, MAX_FPS, MAX_FRAMES, MAX_GENERATED_TRIANGLES, MAX_IMAGE_SIDE, MAX_LIST,
    MAX_MESH_RESOLUTION, MAX_OBJECTS, MAX_PIXELS, MAX_REPEAT, MAX_SAMPLES, MAX_STEPS, MIN_EPSILON,
};
use crate::diag::{codes, Diagnostic};
use crate::ir::{self, Camera, Scene, Settings};
use crate::source::{FileId, Loader, SourceMap};
use crate::span::Span;
use crate::syntax::ast;
use env::{Binding, Captured, Env, Found};
pub use param::{Override, Overrides};
pub use range::{MAX_INTENSITY, MAX_REACH, MIN_SIZE};
pub use time::{Reuse, Time};

/// Most loop iterations in one compile, over all loops.
pub const MAX_ITERATIONS: u64 = 1_000_000;
/// Deepest chain of function calls.
pub const MAX_CALL_DEPTH: usize = 64;
/// Deepest chain of includes.
pub const MAX_INCLUDE_DEPTH: usize = 16;
/// Most `include` statements one compile may carry out (a file including the next twice,
/// sixteen deep, would read 65,536 files).
pub const MAX_INCLUDES: usize = 1_000;
/// Most lights in a scene.
pub const MAX_LIGHTS: usize = 1_000;
/// Deepest expression nesting (operators, calls and transforms count).
pub const MAX_EXPR_DEPTH: usize = 256;
/// Evaluation steps one compile may take: every expression evaluated, and every list
/// element copied, is one. Depth limits bound recursion, not total work; this does.
pub const MAX_FUEL: u64 = 10_000_000;
/// Shape nodes one scene may hold, shared parts counted each time they are used.
pub const MAX_SCENE_NODES: u64 = 4_000_000;
/// Error reports (repeats included) after which evaluation stops.
pub const MAX_ERROR_REPORTS: u64 = 10_000;
/// Evaluation steps between two questions whether a result is still wanted: about a
/// tenth of a millisecond of work.
const POLL_STEPS: u64 = 4096;

/// What a name is bound to.
#[derive(Clone, Debug)]
enum Bound {
    Value(Value),
    Func(Rc<Func>),
}

#[derive(Debug)]
struct Func {
    name: String,
    params: Vec<ast::Ident>,
    body: Rc<ast::Expr>,
    /// The parameters and the outer bindings the body refers to.
    captured: Rc<Captured>,
    file_dir: Rc<Path>,
    /// Calls so far, to name what used the fuel.
    calls: Cell<u64>,
}

/// The evaluator's state for one compile.
struct Ctx<'a> {
    map: &'a mut SourceMap,
    loader: &'a dyn Loader,
    /// The frame being evaluated: what `clock` and `frame` are.
    time: Time,
    /// Files read and parsed by earlier evaluations of the same scene.
    reuse: &'a mut Reuse,
    diags: Vec<Diagnostic>,
    /// Each diagnostic reported so far, by code, span and message: its index in `diags`.
    reported: HashMap<(&'static str, Span, String), usize>,
    /// How many more times each diagnostic of `diags` was reported.
    repeats: Vec<u64>,
    /// Error reports so far, repeats included.
    error_reports: u64,
    /// Evaluation steps left (see [`MAX_FUEL`]).
    fuel: u64,
    /// Every user function defined so far, to name what used the fuel.
    funcs: Vec<Rc<Func>>,
    /// Shape nodes of the scene's objects so far (see [`MAX_SCENE_NODES`]).
    scene_nodes: u64,
    /// `include` statements carried out so far.
    includes: usize,
    /// Set when fuel ran out or errors passed their cap: everything left evaluates to
    /// an error at once, and loops stop.
    halted: bool,
    /// Asked every [`POLL_STEPS`] steps whether the result is still wanted (the language
    /// server's document changed meanwhile); a yes halts evaluation.
    cancel: &'a dyn Fn() -> bool,
    /// Steps until `cancel` is asked again.
    until_poll: u64,
    /// Set when `cancel` said yes: the result is incomplete and must not be shown.
    cancelled: bool,
    /// The names in scope where evaluation is.
    env: Env,
    /// The environments of the callers of the calls in progress, innermost last.
    outer: Vec<Env>,
    /// Values given to the scene's parameters from outside its file.
    overrides: &'a Overrides,
    /// The `param`s declared so far.
    params: Vec<ir::SceneParam>,
    /// `let` definitions by span, and whether each was ever used.
    lets: HashMap<Span, (String, bool)>,
    camera: Option<Camera>,
    settings: Option<Settings>,
    lights: Vec<ir::Light>,
    objects: Vec<ir::Object>,
    /// Object names given so far (they are made unique).
    object_names: HashSet<String>,
    /// The number the next object of each base name gets.
    name_counts: HashMap<String, usize>,
    /// Materials bound by `let`, by their call's span: the first name wins.
    material_names: HashMap<Span, String>,
    iterations: u64,
    call_depth: usize,
    expr_depth: usize,
    include_stack: Vec<PathBuf>,
    /// Directory of the file being evaluated (for `include` and `mesh file`).
    dir: Rc<Path>,
    /// > 0 while evaluating code only to find mistakes (nothing is emitted).
    dry: u32,
    /// Non-zero while exploring code that does not run: only mistakes that do not
    /// depend on values are reported (`control::explore`).
    quiet: u32,
    /// The branches explored so, each once.
    explored: HashSet<Span>,
    too_many_objects: bool,
    /// Set once "expression nests too deeply" was reported, so it is reported once.
    too_deep: bool,
    /// Names and types for editor tooling, when asked for.
    index: Option<index::Index>,
    /// Where the innermost block being evaluated ends (global offset), for scopes in the index.
    block_end: u32,
    /// How many field literals' bodies are being evaluated (`dist` needs one).
    field_depth: u32,
    /// Set while binding the arguments of a builtin that takes values depending on a
    /// field's point (the maths builtins), so they pass the type checks.
    symbolic_args: bool,
    /// While evaluating a file included from the root file: the span in the root after
    /// which the included top-level names are in scope, and the scope depth of that level.
    export: Option<(u32, u32, usize)>,
}

/// The evaluator as the builtins' constructors see it.
impl Host for Ctx<'_> {
    fn report(&mut self, d: Diagnostic) {
        Ctx::report(self, d);
    }

    fn burn(&mut self, steps: u64, span: Span) -> bool {
        Ctx::burn(self, steps, span)
    }

    fn in_field_body(&self) -> bool {
        self.field_depth > 0
    }

    fn file_dir(&self) -> &Path {
        &self.dir
    }

    fn read_file(&self, path: &Path, limit: u64) -> std::io::Result<Vec<u8>> {
        self.loader.read_bytes(path, limit)
    }
}

impl<'a> Ctx<'a> {
    /// The evaluator as a constructor's host: `self.host().construct(…)`.
    fn host(&mut self) -> &mut (dyn Host + 'a) {
        self
    }

    /// The bound arguments of a `camera` or `render` statement.
    fn statement_args(&mut self, name: &str, args: &[ast::Arg], span: Span) -> Option<BoundArgs> {
        let kind = if name == "camera" { builtins::Kind::Camera } else { builtins::Kind::Render };
        let b = builtins::lookup(name, kind)?;
        let vals = args
            .iter()
            .map(|arg| expr::ArgVal {
                name: arg.name.clone(),
                value: self.expr(&arg.value),
                span: arg.name.as_ref().map_or(arg.value.span, |n| n.span.to(arg.value.span)),
            })
            .collect();
        self.bind_builtin(b, vals, span)
    }
}

impl Ctx<'_> {
    /// Records a diagnostic; the same one again (code, span and message) only counts.
    fn report(&mut self, d: Diagnostic) {
        if self.quiet > 0 && !control::holds_in_dead_code(d.code) {
            return;
        }
        let is_error = d.is_error();
        let key = (d.code, d.span(), d.message.clone());
        match self.reported.get(&key) {
            Some(&i) => self.repeats[i] += 1,
            None => {
                self.reported.insert(key, self.diags.len());
                self.diags.push(d);
                self.repeats.push(0);
            }
        }
        if is_error {
            self.error_reports += 1;
            if self.error_reports == MAX_ERROR_REPORTS && !self.halted {
                self.halted = true;
                let span = self.diags.last().map_or(Span::default(), Diagnostic::span);
                self.report(
                    Diagnostic::error(codes::TOO_MANY_ERRORS, span, "too many errors", "evaluation stopped here")
                        .with_note(format!("evaluation stops after {MAX_ERROR_REPORTS} errors; fix these first")),
                );
            }
        }
    }

    /// Spends `steps` of fuel on the work at `span`; `false` once it has run out (or
    /// evaluation stopped), after reporting where, and what used it, once.
    #[inline]
    fn burn(&mut self, steps: u64, span: Span) -> bool {
        // Every expression node burns: the common case stays inline, the rest is
        // `burn_slow`, which decides exactly as if it were alone.
        if !self.halted && self.until_poll >= steps && self.fuel >= steps {
            self.until_poll -= steps;
            self.fuel -= steps;
            return true;
        }
        self.burn_slow(steps, span)
    }

    /// [`burn`](Self::burn) when evaluation has stopped, a poll is due or fuel runs out.
    #[cold]
    fn burn_slow(&mut self, steps: u64, span: Span) -> bool {
        if self.halted {
            return false;
        }
        if let Some(left) = self.until_poll.checked_sub(steps) {
            self.until_poll = left;
        } else {
            self.until_poll = POLL_STEPS;
            if (self.cancel)() {
                self.halted = true;
                self.cancelled = true;
                return false;
            }
        }
        if let Some(left) = self.fuel.checked_sub(steps) {
            self.fuel = left;
            return true;
        }
        self.halted = true;
        let mut d = Diagnostic::error(
            codes::OUT_OF_FUEL,
            span,
            "the scene takes too long to evaluate",
            "evaluation ran out of fuel here",
        )
        .with_note(format!("a scene may take at most {MAX_FUEL} evaluation steps"));
        let mut calls: HashMap<&str, u64> = HashMap::new();
        for f in &self.funcs {
            *calls.entry(&f.name).or_default() += f.calls.get();
        }
        if let Some((name, n)) =
            calls.into_iter().filter(|&(_, n)| n > 0).max_by_key(|&(name, n)| (n, std::cmp::Reverse(name)))
        {
            d = d.with_note(format!("`{name}` was called {n} times"));
        }
        self.report(d);
        false
    }

    fn lookup(&mut self, id: &ast::Ident) -> Option<Found> {
        let found = self.env.find(&id.name)?;
        if let Some(b) = found.binding.as_ref().filter(|b| !b.used.replace(true)) {
            if let Some(entry) = self.lets.get_mut(&b.span) {
                entry.1 = true;
            }
        }
        if let Some(ix) = &mut self.index {
            ix.refer(id.span, found.span);
        }
        Some(found)
    }

    /// Records a definition in the index (when there is one), in scope from `from` to
    /// `to` when those are offsets of the root file.
    fn note_def(&mut self, name: &ast::Ident, kind: index::DefKind, ty: Option<String>, from: u32, to: u32) {
        if self.index.is_none() {
            return;
        }
        let visible = if self.include_stack.len() <= 1 {
            Some((from, to))
        } else {
            let exported = matches!(kind, index::DefKind::Value | index::DefKind::Function);
            self.export.filter(|e| exported && Some(e.2) == self.env.depth()).map(|(f, t, _)| (f, t))
        };
        let params = Vec::new();
        let def = index::Def { name: name.name.clone(), span: name.span, kind, ty, params, visible };
        if let Some(ix) = &mut self.index {
            ix.define(def);
        }
    }

    fn bind(&mut self, name: &ast::Ident, bound: Bound) {
        self.env.bind(Binding { name: Rc::from(name.name.as_str()), span: name.span, bound, used: Cell::new(false) });
    }

    /// The names visible here that are (or are not) functions, for suggestions. While
    /// a function is evaluated at its definition, those around the definition count too.
    fn names_in_scope(&self, funcs: bool) -> Vec<String> {
        let around = self.outer.last().filter(|_| self.env.defining());
        let mut names: Vec<String> = around
            .into_iter()
            .flat_map(Env::names)
            .chain(self.env.names())
            .filter(|&(_, is_func)| is_func == funcs)
            .map(|(name, _)| name.to_string())
            .collect();
        names.sort_unstable();
        names.dedup();
        names
    }

    fn stmts(&mut self, stmts: &[ast::Stmt]) {
        for stmt in stmts {
            if self.halted {
                break;
            }
            self.stmt(stmt);
        }
    }

    /// Evaluates one statement. Long because it is one match over the statement kinds.
    fn stmt(&mut self, stmt: &ast::Stmt) {
        match &stmt.kind {
            ast::StmtKind::Error => {}
            ast::StmtKind::Let { name, params, value } if matches!(value.kind, ast::ExprKind::Field { .. }) => {
                self.report(
                    Diagnostic::error(
                        codes::MISPLACED_FIELD,
                        value.span,
                        "a field literal cannot be stored in a `let` or returned from a function",
                        "a field literal",
                    )
                    .with_note("`p => …` is an argument of `field`, `warp` or `displace` only")
                    .with_hint("write the body as a function of the point, `let f(p) = …`, and pass `p => f(p)`"),
                );
                // Bound as poison, so its uses are not reported again as unknown names.
                if params.is_none() {
                    self.bind(name, Bound::Value(Value::Error));
                } else {
                    self.define_function(name, params.as_deref().unwrap_or_default(), value);
                }
            }
            ast::StmtKind::Let { name, params: None, value } => {
                let v = self.expr(value);
                self.lets.entry(name.span).or_insert_with(|| (name.name.clone(), false));
                if let Value::Material(m) = &v {
                    self.material_names.entry(m.span).or_insert_with(|| name.name.clone());
                }
                let ty = (!v.is_error()).then(|| v.ty_name());
                self.note_def(name, index::DefKind::Value, ty, stmt.span.end, self.block_end);
                self.bind(name, Bound::Value(v));
            }
            ast::StmtKind::Let { name, params: Some(params), value } => {
                self.define_function(name, params, value);
                let names: Vec<&str> = params.iter().map(|p| p.name.as_str()).collect();
                let sig = format!("{}({})", name.name, names.join(", "));
                self.note_def(name, index::DefKind::Function, Some(sig), stmt.span.end, self.block_end);
                if let Some(ix) = &mut self.index {
                    ix.set_params(name.span, names.iter().map(|n| n.to_string()).collect());
                }
            }
            ast::StmtKind::Param(p) => self.param(p, stmt.span),
            ast::StmtKind::Object(e) => {
                let v = self.expr(e);
                self.object(v, e, stmt.span);
            }
            ast::StmtKind::Light(e) => {
                let v = self.expr(e);
                match v {
                    Value::Light(light) => {
                        if self.dry == 0 {
                            if self.lights.len() >= MAX_LIGHTS {
                                self.report(Diagnostic::error(codes::TOO_MANY_OBJECTS, stmt.span, "too many lights", format!("light number {} is one too many", MAX_LIGHTS + 1)).with_note(format!("a scene may have at most {MAX_LIGHTS} lights")));
                            } else {
                                self.lights.push((*light).clone());
                            }
                        }
                    }
                    Value::Error => {}
                    other => self.report(
                        Diagnostic::error(codes::NOT_A_LIGHT, e.span, format!("expected a light, found `{}`", other.ty_name()), other.this_is())
                            .with_hint("try `light ambient(0.2)`, `light point(0.6) at [2, 1, 0]` or `light directional(0.2, towards = [1, 4, 4])`"),
                    ),
                }
            }
            ast::StmtKind::Camera(args) => {
                let cam =
                    self.statement_args("camera", args, stmt.span).and_then(|a| self.host().camera(&a, stmt.span));
                if self.dry > 0 {
                    return;
                }
                if let Some(prev) = self.camera.as_ref().and_then(|c| c.span) {
                    self.report(
                        Diagnostic::error(
                            codes::DUPLICATE_STATEMENT,
                            stmt.span,
                            "the camera is set twice",
                            "second `camera` statement",
                        )
                        .with_label(prev, "first set here")
                        .with_hint("try merging the two into one `camera(…)`"),
                    );
                } else if let Some(cam) = cam {
                    self.camera = Some(cam);
                } else {
                    // Remember that a (bad) camera statement was here, so a second one is still a duplicate.
                    self.camera = Some(Camera { span: Some(stmt.span), ..Camera::default() });
                }
            }
            ast::StmtKind::Render(args) => {
                let settings =
                    self.statement_args("render", args, stmt.span).and_then(|a| self.host().settings(&a, stmt.span));
                if self.dry > 0 {
                    return;
                }
                if let Some(prev) = self.settings.as_ref().and_then(|s| s.span) {
                    self.report(
                        Diagnostic::error(
                            codes::DUPLICATE_STATEMENT,
                            stmt.span,
                            "render settings are given twice",
                            "second `render` statement",
                        )
                        .with_label(prev, "first given here")
                        .with_hint("try merging the two into one `render(…)`"),
                    );
                } else {
                    self.settings = Some(settings.unwrap_or(Settings { span: Some(stmt.span), ..Settings::default() }));
                }
            }
            ast::StmtKind::For { each, body } => self.for_loop(each, body, stmt.span),
            ast::StmtKind::If { branches, otherwise } => self.if_stmt(branches, otherwise.as_deref()),
            ast::StmtKind::Include { path, path_span } => self.include_stmt(path, *path_span, stmt.span),
        }
    }

    fn define_function(&mut self, name: &ast::Ident, params: &[ast::Ident], body: &ast::Expr) {
        let mut seen: HashMap<&str, Span> = HashMap::new();
        for p in params {
            if let Some(first) = seen.insert(&p.name, p.span) {
                self.report(
                    Diagnostic::error(
                        codes::DUPLICATE_PARAM,
                        p.span,
                        format!("parameter `{}` is declared twice", p.name),
                        "declared again here",
                    )
                    .with_label(first, "first declared here"),
                );
            }
        }
        let func = Rc::new(Func {
            name: name.name.clone(),
            params: params.to_vec(),
            body: Rc::new(body.clone()),
            captured: Rc::new(Captured::new(&self.env, params, body)),
            file_dir: self.dir.clone(),
            calls: Cell::new(0),
        });
        self.funcs.push(func.clone());
        self.lets.entry(name.span).or_insert_with(|| (name.name.clone(), false));
        // Evaluate the body once with poisoned parameters: reports unknown names and type
        // errors that do not depend on the arguments, even if the function is never called.
        let poisoned = params.iter().map(|_| Value::Error).collect();
        self.dry += 1;
        let _ = self.call_user(&func, poisoned, name.span, true);
        self.dry -= 1;
        self.bind(name, Bound::Func(func));
    }

    /// A number that must be a whole number in i64 range, for loop bounds.
    fn int_operand(&mut self, v: &Value, span: Span, what: &str) -> Option<i64> {
        match v {
            Value::Num(x) if x.fract() == 0.0 && x.abs() <= 1e15 => Some(*x as i64),
            Value::Num(x) if x.fract() == 0.0 => {
                // Past 2^53 not every whole number exists as a number: say so, not "whole".
                self.report(
                    Diagnostic::error(
                        codes::NOT_INTEGER,
                        span,
                        format!("{what} is too large"),
                        format!("this is {}", ir::dump_num(*x)),
                    )
                    .with_note("loop bounds must lie within ±1e15: past 2^53 (about 9e15) numbers skip whole values"),
                );
                None
            }
            Value::Num(x) => {
                self.report(
                    Diagnostic::error(
                        codes::NOT_INTEGER,
                        span,
                        format!("{what} must be a whole number"),
                        format!("this is {}", ir::dump_num(*x)),
                    )
                    .with_hint("try `floor(…)`"),
                );
                None
            }
            Value::Error => None,
            other => {
                self.report(Diagnostic::error(
                    codes::TYPE_MISMATCH,
                    span,
                    format!("expected `int`, found `{}`", other.ty_name()),
                    format!("{what} must be a whole number"),
                ));
                None
            }
        }
    }
}

/// What one evaluation of a scene reads and where it is in time.
struct Input<'a> {
    map: &'a mut SourceMap,
    root: FileId,
    loader: &'a dyn Loader,
    time: Time,
    reuse: &'a mut Reuse,
    overrides: &'a Overrides,
}

#[allow(clippy::type_complexity, reason = "the three results of one compile")]
fn run(
    input: Input<'_>,
    indexed: bool,
    cancel: &dyn Fn() -> bool,
) -> Option<(Option<Scene>, Vec<Diagnostic>, Option<index::Index>)> {
    let Input { map, root, loader, time, reuse, overrides } = input;
    let dir: Rc<Path> = Rc::from(map.file(root).path.parent().unwrap_or(Path::new("")));
    let mut ctx = Ctx {
        map,
        loader,
        time,
        reuse,
        diags: Vec::new(),
        reported: HashMap::new(),
        repeats: Vec::new(),
        error_reports: 0,
        fuel: MAX_FUEL,
        funcs: Vec::new(),
        scene_nodes: 0,
        halted: false,
        cancel,
        until_poll: POLL_STEPS,
        cancelled: false,
        includes: 0,
        env: Env::default(),
        outer: Vec::new(),
        overrides,
        params: Vec::new(),
        lets: HashMap::new(),
        camera: None,
        settings: None,
        lights: Vec::new(),
        objects: Vec::new(),
        object_names: HashSet::new(),
        name_counts: HashMap::new(),
        material_names: HashMap::new(),
        iterations: 0,
        call_depth: 0,
        expr_depth: 0,
        include_stack: Vec::new(),
        dir,
        dry: 0,
        quiet: 0,
        explored: HashSet::new(),
        too_many_objects: false,
        too_deep: false,
        index: indexed.then(index::Index::default),
        block_end: u32::MAX,
        field_depth: 0,
        symbolic_args: false,
        export: None,
    };
    ctx.reuse.start();
    ctx.run_file(root);
    ctx.unknown_overrides();
    if ctx.cancelled {
        return None;
    }
    let index = ctx.index.take();
    let (scene, diags) = ctx.finish();
    Some((scene, diags, index))
}

/// Checks and evaluates the file `root` of `map` (already added), loading includes
/// through `loader`. Returns the scene when there are no errors, and every diagnostic.
/// The scene is a still, or the first frame of its animation (`clock` and `frame` are 0).
pub fn check(map: &mut SourceMap, root: FileId, loader: &dyn Loader) -> (Option<Scene>, Vec<Diagnostic>) {
    check_at(map, root, loader, Time::STILL, &mut Reuse::default(), &Overrides::default())
}

/// [`check`] at `time`, its parameters set by `overrides`, reusing the files and parses
/// of earlier evaluations of the same scene in `map` that `reuse` remembers (and
/// remembering this one's).
pub fn check_at(
    map: &mut SourceMap,
    root: FileId,
    loader: &dyn Loader,
    time: Time,
    reuse: &mut Reuse,
    overrides: &Overrides,
) -> (Option<Scene>, Vec<Diagnostic>) {
    let input = Input { map, root, loader, time, reuse, overrides };
    // Nothing cancels this compile, so there is always a result.
    run(input, false, &|| false).map(|(scene, diags, _)| (scene, diags)).unwrap_or_default()
}

/// [`check`], also returning the [`index::Index`] of names and types for editor tooling.
/// `cancel` is asked now and then whether the result is still wanted; once it says yes,
/// evaluation stops and the result is `None`.
pub fn check_indexed(
    map: &mut SourceMap,
    root: FileId,
    loader: &dyn Loader,
    cancel: &dyn Fn() -> bool,
) -> Option<(Option<Scene>, Vec<Diagnostic>, index::Index)> {
    let none = Overrides::default();
    let input = Input { map, root, loader, time: Time::STILL, reuse: &mut Reuse::default(), overrides: &none };
    let (scene, diags, index) = run(input, true, cancel)?;
    Some((scene, diags, index.unwrap_or_default()))
}
