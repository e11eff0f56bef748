//! Output files that are never half written: each file is written to a temporary name in its own
//! directory and renamed over the final path only when complete, so an interrupted or failed write
//! never leaves a truncated `patches.csv` that looks valid.
//!
//! Architecture invariant: every file the project writes goes through [`write_file`] or
//! [`AtomicFile`]. A writer that fails (or panics) midway leaves no file at the final path (an older
//! complete file there is kept) and no temporary file behind. A process killed midway may leave the
//! temporary `.NAME.PID.tmp`, never a partial `NAME`.

use std::fs::File;
use std::io::{BufWriter, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

/// A file being written under a temporary name beside `path`; [`AtomicFile::commit`] renames it to
/// `path`. Dropped without a commit, it removes the temporary file.
pub struct AtomicFile {
    path: PathBuf,
    tmp: PathBuf,
    /// `None` once committed or abandoned.
    w: Option<BufWriter<File>>,
}

impl AtomicFile {
    /// Creates the temporary file `.NAME.PID.tmp` in `path`'s directory (which must exist).
    pub fn create(path: &Path) -> std::io::Result<AtomicFile> {
        let tmp = temp_path(path);
        let file = File::create(&tmp)?;
        Ok(AtomicFile { path: path.to_path_buf(), tmp, w: Some(BufWriter::new(file)) })
    }

    /// The final path.
    #[must_use]
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Flushes the file and renames it to its final path; on failure the temporary file is removed.
    pub fn commit(mut self) -> std::io::Result<()> {
        let Some(w) = self.w.take() else { return Ok(()) };
        let result = w.into_inner().map_err(std::io::IntoInnerError::into_error).and_then(|f| {
            drop(f);
            std::fs::rename(&self.tmp, &self.path)
        });
        if result.is_err() {
            let _ = std::fs::remove_file(&self.tmp);
        }
        result
    }

    fn writer(&mut self) -> std::io::Result<&mut BufWriter<File>> {
        self.w.as_mut().ok_or_else(|| std::io::Error::other("file already committed"))
    }
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.writer()?.write(buf)
    }

    fn write_all(&mut self, buf: &[u8]) -> std::io::Result<()> {
        self.writer()?.write_all(buf)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.writer()?.flush()
    }
}

impl Seek for AtomicFile {
    fn seek(&mut self, pos: SeekFrom) -> std::io::Result<u64> {
        self.writer()?.seek(pos)
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        if self.w.take().is_some() {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

/// Writes `path` atomically: `write` fills the temporary file, which is renamed to `path` if it
/// returns `Ok` and removed if it returns an error or panics. The error is `write`'s or the rename's.
pub fn write_file<E: From<std::io::Error>>(path: &Path, write: impl FnOnce(&mut AtomicFile) -> Result<(), E>) -> Result<(), E> {
    let mut file = AtomicFile::create(path)?;
    write(&mut file)?;
    file.commit()?;
    Ok(())
}

/// Writes `bytes` to `path` atomically (the atomic `std::fs::write`).
pub fn write_bytes(path: &Path, bytes: impl AsRef<[u8]>) -> std::io::Result<()> {
    write_file(path, |w| w.write_all(bytes.as_ref()))
}

/// `.NAME.PID.tmp` beside `path`: hidden, never the name of an output, distinct per process.
fn temp_path(path: &Path) -> PathBuf {
    let name = path.file_name().map_or_else(|| "output".into(), |n| n.to_string_lossy().into_owned());
    path.with_file_name(format!(".{name}.{}.tmp", std::process::id()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("radiosity-atomic-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("scratch dir");
        dir
    }

    fn entries(dir: &Path) -> Vec<String> {
        let mut names: Vec<String> =
            std::fs::read_dir(dir).expect("read dir").map(|e| e.expect("entry").file_name().to_string_lossy().into_owned()).collect();
        names.sort();
        names
    }

    #[test]
    fn complete_write_lands_at_the_final_path() {
        let dir = scratch("ok");
        let path = dir.join("patches.csv");
        write_bytes(&path, "a,b\n1,2\n").expect("write");
        assert_eq!(std::fs::read_to_string(&path).expect("read"), "a,b\n1,2\n");
        assert_eq!(entries(&dir), ["patches.csv"]);
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn writer_failing_midway_leaves_nothing() {
        let dir = scratch("fail");
        let path = dir.join("patches.csv");
        let result = write_file(&path, |w| {
            w.write_all(b"index,group\n0,")?;
            // Big enough to pass the buffer and reach the temporary file.
            w.write_all(&vec![b'9'; 1 << 17])?;
            Err(std::io::Error::other("solver interrupted"))
        });
        assert_eq!(result.expect_err("must fail").to_string(), "solver interrupted");
        assert!(entries(&dir).is_empty(), "left behind: {:?}", entries(&dir));
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn failed_rewrite_keeps_the_old_complete_file() {
        let dir = scratch("keep");
        let path = dir.join("stats.json");
        write_bytes(&path, "{}\n").expect("first write");
        let result: std::io::Result<()> = write_file(&path, |w| {
            w.write_all(b"{\"trunc")?;
            Err(std::io::Error::other("disk full"))
        });
        assert!(result.is_err());
        assert_eq!(std::fs::read_to_string(&path).expect("read"), "{}\n");
        assert_eq!(entries(&dir), ["stats.json"]);
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn writer_panicking_midway_leaves_nothing() {
        let dir = scratch("panic");
        let path = dir.join("solution.ply");
        let caught = std::panic::catch_unwind(|| {
            let _ = write_file(&path, |w| -> std::io::Result<()> {
                w.write_all(&vec![0u8; 1 << 17])?;
                panic!("bug in a writer");
            });
        });
        assert!(caught.is_err());
        assert!(entries(&dir).is_empty(), "left behind: {:?}", entries(&dir));
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn dropped_atomic_file_is_removed() {
        let dir = scratch("drop");
        let mut f = AtomicFile::create(&dir.join("patches.csv")).expect("create");
        f.write_all(b"index\n").expect("write");
        assert_eq!(entries(&dir).len(), 1, "the temporary file exists while writing");
        drop(f);
        assert!(entries(&dir).is_empty(), "left behind: {:?}", entries(&dir));
        let _ = std::fs::remove_dir_all(&dir);
    }
}
