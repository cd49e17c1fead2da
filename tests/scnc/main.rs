//! The single integration-test binary: every test module links into it.

mod animation;
mod budget;
mod cli;
mod conformance;
mod deploy;
mod derived;
mod effects;
mod export;
mod fmt;
mod glass;
mod golden;
mod grammar;
mod isosurface;
mod layers;
mod lsp;
mod mesh;
mod nopanic;
mod primitives;
mod pruning;
mod readme;
mod render;
mod skip;
mod stability;
mod support;
mod tiles;
mod watch;
