//! Writing a result file so that a reader never finds it half written, and so that nothing
//! but a regular file is ever replaced.

use std::path::{Path, PathBuf};

/// Write `text` to `path`. A regular file (or a path not there yet) is written beside it and
/// renamed over it, so an existing file is never left half written. A symbolic link is
/// followed, and the file it names is replaced, not the link. A device or a pipe
/// (`/dev/stdout`, `/dev/null`, a FIFO) is written in place: renaming over it would replace
/// the special file itself with a regular one. A directory is an error.
pub fn write_atomically(path: &Path, text: &str) -> Result<(), String> {
    let target = match std::fs::metadata(path) {
        Ok(meta) if meta.is_dir() => {
            return Err(format!("cannot write {}: it is a directory", path.display()));
        }
        Ok(meta) if !meta.is_file() => {
            return std::fs::write(path, text).map_err(|e| format!("cannot write {}: {e}", path.display()));
        }
        Ok(_) => std::fs::canonicalize(path).map_err(|e| format!("cannot write {}: {e}", path.display()))?,
        Err(_) => path.to_path_buf(),
    };
    let mut partial = target.as_os_str().to_owned();
    partial.push(".partial");
    let partial = PathBuf::from(partial);
    std::fs::write(&partial, text).map_err(|e| format!("cannot write {}: {e}", partial.display()))?;
    std::fs::rename(&partial, &target).map_err(|e| {
        let _ = std::fs::remove_file(&partial);
        format!("cannot write {}: {e}", path.display())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("jetpipe-output-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn a_regular_file_is_replaced_and_no_partial_file_is_left() {
        let dir = scratch("regular");
        let path = dir.join("report.json");
        std::fs::write(&path, "old, and longer than the new text").unwrap();
        write_atomically(&path, "new").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "new");
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn a_symbolic_link_stays_a_link_and_the_file_it_names_is_written() {
        let dir = scratch("link");
        let (file, link) = (dir.join("real.json"), dir.join("link.json"));
        std::fs::write(&file, "old").unwrap();
        std::os::unix::fs::symlink(&file, &link).unwrap();
        write_atomically(&link, "new").unwrap();
        assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
        assert_eq!(std::fs::read_to_string(&file).unwrap(), "new");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn a_pipe_is_written_in_place_and_stays_a_pipe() {
        // A FIFO rather than /dev/null: were the special file replaced, the test would break
        // only its own scratch directory, not the machine.
        use std::os::unix::fs::FileTypeExt;
        let dir = scratch("pipe");
        let fifo = dir.join("pipe");
        let name = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
        assert_eq!(unsafe { libc::mkfifo(name.as_ptr(), 0o600) }, 0);
        let reader = {
            let fifo = fifo.clone();
            std::thread::spawn(move || std::fs::read_to_string(fifo).unwrap())
        };
        write_atomically(&fifo, "through the pipe").unwrap();
        assert_eq!(reader.join().unwrap(), "through the pipe");
        assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_directory_is_refused_by_name() {
        let dir = scratch("directory");
        let e = write_atomically(&dir, "text").unwrap_err();
        assert!(
            e.contains("is a directory") && e.contains("jetpipe-output-directory"),
            "{e}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
