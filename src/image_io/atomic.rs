//! Files written whole or not at all. The bytes go to a temporary file beside the
//! target, which is synced and renamed over it only at the end; on any error, or when
//! the writes are interrupted, the temporary file is removed and the target is left as
//! it was. A target that exists and is not a regular file (a device, a FIFO) cannot be
//! replaced and is written in place.
//!
//! Interruption is process-wide, as signals are: once [`interrupt_writes`] has been
//! called (the command line calls it on Ctrl-C or SIGTERM), no file is put in place
//! any more and a wait for a FIFO's reader ends.

use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use super::SaveError;

static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// From now on, files being written are dropped rather than put in place, and no new
/// one is started. Safe to call from a signal handler's thread.
pub fn interrupt_writes() {
    INTERRUPTED.store(true, Ordering::SeqCst);
}

/// Whether [`interrupt_writes`] has been called.
pub fn writes_interrupted() -> bool {
    INTERRUPTED.load(Ordering::SeqCst)
}

const INTERRUPTED_MESSAGE: &str = "interrupted: not written";

/// The folder a file at `path` goes into (`.` for a bare file name).
fn folder_of(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

fn save_error(path: &Path, message: impl Into<String>) -> SaveError {
    SaveError {
        path: path.display().to_string(),
        message: message.into(),
    }
}

/// A temporary file beside `path`, where the bytes go first.
fn temp_file_for(path: &Path) -> Result<tempfile::NamedTempFile, SaveError> {
    let dir = folder_of(path);
    match std::fs::metadata(dir) {
        Err(e) => {
            let message = format!("cannot use the folder {}: {e}", dir.display());
            return Err(save_error(path, message));
        }
        Ok(m) if !m.is_dir() => {
            return Err(save_error(
                path,
                format!("{} is not a folder", dir.display()),
            ));
        }
        Ok(_) => {}
    }
    let mut builder = tempfile::Builder::new();
    builder.prefix(".whitted-").suffix(".part");
    // tempfile makes private (0600) files; an image is an ordinary file, readable as
    // the user's umask allows, like any file a program creates.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    builder.tempfile_in(dir).map_err(|e| {
        // tempfile appends the random name it tried, which means nothing to the user.
        let text = e.to_string();
        let reason = text.split(" at path ").next().unwrap_or(&text);
        save_error(
            path,
            format!("cannot write into {}: {reason}", dir.display()),
        )
    })
}

/// What a path to save to really is.
enum Target {
    /// A regular file, or nothing yet: replaced atomically at this path. A symbolic
    /// link is resolved first, so that it keeps pointing at the new image.
    File(PathBuf),
    /// An existing device, FIFO or socket: it cannot be replaced (and must not be:
    /// renaming over `/dev/full` would swallow the error), so it is written in place.
    Special,
}

fn target_of(path: &Path) -> Target {
    match std::fs::metadata(path) {
        Ok(m) if !m.is_file() && !m.is_dir() => Target::Special,
        Ok(_) => Target::File(std::fs::canonicalize(path).unwrap_or_else(|_| path.into())),
        Err(_) => Target::File(path.into()),
    }
}

/// Opens a device or FIFO to write into. Opening a FIFO waits for a reader, inside a
/// call that no signal ends; so it is opened without waiting, again every few
/// milliseconds until a reader comes or the writes are interrupted.
fn open_in_place(path: &Path) -> std::io::Result<File> {
    #[cfg(unix)]
    {
        use rustix::fs::{fcntl_getfl, fcntl_setfl, Mode, OFlags};
        use std::os::unix::fs::FileTypeExt;
        let is_fifo = std::fs::metadata(path).is_ok_and(|m| m.file_type().is_fifo());
        if is_fifo {
            let flags = OFlags::WRONLY | OFlags::CLOEXEC;
            loop {
                match rustix::fs::open(path, flags | OFlags::NONBLOCK, Mode::empty()) {
                    Ok(fd) => {
                        // Writes wait for the reader as usual from here on.
                        fcntl_setfl(&fd, fcntl_getfl(&fd)? - OFlags::NONBLOCK)?;
                        return Ok(File::from(fd));
                    }
                    // No reader yet.
                    Err(rustix::io::Errno::NXIO) => {
                        if writes_interrupted() {
                            return Err(std::io::Error::other(
                                "interrupted while waiting for a reader",
                            ));
                        }
                        std::thread::sleep(Duration::from_millis(20));
                    }
                    Err(e) => return Err(e.into()),
                }
            }
        }
    }
    std::fs::OpenOptions::new().write(true).open(path)
}

/// Fails unless a file can be created in the folder of `path`: lets a command refuse
/// an unwritable target before it spends time rendering. Leaves nothing behind.
pub fn check_writable(path: &Path) -> Result<(), SaveError> {
    if path.is_dir() {
        return Err(save_error(path, "is a folder"));
    }
    match target_of(path) {
        // Opening a FIFO would wait for a reader: the write will tell.
        Target::Special => Ok(()),
        Target::File(real) => temp_file_for(&real).map(drop),
    }
}

enum Sink {
    /// The temporary file, and the path it is renamed to.
    Temp(tempfile::NamedTempFile, PathBuf),
    InPlace(File),
}

/// A file being written: [`Write`] the bytes, then [`AtomicFile::commit`]. Dropped
/// uncommitted, it leaves nothing behind (a device or FIFO keeps what it was sent).
pub struct AtomicFile {
    path: PathBuf,
    sink: Sink,
}

impl AtomicFile {
    /// Starts writing `path`.
    pub fn create(path: &Path) -> Result<AtomicFile, SaveError> {
        if writes_interrupted() {
            return Err(save_error(path, INTERRUPTED_MESSAGE));
        }
        if path.is_dir() {
            return Err(save_error(path, "is a folder"));
        }
        let sink = match target_of(path) {
            Target::Special => {
                Sink::InPlace(open_in_place(path).map_err(|e| save_error(path, e.to_string()))?)
            }
            Target::File(real) => Sink::Temp(temp_file_for(&real)?, real),
        };
        Ok(AtomicFile {
            path: path.to_path_buf(),
            sink,
        })
    }

    fn error(&self, message: impl Into<String>) -> SaveError {
        save_error(&self.path, message)
    }

    /// The temporary file, for an encoder that seeks (EXR writes its table of chunk
    /// offsets last); `None` when the target is written in place (a device or a FIFO,
    /// which may not seek).
    pub fn temporary_file(&mut self) -> Option<&mut File> {
        match &mut self.sink {
            Sink::Temp(temp, _) => Some(temp.as_file_mut()),
            Sink::InPlace(_) => None,
        }
    }

    /// Fails if the temporary file has been removed (its folder deleted, say): what
    /// is written to it from then on would be lost, so a long writer stops early.
    pub fn check_still_there(&self) -> Result<(), SaveError> {
        #[cfg(unix)]
        if let Sink::Temp(temp, _) = &self.sink {
            use std::os::unix::fs::MetadataExt;
            let links = temp.as_file().metadata().map(|m| m.nlink()).unwrap_or(1);
            if links == 0 {
                let folder = folder_of(&self.path).display().to_string();
                return Err(self.error(format!(
                    "the file being written was removed (is the folder {folder} gone?)"
                )));
            }
        }
        Ok(())
    }

    /// Puts the file in place: syncs the temporary file and renames it over the
    /// target (a device or FIFO is flushed). Unless the writes were interrupted: then
    /// the temporary file is removed and the target left as it was.
    pub fn commit(self) -> Result<(), SaveError> {
        let path = self.path;
        let error = |e: std::io::Error| save_error(&path, e.to_string());
        match self.sink {
            Sink::InPlace(mut file) => file.flush().map_err(error),
            Sink::Temp(temp, real) => {
                temp.as_file().sync_all().map_err(error)?;
                if writes_interrupted() {
                    return Err(save_error(&path, INTERRUPTED_MESSAGE));
                }
                temp.persist(&real).map_err(|e| error(e.error))?;
                Ok(())
            }
        }
    }
}

impl Write for AtomicFile {
    // Through the temporary file's `File`: its own errors name the temporary path,
    // which means nothing to the user.
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        match &mut self.sink {
            Sink::Temp(temp, _) => temp.as_file_mut().write(buf),
            Sink::InPlace(file) => file.write(buf),
        }
    }

    fn flush(&mut self) -> std::io::Result<()> {
        match &mut self.sink {
            Sink::Temp(temp, _) => temp.as_file_mut().flush(),
            Sink::InPlace(file) => file.flush(),
        }
    }
}

/// Writes `bytes` into `path` whole or not at all (see [`AtomicFile`]).
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), SaveError> {
    let mut file = AtomicFile::create(path)?;
    file.write_all(bytes)
        .map_err(|e| file.error(e.to_string()))?;
    file.commit()
}
