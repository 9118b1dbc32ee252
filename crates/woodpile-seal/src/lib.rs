//! The seal of a woodpile table: a blake3 hash of the whole parquet file, written as the last
//! field (`"checksum"`) of the manifest in its footer. Computed over every byte, with the seal's
//! own 64 characters read as [`UNSEALED`], so a changed byte anywhere (data, footer, manifest)
//! breaks it. It detects damage, not tampering: it has no key.
//!
//! Polars-free on purpose: the engine (`woodpile-pipeline`) seals and checks its tables with
//! it, and the Python module checks them with it before pyarrow decodes them, so both refuse the
//! same damaged files.

/// The key of the manifest in a table's parquet key-value metadata.
pub const METADATA_KEY: &str = "woodpile";

/// The seal's placeholder while it is computed: 64 characters, as the seal itself.
pub const UNSEALED: &str = "unsealed-unsealed-unsealed-unsealed-unsealed-unsealed-unsealed-u";
/// The length of a seal: blake3's 32 bytes in hex.
pub const SEAL_LEN: usize = 64;
/// What precedes the seal in the manifest's text (its last field).
const SEAL_MARK: &[u8] = b"\"checksum\":\"";

/// Where the seal's 64 characters start in a sealed file: after the last `"checksum":"`
/// (the manifest's last field, in the footer near the end of the file).
pub fn position(bytes: &[u8]) -> Option<usize> {
    let at = bytes
        .windows(SEAL_MARK.len())
        .rposition(|w| w == SEAL_MARK)?
        + SEAL_MARK.len();
    (at + SEAL_LEN <= bytes.len()).then_some(at)
}

/// The seal of a file whose seal starts at `at`.
pub fn seal(bytes: &[u8], at: usize) -> String {
    let mut hasher = blake3::Hasher::new();
    hasher.update(b"woodpile table seal 2\n");
    hasher.update(&bytes[..at]);
    hasher.update(UNSEALED.as_bytes());
    hasher.update(&bytes[at + SEAL_LEN..]);
    hasher.finalize().to_hex().to_string()
}

/// Whether a table's bytes still match the seal its manifest recorded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Integrity {
    /// They do.
    Intact,
    /// They do not: the file was damaged (or edited) after it was written. It is not decoded.
    Damaged,
    /// There is no seal to check against: not a woodpile table.
    Unchecked,
}

/// The integrity of a table's `bytes`, checked before anything decodes them. A file that
/// carries woodpile's marks (the manifest's metadata key or a seal field) but no matching seal
/// is damaged; only a file with neither is unchecked (a foreign parquet file).
pub fn integrity(bytes: &[u8]) -> Integrity {
    match position(bytes) {
        Some(at) if bytes[at..at + SEAL_LEN] == *seal(bytes, at).as_bytes() => Integrity::Intact,
        Some(_) => Integrity::Damaged,
        None if contains(bytes, METADATA_KEY.as_bytes()) => Integrity::Damaged,
        None => Integrity::Unchecked,
    }
}

fn contains(haystack: &[u8], needle: &[u8]) -> bool {
    haystack.windows(needle.len()).any(|w| w == needle)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sealed stand-in for a table: some bytes, then the manifest's seal field.
    fn sealed() -> Vec<u8> {
        let mut bytes = b"PAR1 data {\"woodpile\":{\"checksum\":\"".to_vec();
        bytes.extend_from_slice(UNSEALED.as_bytes());
        bytes.extend_from_slice(b"\"}} PAR1");
        let at = position(&bytes).unwrap();
        let s = seal(&bytes, at);
        bytes[at..at + SEAL_LEN].copy_from_slice(s.as_bytes());
        bytes
    }

    #[test]
    fn a_sealed_file_is_intact_and_any_flipped_bit_damages_it() {
        let bytes = sealed();
        assert_eq!(integrity(&bytes), Integrity::Intact);
        for i in 0..bytes.len() * 8 {
            let mut copy = bytes.clone();
            copy[i / 8] ^= 1 << (i % 8);
            assert_ne!(integrity(&copy), Integrity::Intact, "bit {i}");
        }
        assert_eq!(integrity(b"PAR1 foreign PAR1"), Integrity::Unchecked);
    }
}
