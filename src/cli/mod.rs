//! The `nadf` commands, as library functions: `src/main.rs` only parses the command line
//! (with the argument structs here) and dispatches. Each command prints what it reports to
//! standard output and returns `Err(Failure)` when it cannot do its job; the one mapping from
//! a failure to the process's exit status is [`Failure::exit_code`]:
//!
//! | status | meaning |
//! |---|---|
//! | 0 | success (and every `[expect]`ation held) |
//! | 1 | the run finished but an `[expect]`ation failed |
//! | 2 | bad input: a world file, an override, an output that cannot be written, or an intractable task |
//! | 130 | interrupted with Ctrl-C |

/// `println!` for what a command reports, without its panic when standard output is closed
/// (`nadf field … | head -3`): see [`say`].
macro_rules! say {
    ($($arg:tt)*) => {
        $crate::cli::say(format_args!($($arg)*))
    };
}

mod check;
mod experiment;
mod field;
mod reproduce;
mod run;
mod scen;
mod sweep;

pub use check::{CheckArgs, check};
pub use experiment::{ExperimentArgs, MergeArgs, experiment, merge};
pub use field::{FieldArgs, field};
pub use reproduce::{ReproduceArgs, reproduce};
pub use run::{RunArgs, run};
pub use scen::{ScenArgs, scen};
pub use sweep::{SweepArgs, sweep};

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use crate::output::{Contents, write_contents};
use crate::world::{Override, World, WorldFile};

/// Writes `text` and a newline to standard output. A reader that has gone (`nadf field … |
/// head -3`) is not the run's failure: its files are still written and its exit status stands,
/// so a line that cannot be written is dropped, where `println!` would panic.
///
/// ```
/// nadf::cli::say(format_args!("solve: {:.1} ms", 12.25));
/// ```
pub fn say(text: std::fmt::Arguments) {
    use std::io::Write;
    let _ = writeln!(std::io::stdout().lock(), "{text}");
}

/// [`say`] for a block of lines that ends with its own newline (a table).
pub fn say_block(block: &str) {
    use std::io::Write;
    let _ = std::io::stdout().lock().write_all(block.as_bytes());
}

/// Why a command did not succeed.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum Failure {
    /// Bad input: a world file, an override, an output that cannot be written, an intractable
    /// task. The message says what and where.
    #[error("{0}")]
    BadInput(String),
    /// The run finished but some of its expectations failed (listed in the message).
    #[error("{0}")]
    Expectations(String),
    /// Stopped by Ctrl-C.
    #[error("{0}")]
    Interrupted(String),
}

impl Failure {
    /// The process's exit status for this failure.
    pub fn exit_code(&self) -> u8 {
        match self {
            Self::Expectations(_) => 1,
            Self::BadInput(_) => 2,
            Self::Interrupted(_) => 130,
        }
    }
}

/// What every command shares: whether to draw progress bars, and the flag Ctrl-C sets.
#[derive(Debug, Clone)]
pub struct Console {
    /// Draw progress bars on standard error.
    pub progress: bool,
    /// Set when Ctrl-C is pressed: long work stops after its current step.
    pub interrupt: Arc<AtomicBool>,
}

impl Console {
    /// Progress bars when standard error is a terminal outside CI, and one Ctrl-C handler
    /// that sets [`Console::interrupt`] (a warning is printed if it cannot be installed).
    pub fn new() -> Self {
        let interrupt = Arc::new(AtomicBool::new(false));
        let flag = Arc::clone(&interrupt);
        if let Err(e) = ctrlc::set_handler(move || flag.store(true, Ordering::Relaxed)) {
            eprintln!("warning: Ctrl-C will not stop a run cleanly: {e}");
        }
        Self {
            progress: std::io::stderr().is_terminal() && std::env::var_os("CI").is_none(),
            interrupt,
        }
    }

    /// A progress bar of `len` steps in the given template, hidden without progress.
    pub fn bar(&self, len: u64, template: &str) -> indicatif::ProgressBar {
        if !self.progress {
            return indicatif::ProgressBar::hidden();
        }
        let bar = indicatif::ProgressBar::new(len);
        bar.set_style(
            indicatif::ProgressStyle::with_template(template)
                .expect("a valid template")
                .progress_chars("=> "),
        );
        bar
    }
}

impl Default for Console {
    fn default() -> Self {
        Self::new()
    }
}

/// Reads and loads a world file with overrides, printing its warnings; every problem in it is
/// bad input.
fn load(path: &Path, overrides: &[Override]) -> Result<World, Failure> {
    let file = WorldFile::read(path).map_err(|e| Failure::BadInput(e.to_string()))?;
    let world = file
        .load(overrides)
        .map_err(|e| Failure::BadInput(e.to_string()))?;
    for w in file.warnings(&world) {
        eprintln!("warning: {w}");
    }
    Ok(world)
}

/// The options every batch of runs takes (`sweep`, `scen`).
#[derive(Debug, Clone, clap::Args)]
pub struct BatchArgs {
    /// Override a world value for every run (see `run`). Repeatable.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub overrides: Vec<Override>,
    /// The directory to write into [default: WORLD_STEM-sweep or WORLD_STEM-scen].
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Threads to run on [default: one per core].
    #[arg(long, short = 'j', value_name = "N", value_parser = clap::value_parser!(u16).range(1..))]
    pub jobs: Option<u16>,
}

impl BatchArgs {
    /// The directory to write into: `--out`, or `WORLD_STEM-KIND` in the current directory.
    fn dir(&self, world: &Path, kind: &str) -> PathBuf {
        self.out.clone().unwrap_or_else(|| {
            let stem = world
                .file_stem()
                .map_or_else(|| "world".into(), |s| s.to_string_lossy().into_owned());
            PathBuf::from(format!("{stem}-{kind}"))
        })
    }

    /// The threads asked for.
    fn threads(&self) -> Option<usize> {
        self.jobs.map(usize::from)
    }
}

/// Writes each file whole (see [`crate::output`]) and says so; a failure is the world's bad
/// input (its outputs were checked before the work).
///
/// The files are written at once, one thread each: most of a file's time is the system's
/// (copying it into the page cache, and the wait for the disk before the rename), and the
/// field's four arrays at 1025² took about 0.1 s one after another. A file that fails leaves
/// nothing behind; the others are written all the same, and the first failure is reported.
fn write_all<'a, C: Into<Contents<'a>>>(
    world: &Path,
    files: impl IntoIterator<Item = (PathBuf, C)>,
) -> Result<(), Failure> {
    let files: Vec<(PathBuf, Contents)> = files.into_iter().map(|(f, c)| (f, c.into())).collect();
    let written: Vec<_> = std::thread::scope(|s| {
        let threads: Vec<_> = (files.iter())
            .map(|(file, contents)| s.spawn(move || write_contents(file, contents)))
            .collect();
        let joined = threads.into_iter().map(|t| t.join());
        joined
            .map(|r| r.unwrap_or_else(|panic| std::panic::resume_unwind(panic)))
            .collect()
    });
    for ((file, _), result) in files.iter().zip(written) {
        result.map_err(|e| bad_input(world, e))?;
        say!("wrote {}", file.display());
    }
    Ok(())
}

/// `error: FILE: MESSAGE`, bad input.
fn bad_input(path: &Path, message: impl std::fmt::Display) -> Failure {
    Failure::BadInput(format!("error: {}: {message}", path.display()))
}
