//! The `mcgv-video` command: maps flags, progress bars and JSON onto the `mcgv_video` library.

mod args;
mod commands;
mod progress;
mod render;

use args::{Cli, Command};
use clap::Parser;

fn main() {
    std::process::exit(run());
}

/// Runs the CLI and returns the process exit code: 0 on success, 1 on error (message on stderr),
/// 2 on a usage error (clap's own).
fn run() -> i32 {
    // A panic anywhere (a dependency's bug, caught where it can be) is reported in one line, like
    // every other error, instead of a backtrace.
    std::panic::set_hook(Box::new(|info| {
        eprintln!("mcgv-video: internal error: {info}");
    }));
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            let code = if e.use_stderr() { 2 } else { 0 };
            let _ = e.print();
            return code;
        }
    };
    let result = match &cli.command {
        Command::Encode(a) => commands::encode::run(a, cli.quiet),
        Command::Decode(a) => commands::decode::run(a, cli.quiet),
        Command::Inspect(a) => commands::inspect::run(a, cli.quiet),
        Command::Eval(a) => commands::eval::run(a, cli.quiet),
        Command::Info(a) => commands::info::run(a, cli.quiet),
        Command::Convert(a) => commands::convert::run(a, cli.quiet),
    };
    match result {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("mcgv-video: error: {}", render(&e));
            1
        }
    }
}

/// An error as the command line says it: an invalid option by its flag, not its field name.
fn render(e: &mcgv_video::Error) -> String {
    match e {
        mcgv_video::Error::InvalidOption { option, message } => {
            format!("{} {message}", flag(option))
        }
        e => e.to_string(),
    }
}

/// The flag that sets an options field.
fn flag(option: &str) -> String {
    match option {
        "max_bands" => "--bands".to_string(),
        other => format!("--{}", other.replace('_', "-")),
    }
}
