//! Reading input files safely: only regular files, and only up to a size limit, so that a FIFO,
//! a device such as `/dev/zero` or a huge file given by mistake cannot block a run or exhaust the
//! memory.

use std::io::Read;
use std::path::Path;

/// The largest model file read (bytes): models are a few kilobytes.
pub const MODEL_FILE_LIMIT: u64 = 16 << 20;

/// The largest record or results file read (bytes).
pub const DATA_FILE_LIMIT: u64 = 1 << 30;

/// Reads the file at `path` if it is a regular file of at most `limit` bytes. The error says
/// which condition failed (kind `InvalidInput` for a non-regular or oversized file).
pub fn read_regular_file(path: &Path, limit: u64) -> std::io::Result<Vec<u8>> {
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "not a regular file (a folder, a pipe or a device)",
        ));
    }
    if meta.len() > limit {
        return Err(too_large(meta.len(), limit));
    }
    // The size may change while reading: read at most limit + 1 bytes.
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    std::fs::File::open(path)?
        .take(limit + 1)
        .read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(too_large(bytes.len() as u64, limit));
    }
    Ok(bytes)
}

/// Opens the file at `path` for reading in pieces if it is a regular file (no size limit: the
/// caller reads it in constant memory).
pub fn open_regular_file(path: &Path) -> std::io::Result<std::fs::File> {
    if !std::fs::metadata(path)?.is_file() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "not a regular file (a folder, a pipe or a device)",
        ));
    }
    std::fs::File::open(path)
}

/// [`read_regular_file`] as UTF-8 text (invalid sequences are an error naming the byte offset).
pub fn read_regular_text(path: &Path, limit: u64) -> std::io::Result<String> {
    String::from_utf8(read_regular_file(path, limit)?).map_err(|e| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!(
                "not UTF-8 text (invalid byte at offset {})",
                e.utf8_error().valid_up_to()
            ),
        )
    })
}

fn too_large(len: u64, limit: u64) -> std::io::Error {
    std::io::Error::new(
        std::io::ErrorKind::InvalidInput,
        format!("the file holds {len} bytes or more, over the limit of {limit}"),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regular_files_are_read_and_others_refused() {
        let dir = std::env::temp_dir().join(format!("crr-input-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("a.txt");
        std::fs::write(&f, "hello").unwrap();
        assert_eq!(read_regular_text(&f, 5).unwrap(), "hello");
        let e = read_regular_file(&f, 4).unwrap_err();
        assert!(e.to_string().contains("over the limit of 4"), "{e}");
        let e = read_regular_file(&dir, 100).unwrap_err();
        assert!(e.to_string().contains("not a regular file"), "{e}");
        let e = open_regular_file(&dir).unwrap_err();
        assert!(e.to_string().contains("not a regular file"), "{e}");
        assert!(open_regular_file(&f).is_ok());
        #[cfg(unix)]
        {
            let e = read_regular_file(Path::new("/dev/zero"), 100).unwrap_err();
            assert!(e.to_string().contains("not a regular file"), "{e}");
            let e = open_regular_file(Path::new("/dev/zero")).unwrap_err();
            assert!(e.to_string().contains("not a regular file"), "{e}");
        }
        std::fs::write(&f, [0x66, 0xff, 0x66]).unwrap();
        let e = read_regular_text(&f, 100).unwrap_err();
        assert!(e.to_string().contains("offset 1"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
