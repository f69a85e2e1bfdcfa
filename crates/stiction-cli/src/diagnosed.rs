//! Every diagnosis the CLI makes goes through here: the core's `diagnose_checked`, then its
//! words filled ([`crate::words::fill`]), so what is printed, written as JSON or ranked in a
//! fleet carries each reason's and the next step's `text`.

use stiction_core::checked::Checked;
use stiction_core::diagnose::{
    diagnose_checked, DiagnoseError, DiagnoseRequest, Diagnosis, LoopRecord,
};

/// Diagnose `r` and fill the diagnosis's words.
pub fn diagnose(
    r: &LoopRecord,
    req: &Checked<DiagnoseRequest>,
) -> Result<Diagnosis, DiagnoseError> {
    let mut d = diagnose_checked(r, req)?;
    crate::words::fill(&mut d);
    Ok(d)
}
