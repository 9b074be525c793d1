//! Reading text files, and the one writer of every output file ([`write_output`]).
//!
//! An output is first written next to its destination into a new temporary file (random
//! name, `O_EXCL`, never a name derived from the output's) and renamed into place only when
//! complete, so a failed run never leaves partial output and no file or link another user
//! planted is ever opened; FIFOs, devices and standard output are written directly. A failure
//! to write is a [`WriteError`], so a program can tell a broken environment (disk full, no
//! permission) from bad input.

use std::path::{Path, PathBuf};

use anyhow::{anyhow, Context, Result};
use serde::de::DeserializeOwned;

/// Where an input came from, for messages.
#[derive(Debug, Clone)]
pub enum Source {
    /// A built-in preset.
    Preset(&'static str),
    /// A file.
    File(PathBuf),
}

impl std::fmt::Display for Source {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Source::Preset(n) => write!(f, "preset `{n}`"),
            Source::File(p) => write!(f, "{}", p.display()),
        }
    }
}

/// Reads a whole file, naming it in the error.
pub fn read_text(path: &Path) -> Result<String> {
    std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))
}

/// Parses TOML into `T`, naming the source; unknown keys are rejected by `T`'s definition,
/// with the key the user most likely meant ([`did_you_mean`]).
pub fn parse_toml<T: DeserializeOwned>(text: &str, source: &Source) -> Result<T> {
    toml::from_str(text).map_err(|e| {
        let message = e.to_string();
        let hint = did_you_mean(&message).map(|k| format!("; did you mean `{k}`?")).unwrap_or_default();
        anyhow!("{source}: {}{hint}", message.trim_end())
    })
}

/// For serde's "unknown field `KEY`, expected one of `A`, `B`, ..." (or "expected `A`"), the
/// valid key the user most likely meant: one with KEY as a whole word (`legs`: `stance_legs`;
/// `mass`: `mass_kg`), else the nearest by Jaro-Winkler similarity of at least 0.8
/// (`mass_kgs`: `mass_kg`); `None` for any other message or when nothing is near.
pub fn did_you_mean(message: &str) -> Option<String> {
    let rest = &message[message.find("unknown field `")? + "unknown field `".len()..];
    let (key, rest) = rest.split_once('`')?;
    let expected = &rest[rest.find("expected")?..];
    let valid: Vec<&str> = expected.split('`').skip(1).step_by(2).collect();
    let key = key.to_ascii_lowercase();
    let word = valid.iter().filter(|v| v.split('_').any(|w| w == key)).collect::<Vec<_>>();
    if let [one] = word.as_slice() {
        return Some(one.to_string());
    }
    valid
        .iter()
        .map(|v| (strsim::jaro_winkler(&key, v), v))
        .filter(|(score, _)| *score >= 0.8)
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, v)| v.to_string())
}

/// An output file that could not be written: the environment's fault, not the input's.
#[derive(Debug, thiserror::Error)]
#[error("cannot write {}", path.display())]
pub struct WriteError {
    /// The destination.
    pub path: PathBuf,
    /// What the operating system said.
    #[source]
    pub source: std::io::Error,
}

/// CSV text of `rows` (with a header from the field names).
pub fn csv_string<T: serde::Serialize>(rows: &[T]) -> Result<String> {
    let mut w = csv::Writer::from_writer(Vec::new());
    for r in rows {
        w.serialize(r)?;
    }
    Ok(String::from_utf8(w.into_inner().context("CSV output")?)?)
}

/// Fails with a clear message when the folder `path` should be written into does not exist.
pub fn check_parent_exists(path: &Path) -> Result<()> {
    match path.parent().filter(|p| !p.as_os_str().is_empty()) {
        Some(dir) if !dir.is_dir() => {
            anyhow::bail!("cannot write {}: the folder {} does not exist", path.display(), dir.display())
        }
        _ => Ok(()),
    }
}

/// Writes `bytes` to `path` as [`write_output`] does.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    write_output(path, |out| {
        std::io::Write::write_all(out, bytes)
            .map_err(|source| WriteError { path: path.to_path_buf(), source })?;
        Ok(())
    })
}

/// The file an output's content is written into by [`write_output`]: a new temporary file
/// beside a regular destination, or memory for a destination that cannot be replaced (a FIFO,
/// a device, standard output). It is `Write + Seek` (a TIFF encoder needs both) and remembers
/// the first I/O error it met, so that a full disk is reported as such whatever the encoder
/// on top made of it.
#[derive(Debug)]
pub struct OutputFile {
    sink: Sink,
    failed: Option<std::io::Error>,
}

#[derive(Debug)]
enum Sink {
    File(std::fs::File),
    Memory(std::io::Cursor<Vec<u8>>),
}

impl OutputFile {
    fn note<T>(&mut self, r: std::io::Result<T>) -> std::io::Result<T> {
        if let Err(e) = &r {
            if self.failed.is_none() && e.kind() != std::io::ErrorKind::Interrupted {
                self.failed = Some(std::io::Error::new(e.kind(), e.to_string()));
            }
        }
        r
    }
}

impl OutputFile {
    /// Forgets the first write error met so far and returns it, so that what was written before
    /// it is put in place rather than discarded. For a record whose every row up to a failure
    /// is worth keeping (`drive`'s servo log when the disk fills mid-run: the rows are what the
    /// robot did), never for a file that must be whole to be read.
    pub fn take_failure(&mut self) -> Option<std::io::Error> {
        self.failed.take()
    }
}

impl std::io::Write for OutputFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let r = match &mut self.sink {
            Sink::File(f) => f.write(buf),
            Sink::Memory(m) => m.write(buf),
        };
        self.note(r)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        let r = match &mut self.sink {
            Sink::File(f) => f.flush(),
            Sink::Memory(m) => m.flush(),
        };
        self.note(r)
    }
}

impl std::io::Seek for OutputFile {
    fn seek(&mut self, pos: std::io::SeekFrom) -> std::io::Result<u64> {
        let r = match &mut self.sink {
            Sink::File(f) => f.seek(pos),
            Sink::Memory(m) => m.seek(pos),
        };
        self.note(r)
    }
}

/// Writes one output: `write` fills an [`OutputFile`], which is then put in place of `path`;
/// on failure nothing of it is left and `path` is untouched.
///
/// How, following the most careful Unix tools (coreutils, `sed -i`, `rsync`):
/// - a regular file (existing or new) is written to a new temporary file in the same folder,
///   created with a random name, `O_EXCL` (so no file or symbolic link planted there is ever
///   opened) and mode 0666 less the umask, and renamed over `path` once complete and synced.
///   A file it replaces keeps its permissions (and, when run as root, its owner).
/// - `path` may be a symbolic link: its target is what is written (as the shell's `>` does),
///   except a link in a shared sticky folder such as `/tmp` owned by another user, which is
///   refused, as the kernel's `fs.protected_symlinks` refuses it to `open`.
/// - anything else that exists (a FIFO, `/dev/null`, a terminal) and standard output or error
///   named as `/dev/stdout`, `/dev/fd/N` or `/proc/self/fd/N` (or a link to one) is written
///   into directly, never replaced and never through a file in a shared folder: the content is
///   held in memory until the run completes. Standard output is written through the process's
///   own descriptor, so a shell's `>>` appends and a pipe receives the bytes.
///
/// When [`stage_outputs`] was called (the `sandslope` binary does at start-up), nothing is
/// put in place until [`commit_outputs`], so a run that fails after writing some of its
/// outputs leaves none of them. A failure to write is a [`WriteError`] naming `path` with
/// what the operating system said, whatever layer (an image encoder) met it.
pub fn write_output(path: &Path, write: impl FnOnce(&mut OutputFile) -> Result<()>) -> Result<()> {
    let target = OutputTarget::resolve(path)?;
    let fail = |source: std::io::Error| WriteError { path: path.to_path_buf(), source };
    let (mut out, temp) = match &target {
        OutputTarget::Replace(p) => {
            let (file, temp) = create_temp_beside(p).map_err(fail)?;
            (OutputFile { sink: Sink::File(file), failed: None }, Some(temp))
        }
        OutputTarget::Stream(_) | OutputTarget::Descriptor(_) => {
            (OutputFile { sink: Sink::Memory(std::io::Cursor::new(Vec::new())), failed: None }, None)
        }
    };
    let written = write(&mut out).and_then(|()| {
        use std::io::Write;
        out.flush().map_err(fail)?;
        // An error a writer on top swallowed (a `BufWriter` flushing as it is dropped).
        if let Some(source) = out.failed.take() {
            return Err(fail(source).into());
        }
        if let Sink::File(f) = &out.sink {
            f.sync_all().map_err(fail)?;
        }
        Ok(())
    });
    if let Err(e) = written {
        if let Some(t) = &temp {
            remove_temp(t);
        }
        // The operating system's own reason (a full disk) rather than what an encoder on top
        // made of it (`ImageError(IoError(Custom { .. }))`).
        return Err(match out.failed.take() {
            Some(source) if !e.chain().any(|c| c.is::<WriteError>()) => fail(source).into(),
            _ => e,
        });
    }
    let content = match (out.sink, temp) {
        (Sink::File(_), Some(t)) => Content::Temp(t),
        (Sink::Memory(m), _) => Content::Bytes(m.into_inner()),
        (Sink::File(_), None) => unreachable!("a file sink always has its temporary path"),
    };
    let staged = Staged { content, target, requested: path.to_path_buf() };
    let mut guard = lock_outputs();
    match guard.staged.as_mut() {
        Some(list) => {
            // The same output written twice in one run: the later content wins.
            if let Some(i) = list.iter().position(|s| s.target == staged.target) {
                let old = list.remove(i);
                if let Content::Temp(t) = &old.content {
                    let _ = std::fs::remove_file(t);
                    guard.temps.retain(|x| x != t);
                }
            }
            guard.staged.as_mut().expect("checked above").push(staged);
            Ok(())
        }
        None => {
            drop(guard);
            let result = staged.put_in_place();
            staged.forget();
            result
        }
    }
}

/// Creates the temporary file for `target` in its folder: random name, `O_EXCL`, mode 0666
/// less the umask; registered so that an interrupted run removes it.
fn create_temp_beside(target: &Path) -> std::io::Result<(std::fs::File, PathBuf)> {
    let dir = match target.parent().filter(|p| !p.as_os_str().is_empty()) {
        Some(d) => d.to_path_buf(),
        None => PathBuf::from("."),
    };
    let named = tempfile::Builder::new()
        .prefix(".sandslope-")
        .suffix(".partial")
        .rand_bytes(12)
        .permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666))
        .tempfile_in(dir)?;
    // The run, not `tempfile`, removes it (on failure, on a signal, or by renaming it).
    let (file, temp) = named.into_parts();
    let temp = temp.keep().map_err(|e| e.error)?;
    register_temp(&temp);
    Ok((file, temp))
}

/// Where an output goes once its content is complete.
#[derive(Debug, Clone, PartialEq, Eq)]
enum OutputTarget {
    /// A regular file, existing or new (symbolic links resolved): replaced by a rename.
    Replace(PathBuf),
    /// An existing file that is not a regular file (a device, a FIFO): written into.
    Stream(PathBuf),
    /// One of this process's open descriptors (`/dev/stdout`, `/dev/fd/N`, `/proc/self/fd/N`).
    Descriptor(i32),
}

impl OutputTarget {
    /// Follows symbolic links from `path` (at most 40, as the kernel does) and decides how the
    /// output is put in place.
    fn resolve(path: &Path) -> Result<OutputTarget> {
        let mut at = path.to_path_buf();
        for _ in 0..40 {
            if let Some(fd) = own_descriptor(&at) {
                return Ok(OutputTarget::Descriptor(fd));
            }
            match std::fs::symlink_metadata(&at) {
                Ok(m) if m.file_type().is_symlink() => {
                    refuse_foreign_link_in_shared_folder(&at, &m, path)?;
                    let link =
                        std::fs::read_link(&at).map_err(|source| WriteError { path: at.clone(), source })?;
                    at = match at.parent() {
                        Some(dir) if link.is_relative() => dir.join(link),
                        _ => link,
                    };
                }
                Ok(m) if m.is_dir() => {
                    anyhow::bail!("cannot write {}: it is a folder; give a file name", path.display())
                }
                Ok(m) if !m.is_file() => return Ok(OutputTarget::Stream(at)),
                _ => {
                    check_parent_exists(&at)?;
                    return Ok(OutputTarget::Replace(at));
                }
            }
        }
        Err(WriteError {
            path: path.to_path_buf(),
            source: std::io::Error::other("too many levels of symbolic links"),
        }
        .into())
    }
}

/// The descriptor number when `path` names one of this process's open descriptors:
/// `/dev/stdout` (1), `/dev/stderr` (2), or `N` in a folder that is this process's
/// `/proc/<pid>/fd` (`/dev/fd/N`, `/proc/self/fd/N`).
fn own_descriptor(path: &Path) -> Option<i32> {
    match path.to_str()? {
        "/dev/stdout" => return Some(1),
        "/dev/stderr" => return Some(2),
        _ => {}
    }
    let n: i32 = path.file_name()?.to_str()?.parse().ok()?;
    let dir = std::fs::canonicalize(path.parent()?).ok()?;
    let own = PathBuf::from(format!("/proc/{}/fd", std::process::id()));
    let task_fd = dir.parent().and_then(Path::parent).is_some_and(|p| p.ends_with("task"))
        && dir.starts_with(format!("/proc/{}/task", std::process::id()))
        && dir.ends_with("fd");
    (dir == own || task_fd).then_some(n)
}

/// Refuses to follow the symbolic link `link` (metadata `m`) when it sits in a sticky,
/// world-writable folder (such as `/tmp`) and belongs neither to this user nor to the
/// folder's owner: the rule of the kernel's `fs.protected_symlinks`, which a link followed by
/// hand would otherwise escape. Another user could aim such a link at any of this user's files.
fn refuse_foreign_link_in_shared_folder(link: &Path, m: &std::fs::Metadata, requested: &Path) -> Result<()> {
    use std::os::unix::fs::MetadataExt;
    let dir = match link.parent().filter(|p| !p.as_os_str().is_empty()) {
        Some(d) => d,
        None => Path::new("."),
    };
    let Ok(d) = std::fs::metadata(dir) else { return Ok(()) };
    let shared = d.mode() & 0o1002 == 0o1002;
    // SAFETY: geteuid has no preconditions and cannot fail.
    let me = unsafe { libc::geteuid() };
    if shared && m.uid() != me && m.uid() != d.uid() {
        anyhow::bail!(
            "cannot write {}: {} is a symbolic link owned by another user (uid {}) in the shared folder {}; \
             refusing to follow it (it could point at any of your files); write to another path",
            requested.display(),
            link.display(),
            m.uid(),
            dir.display()
        );
    }
    Ok(())
}

/// What an output holds once written: a complete temporary file, or bytes for a stream.
#[derive(Debug)]
enum Content {
    Temp(PathBuf),
    Bytes(Vec<u8>),
}

/// One output written completely, waiting to be put in place.
#[derive(Debug)]
struct Staged {
    content: Content,
    target: OutputTarget,
    requested: PathBuf,
}

impl Staged {
    /// Whether putting this output in place means writing into something that exists.
    fn is_stream(&self) -> bool {
        matches!(self.content, Content::Bytes(_))
    }

    fn put_in_place(&self) -> Result<()> {
        use std::io::Write;
        use std::os::unix::fs::OpenOptionsExt;
        let fail = |source| WriteError { path: self.requested.clone(), source };
        match (&self.target, &self.content) {
            (OutputTarget::Replace(p), Content::Temp(t)) => {
                keep_mode_and_owner(p, t);
                std::fs::rename(t, p).map_err(fail)?;
            }
            (OutputTarget::Stream(p), Content::Bytes(b)) => {
                let mut to = std::fs::OpenOptions::new()
                    .write(true)
                    .custom_flags(libc::O_NOFOLLOW | libc::O_NOCTTY)
                    .open(p)
                    .map_err(fail)?;
                to.write_all(b).and_then(|()| to.flush()).map_err(fail)?;
            }
            (OutputTarget::Descriptor(fd), Content::Bytes(b)) => {
                // SAFETY: the descriptor is only borrowed to duplicate it; a number that is not
                // open makes the duplication fail (EBADF), which is reported.
                let owned =
                    unsafe { std::os::fd::BorrowedFd::borrow_raw(*fd) }.try_clone_to_owned().map_err(fail)?;
                let mut to = std::fs::File::from(owned);
                to.write_all(b).and_then(|()| to.flush()).map_err(fail)?;
            }
            _ => unreachable!("a regular target is staged as a temporary file, a stream as bytes"),
        }
        Ok(())
    }

    /// Removes the temporary file if it is still there and forgets it.
    fn forget(&self) {
        if let Content::Temp(t) = &self.content {
            remove_temp(t);
        }
    }
}

/// Gives the temporary file `temp` the permissions (and, when run as root, the owner) of the
/// file `target` it is about to replace, as `sed -i` does; a new file keeps 0666 less the umask.
fn keep_mode_and_owner(target: &Path, temp: &Path) {
    use std::os::unix::fs::MetadataExt;
    if let Ok(m) = std::fs::metadata(target) {
        let _ = std::fs::set_permissions(temp, m.permissions());
        // SAFETY: geteuid has no preconditions and cannot fail.
        if unsafe { libc::geteuid() } == 0 {
            let _ = std::os::unix::fs::chown(temp, Some(m.uid()), Some(m.gid()));
            let _ = std::fs::set_permissions(temp, m.permissions());
        }
    }
}

/// The process's outputs: temporary files that exist now, and (when staging) the outputs
/// waiting for [`commit_outputs`].
#[derive(Debug, Default)]
struct Outputs {
    temps: Vec<PathBuf>,
    staged: Option<Vec<Staged>>,
    /// Folders this run created for its outputs, parents first.
    dirs: Vec<PathBuf>,
}

static OUTPUTS: std::sync::Mutex<Outputs> =
    std::sync::Mutex::new(Outputs { temps: Vec::new(), staged: None, dirs: Vec::new() });

/// Held while [`commit_outputs`] renames: [`discard_outputs`] (what a signal handler calls)
/// waits for it, so an interrupted run never leaves a mixed set of new and old outputs.
static COMMITTING: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn lock_outputs() -> std::sync::MutexGuard<'static, Outputs> {
    OUTPUTS.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}

fn register_temp(tmp: &Path) {
    lock_outputs().temps.push(tmp.to_path_buf());
}

fn remove_temp(tmp: &Path) {
    let _ = std::fs::remove_file(tmp);
    lock_outputs().temps.retain(|t| t != tmp);
}

/// From now on, outputs are staged and put in place together by [`commit_outputs`] (the
/// `sandslope` binary calls this at start-up; a library user who never calls it gets each
/// output in place as soon as it is written).
pub fn stage_outputs() {
    lock_outputs().staged.get_or_insert_with(Vec::new);
}

/// Puts every staged output in place and returns the paths as they were asked for.
///
/// Streams (FIFOs, devices, standard output) are written first, since they may block (a FIFO
/// waits for its reader) and cannot be taken back; a failure there leaves every regular file
/// untouched. Then the regular files are renamed into place, one after the other, while
/// [`discard_outputs`] waits: a signal during the renames takes effect only after the last,
/// so the set is all new or (on a failure before the renames) all old.
pub fn commit_outputs() -> Result<Vec<PathBuf>> {
    let staged = {
        let mut guard = lock_outputs();
        guard.dirs.clear();
        guard.staged.as_mut().map(std::mem::take).unwrap_or_default()
    };
    let forget_all = |list: &[Staged]| list.iter().for_each(Staged::forget);
    let (streams, files): (Vec<&Staged>, Vec<&Staged>) = staged.iter().partition(|s| s.is_stream());
    let mut written = Vec::with_capacity(staged.len());
    for s in streams {
        if let Err(e) = s.put_in_place() {
            forget_all(&staged);
            return Err(e);
        }
        written.push(s.requested.clone());
    }
    let _renaming = COMMITTING.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    for s in files {
        if let Err(e) = s.put_in_place() {
            forget_all(&staged);
            return Err(e);
        }
        written.push(s.requested.clone());
        s.forget();
    }
    Ok(written)
}

/// Removes every temporary file of this process and forgets the staged outputs: what a failed
/// or interrupted run calls so that it leaves nothing behind. Safe to call from a signal
/// handler's thread; waits for renames [`commit_outputs`] has begun.
pub fn discard_outputs() {
    let _renaming = COMMITTING.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    let mut guard = lock_outputs();
    for t in guard.temps.drain(..) {
        let _ = std::fs::remove_file(t);
    }
    if let Some(list) = guard.staged.as_mut() {
        list.clear();
    }
    // Deepest first; a folder that is not empty (something else put a file there) stays.
    for d in guard.dirs.drain(..).rev() {
        let _ = std::fs::remove_dir(d);
    }
}

/// Creates the output folder `dir` and its missing parents, as `mkdir -p` does. A run that
/// then fails removes the folders it created ([`discard_outputs`]); [`commit_outputs`] keeps them.
pub fn create_output_dir(dir: &Path) -> Result<()> {
    if dir.is_file() {
        anyhow::bail!("cannot write into {}: it is a file, not a folder", dir.display());
    }
    let mut missing = Vec::new();
    let mut at = Some(dir);
    while let Some(d) = at.filter(|d| !d.as_os_str().is_empty() && !d.exists()) {
        missing.push(d.to_path_buf());
        at = d.parent();
    }
    std::fs::create_dir_all(dir).map_err(|source| WriteError { path: dir.to_path_buf(), source })?;
    lock_outputs().dirs.extend(missing.into_iter().rev());
    Ok(())
}

/// The line a record is on: the csv reader's position is where it began reading, before the
/// blank lines and `#` comments it skipped, so those are stepped over here.
pub fn record_line(text: &str, at: &csv::Position) -> u64 {
    let mut line = at.line();
    let mut rest = text.get(at.byte() as usize..).unwrap_or("");
    while let Some((first, after)) = rest.split_once('\n') {
        if !(first.starts_with('#') || first.is_empty() || first == "\r") {
            break;
        }
        line += 1;
        rest = after;
    }
    line
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atomic_write_leaves_nothing_when_the_folder_is_missing() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("missing").join("out.csv");
        let err = write_atomic(&path, b"x").unwrap_err().to_string();
        assert!(err.contains("does not exist"), "{err}");
        assert!(std::fs::read_dir(dir.path()).unwrap().next().is_none());
    }

    #[test]
    fn atomic_write_replaces_the_file_whole() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.txt");
        write_atomic(&path, b"first").unwrap();
        write_atomic(&path, b"second").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "second");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }
}
