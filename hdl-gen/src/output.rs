//! Writing output files so that a folder never holds a half-written set: every file is staged
//! under a temporary name in its own folder (`tempfile`, so a failed run removes what it
//! staged) and renamed over its destination only when all of them were written. The one
//! implementation behind `generate`, `rom`, `report --png`, `render` and `sweep --out`.

use crate::GeneratedFile;
use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Prefix of the staged files (tests check that none is left behind).
pub const TEMP_PREFIX: &str = ".tmp-segshade-";

/// Writes every file, or none: on any error the staged files are removed and no destination
/// is touched (a failure of the final renames can leave the earlier ones done; it says so).
pub fn write_files(files: &[(PathBuf, &[u8])]) -> Result<(), String> {
    let mut staged = Vec::with_capacity(files.len());
    for (path, bytes) in files {
        let dir = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
        if path.file_name().is_none() {
            return Err(format!("{} is not a file path", path.display()));
        }
        let mut builder = tempfile::Builder::new();
        builder.prefix(TEMP_PREFIX);
        // As `fs::write` would create it (0666 less the umask), not tempfile's private 0600.
        #[cfg(unix)]
        builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
        let mut tmp = builder.tempfile_in(dir).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        tmp.write_all(bytes).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        staged.push((tmp, path));
    }
    let n = staged.len();
    for (k, (tmp, path)) in staged.into_iter().enumerate() {
        tmp.persist(path).map_err(|e| format!("cannot write {}: {} ({k} of {n} files already written)", path.display(), e.error))?;
    }
    Ok(())
}

/// Every generated file into `dir` (created if missing), all or none.
pub fn write_all(dir: &Path, files: &[GeneratedFile]) -> Result<(), String> {
    fs::create_dir_all(dir).map_err(|e| format!("cannot create output folder {}: {e}", dir.display()))?;
    let files: Vec<(PathBuf, &[u8])> = files.iter().map(|f| (dir.join(&f.name), f.contents.as_bytes())).collect();
    write_files(&files)
}

/// One file, atomically (ROM images, images, tables).
pub fn write_one(path: &Path, contents: &[u8]) -> Result<(), String> {
    write_files(&[(path.to_path_buf(), contents)])
}
