//! `board send --port PATH [--baud N] FILE`: a triangle file to the board's UART source, in the
//! packets of docs/spec.md ("Board serial packets"): a clear, then every triangle in order. A tty
//! is set to raw 8N1 at the baud; anything else (a plain file, a pipe) is written as it is, so the
//! bytes can be checked without a board.

use crate::{config, fixed, SCREEN};
use golden::frontend::FrontEnd;
use hdl_gen::board::uart;
use std::io::Write;
use std::os::fd::AsRawFd;
use std::path::Path;

#[derive(Debug, thiserror::Error)]
pub enum SendError {
    #[error("--baud {0}")]
    Baud(#[from] uart::WireError),
    #[error("{what}: {error}")]
    File { what: String, error: String },
    /// The file could not be read as text (`hdl_gen::input`'s message, which names it).
    #[error("{0}")]
    Input(String),
    #[error("{what}: triangle {triangle} does not fit the board's front-end (a vertex too far off the 320x240 screen)")]
    Ports { what: String, triangle: usize },
    #[error("--port {port}: {error}")]
    Port { port: String, error: std::io::Error },
    #[error("--status: {0} is not a serial port (a tty), so no record can come back")]
    NotTty(String),
}

impl SendError {
    /// Bad input (exit 2) rather than a port that failed (exit 1).
    pub fn is_usage(&self) -> bool {
        !matches!(self, SendError::Port { .. })
    }
}

/// The packets of a triangle file's text (`what` names it in errors).
pub fn packets(text: &str, what: &str) -> Result<Vec<u8>, SendError> {
    let tris = golden::setup::parse_triangles(text).map_err(|e| SendError::File { what: what.into(), error: e.to_string() })?;
    if tris.is_empty() {
        return Err(SendError::File { what: what.into(), error: "no triangles".into() });
    }
    // The ports' widths do not depend on P: any P's front-end says what fits.
    let cfg = config(8).expect("the board's configuration");
    let fe = FrontEnd::new(cfg, SCREEN).expect("the board's front-end");
    let tris = fixed(&cfg, &tris);
    if let Some(k) = tris.iter().position(|t| !fe.fits_ports(t)) {
        return Err(SendError::Ports { what: what.into(), triangle: k + 1 });
    }
    Ok(uart::stream(&tris).expect("what fits the ports fits the packet"))
}

/// The termios speed of a rate in [`uart::TTY_BAUDS`].
fn speed(baud: u32) -> libc::speed_t {
    match baud {
        9600 => libc::B9600,
        19200 => libc::B19200,
        38400 => libc::B38400,
        57600 => libc::B57600,
        115200 => libc::B115200,
        230400 => libc::B230400,
        460800 => libc::B460800,
        500000 => libc::B500000,
        576000 => libc::B576000,
        921600 => libc::B921600,
        1000000 => libc::B1000000,
        1152000 => libc::B1152000,
        1500000 => libc::B1500000,
        2000000 => libc::B2000000,
        2500000 => libc::B2500000,
        _ => libc::B3000000,
    }
}

/// Raw 8N1 at `baud`, no flow control, the modem lines ignored.
fn set_tty(f: &std::fs::File, baud: u32) -> std::io::Result<()> {
    let fd = f.as_raw_fd();
    // SAFETY: fd is open for the call's duration; termios is plain data that tcgetattr fills.
    unsafe {
        let mut t: libc::termios = std::mem::zeroed();
        if libc::tcgetattr(fd, &mut t) != 0 {
            return Err(std::io::Error::last_os_error());
        }
        libc::cfmakeraw(&mut t);
        t.c_cflag |= libc::CLOCAL | libc::CREAD;
        t.c_cflag &= !(libc::CSTOPB | libc::PARENB | libc::CRTSCTS);
        if libc::cfsetispeed(&mut t, speed(baud)) != 0
            || libc::cfsetospeed(&mut t, speed(baud)) != 0
            || libc::tcsetattr(fd, libc::TCSANOW, &t) != 0
        {
            return Err(std::io::Error::last_os_error());
        }
    }
    Ok(())
}

/// How long `--status` waits for the board's record.
const STATUS_WAIT: std::time::Duration = std::time::Duration::from_secs(2);

/// Sends `bytes` to `port`: a tty at `baud`, a pipe or device as it is, a plain file (or a new
/// one) written whole under a temporary name and renamed. With `status` (a tty only), then sends
/// a status request and returns the board's record.
pub fn send(port: &Path, baud: u32, bytes: &[u8], status: bool) -> Result<Option<uart::Status>, SendError> {
    let err = |error| SendError::Port { port: port.display().to_string(), error };
    let plain = std::fs::metadata(port).map(|m| m.is_file()).unwrap_or(true);
    if plain && status {
        return Err(SendError::NotTty(port.display().to_string()));
    }
    if plain {
        hdl_gen::output::write_one(port, bytes).map_err(|e| err(std::io::Error::other(e.to_string())))?;
        return Ok(None);
    }
    let mut f = std::fs::OpenOptions::new().read(status).write(true).open(port).map_err(err)?;
    // SAFETY: isatty only reads the descriptor's kind.
    let tty = unsafe { libc::isatty(f.as_raw_fd()) } == 1;
    if status && !tty {
        return Err(SendError::NotTty(port.display().to_string()));
    }
    if tty {
        set_tty(&f, baud).map_err(err)?;
    }
    f.write_all(bytes).map_err(err)?;
    f.flush().map_err(err)?;
    // SAFETY: as above; tcdrain waits until a tty has sent everything (fails harmlessly otherwise).
    unsafe { libc::tcdrain(f.as_raw_fd()) };
    if !status {
        return Ok(None);
    }
    f.write_all(&uart::encode(&uart::Command::Status).expect("a request fits")).map_err(err)?;
    read_status(&mut f).map_err(err)
}

/// Reads until a status record has come (the bytes before it skipped) or [`STATUS_WAIT`] passed.
fn read_status(f: &mut std::fs::File) -> std::io::Result<Option<uart::Status>> {
    use std::io::Read;
    // SAFETY: as in set_tty; VMIN 0 and VTIME 2: a read returns after 0.2 s without a byte.
    unsafe {
        let mut t: libc::termios = std::mem::zeroed();
        if libc::tcgetattr(f.as_raw_fd(), &mut t) != 0 {
            return Err(std::io::Error::last_os_error());
        }
        t.c_cc[libc::VMIN] = 0;
        t.c_cc[libc::VTIME] = 2;
        if libc::tcsetattr(f.as_raw_fd(), libc::TCSANOW, &t) != 0 {
            return Err(std::io::Error::last_os_error());
        }
    }
    let start = std::time::Instant::now();
    let mut got = Vec::new();
    while start.elapsed() < STATUS_WAIT {
        let mut buf = [0u8; 64];
        let n = f.read(&mut buf)?;
        got.extend_from_slice(&buf[..n]);
        if let Some(s) = (0..got.len()).find_map(|k| uart::status(&got[k..])) {
            return Ok(Some(s));
        }
    }
    Ok(None)
}
