//! The files a command writes: each goes to `OUT.partial` first and is renamed into place once
//! complete, so a failed run never leaves a half-written file where a good one was; and every
//! output is checked before a long run starts, so a typo in a path fails in a second, as bad
//! input, rather than after the whole run.

use std::io::Write;
use std::path::{Path, PathBuf};

/// An output that cannot be written.
#[derive(Debug, thiserror::Error)]
#[error("cannot write {}: {reason}", path.display())]
pub struct OutputError {
    /// The file or directory.
    pub path: PathBuf,
    /// Why.
    pub reason: String,
}

impl OutputError {
    fn new(path: &Path, reason: impl ToString) -> Self {
        Self {
            path: path.to_path_buf(),
            reason: reason.to_string(),
        }
    }
}

/// `path` with `.partial` appended: where an output is written until it is complete.
pub fn partial_path(path: &Path) -> PathBuf {
    let mut partial = path.as_os_str().to_owned();
    partial.push(".partial");
    PathBuf::from(partial)
}

/// What a command writes to a file: its bytes, or a writer of them (a large array written a
/// piece at a time rather than held whole in memory).
pub enum Contents<'a> {
    /// The file's bytes.
    Bytes(Vec<u8>),
    /// Writes the file's bytes to the writer it is given.
    Stream(Box<Writer<'a>>),
}

/// Writes a file's bytes to the writer it is given (see [`Contents::Stream`]).
pub type Writer<'a> = dyn Fn(&mut dyn Write) -> std::io::Result<()> + Send + Sync + 'a;

impl From<Vec<u8>> for Contents<'_> {
    fn from(bytes: Vec<u8>) -> Self {
        Self::Bytes(bytes)
    }
}

/// Writes `bytes` to `OUT.partial`, then renames it to `path`.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    write_with(path, |f| f.write_all(bytes))
}

/// Writes `contents` to `OUT.partial`, then renames it to `path` (see [`write_atomically`]).
pub fn write_contents(path: &Path, contents: &Contents) -> Result<(), OutputError> {
    match contents {
        Contents::Bytes(bytes) => write_atomically(path, bytes),
        Contents::Stream(write) => write_with(path, |f| write(f)),
    }
}

/// Creates `OUT.partial`, has `write` fill it, syncs it and renames it to `path`; on any
/// failure removes it.
fn write_with(
    path: &Path,
    write: impl FnOnce(&mut std::fs::File) -> std::io::Result<()>,
) -> Result<(), OutputError> {
    let partial = partial_path(path);
    let result = std::fs::File::create(&partial)
        .and_then(|mut f| write(&mut f).and_then(|()| f.sync_all()))
        .and_then(|()| std::fs::rename(&partial, path));
    if let Err(e) = result {
        let _ = std::fs::remove_file(&partial);
        return Err(OutputError::new(path, e));
    }
    Ok(())
}

/// Checks, before any work, that the file `path` can be written: its directory exists and
/// takes a new file, and `path` is not a directory. Leaves nothing behind.
pub fn check_file(path: &Path) -> Result<(), OutputError> {
    if path.is_dir() {
        return Err(OutputError::new(path, "it is a directory"));
    }
    let dir = parent(path);
    if !dir.is_dir() {
        return Err(OutputError::new(
            path,
            format!("the directory {} does not exist", dir.display()),
        ));
    }
    probe(path, &partial_path(path))
}

/// Checks, before any work, that files can be written in the directory `dir`: it exists and
/// takes a new file, or it can be created (its nearest existing ancestor is a directory that
/// takes a new file). Creates nothing.
pub fn check_dir(dir: &Path) -> Result<(), OutputError> {
    let mut existing = dir;
    while !existing.exists() {
        existing = match existing.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
    }
    if !existing.is_dir() {
        return Err(OutputError::new(
            dir,
            format!("{} is not a directory", existing.display()),
        ));
    }
    probe(
        dir,
        &existing.join(format!(".nadf-probe-{}", std::process::id())),
    )
}

/// The directory a file goes in (`.` for a bare file name).
fn parent(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// Creates and removes `file` to see whether the output `what` can be written.
fn probe(what: &Path, file: &Path) -> Result<(), OutputError> {
    match std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(file)
    {
        Ok(_) => {
            let _ = std::fs::remove_file(file);
            Ok(())
        }
        // A stale probe (or partial file) of an earlier run: the directory is writable.
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => Ok(()),
        Err(e) => Err(OutputError::new(what, e)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outputs_in_missing_directories_are_refused_and_nothing_is_left() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("x.json");
        check_file(&file).unwrap();
        assert!(check_file(&dir.path().join("missing/x.json")).is_err());
        assert!(check_file(dir.path()).is_err());
        // A directory that can be created is fine; one under a file is not.
        check_dir(&dir.path().join("a/b")).unwrap();
        std::fs::write(&file, b"{}").unwrap();
        assert!(check_dir(&file.join("sub")).is_err());
        let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(left.len(), 1, "{left:?}");
    }

    #[test]
    fn an_atomic_write_replaces_the_file_whole() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("out.csv");
        write_atomically(&file, b"a").unwrap();
        write_atomically(&file, b"bc").unwrap();
        assert_eq!(std::fs::read(&file).unwrap(), b"bc");
        assert!(!partial_path(&file).exists());
        let err = write_atomically(&dir.path().join("no/out.csv"), b"x").unwrap_err();
        assert!(err.to_string().contains("cannot write"), "{err}");
    }

    /// A streamed file that fails part way leaves neither its partial file nor a file at its
    /// path (the good one there stays); one that succeeds is whole.
    #[test]
    fn a_stream_that_fails_leaves_the_old_file() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("out.npy");
        write_atomically(&file, b"old").unwrap();
        let failing = Contents::Stream(Box::new(|out: &mut dyn Write| {
            out.write_all(b"half")?;
            Err(std::io::Error::other("disk full"))
        }));
        let err = write_contents(&file, &failing).unwrap_err();
        assert!(err.to_string().contains("disk full"), "{err}");
        assert_eq!(std::fs::read(&file).unwrap(), b"old");
        assert!(!partial_path(&file).exists());
        let pieces = Contents::Stream(Box::new(|out: &mut dyn Write| {
            (0..3).try_for_each(|i| out.write_all(&[b'a' + i]))
        }));
        write_contents(&file, &pieces).unwrap();
        assert_eq!(std::fs::read(&file).unwrap(), b"abc");
    }
}
