//! The `scnc` command line: the only code that reads arguments, prints, or exits.

use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand, ValueEnum};

use scnc::check::{FsLoader, Loader};
use scnc::diag::Diagnostic;
use scnc::Compiled;

#[derive(Parser)]
#[command(name = "scnc", version, about = "Compile and render .scn scene files")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum MessageFormat {
    /// Rendered for people, with source excerpts.
    Human,
    /// One JSON object per line, for editors and tests.
    Json,
}

#[derive(Subcommand)]
enum Command {
    /// Check files for errors without rendering (exit 0 clean, 1 on errors).
    Check {
        /// The scene files.
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// How to print diagnostics.
        #[arg(long, value_enum, default_value = "human")]
        message_format: MessageFormat,
    },
    /// Print the evaluated scene IR.
    Ir {
        /// The scene file.
        file: PathBuf,
        /// How to print diagnostics.
        #[arg(long, value_enum, default_value = "human")]
        message_format: MessageFormat,
    },
}

fn compile(path: &Path) -> Compiled {
    let name = path.display().to_string();
    match FsLoader.read(path) {
        Ok(text) => scnc::with_big_stack(|| scnc::compile_source(&name, path, text, &FsLoader)),
        Err(e) => {
            let mut map = scnc::source::SourceMap::new();
            let _ = map.add(name.clone(), path, String::new());
            let reason = match e.kind() {
                std::io::ErrorKind::NotFound => "no such file".to_string(),
                _ => e.to_string(),
            };
            let d = Diagnostic::error(
                scnc::diag::codes::INCLUDE_READ,
                scnc::span::Span::default(),
                format!("cannot read `{name}`: {reason}"),
                reason,
            );
            Compiled {
                map,
                scene: None,
                diagnostics: vec![d],
            }
        }
    }
}

/// Prints diagnostics to stderr; returns whether any was an error.
fn report(c: &Compiled, format: MessageFormat) -> bool {
    let color = std::io::stderr().is_terminal() && std::env::var_os("NO_COLOR").is_none();
    let mut err = std::io::stderr().lock();
    for d in &c.diagnostics {
        let text = match format {
            MessageFormat::Human
                if c.map.files().next().is_some_and(|(_, f)| f.text.is_empty())
                    && d.span() == scnc::span::Span::default() =>
            {
                format!("error[{}]: {}\n", d.code, d.message)
            }
            MessageFormat::Human => d.render(&c.map, color),
            MessageFormat::Json => format!("{}\n", d.to_json(&c.map)),
        };
        let _ = err.write_all(text.as_bytes());
    }
    c.diagnostics.iter().any(Diagnostic::is_error)
}

fn run(cli: Cli) -> ExitCode {
    match cli.command {
        Command::Check { files, message_format } => {
            let mut failed = false;
            for file in &files {
                let compiled = compile(file);
                failed |= report(&compiled, message_format);
            }
            if failed {
                ExitCode::from(1)
            } else {
                ExitCode::SUCCESS
            }
        }
        Command::Ir { file, message_format } => {
            let compiled = compile(&file);
            if report(&compiled, message_format) {
                return ExitCode::from(1);
            }
            if let Some(scene) = &compiled.scene {
                let _ = std::io::stdout()
                    .lock()
                    .write_all(scnc::ir::dump(scene, &compiled.map).as_bytes());
            }
            ExitCode::SUCCESS
        }
    }
}

fn main() -> ExitCode {
    run(Cli::parse())
}
