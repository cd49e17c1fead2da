//! scnc: a scene-language compiler and renderer.
//!
//! The pipeline, one module per stage, each with one entry point:
//!
//! ```text
//! text ─syntax::parse─▶ ast::File ─check::check─▶ ir::Scene ─render::effects::derive─▶ Effects
//!                                                    │
//!                    world::prepare(scene, effects, Mode::Sdf | Mode::Mesh(detail))
//!                                                    ▼
//!      Frame (camera, lights, materials) + World (SdfObject | MeshObject under one Bvh)
//!                                                    │
//!                          render::render(&dyn Geometry, &Frame) ─▶ Image, Counters
//! ```
//!
//! - [`syntax`]: logos tokens and a chumsky parser that recovers, so one run reports many errors.
//! - [`check`]: names, types, arity and ranges, by evaluating the pure language to the IR;
//!   every builtin names its constructor.
//! - [`ir`]: the evaluated scene in f64 with source spans; every per-primitive fact in
//!   [`ir::Primitive`]; bounds; a stable text dump.
//! - [`field`]: field bodies (`p => …`) compiled to tapes and evaluated as f32, dual
//!   numbers and intervals; the bound of their slope.
//! - [`sdf`] and [`mesh`]: the two geometry back-ends; [`world`] puts their objects, in
//!   camera-relative f32, under one top-level [`accel::Bvh`].
//! - [`accel`]: boxes, the robust slab test and the BVH (build, single-ray and packet walks).
//! - [`trace`]: what the back-ends and the tracer share: rays, packets, hits, the
//!   [`trace::Geometry`] contract, counters, materials and patterns. Both back-ends and
//!   the tracer stand on it, so neither depends on the other (`tests/scnc/layers.rs`).
//! - [`render`]: the one Whitted tracer, built for the scene's [`render::effects`].
//! - [`study`]: what accuracy costs (`--tolerance`, `scnc sweep`, its report and charts).
//! - [`source`], [`span`] and [`diag`]: input text, positions and diagnostics; [`fmt`] and
//!   [`lsp`]: the formatter and the language server.
//!
//! An animation is checked once: [`compile_source`] evaluates frame 0, and
//! [`Compiled::frame`] evaluates any other frame from the files already read and parsed;
//! [`world::prepare_reusing`] then lowers only the objects that changed.
//!
//! Every stage reports problems as [`diag::Diagnostic`] values; only the binary prints.

pub mod accel;
pub mod builtins;
pub mod check;
pub mod compile;
pub mod diag;
pub mod export;
pub mod field;
pub mod fmt;
pub mod geom;
pub mod ir;
pub mod lsp;
pub mod measure;
pub mod mesh;
pub mod meshfile;
pub mod primitive;
pub mod render;
pub mod sdf;
pub mod sig;
pub mod source;
pub mod span;
pub mod study;
pub mod syntax;
pub mod trace;
pub mod world;

pub use compile::{
    compile_file, compile_file_with, compile_source, compile_source_with, with_big_stack, with_big_stack_on, Compiled,
    NoThread, COMPILER_STACK,
};
