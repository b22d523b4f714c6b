//! Writing output files so that a folder never holds a half-written set: every file is staged
//! under a temporary name in its own folder (`tempfile`, so a failed run removes what it
//! staged) and renamed over its destination only when all of them were written. The one
//! implementation behind `generate`, `rom`, `report --svg`, `render` and `sweep --out`.
//!
//! What a destination path may be:
//! - a new path, or an existing regular file: staged and renamed over it (atomic);
//! - a symbolic link: its target, as above (the link stays a link, as with a shell's `>`);
//! - a character device or a FIFO (`/dev/null`, `/dev/stdout` on a terminal, a named pipe):
//!   written through, never replaced, after every regular file is staged;
//! - anything else (a folder, a block device, a socket, a broken link): refused, nothing written.

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
    /// An existing path that is neither a regular file nor a stream (see the module's list).
    #[error("{} is {what}, not a file to write", path.display())]
    NotWritable { path: PathBuf, what: &'static str },
    #[error("cannot create output folder {}: {error}", path.display())]
    CreateDir { path: PathBuf, error: std::io::Error },
    #[error("cannot write {}: {error}", path.display())]
    Write { path: PathBuf, error: std::io::Error },
    /// A rename failed after `written` of the `total` files had replaced their destinations.
    #[error("cannot write {}: {error} ({written} of {total} files already written)", path.display())]
    Persist { path: PathBuf, error: std::io::Error, written: usize, total: usize },
    /// The output is one of the command's input files (the same file, by any name).
    #[error("{} is the input file {}: refusing to overwrite it", out.display(), input.display())]
    IsInput { out: PathBuf, input: PathBuf },
    /// A folder `generate` would write into holds files it did not write ([`write_owned`]).
    #[error(
        "{} holds {} that generate did not write ({}{}); generate replaces only the files listed by \
         the manifest.json it wrote there: empty the folder or choose another",
        dir.display(),
        if names.len() == 1 { "a file" } else { "files" },
        names.iter().take(3).cloned().collect::<Vec<_>>().join(", "),
        if names.len() > 3 { format!(" and {} more", names.len() - 3) } else { String::new() }
    )]
    Foreign { dir: PathBuf, names: Vec<String> },
    #[error("cannot remove {}, which an earlier generate wrote: {error}", path.display())]
    Remove { path: PathBuf, error: std::io::Error },
}

/// Where the bytes of one destination go.
enum Dest {
    /// Staged and renamed over this path (the destination, or its link's target).
    Replace(PathBuf),
    /// Opened and written in place.
    Through(PathBuf),
}

/// What `path` is, as a destination (the module's list).
fn destination(path: &Path) -> Result<Dest, OutputError> {
    if path.file_name().is_none() {
        return Err(OutputError::NotAFile(path.to_path_buf()));
    }
    let write = |error| OutputError::Write { path: path.to_path_buf(), error };
    let meta = match fs::symlink_metadata(path) {
        Ok(m) => m,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Dest::Replace(path.to_path_buf())),
        Err(e) => return Err(write(e)),
    };
    let (target, meta) = if meta.file_type().is_symlink() {
        match fs::canonicalize(path) {
            Ok(t) => {
                let m = fs::metadata(&t).map_err(write)?;
                (t, m)
            }
            Err(_) => return Err(OutputError::NotWritable { path: path.to_path_buf(), what: "a broken symbolic link" }),
        }
    } else {
        (path.to_path_buf(), meta)
    };
    let kind = meta.file_type();
    if kind.is_file() {
        return Ok(Dest::Replace(target));
    }
    let not = |what| Err(OutputError::NotWritable { path: path.to_path_buf(), what });
    if kind.is_dir() {
        return not("a folder");
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if kind.is_char_device() || kind.is_fifo() {
            return Ok(Dest::Through(target));
        }
        if kind.is_block_device() {
            return not("a block device");
        }
        if kind.is_socket() {
            return not("a socket");
        }
    }
    not("not a regular file")
}

/// Whether `path` can be written by [`write_files`] as far as can be told before the bytes
/// exist: what it is (the module's list) and, for a file to replace, that its folder exists. A
/// long run checks its output with this first, so it does not fail at the end.
pub fn check_writable(path: &Path) -> Result<(), OutputError> {
    match destination(path)? {
        Dest::Through(_) => Ok(()),
        Dest::Replace(target) => {
            let dir = target.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
            match fs::metadata(dir) {
                Ok(m) if m.is_dir() => Ok(()),
                Ok(_) => Err(OutputError::NotWritable { path: dir.to_path_buf(), what: "not a folder" }),
                Err(error) => Err(OutputError::Write { path: path.to_path_buf(), error }),
            }
        }
    }
}

/// One output being written ([`stage`]): a temporary file beside its destination, renamed over
/// it by [`commit`], or a stream written through (opened at the first write). Dropped without
/// [`commit`], it leaves no file behind. Buffered.
pub struct Staged {
    path: PathBuf,
    dest: StagedDest,
}

enum StagedDest {
    Temp { file: std::io::BufWriter<tempfile::NamedTempFile>, target: PathBuf },
    Through { file: Option<std::io::BufWriter<fs::File>>, target: PathBuf },
}

/// Starts writing `path` (see the module's list of what it may be): nothing is visible at
/// `path` until [`commit`].
pub fn stage(path: &Path) -> Result<Staged, OutputError> {
    let dest = match destination(path)? {
        Dest::Through(target) => StagedDest::Through { file: None, target },
        Dest::Replace(target) => {
            let dir = target.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
            let mut builder = tempfile::Builder::new();
            builder.prefix(TEMP_PREFIX);
            // As `fs::write` would create it (0666 less the umask), not tempfile's private 0600.
            #[cfg(unix)]
            builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
            let tmp = builder.tempfile_in(dir).map_err(|error| OutputError::Write { path: path.to_path_buf(), error })?;
            StagedDest::Temp { file: std::io::BufWriter::with_capacity(1 << 20, tmp), target }
        }
    };
    Ok(Staged { path: path.to_path_buf(), dest })
}

impl Staged {
    /// The path it was staged for (for messages).
    pub fn path(&self) -> &Path {
        &self.path
    }

    fn is_through(&self) -> bool {
        matches!(self.dest, StagedDest::Through { .. })
    }

    /// `write_all`, its error naming the path.
    pub fn put(&mut self, bytes: &[u8]) -> Result<(), OutputError> {
        self.write_all(bytes).map_err(|error| OutputError::Write { path: self.path.clone(), error })
    }
}

impl Write for Staged {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        match &mut self.dest {
            StagedDest::Temp { file, .. } => file.write(buf),
            StagedDest::Through { file, target } => match file {
                Some(f) => f.write(buf),
                None => file.insert(std::io::BufWriter::new(fs::OpenOptions::new().write(true).open(target)?)).write(buf),
            },
        }
    }
    fn flush(&mut self) -> std::io::Result<()> {
        match &mut self.dest {
            StagedDest::Temp { file, .. } => file.flush(),
            StagedDest::Through { file, .. } => file.as_mut().map_or(Ok(()), |f| f.flush()),
        }
    }
}

/// Makes every staged output visible, all or none as far as the system allows: every buffer is
/// flushed first (a full disk fails here, nothing renamed); a failure of the renames can leave
/// the earlier ones done, and says so.
pub fn commit(staged: Vec<Staged>) -> Result<(), OutputError> {
    let mut temps = Vec::with_capacity(staged.len());
    for s in staged {
        let write = |error| OutputError::Write { path: s.path.clone(), error };
        match s.dest {
            StagedDest::Temp { file, target } => temps.push((file.into_inner().map_err(|e| write(e.into_error()))?, s.path, target)),
            StagedDest::Through { file, .. } => {
                if let Some(f) = file {
                    f.into_inner().map_err(|e| write(e.into_error()))?;
                }
            }
        }
    }
    let total = temps.len();
    for (written, (tmp, path, target)) in temps.into_iter().enumerate() {
        tmp.persist(&target).map_err(|e| OutputError::Persist { path, error: e.error, written, total })?;
    }
    Ok(())
}

/// Writes every file, or none: on any error the staged files are removed and no destination
/// is touched (a failure of the final renames can leave the earlier ones done; it says so).
/// Streams (devices, FIFOs) are written after every regular file is staged.
pub fn write_files(files: &[(PathBuf, &[u8])]) -> Result<(), OutputError> {
    let mut staged = Vec::with_capacity(files.len());
    for (path, bytes) in files {
        staged.push((stage(path)?, *bytes));
    }
    // Regular files first: a stream, once written, cannot be taken back.
    staged.sort_by_key(|(s, _)| s.is_through());
    let mut done = Vec::with_capacity(staged.len());
    for (mut s, bytes) in staged {
        s.put(bytes)?;
        s.flush().map_err(|error| OutputError::Write { path: s.path.clone(), error })?;
        done.push(s);
    }
    commit(done)
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

/// `generate`'s write: `dir` is the generator's own. `owned` names the files an earlier run
/// wrote there (from its manifest.json; empty when there is none). Any other entry of `dir` (a
/// file, a folder, a link) is refused before anything is written. Then every file is written
/// ([`write_all`]) and the owned files the new set does not have are removed, so the folder
/// holds exactly one configuration.
pub fn write_owned(dir: &Path, files: &[GeneratedFile], owned: &[String]) -> Result<(), OutputError> {
    let mut foreign = Vec::new();
    let mut stale = Vec::new();
    if let Ok(entries) = fs::read_dir(dir) {
        for entry in entries {
            let entry = entry.map_err(|error| OutputError::Write { path: dir.to_path_buf(), error })?;
            let name = entry.file_name().to_string_lossy().into_owned();
            let kind = entry.file_type().ok();
            let regular = kind.is_some_and(|t| t.is_file());
            if !regular || !owned.contains(&name) {
                foreign.push(if kind.is_some_and(|t| t.is_dir()) { format!("{name}/") } else { name });
            } else if !files.iter().any(|f| f.name == name) {
                stale.push(name);
            }
        }
    }
    if !foreign.is_empty() {
        foreign.sort();
        return Err(OutputError::Foreign { dir: dir.to_path_buf(), names: foreign });
    }
    write_all(dir, files)?;
    for name in stale {
        let path = dir.join(name);
        fs::remove_file(&path).map_err(|error| OutputError::Remove { path, error })?;
    }
    Ok(())
}

/// Refuses an output that is one of `inputs` (the same file by another name or link too, where
/// both exist): writing it would destroy the input it is made from.
pub fn check_not_input(out: &Path, inputs: &[&Path]) -> Result<(), OutputError> {
    let Ok(o) = fs::metadata(out) else { return Ok(()) };
    for input in inputs {
        let Ok(i) = fs::metadata(input) else { continue };
        #[cfg(unix)]
        let same = {
            use std::os::unix::fs::MetadataExt;
            (o.dev(), o.ino()) == (i.dev(), i.ino())
        };
        #[cfg(not(unix))]
        let same = fs::canonicalize(out).ok().is_some_and(|c| fs::canonicalize(input).ok() == Some(c)) && o.len() == i.len();
        if same {
            return Err(OutputError::IsInput { out: out.to_path_buf(), input: input.to_path_buf() });
        }
    }
    Ok(())
}
