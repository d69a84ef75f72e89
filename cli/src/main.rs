//! The `mcgv-video` command: maps flags, progress bars and JSON onto the `mcgv_video` library.

#[macro_use]
mod output;
mod annotate;
mod args;
mod commands;
mod progress;
mod render;
mod staging;
mod target;

use args::{Cli, Command};
use clap::{CommandFactory, Parser};

fn main() {
    std::process::exit(run());
}

/// Runs the CLI and returns the process exit code: 0 on success (and when stdout's reader went
/// away), 1 on a runtime error, 2 on a usage error (a malformed command line, an option that does
/// not apply or has a bad value); the message goes to stderr.
fn run() -> i32 {
    // A panic anywhere (a dependency's bug, caught where it can be) is reported in one line, like
    // every other error, instead of a backtrace.
    std::panic::set_hook(Box::new(|info| {
        eprintln!("mcgv-video: internal error: {info}");
    }));
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => return clap_error(&e),
    };
    if let Some(threads) = cli.threads {
        // Before any parallel work: the global pool is built once.
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads as usize);
        if let Err(e) = pool.build_global() {
            eprintln!("mcgv-video: error: --threads {threads}: {e}");
            return 1;
        }
    }
    if cli.verbose {
        mcgv_video::set_codec_log(Some(|source, message| match source {
            "" => eprintln!("mcgv-video: codec: {message}"),
            _ => eprintln!("mcgv-video: codec: {source}: {message}"),
        }));
    }
    let result = match &cli.command {
        Command::Encode(a) => commands::encode::run(a, cli.quiet, cli.threads),
        Command::Decode(a) => commands::decode::run(a, cli.quiet),
        Command::Inspect(a) => commands::inspect::run(a, cli.quiet),
        Command::Eval(a) => commands::eval::run(a, cli.quiet),
        Command::Info(a) => commands::info::run(a, cli.quiet),
        Command::Convert(a) => commands::convert::run(a, cli.quiet),
        Command::Completions { shell } => completions(*shell),
        Command::Man { command } => man(command.as_deref()),
    };
    match result {
        Ok(()) => 0,
        Err(e) if output::is_closed_pipe(&e) => 0,
        Err(e) => {
            eprintln!("mcgv-video: error: {}", render(&e));
            match e {
                mcgv_video::Error::InvalidOption { .. } => 2,
                _ => 1,
            }
        }
    }
}

/// Prints clap's message (help and version to stdout, exit 0; usage errors to stderr, exit 2),
/// with a hint when extra arguments look like an unquoted glob the shell expanded.
fn clap_error(e: &clap::Error) -> i32 {
    let _ = e.print();
    if !e.use_stderr() {
        return 0;
    }
    if e.kind() == clap::error::ErrorKind::UnknownArgument {
        let extra = e
            .get(clap::error::ContextKind::InvalidArg)
            .map(|v| v.to_string())
            .unwrap_or_default();
        if !extra.starts_with('-') {
            eprintln!(
                "hint: the shell expanded a pattern into several files; quote it so that \
                 mcgv-video reads the frames itself, e.g. 'frames/*.obj'"
            );
        }
    }
    2
}

/// Writes the completion script of `shell` to stdout.
fn completions(shell: clap_complete::Shell) -> mcgv_video::Result<()> {
    let mut buffer = Vec::new();
    clap_complete::generate(shell, &mut Cli::command(), BIN, &mut buffer);
    let script = String::from_utf8_lossy(&buffer);
    let script = match shell {
        clap_complete::Shell::Bash => fix_bash_labels(&script),
        _ => script.into_owned(),
    };
    outln!("{}", script.trim_end())
}

/// The binary's name, as shells and man pages call it.
const BIN: &str = "mcgv-video";

/// clap_complete's bash script names a subcommand's state `mcgv__video__subcmd__encode` where it
/// sets it but `mcgv__subcmd__video__subcmd__encode` in the case labels that read it (it splits a
/// name holding `-` twice), so no option would ever complete: the labels are renamed to match.
fn fix_bash_labels(script: &str) -> String {
    let set = format!("{}__subcmd__", BIN.replace('-', "__"));
    let read = format!("{}__subcmd__", BIN.replace('-', "__subcmd__"));
    script.replace(&read, &set)
}

/// Writes a man page (roff) to stdout: the command's, or subcommand `command`'s, named
/// `mcgv-video-COMMAND` as the main page's SEE ALSO lists it, with the global options.
fn man(command: Option<&str>) -> mcgv_video::Result<()> {
    let mut cli = Cli::command();
    // Propagates the global options (--quiet, --threads) into every subcommand.
    cli.build();
    let page = match command {
        None => cli,
        Some(name) => {
            let sub = cli.find_subcommand(name).ok_or_else(|| {
                mcgv_video::Error::option("command", format!("{name}: no such subcommand"))
            })?;
            let full = format!("{BIN}-{name}");
            sub.clone()
                .name(full.clone())
                .bin_name(format!("{BIN} {name}"))
                .display_name(full)
                .version(env!("CARGO_PKG_VERSION"))
        }
    };
    let mut buffer = Vec::new();
    clap_mangen::Man::new(page)
        .render(&mut buffer)
        .map_err(|e| mcgv_video::Error::io("stdout", e))?;
    out!("{}", String::from_utf8_lossy(&buffer))
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
