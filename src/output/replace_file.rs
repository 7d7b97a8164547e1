//! Writing an output file by replacing it whole: the text goes to a hidden temporary file in the
//! same folder (`.partial.NAME`), which is then renamed over the destination. Whatever the
//! destination was (a FIFO, a file another program is reading, a symbolic link), it is never
//! opened for writing: a FIFO left where an output goes would block the writer for ever.

use std::io;
use std::path::{Path, PathBuf};

/// The temporary file that [`replace_file`] writes before renaming it to `path`.
pub fn temporary_for(path: &Path) -> PathBuf {
    let dir = path.parent().unwrap_or(Path::new("."));
    let name = path
        .file_name()
        .map_or_else(|| "output".into(), |n| n.to_string_lossy().into_owned());
    crate::output::results_folder::partial_name(dir, &name)
}

/// Fails when `path` is a folder (an output file cannot replace one).
fn not_a_folder(path: &Path) -> io::Result<()> {
    match std::fs::symlink_metadata(path) {
        Ok(m) if m.is_dir() => Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "{} is a folder, where a file is to be written",
                path.display()
            ),
        )),
        _ => Ok(()),
    }
}

/// A fresh temporary file for `path`: whatever was left at its name (a file of an interrupted
/// write, a FIFO, a link) is removed first, and the new one is created, never opened.
fn fresh_temporary(path: &Path) -> io::Result<(PathBuf, std::fs::File)> {
    let tmp = temporary_for(path);
    match std::fs::remove_file(&tmp) {
        Err(e) if e.kind() != io::ErrorKind::NotFound => return Err(e),
        _ => {}
    }
    let file = std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&tmp)?;
    Ok((tmp, file))
}

/// Writes `bytes` to `path` through [`temporary_for`] and a rename; the temporary file is
/// removed when either fails.
pub fn replace_file(path: &Path, bytes: impl AsRef<[u8]>) -> io::Result<()> {
    use std::io::Write;
    not_a_folder(path)?;
    let (tmp, mut file) = fresh_temporary(path)?;
    let done = file
        .write_all(bytes.as_ref())
        .and_then(|_| file.flush())
        .and_then(|_| std::fs::rename(&tmp, path));
    if done.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    done
}

/// Runs `write` on the temporary file of `path`, then renames it over `path` (for writers that
/// take a path, such as the plotting backends). The temporary file is removed when either fails.
pub fn replace_file_with<E>(
    path: &Path,
    write: impl FnOnce(&Path) -> Result<(), E>,
    io_error: impl Fn(io::Error) -> E,
) -> Result<(), E> {
    not_a_folder(path).map_err(&io_error)?;
    // Created fresh (and closed) so that the writer opens a regular file of ours.
    let (tmp, _) = fresh_temporary(path).map_err(&io_error)?;
    let done = write(&tmp).and_then(|_| std::fs::rename(&tmp, path).map_err(&io_error));
    if done.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    done
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    #[cfg(unix)]
    fn a_fifo_where_the_output_goes_is_replaced_not_opened() {
        let dir = std::env::temp_dir().join(format!("crr-replace-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let fifo = dir.join("study.json");
        let _ = std::fs::remove_file(&fifo);
        let made = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap();
        assert!(made.success());
        // A FIFO left at the temporary name as well: removed, not opened.
        let made = std::process::Command::new("mkfifo")
            .arg(temporary_for(&fifo))
            .status()
            .unwrap();
        assert!(made.success());
        replace_file(&fifo, "{}\n").unwrap();
        assert!(std::fs::metadata(&fifo).unwrap().is_file());
        assert_eq!(std::fs::read_to_string(&fifo).unwrap(), "{}\n");
        assert!(!temporary_for(&fifo).exists());
        let e = replace_file(&dir, "x").unwrap_err();
        assert!(e.to_string().contains("is a folder"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
