//! The single integration-test binary: every test module links into it.

mod cli;
mod golden;
mod nopanic;
mod render;
mod support;
