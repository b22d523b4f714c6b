//! Writing output files so that a folder never holds a half-written set: every file is staged
//! under a temporary name in its own folder (`tempfile`, so a failed run removes what it
//! staged) and renamed over its destination only when all of them were written. The one
//! implementation behind `generate`, `rom`, `report --svg`, `render` and `sweep --out`.

use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};

/// One output file, name relative to the output folder.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct GeneratedFile {
    pub name: String,
    pub contents: String,
}

/// Prefix of the staged files (tests check that none is left behind).
pub const TEMP_PREFIX: &str = ".tmp-segshade-";

/// A file that could not be written; the message names it and the system's reason.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    #[error("{} is not a file path", .0.display())]
    NotAFile(PathBuf),
    #[error("cannot create output folder {}: {error}", path.display())]
    CreateDir { path: PathBuf, error: std::io::Error },
    #[error("cannot write {}: {error}", path.display())]
    Write { path: PathBuf, error: std::io::Error },
    /// A rename failed after `written` of the `total` files had replaced their destinations.
    #[error("cannot write {}: {error} ({written} of {total} files already written)", path.display())]
    Persist { path: PathBuf, error: std::io::Error, written: usize, total: usize },
}

/// Writes every file, or none: on any error the staged files are removed and no destination
/// is touched (a failure of the final renames can leave the earlier ones done; it says so).
pub fn write_files(files: &[(PathBuf, &[u8])]) -> Result<(), OutputError> {
    let mut staged = Vec::with_capacity(files.len());
    for (path, bytes) in files {
        let dir = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
        if path.file_name().is_none() {
            return Err(OutputError::NotAFile(path.clone()));
        }
        let write = |error| OutputError::Write { path: path.clone(), error };
        let mut builder = tempfile::Builder::new();
        builder.prefix(TEMP_PREFIX);
        // As `fs::write` would create it (0666 less the umask), not tempfile's private 0600.
        #[cfg(unix)]
        builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
        let mut tmp = builder.tempfile_in(dir).map_err(write)?;
        tmp.write_all(bytes).map_err(write)?;
        staged.push((tmp, path));
    }
    let total = staged.len();
    for (written, (tmp, path)) in staged.into_iter().enumerate() {
        tmp.persist(path).map_err(|e| OutputError::Persist { path: path.clone(), error: e.error, written, total })?;
    }
    Ok(())
}

/// Every generated file into `dir` (created if missing), all or none.
pub fn write_all(dir: &Path, files: &[GeneratedFile]) -> Result<(), OutputError> {
    fs::create_dir_all(dir).map_err(|error| OutputError::CreateDir { path: dir.to_path_buf(), error })?;
    let files: Vec<(PathBuf, &[u8])> = files.iter().map(|f| (dir.join(&f.name), f.contents.as_bytes())).collect();
    write_files(&files)
}

/// One file, atomically (ROM images, images, tables).
pub fn write_one(path: &Path, contents: &[u8]) -> Result<(), OutputError> {
    write_files(&[(path.to_path_buf(), contents)])
}
