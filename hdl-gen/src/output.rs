//! Writing generated files so that a folder never holds a half-written set: every file goes to
//! a temporary name first and is renamed only when all of them were written.

use crate::GeneratedFile;
use std::fs;
use std::path::{Path, PathBuf};

pub fn write_all(dir: &Path, files: &[GeneratedFile]) -> Result<(), String> {
    fs::create_dir_all(dir).map_err(|e| format!("cannot create output folder {}: {e}", dir.display()))?;
    let mut staged: Vec<(PathBuf, PathBuf)> = Vec::new();
    let result = (|| {
        for f in files {
            let tmp = dir.join(format!(".{}.tmp-{}", f.name, std::process::id()));
            staged.push((tmp.clone(), dir.join(&f.name)));
            fs::write(&tmp, &f.contents).map_err(|e| format!("cannot write {}: {e}", tmp.display()))?;
        }
        for (tmp, dst) in &staged {
            fs::rename(tmp, dst).map_err(|e| format!("cannot rename {} to {}: {e}", tmp.display(), dst.display()))?;
        }
        Ok(())
    })();
    if result.is_err() {
        for (tmp, _) in &staged {
            let _ = fs::remove_file(tmp);
        }
    }
    result
}

/// One file, atomically (for single-file outputs such as ROM images and images).
pub fn write_one(path: &Path, contents: &[u8]) -> Result<(), String> {
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let name = path.file_name().ok_or_else(|| format!("{} is not a file path", path.display()))?;
    let tmp = dir.join(format!(".{}.tmp-{}", name.to_string_lossy(), std::process::id()));
    fs::write(&tmp, contents).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    fs::rename(&tmp, path).map_err(|e| {
        let _ = fs::remove_file(&tmp);
        format!("cannot write {}: {e}", path.display())
    })
}
