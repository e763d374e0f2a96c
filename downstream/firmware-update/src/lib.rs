//! A program update over SDO, as CiA 302-3 describes it, for the bootloader
//! slave of the shared corpus (`lely_co-nmt-slave.dcf`): stop the program,
//! clear it, stream the new image into program data 0x1F50 by block
//! download, check the device's software identification 0x1F56 against the
//! image, start it. Every object is a typed entry of the generated
//! dictionary; the image is read as it goes, never held whole.

use std::fmt;
use std::io::{self, Read};

use eds2rust_runtime::blocking::{self, SdoClient};
use eds2rust_runtime::sdo::client::{Method, Progress};
use eds2rust_runtime::transport::Bus;

pub mod slave {
    include!(concat!(env!("OUT_DIR"), "/slave.rs"));
}

use slave::od::{program_control, program_data, program_software_identification};

/// Program control values (CiA 302-3).
const STOP: u8 = 0;
const START: u8 = 1;
const CLEAR: u8 = 3;

/// Why an update did not go through.
#[derive(Debug)]
pub enum UpdateError {
    /// An SDO step failed; `step` says which.
    Sdo {
        step: &'static str,
        error: blocking::Error,
    },
    /// The device reports another identification than the image's CRC-32.
    Mismatch { image: u32, device: u32 },
    /// The device did not start the program.
    NotStarted { status: u8 },
}

impl fmt::Display for UpdateError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            UpdateError::Sdo { step, error } => write!(f, "{step}: {error}"),
            UpdateError::Mismatch { image, device } => write!(
                f,
                "the device reports program identification {device:#010X}, the image's CRC-32 is {image:#010X}"
            ),
            UpdateError::NotStarted { status } => {
                write!(
                    f,
                    "the program did not start (program control reads {status})"
                )
            }
        }
    }
}

impl std::error::Error for UpdateError {}

/// A reader that computes the CRC-32 of what passes through it.
struct Crc32Reader<'a, R> {
    inner: R,
    digest: crc::Digest<'a, u32>,
}

impl<R: Read> Read for Crc32Reader<'_, R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.digest.update(&buf[..n]);
        Ok(n)
    }
}

static CRC32: crc::Crc<u32> = crc::Crc::<u32>::new(&crc::CRC_32_ISO_HDLC);

/// Updates program 1 with the `size` bytes `image` yields; `progress` hears
/// of the download. Returns the image's CRC-32, which the device confirmed.
pub fn update_program<B: Bus>(
    sdo: &mut SdoClient<B>,
    image: impl Read,
    size: u64,
    progress: impl FnMut(Progress),
) -> Result<u32, UpdateError> {
    let step = |step| move |error| UpdateError::Sdo { step, error };
    sdo.write::<program_control::ProgramNumber1>(STOP)
        .map_err(step("stop the program"))?;
    sdo.write::<program_control::ProgramNumber1>(CLEAR)
        .map_err(step("clear the program"))?;
    let mut reader = Crc32Reader {
        inner: image,
        digest: CRC32.digest(),
    };
    sdo.write_from::<program_data::ProgramNumber1>(
        &mut reader,
        Some(size),
        Method::Block,
        progress,
    )
    .map_err(step("download the program"))?;
    let image = reader.digest.finalize();
    let device = sdo
        .read::<program_software_identification::ProgramNumber1>()
        .map_err(step("read the program identification"))?;
    if device != image {
        return Err(UpdateError::Mismatch { image, device });
    }
    sdo.write::<program_control::ProgramNumber1>(START)
        .map_err(step("start the program"))?;
    let status = sdo
        .read::<program_control::ProgramNumber1>()
        .map_err(step("read the program control"))?;
    if status != START {
        return Err(UpdateError::NotStarted { status });
    }
    Ok(image)
}
