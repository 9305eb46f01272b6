//! One error type for the whole program. Its variant decides the exit code: bad input from the user
//! (a flag, a file, a coefficient) exits 2, a failure at run time (the driver, the disk) exits 1.

use std::fmt;

#[derive(Debug)]
pub enum Error {
    /// The user's input is wrong: usage, a flag value, a mesh file, a material. Exit code 2.
    BadInput(String),
    /// Something failed while running: Vulkan, memory, I/O on output. Exit code 1.
    Runtime(String),
}

pub type Result<T> = std::result::Result<T, Error>;

impl Error {
    pub fn exit_code(&self) -> i32 {
        match self {
            Error::BadInput(_) => 2,
            Error::Runtime(_) => 1,
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::BadInput(m) | Error::Runtime(m) => f.write_str(m),
        }
    }
}

impl std::error::Error for Error {}

/// `bad_input!("--width: {} is too large", w)` builds an [`Error::BadInput`].
#[macro_export]
macro_rules! bad_input {
    ($($arg:tt)*) => { $crate::error::Error::BadInput(format!($($arg)*)) };
}

/// `runtime!("vkCreateDevice: {e}")` builds an [`Error::Runtime`].
#[macro_export]
macro_rules! runtime {
    ($($arg:tt)*) => { $crate::error::Error::Runtime(format!($($arg)*)) };
}

/// Writes `text` to stdout and flushes it. A failure (a full disk, a closed pipe: Rust ignores
/// SIGPIPE, so a reader that went away shows up here as EPIPE) is a run-time error naming stdout,
/// never a panic as `print!` would give.
pub fn write_stdout(text: &str) -> Result<()> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    out.write_all(text.as_bytes()).and_then(|_| out.flush()).map_err(|e| Error::Runtime(format!("stdout: {e}")))
}

/// `note!("wrote {}", path)`: a line on stderr. Unlike `eprintln!` it cannot panic: when stderr
/// itself cannot be written (`2>/dev/full`, a closed pipe) the line is dropped, since there is
/// nowhere left to report it; the exit code still tells.
#[macro_export]
macro_rules! note {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}
