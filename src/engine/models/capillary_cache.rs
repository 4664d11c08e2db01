//! The Young–Laplace force tables on disk: built at first use and cached, so that only the first job of a campaign
//! pays the 1–3 s per unlike species pair (and per particle–wall species pair).
//!
//! A table in dimensionless form depends only on R₂/R₁, θ₁ and θ₂ (and on the solver and its grid), so the file
//! is named by a hash of their bit patterns and of [`FORMAT`]. The file holds the rows' f64 bit patterns followed by
//! an xxh3 checksum: a loaded table is bit-for-bit the table a fresh build gives, so runs (and restarts) do not
//! depend on whether the cache was warm. A file that is missing, truncated, corrupt or for other inputs is rebuilt
//! and replaced; a cache directory that cannot be written only costs the rebuild.
//!
//! Where: `$GRANFLOW_CACHE_DIR` if set (empty: no cache), else the user's cache directory (`$XDG_CACHE_HOME` or
//! `~/.cache` on Linux) + `granflow/`.

use std::io::Write;
use std::path::{Path, PathBuf};

use super::capillary_table::CapillaryTable;

/// Bump when the solver, the table's grid or this layout changes: old files are then ignored.
const FORMAT: u32 = 1;
const MAGIC: &[u8; 8] = b"GFCAPTAB";

/// The cache directory: `$GRANFLOW_CACHE_DIR`, else the user's cache directory + `granflow`; `None`: no cache.
pub fn cache_dir() -> Option<PathBuf> {
    match std::env::var_os("GRANFLOW_CACHE_DIR") {
        Some(d) if d.is_empty() => None,
        Some(d) => Some(PathBuf::from(d)),
        None => dirs::cache_dir().map(|d| d.join("granflow")),
    }
}

/// How a table was obtained.
#[derive(Debug, Clone, PartialEq)]
pub enum Provenance {
    Loaded(PathBuf),
    /// Built and written to this file.
    BuiltAndCached(PathBuf),
    /// Built; not cached, for this reason.
    BuiltOnly(String),
}

/// The table for R₁, R₂, θ₁, θ₂: from `dir` when a valid file is there, else built (and written there).
pub fn load_or_build(
    dir: Option<&Path>,
    radius_1_m: f64,
    radius_2_m: f64,
    contact_angle_1_rad: f64,
    contact_angle_2_rad: f64,
) -> (CapillaryTable, Provenance) {
    let key = Key {
        radius_ratio: radius_2_m / radius_1_m,
        contact_angle_1_rad,
        contact_angle_2_rad,
    };
    let Some(dir) = dir else {
        let table = CapillaryTable::new(radius_1_m, radius_2_m, contact_angle_1_rad, contact_angle_2_rad);
        return (table, Provenance::BuiltOnly("no cache directory".into()));
    };
    let path = dir.join(key.file_name());
    if let Ok(bytes) = std::fs::read(&path)
        && let Some(rows) = decode(&bytes, &key)
    {
        return (CapillaryTable::from_rows(radius_1_m, rows), Provenance::Loaded(path));
    }
    let table = CapillaryTable::new(radius_1_m, radius_2_m, contact_angle_1_rad, contact_angle_2_rad);
    let provenance = match write_atomically(dir, &path, &encode(&key, &table.rows())) {
        Ok(()) => Provenance::BuiltAndCached(path),
        Err(e) => Provenance::BuiltOnly(format!("cannot write {}: {e}", path.display())),
    };
    (table, provenance)
}

/// The inputs a dimensionless table depends on.
struct Key {
    radius_ratio: f64,
    contact_angle_1_rad: f64,
    contact_angle_2_rad: f64,
}

impl Key {
    fn bytes(&self) -> Vec<u8> {
        let mut b = Vec::with_capacity(32);
        b.extend_from_slice(MAGIC);
        b.extend_from_slice(&FORMAT.to_le_bytes());
        for v in [self.radius_ratio, self.contact_angle_1_rad, self.contact_angle_2_rad] {
            b.extend_from_slice(&v.to_bits().to_le_bytes());
        }
        b
    }

    fn file_name(&self) -> String {
        format!(
            "young-laplace-v{FORMAT}-{:016x}.bin",
            xxhash_rust::xxh3::xxh3_64(&self.bytes())
        )
    }
}

/// Key bytes, row count, then per row: its length and its (ln V̂, F̂) columns; last, the xxh3 of all before.
fn encode(key: &Key, rows: &[(Vec<f64>, Vec<f64>)]) -> Vec<u8> {
    let mut b = key.bytes();
    b.extend_from_slice(&(rows.len() as u64).to_le_bytes());
    for (ln_volume, force) in rows {
        b.extend_from_slice(&(ln_volume.len() as u64).to_le_bytes());
        for v in ln_volume.iter().chain(force) {
            b.extend_from_slice(&v.to_bits().to_le_bytes());
        }
    }
    let sum = xxhash_rust::xxh3::xxh3_64(&b);
    b.extend_from_slice(&sum.to_le_bytes());
    b
}

/// The rows, if `bytes` is a complete, uncorrupted file for `key`.
fn decode(bytes: &[u8], key: &Key) -> Option<Vec<(Vec<f64>, Vec<f64>)>> {
    let body = bytes.len().checked_sub(8).map(|n| &bytes[..n])?;
    let sum = u64::from_le_bytes(bytes[body.len()..].try_into().ok()?);
    if xxhash_rust::xxh3::xxh3_64(body) != sum {
        return None;
    }
    let head = key.bytes();
    let mut rest = body.strip_prefix(head.as_slice())?;
    let mut word = || -> Option<u64> {
        let (w, r) = rest.split_first_chunk::<8>()?;
        rest = r;
        Some(u64::from_le_bytes(*w))
    };
    let count = word()?;
    let mut rows = Vec::new();
    for _ in 0..count {
        let n = usize::try_from(word()?).ok()?;
        let mut column = |n: usize| (0..n).map(|_| word().map(f64::from_bits)).collect::<Option<Vec<f64>>>();
        let ln_volume = column(n)?;
        let force = column(n)?;
        if !ln_volume.windows(2).all(|w| w[0] < w[1]) || !force.iter().all(|f| f.is_finite()) {
            return None;
        }
        rows.push((ln_volume, force));
    }
    word().is_none().then_some(rows)
}

/// Writes to a temporary file in `dir` and renames it over `path`, so readers see a whole file or none.
fn write_atomically(dir: &Path, path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let mut tmp = tempfile::NamedTempFile::new_in(dir)?;
    tmp.write_all(bytes)?;
    tmp.as_file().sync_all()?;
    tmp.persist(path).map_err(|e| e.error)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cached_table_is_the_built_table_bit_for_bit_and_a_damaged_file_is_rebuilt() {
        let dir = tempfile::tempdir().expect("temp dir");
        let (r1, r2, t1, t2) = (1e-3, 1.6e-3, 20f64.to_radians(), 50f64.to_radians());
        let (built, first) = load_or_build(Some(dir.path()), r1, r2, t1, t2);
        let Provenance::BuiltAndCached(path) = first else {
            panic!("first use builds and caches: {first:?}")
        };
        let (loaded, second) = load_or_build(Some(dir.path()), r1, r2, t1, t2);
        assert_eq!(second, Provenance::Loaded(path.clone()));
        let bits = |t: &CapillaryTable| -> Vec<u64> {
            t.rows()
                .iter()
                .flat_map(|(v, f)| v.iter().chain(f))
                .map(|x| x.to_bits())
                .collect()
        };
        assert_eq!(bits(&loaded), bits(&built));
        assert!(bits(&built).len() > 1000, "a real table");
        // Another radius with the same ratio reads the same file; the lengths scale.
        let (scaled, third) = load_or_build(Some(dir.path()), 2.0 * r1, 2.0 * r2, t1, t2);
        assert_eq!(third, Provenance::Loaded(path.clone()));
        let f = |t: &CapillaryTable, scale: f64| t.force_n(2e-3 * (scale * r1).powi(3), 0.1 * scale * r1, 0.07);
        assert!((f(&scaled, 2.0) / f(&built, 1.0) - 2.0).abs() < 1e-12);
        // Another contact angle is another file.
        let (_, other) = load_or_build(Some(dir.path()), r1, r2, t1, 40f64.to_radians());
        assert!(matches!(other, Provenance::BuiltAndCached(p) if p != path));
        // A flipped bit or a truncated file is rebuilt and replaced.
        let good = std::fs::read(&path).unwrap();
        for damaged in [
            {
                let mut b = good.clone();
                b[good.len() / 2] ^= 0x10;
                b
            },
            good[..good.len() - 9].to_vec(),
        ] {
            std::fs::write(&path, damaged).unwrap();
            let (rebuilt, how) = load_or_build(Some(dir.path()), r1, r2, t1, t2);
            assert_eq!(how, Provenance::BuiltAndCached(path.clone()));
            assert_eq!(bits(&rebuilt), bits(&built));
            assert_eq!(std::fs::read(&path).unwrap(), good);
        }
        // No directory: built, not cached.
        assert!(matches!(
            load_or_build(None, r1, r2, t1, t2).1,
            Provenance::BuiltOnly(_)
        ));
    }
}
