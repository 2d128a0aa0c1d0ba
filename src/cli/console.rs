//! Printing that never panics (issue 10, defect 3).
//!
//! `eprintln!` and `println!` panic when the write fails (standard error on a full
//! device, standard output on a closed pipe), which turned `2>/dev/full` into exit 101.
//! Messages to standard error are informational: [`note!`] writes them and ignores a
//! failure (there is nowhere left to report it). Results on standard output are the
//! command's product: [`Stdout`] writes them and returns every error, so the command
//! fails with status 2 and a message instead of losing its output silently.

use std::io::Write;

/// `eprintln!` that ignores write errors.
macro_rules! note {
    ($($arg:tt)*) => {
        $crate::cli::console::note_line(format_args!($($arg)*))
    };
}
pub(crate) use note;

/// Writes one line to standard error, ignoring errors.
pub fn note_line(args: std::fmt::Arguments) {
    let mut err = std::io::stderr().lock();
    let _ = err.write_fmt(args);
    let _ = err.write_all(b"\n");
}

/// Standard output for results, with every write error returned.
///
/// A *closed* standard output (`>&-`) is reported at [`Stdout::open`]: the Rust runtime
/// reopens a closed descriptor 1 on `/dev/null` (read-write) before `main`, so writes
/// would succeed into nothing. On Linux that case is recognised (descriptor 1 is
/// `/dev/null` opened read-write, which a shell's `>/dev/null` never does); elsewhere a
/// duplicate of descriptor 1 is used, which fails when it is closed.
pub struct Stdout(Box<dyn Write>);

impl Stdout {
    pub fn open() -> anyhow::Result<Stdout> {
        #[cfg(unix)]
        {
            use std::os::fd::AsFd;
            let fd = std::io::stdout()
                .as_fd()
                .try_clone_to_owned()
                .map_err(|e| anyhow::anyhow!("cannot write to standard output: {e}"))?;
            if stdout_was_closed() {
                anyhow::bail!(
                    "standard output is closed; redirect it to a file (or to /dev/null to \
                     discard the results)"
                );
            }
            Ok(Stdout(Box::new(std::io::BufWriter::new(
                std::fs::File::from(fd),
            ))))
        }
        #[cfg(not(unix))]
        {
            Ok(Stdout(Box::new(std::io::BufWriter::new(std::io::stdout()))))
        }
    }

    /// Writes `text` as it is.
    pub fn write(&mut self, text: &str) -> anyhow::Result<()> {
        self.0
            .write_all(text.as_bytes())
            .map_err(|e| anyhow::anyhow!("cannot write to standard output: {e}"))
    }

    /// Flushes; the results are only delivered when this succeeds.
    pub fn finish(mut self) -> anyhow::Result<()> {
        self.0
            .flush()
            .map_err(|e| anyhow::anyhow!("cannot write to standard output: {e}"))
    }
}

/// True when descriptor 1 is the runtime's stand-in for a closed standard output:
/// `/dev/null` opened read-write (see [`Stdout`]).
#[cfg(unix)]
fn stdout_was_closed() -> bool {
    #[cfg(target_os = "linux")]
    {
        use std::os::unix::fs::MetadataExt;
        let (Ok(out), Ok(null)) = (
            std::fs::metadata("/proc/self/fd/1"),
            std::fs::metadata("/dev/null"),
        ) else {
            return false;
        };
        if out.rdev() != null.rdev() || out.ino() != null.ino() {
            return false;
        }
        // `flags:\t0100002`: the access mode is the low two bits (2 = read-write).
        std::fs::read_to_string("/proc/self/fdinfo/1")
            .ok()
            .and_then(|info| {
                let flags = info.lines().find_map(|l| l.strip_prefix("flags:"))?;
                u32::from_str_radix(flags.trim(), 8).ok()
            })
            .is_some_and(|flags| flags & 3 == 2)
    }
    #[cfg(not(target_os = "linux"))]
    {
        false
    }
}
