//! Text input files (triangle lists, Wavefront meshes) read with limits, the one reader of the
//! binaries that take them (`render`, `board`): a folder, a file too large or not text, or a line
//! too long is refused with one message naming the file, before anything is sized by it.

use std::io::Read;
use std::path::{Path, PathBuf};

/// Largest input file: read no further than this. A triangle line takes about 60 bytes, so this
/// is about a million triangles, each simulated clock by clock; a larger file is a mistake more
/// often than an input (a 1 GB file was read whole).
pub const MAX_BYTES: u64 = 64 << 20;
/// Longest line: a triangle takes nine numbers, an OBJ face a vertex list.
pub const MAX_LINE_BYTES: usize = 4096;

/// An input file [`read_text`] refuses; its message begins with the file's name.
#[derive(Debug, thiserror::Error)]
pub enum InputError {
    #[error("{}: is a folder", .0.display())]
    Folder(PathBuf),
    #[error("{}: {error}", path.display())]
    Read { path: PathBuf, error: std::io::Error },
    #[error("{}: larger than {} MiB, the most an input file may hold", .0.display(), MAX_BYTES >> 20)]
    TooLarge(PathBuf),
    #[error("{}: not UTF-8 text", .0.display())]
    NotText(PathBuf),
    #[error("{}: line {line} is longer than {MAX_LINE_BYTES} bytes", path.display())]
    LongLine { path: PathBuf, line: usize },
}

/// The text of `path`, refused when it is a folder, larger than [`MAX_BYTES`], not UTF-8, or has
/// a line longer than [`MAX_LINE_BYTES`]. Reads at most one byte past the limit.
pub fn read_text(path: &Path) -> Result<String, InputError> {
    if path.is_dir() {
        return Err(InputError::Folder(path.to_path_buf()));
    }
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(MAX_BYTES + 1).read_to_end(&mut bytes))
        .map_err(|error| InputError::Read { path: path.to_path_buf(), error })?;
    if bytes.len() as u64 > MAX_BYTES {
        return Err(InputError::TooLarge(path.to_path_buf()));
    }
    let text = String::from_utf8(bytes).map_err(|_| InputError::NotText(path.to_path_buf()))?;
    if let Some(n) = text.lines().position(|l| l.len() > MAX_LINE_BYTES) {
        return Err(InputError::LongLine { path: path.to_path_buf(), line: n + 1 });
    }
    Ok(text)
}
