//! One writer per results folder. `crr simulate`, `crr study` (and its resume and merge),
//! `crr poincare` and `crr animate` write several files into a folder and rename them into place;
//! two processes writing into the same folder would rename each other's files away (two `simulate --force` runs: one announced
//! its results while the folder held none). A writer takes `DIR/.crr.lock`, created exclusively
//! and holding its process id, for as long as it writes, and removes it when done (also when it
//! fails). A lock whose process no longer runs (a writer killed with SIGKILL) is taken over (two
//! processes taking over the same stale lock at the same instant could both proceed: the one
//! race left, and only after a kill).

use std::io::Write;
use std::path::{Path, PathBuf};

use crate::Error;

/// The lock file's name inside the folder.
pub const LOCK_FILE: &str = ".crr.lock";

/// A held lock on a results folder; dropping it releases the folder.
#[derive(Debug)]
pub struct FolderLock {
    path: PathBuf,
    /// The folder, when this lock created it: removed again on release if left empty (a run
    /// that failed before writing anything leaves no folder behind).
    created: Option<PathBuf>,
}

impl FolderLock {
    /// Creates `dir` if needed and takes its lock, or says which process holds it.
    pub fn acquire(dir: &Path) -> Result<Self, Error> {
        let output = |source| Error::Output {
            dir: dir.to_path_buf(),
            source,
        };
        let created = (!dir.exists()).then(|| dir.to_path_buf());
        std::fs::create_dir_all(dir).map_err(output)?;
        let path = dir.join(LOCK_FILE);
        // Twice at most: the second attempt follows the removal of a stale lock.
        for _ in 0..2 {
            match create_with_pid(dir, &path) {
                Ok(()) => return Ok(Self { path, created }),
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                    let holder = std::fs::read_to_string(&path)
                        .ok()
                        .and_then(|t| t.trim().parse::<u32>().ok());
                    match holder {
                        Some(pid) if process_runs(pid) => {
                            return Err(Error::Argument(format!(
                                "{}: another crr process (pid {pid}) is writing into this \
                                 folder; wait for it to finish or choose another folder (if no \
                                 such process runs, remove {})",
                                dir.display(),
                                path.display()
                            )));
                        }
                        // A lock without a live writer (killed, or the file cut short).
                        _ => match std::fs::remove_file(&path) {
                            Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                                return Err(output(e));
                            }
                            _ => {}
                        },
                    }
                }
                Err(e) => return Err(output(e)),
            }
        }
        Err(Error::Argument(format!(
            "{}: the folder's lock {} keeps reappearing; another process is writing into it",
            dir.display(),
            path.display()
        )))
    }
}

impl Drop for FolderLock {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.path);
        if let Some(dir) = &self.created {
            // Fails, and so keeps the folder, unless it is empty.
            let _ = std::fs::remove_dir(dir);
        }
    }
}

/// Creates `path` holding this process' id, failing with `AlreadyExists` when it exists. The id is
/// written to a file of this process' own first and hard-linked to `path` (a link is created
/// whole or not at all), so that another writer never reads the lock before its id is in it
/// (and takes an empty lock for a dead one's); where links are not supported, the lock is
/// created exclusively and then written.
fn create_with_pid(dir: &Path, path: &Path) -> std::io::Result<()> {
    let pid = std::process::id();
    let own = dir.join(format!("{LOCK_FILE}.{pid}"));
    std::fs::write(&own, format!("{pid}\n"))?;
    let linked = std::fs::hard_link(&own, path);
    let _ = std::fs::remove_file(&own);
    match linked {
        Err(e) if e.kind() == std::io::ErrorKind::Unsupported => {
            let mut f = std::fs::OpenOptions::new()
                .write(true)
                .create_new(true)
                .open(path)?;
            writeln!(f, "{pid}")
        }
        other => other,
    }
}

/// Whether process `pid` runs (Linux: /proc/pid exists; elsewhere every holder is taken to run).
fn process_runs(pid: u32) -> bool {
    if pid == std::process::id() {
        return true;
    }
    let proc_root = Path::new("/proc");
    if proc_root.join("self").exists() {
        proc_root.join(pid.to_string()).exists()
    } else {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_second_writer_is_refused_and_a_dead_ones_lock_is_taken_over() {
        let dir = std::env::temp_dir().join(format!("crr_lock_{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let first = FolderLock::acquire(&dir).unwrap();
        let err = FolderLock::acquire(&dir).unwrap_err().to_string();
        assert!(err.contains("another crr process"), "{err}");
        assert!(err.contains(&std::process::id().to_string()), "{err}");
        drop(first);
        assert!(
            !dir.join(LOCK_FILE).exists(),
            "the lock is removed when dropped"
        );
        // A pid no process has (above Linux's pid_max of 2^22): a stale lock.
        std::fs::write(dir.join(LOCK_FILE), "4294967295\n").unwrap();
        let taken = FolderLock::acquire(&dir).unwrap();
        let holder = std::fs::read_to_string(dir.join(LOCK_FILE)).unwrap();
        assert_eq!(holder.trim(), std::process::id().to_string());
        drop(taken);
        std::fs::remove_dir_all(&dir).unwrap();
        // A folder the lock created is removed again when nothing was written into it, and
        // kept when something was.
        let fresh = dir.join("fresh");
        drop(FolderLock::acquire(&fresh).unwrap());
        assert!(!fresh.exists());
        let lock = FolderLock::acquire(&fresh).unwrap();
        std::fs::write(fresh.join("result.csv"), "t\n").unwrap();
        drop(lock);
        assert!(fresh.join("result.csv").exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
