//! What every command-line tool shares: errors as messages, JSON output, the `main` wrapper.

/// Every tool error is a message for a person: what could not be done, and why.
pub type Result<T> = std::result::Result<T, String>;

/// Prefix an error with what was being done (`"cannot read x.png: No such file"`).
pub trait Context<T> {
    fn context(self, what: impl FnOnce() -> String) -> Result<T>;
}

impl<T, E: std::fmt::Display> Context<T> for std::result::Result<T, E> {
    fn context(self, what: impl FnOnce() -> String) -> Result<T> {
        self.map_err(|e| format!("{}: {e}", what()))
    }
}

/// Write `value` as pretty-printed JSON.
pub fn write_json(path: &std::path::Path, value: &impl serde::Serialize) -> Result<()> {
    let text = serde_json::to_string_pretty(value).context(|| "cannot encode JSON".into())?;
    std::fs::write(path, text + "\n").context(|| format!("cannot write {}", path.display()))
}

/// The `main` of a command-line example: `--help` prints `usage`; otherwise `parse` the arguments
/// and `run`; an error is printed and exits non-zero, as does a run that returns `false`.
pub fn run_cli<A>(
    usage: &str,
    parse: impl FnOnce(Vec<String>) -> Result<A>,
    run: impl FnOnce(&A) -> Result<bool>,
) -> std::process::ExitCode {
    use std::process::ExitCode;
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.iter().any(|a| a == "-h" || a == "--help") {
        println!("{usage}");
        return ExitCode::SUCCESS;
    }
    match parse(args).and_then(|args| run(&args)) {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::FAILURE,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::FAILURE
        }
    }
}
