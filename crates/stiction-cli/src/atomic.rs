//! Writing a file so that no reader, and no crash, ever sees half of it: the content goes to a
//! temporary file in the same folder, which is synced to disk, renamed over the target (atomic on
//! one file system) and the folder synced, so the rename itself survives a power cut. A failed
//! write removes its temporary file; a write that cannot finish leaves the earlier file as it was.
//!
//! Every command writes its files through here. Temporary files are named
//! `.stiction-tmp.<pid>-<n>.<name>` (the name last, so an encoder that picks the format by the
//! extension still sees it), so that [`remove_stale_temps`] can clear those a killed run left
//! without touching anything else.
//!
//! Tests can make writes fail as on a full disk: in debug builds (the test binary's, never a
//! release build) the environment variable `STICTION_TEST_FAIL_WRITE=N` makes the Nth write of
//! the process and every later one fail with "no space left on device", after half of the
//! content has gone to the temporary file.

use anyhow::{Context, Result};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// The start of every temporary file's name.
pub const TEMP_PREFIX: &str = ".stiction-tmp.";

/// Temporary files handed out by this process (keeps concurrent writes of one file apart).
static TEMPS: AtomicU64 = AtomicU64::new(0);

/// Write `bytes` to `path` atomically (see the module doc); creates the folder if needed.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    write_with(path, |w| Ok(w.write_all(bytes)?))
}

/// Write `path` atomically, the content streamed by `body` (nothing is built in memory).
pub fn write_with(path: &Path, body: impl FnOnce(&mut dyn Write) -> Result<()>) -> Result<()> {
    let doomed = fault::doomed();
    replace(path, false, |tmp| {
        let file = File::options().write(true).create_new(true).open(tmp)?;
        let mut w = BufWriter::with_capacity(1 << 16, fault::Writer::new(file, doomed));
        body(&mut w)?;
        let file = w.into_inner().map_err(|e| e.into_error())?.finish()?;
        file.sync_all()?;
        Ok(())
    })
}

/// Write `path` atomically through a writer that only takes a path (an image encoder): `write`
/// creates the temporary file it is given; it is then synced and renamed over `path`.
pub fn write_via(path: &Path, write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    replace(path, fault::doomed(), write)
}

/// Write the temporary file, sync it, rename it over `path`, sync the folder; on any failure
/// remove the temporary file. `doomed`: fail as a full disk would, before the rename.
fn replace(path: &Path, doomed: bool, write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    std::fs::create_dir_all(dir)
        .with_context(|| format!("{}: cannot create the folder", dir.display()))?;
    let tmp = temp_path(path);
    let done = (|| -> Result<()> {
        write(&tmp)?;
        // an encoder that wrote the file itself has not synced it
        File::options().write(true).open(&tmp)?.sync_all()?;
        fault::check(doomed)?;
        std::fs::rename(&tmp, path)?;
        sync_dir(dir)
    })();
    if done.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    done.with_context(|| format!("{}: cannot write the file", path.display()))
}

fn temp_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let n = TEMPS.fetch_add(1, Ordering::Relaxed);
    path.with_file_name(format!("{TEMP_PREFIX}{}-{n}.{name}", std::process::id()))
}

/// Make a rename in `dir` durable. File systems that cannot sync a folder say so with
/// `InvalidInput` or `Unsupported`; there is nothing more to do on those.
fn sync_dir(dir: &Path) -> Result<()> {
    #[cfg(unix)]
    match File::open(dir).and_then(|d| d.sync_all()) {
        Err(e)
            if !matches!(
                e.kind(),
                std::io::ErrorKind::InvalidInput | std::io::ErrorKind::Unsupported
            ) =>
        {
            return Err(e.into())
        }
        _ => {}
    }
    #[cfg(not(unix))]
    let _ = dir;
    Ok(())
}

/// A temporary file of an earlier run: ours (`.stiction-tmp.*`) or one of the `*.tmp<pid>` files
/// earlier versions wrote.
fn is_temp(name: &str) -> bool {
    if name.starts_with(TEMP_PREFIX) {
        return true;
    }
    name.rsplit_once(".tmp")
        .is_some_and(|(_, pid)| !pid.is_empty() && pid.bytes().all(|b| b.is_ascii_digit()))
}

/// Remove the temporary files a killed run left directly in `dir`; returns how many. Only for a
/// folder no other process writes into (a batch's output folder, once locked).
pub fn remove_stale_temps(dir: &Path) -> usize {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return 0;
    };
    entries
        .filter_map(|e| e.ok())
        .filter(|e| e.file_type().is_ok_and(|t| t.is_file()))
        .filter(|e| is_temp(&e.file_name().to_string_lossy()))
        .filter(|e| std::fs::remove_file(e.path()).is_ok())
        .count()
}

/// Writes made to fail as on a full disk, for tests (see the module doc).
mod fault {
    use std::fs::File;
    use std::io::{self, Write};
    use std::sync::atomic::{AtomicU64, Ordering};

    static WRITES: AtomicU64 = AtomicU64::new(0);

    /// The write number (from 1) from which writes fail, in debug builds only.
    fn fail_from() -> Option<u64> {
        #[cfg(debug_assertions)]
        {
            static FROM: std::sync::OnceLock<Option<u64>> = std::sync::OnceLock::new();
            *FROM.get_or_init(|| {
                std::env::var("STICTION_TEST_FAIL_WRITE")
                    .ok()
                    .and_then(|v| v.trim().parse().ok())
            })
        }
        #[cfg(not(debug_assertions))]
        None
    }

    fn full() -> io::Error {
        io::Error::new(io::ErrorKind::StorageFull, "no space left on device")
    }

    /// Count one write; is it one that must fail?
    pub fn doomed() -> bool {
        fail_from().is_some_and(|from| WRITES.fetch_add(1, Ordering::Relaxed) + 1 >= from)
    }

    /// A file that, when doomed, takes half of the first buffer it is given and then fails.
    pub struct Writer {
        file: File,
        doomed: bool,
    }

    impl Writer {
        pub fn new(file: File, doomed: bool) -> Writer {
            Writer { file, doomed }
        }

        /// The file, or the failure of a doomed write that wrote nothing.
        pub fn finish(self) -> io::Result<File> {
            if self.doomed {
                return Err(full());
            }
            Ok(self.file)
        }
    }

    impl Write for Writer {
        fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
            if self.doomed {
                self.file.write_all(&buf[..buf.len() / 2])?;
                return Err(full());
            }
            self.file.write(buf)
        }
        fn flush(&mut self) -> io::Result<()> {
            self.file.flush()
        }
    }

    /// The failure of a doomed write that goes through a path (an image encoder).
    pub fn check(doomed: bool) -> io::Result<()> {
        if doomed {
            return Err(full());
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn temp_names_are_recognised() {
        assert!(is_temp(".stiction-tmp.123-4.summary.csv"));
        assert!(is_temp("summary.csv.tmp4711"));
        assert!(is_temp("x.json.tmp1"));
        assert!(!is_temp("x.tmp"));
        assert!(!is_temp("loop.tmpl.csv"));
        assert!(!is_temp("summary.csv"));
    }

    #[test]
    fn a_write_replaces_the_file_and_leaves_no_temp() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("sub/a.txt");
        write_atomic(&path, b"one").unwrap();
        write_with(&path, |w| Ok(w.write_all(b"two")?)).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"two");
        let names: Vec<_> = std::fs::read_dir(path.parent().unwrap())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, ["a.txt"]);
    }

    #[test]
    fn a_failed_write_keeps_the_old_file_and_removes_its_temp() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.txt");
        write_atomic(&path, b"old").unwrap();
        let err = write_with(&path, |w| {
            w.write_all(b"half")?;
            anyhow::bail!("the body failed")
        })
        .unwrap_err();
        assert!(format!("{err:#}").contains("a.txt: cannot write the file"));
        assert_eq!(std::fs::read(&path).unwrap(), b"old");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        std::fs::write(dir.path().join(".stiction-tmp.1-1.b.json"), b"x").unwrap();
        assert_eq!(remove_stale_temps(dir.path()), 1);
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }
}
