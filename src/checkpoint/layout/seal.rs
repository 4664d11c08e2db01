//! The seal: the length and xxh3-64 of a checkpoint's HDF5 bytes, kept in the file's userblock and checked before
//! libhdf5 parses the file (see the parent module's note on why).

use std::fs::{File, OpenOptions};
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::Path;

use xxhash_rust::xxh3::Xxh3Default;

use super::super::CheckpointError;

/// Size of the HDF5 userblock at the start of every checkpoint, which holds the seal.
pub(crate) const SEAL_BYTES: u64 = 512;
const SEAL_MAGIC: &str = "granflow-checkpoint seal v1\n";

/// The userblock: magic line, `hdf5_bytes=<decimal>`, `file_xxh3_64=0x<16 hex digits>`, zero padding.
fn seal_block(hdf5_bytes: u64, hash: u64) -> Vec<u8> {
    let mut block = format!("{SEAL_MAGIC}hdf5_bytes={hdf5_bytes}\nfile_xxh3_64={hash:#018x}\n").into_bytes();
    block.resize(SEAL_BYTES as usize, 0);
    block
}

/// The length and hash recorded in a seal block, given the bytes after the magic line.
fn parse_seal(rest: &[u8]) -> Option<(u64, u64)> {
    let text = std::str::from_utf8(rest.split(|&b| b == 0).next()?).ok()?;
    let mut lines = text.lines();
    let len = lines.next()?.strip_prefix("hdf5_bytes=")?.parse().ok()?;
    let hash = u64::from_str_radix(lines.next()?.strip_prefix("file_xxh3_64=0x")?, 16).ok()?;
    Some((len, hash))
}

/// The xxh3-64 of everything from the current position of `file` to its end, and the number of bytes hashed.
fn hash_rest(file: &mut File) -> std::io::Result<(u64, u64)> {
    let mut hasher = Xxh3Default::new();
    let mut buf = vec![0u8; 1 << 20];
    let mut len = 0u64;
    loop {
        match file.read(&mut buf) {
            Ok(0) => return Ok((hasher.digest(), len)),
            Ok(k) => {
                hasher.update(&buf[..k]);
                len += k as u64;
            }
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
}

/// Seals the closed HDF5 file at `path` (created with a [`SEAL_BYTES`] userblock): hashes everything after the
/// userblock, writes the seal into it and fsyncs the file.
pub(crate) fn seal(path: &Path) -> Result<(), CheckpointError> {
    let io = |e: std::io::Error| CheckpointError::io(path, "sealing the file", e);
    let mut file = OpenOptions::new().read(true).write(true).open(path).map_err(io)?;
    file.seek(SeekFrom::Start(SEAL_BYTES)).map_err(io)?;
    let (hash, len) = hash_rest(&mut file).map_err(io)?;
    file.seek(SeekFrom::Start(0)).map_err(io)?;
    file.write_all(&seal_block(len, hash)).map_err(io)?;
    file.sync_all().map_err(io)
}

/// Checks the seal of the file at `path`: a well-formed seal block, the recorded length and the recorded hash.
pub(crate) fn verify_seal(path: &Path) -> Result<(), CheckpointError> {
    let io = |e: std::io::Error| CheckpointError::io(path, "reading the file", e);
    let corrupt = |reason: String| CheckpointError::corrupt(path, reason);
    let mut file = File::open(path).map_err(io)?;
    let len = file.metadata().map_err(io)?.len();
    if len < SEAL_BYTES {
        return Err(corrupt(format!(
            "truncated ({len} bytes, shorter than the {SEAL_BYTES}-byte seal block)"
        )));
    }
    let mut block = vec![0u8; SEAL_BYTES as usize];
    file.read_exact(&mut block).map_err(io)?;
    let Some(rest) = block.strip_prefix(SEAL_MAGIC.as_bytes()) else {
        return Err(corrupt(
            "no checkpoint seal at the start of the file (not a granflow checkpoint, or rewritten by another tool)"
                .to_string(),
        ));
    };
    let (hdf5_bytes, stored) = parse_seal(rest)
        .filter(|&(n, h)| seal_block(n, h) == block)
        .ok_or_else(|| corrupt("the seal block is damaged".to_string()))?;
    let expected = SEAL_BYTES.saturating_add(hdf5_bytes);
    if len < expected {
        return Err(corrupt(format!("truncated ({len} bytes, {expected} written)")));
    }
    if len > expected {
        return Err(corrupt(format!(
            "{} bytes longer than the {expected} written",
            len - expected
        )));
    }
    let (computed, _) = hash_rest(&mut file).map_err(io)?;
    if computed != stored {
        return Err(corrupt(format!(
            "file checksum mismatch (stored {stored:#018x}, computed {computed:#018x})"
        )));
    }
    Ok(())
}
