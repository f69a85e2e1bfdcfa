//! What a command says about a loop record besides its result: the core's errors in the CLI's
//! words (naming the flag to change) and the reader's notes.

use crate::loop_file::LoopFile;
use stiction_core::diagnose::DiagnoseError;

/// The core's error in one sentence, naming the file and the flag to change.
pub fn core_error(name: &str, _lf: &LoopFile, e: DiagnoseError) -> anyhow::Error {
    match e {
        DiagnoseError::Window { window, least } => anyhow::anyhow!(
            "{name}: --window {window}: a window needs at least {least} samples; give a larger --window"
        ),
        DiagnoseError::Ts(ts) => anyhow::anyhow!(
            "{name}: --ts {ts}: the sampling time must be a positive number of seconds"
        ),
        DiagnoseError::OpRange { lo, hi } => anyhow::anyhow!(
            "{name}: --op-range {lo}:{hi}: the value of a fully open valve must exceed that of a closed one"
        ),
        e => anyhow::anyhow!("{name}: {e}"),
    }
}

/// What the reader decided (gaps, time order, time form): lines of the human output, or notes
/// on standard error beside JSON.
pub fn print_notes(name: &str, lf: &LoopFile, stderr: bool) {
    for n in &lf.reading_notes() {
        if stderr {
            eprintln!("note: {name}: {n}");
        } else {
            println!("  note: {n}");
        }
    }
}
