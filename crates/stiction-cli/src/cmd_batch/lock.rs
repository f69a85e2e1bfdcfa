//! One writer per output folder: an exclusive advisory lock on `OUTDIR/batch.lock`, taken before
//! anything is written and held until the process ends. The operating system releases it when
//! the process dies, however it dies, so there is never a stale lock to guess about. The file
//! names the run that holds it (pid, host, start time) for the message a second run prints.

use anyhow::{bail, Context, Result};
use serde::{Deserialize, Serialize};
use std::fs::{File, TryLockError};
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::Path;

/// The run holding the lock.
#[derive(Serialize, Deserialize)]
struct Holder {
    pid: u32,
    host: String,
    started: String,
}

/// Held while the batch runs; dropping it (or the process ending) releases the folder.
pub struct Lock {
    _file: File,
}

/// Take the lock of `out` (which exists). Another run holding it is an error naming that run;
/// a file system without locks is said once, and the batch goes on.
pub fn take(out: &Path) -> Result<Lock> {
    let path = out.join("batch.lock");
    let shown = out.display();
    let mut file = File::options()
        .read(true)
        .write(true)
        .create(true)
        .truncate(false)
        .open(&path)
        .with_context(|| {
            format!("{shown}: cannot create its lock file batch.lock; choose a writable folder with -o OUTDIR")
        })?;
    match file.try_lock() {
        Ok(()) => {}
        Err(TryLockError::WouldBlock) => {
            let mut text = String::new();
            let _ = file.read_to_string(&mut text);
            let holder = match serde_json::from_str::<Holder>(&text) {
                Ok(h) => format!("pid {} on {}, started {}", h.pid, h.host, h.started),
                Err(_) => "a run that has just started".into(),
            };
            bail!(
                "{shown}: another stiction batch is writing into this folder ({holder}); wait for it to finish, or choose another folder with -o OUTDIR"
            );
        }
        Err(TryLockError::Error(e)) => {
            eprintln!(
                "note: {shown}: this file system does not lock files ({e}), so nothing keeps a second batch from writing into the folder at the same time; make sure only one runs"
            );
        }
    }
    let holder = Holder {
        pid: std::process::id(),
        host: host_name(),
        started: jiff::Timestamp::now()
            .round(jiff::Unit::Second)?
            .to_string(),
    };
    // the lock is ours: the file's old content is an earlier run's
    let written = file
        .set_len(0)
        .and_then(|()| file.seek(SeekFrom::Start(0)))
        .and_then(|_| file.write_all(&serde_json::to_vec(&holder)?));
    written.with_context(|| format!("{}: cannot write the lock file", path.display()))?;
    Ok(Lock { _file: file })
}

fn host_name() -> String {
    #[cfg(unix)]
    {
        let mut buf = [0u8; 256];
        // SAFETY: the buffer is valid for its whole length, which is what we pass
        let r = unsafe { libc::gethostname(buf.as_mut_ptr().cast(), buf.len()) };
        if r == 0 {
            let end = buf.iter().position(|&b| b == 0).unwrap_or(buf.len());
            let name = String::from_utf8_lossy(&buf[..end]).into_owned();
            if !name.is_empty() {
                return name;
            }
        }
    }
    std::env::var("COMPUTERNAME")
        .or_else(|_| std::env::var("HOSTNAME"))
        .unwrap_or_else(|_| "an unknown host".into())
}
