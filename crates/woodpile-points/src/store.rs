//! The per-point cache of a sweep: one small file per simulated scene, named by the scene's
//! content key, shared by every stage (F4's points are found again by F5).
//!
//! A point is written atomically the moment it is finished, so a sweep stopped by Ctrl-C or
//! `kill -9` resumes with every finished scene kept. Each file ends with a blake3 checksum of
//! its contents: a file damaged after the fact (a full disk, a bad copy) reads as absent and is
//! simply recomputed, never trusted.
//!
//! The format is private to this module (the stage outputs are the public parquet): magic
//! `WPPT`, a format byte (2), the 64-hex key, the outcome, then the checksum. Floats are stored as
//! their exact bits. A point's series are five columns (t, R, T, E_tr, E), or six with a
//! striker's S: the length tells which, so points without a striker keep their bytes.

use std::path::{Path, PathBuf};

use woodpile_files::error::{FileError, Result};
use woodpile_files::key::Key;
use woodpile_files::{atomic, layout, PointsDir};
use woodpile_scene::Scene;

use crate::point::{simulate_points_until, PointData, PointResult, Shares};

const MAGIC: &[u8; 4] = b"WPPT";
/// The largest point file read: far beyond a series of the sample budget's length.
const MAX_POINT_BYTES: u64 = 1 << 30;
/// 2 since sweep tables have `end_reached_at`: a point of format 1 lacks it, and reads as
/// absent (it is simulated again), so that a table never depends on how old its cache is.
const FORMAT: u8 = 2;
/// A point as the store gave it.
#[derive(Debug, Clone, PartialEq)]
pub struct Fetched {
    /// Its series, or why it failed.
    pub result: PointResult,
    /// Whether it was simulated now (not read from the cache).
    pub simulated: bool,
}

/// The point files of a [`PointsDir`], read, written and simulated into.
#[derive(Debug, Clone)]
pub struct PointStore {
    dir: PointsDir,
}

impl From<&PointsDir> for PointStore {
    fn from(dir: &PointsDir) -> Self {
        Self { dir: dir.clone() }
    }
}

impl PointStore {
    /// A store rooted at `dir` (created on first write).
    pub fn new(dir: impl Into<PathBuf>) -> Self {
        Self {
            dir: PointsDir::new(dir),
        }
    }

    /// The root directory.
    pub fn dir(&self) -> &Path {
        self.dir.dir()
    }

    /// Where the point `key` lives.
    pub fn path(&self, key: &Key) -> PathBuf {
        self.dir.path(key)
    }

    /// The cached result of `key`, or `None` when absent or damaged.
    pub fn load(&self, key: &Key) -> Option<PointResult> {
        // Only a regular file of bounded size: a FIFO or a link to /dev/zero in the cache
        // reads as absent (and is recomputed), never blocks or fills the memory.
        let bytes = woodpile_files::regular::read(&self.path(key), MAX_POINT_BYTES).ok()?;
        decode(&bytes, key)
    }

    /// Several points at once (`keys[k]` is the key of `scenes[k]`): from the cache, or
    /// simulated together (four neighbours at a time in SIMD lanes) and saved. Every kind that
    /// simulates scenes goes through here, so a scene is simulated once whichever stage asks
    /// for it first; a stage hands its points over in batches of groups of four
    /// (`woodpile_sim::simulation::batch_size`).
    pub fn get_or_simulate_all(
        &self,
        points: (&[&Key], &[&Scene]),
        series: Shares,
    ) -> Result<Vec<Fetched>> {
        let fetched = self.get_or_simulate_many(points, series, &|| false)?;
        let cancelled = || Fetched {
            result: Err("cancelled".into()),
            simulated: false,
        };
        Ok(fetched
            .into_iter()
            .map(|f| f.unwrap_or_else(cancelled))
            .collect())
    }

    /// The point `key` of `scene`, stopped once `stop()` says so: `None` then, and nothing
    /// is saved ([`PointStore::get_or_simulate_many`] of one point).
    pub fn get_or_simulate_until(
        &self,
        key: &Key,
        scene: &Scene,
        series: Shares,
        stop: &dyn Fn() -> bool,
    ) -> Result<Option<Fetched>> {
        let mut one = self.get_or_simulate_many((&[key], &[scene]), series, stop)?;
        Ok(one.pop().flatten())
    }

    /// Points `keys[k]` of `scenes[k]`: from the cache, or simulated together
    /// ([`simulate_points_until`]: four neighbours at a time in lanes) and saved, each with
    /// whether it was simulated now; `None` for a point stopped by `stop()` (nothing saved).
    /// Saved once all are simulated (callers pass a batch of groups of four; the first failed save ends
    /// the call).
    pub fn get_or_simulate_many(
        &self,
        (keys, scenes): (&[&Key], &[&Scene]),
        series: Shares,
        stop: &dyn Fn() -> bool,
    ) -> Result<Vec<Option<Fetched>>> {
        let mut fetched: Vec<Option<Fetched>> = keys
            .iter()
            .map(|key| {
                self.load(key).map(|cached| Fetched {
                    result: cached,
                    simulated: false,
                })
            })
            .collect();
        let todo: Vec<usize> = (0..keys.len()).filter(|&k| fetched[k].is_none()).collect();
        let to_simulate: Vec<&Scene> = todo.iter().map(|&k| scenes[k]).collect();
        let results = simulate_points_until(&to_simulate, series, stop);
        for (k, result) in todo.into_iter().zip(results) {
            let Some(result) = result else { continue };
            self.save(keys[k], &result)?;
            fetched[k] = Some(Fetched {
                result,
                simulated: true,
            });
        }
        Ok(fetched)
    }

    /// Stores `result` under `key`, atomically. A fan-out folder that is a symbolic link is
    /// refused: the write (and the stale-temporary sweep) would land outside the tree.
    pub fn save(&self, key: &Key, result: &PointResult) -> Result<()> {
        let path = self.path(key);
        if let Some(folder) = path.parent() {
            layout::check_tree_folder(folder)
                .map_err(|reason| FileError::refused(folder, reason))?;
        }
        atomic::write_checksummed(&path, &encode(key, result))
    }
}

fn encode(key: &Key, result: &PointResult) -> Vec<u8> {
    let mut w = Vec::new();
    w.extend_from_slice(MAGIC);
    w.push(FORMAT);
    put_str(&mut w, key.as_str());
    match result {
        Err(reason) => {
            w.push(0);
            put_str(&mut w, reason);
        }
        Ok(p) => {
            w.push(1);
            put_str(&mut w, &p.method);
            for x in [p.dt, p.error_estimate, p.energy_drift] {
                put_f64(&mut w, x.unwrap_or(f64::NAN));
            }
            w.extend_from_slice(&p.steps.to_le_bytes());
            w.extend_from_slice(&p.rhs_evals.to_le_bytes());
            put_f64(&mut w, p.e_initial);
            put_f64(&mut w, p.e_final);
            put_f64(&mut w, p.end_reached_at.unwrap_or(f64::NAN));
            w.extend_from_slice(&(p.t.len() as u64).to_le_bytes());
            let columns = [&p.t, &p.reflected, &p.transmitted, &p.trapped, &p.energy];
            let put_column = |w: &mut Vec<u8>, column: &[f64]| {
                column.iter().for_each(|&x| put_f64(w, x));
            };
            for column in columns {
                put_column(&mut w, column);
            }
            // The optional columns: a striker's S alone as it always was (so that its points
            // keep their bytes), and with D each behind its tag.
            match &p.dissipated {
                None => p.striker.iter().for_each(|s| put_column(&mut w, s)),
                Some(d) => {
                    for (tag, column) in [(b'S', p.striker.as_ref()), (b'D', Some(d))] {
                        if let Some(column) = column {
                            w.push(tag);
                            put_column(&mut w, column);
                        }
                    }
                }
            }
        }
    }
    let checksum = blake3::hash(&w);
    w.extend_from_slice(checksum.as_bytes());
    w
}

fn put_str(w: &mut Vec<u8>, s: &str) {
    w.extend_from_slice(&(s.len() as u64).to_le_bytes());
    w.extend_from_slice(s.as_bytes());
}

fn put_f64(w: &mut Vec<u8>, x: f64) {
    w.extend_from_slice(&x.to_bits().to_le_bytes());
}

fn decode(bytes: &[u8], key: &Key) -> Option<PointResult> {
    let (body, checksum) = bytes.split_at_checked(bytes.len().checked_sub(32)?)?;
    if blake3::hash(body).as_bytes() != checksum {
        return None;
    }
    let mut r = Reader { bytes: body };
    if r.take(4)? != MAGIC || r.take(1)? != [FORMAT] || r.str()? != key.as_str() {
        return None;
    }
    let result = match r.take(1)?[0] {
        0 => Err(r.str()?),
        1 => {
            let method = r.str()?;
            let optional = |x: f64| (!x.is_nan()).then_some(x);
            let (dt, error_estimate, energy_drift) =
                (optional(r.f64()?), optional(r.f64()?), optional(r.f64()?));
            let (steps, rhs_evals) = (r.u64()?, r.u64()?);
            let (e_initial, e_final) = (r.f64()?, r.f64()?);
            let end_reached_at = optional(r.f64()?);
            let n = usize::try_from(r.u64()?).ok()?;
            // Five columns, then S untagged (a striker's point as it always was), or tagged
            // optional columns (S and D with damping), which never add up to six columns.
            let legacy_striker = n > 0 && r.bytes.len() == n.checked_mul(6 * 8)?;
            let column = |r: &mut Reader| (0..n).map(|_| r.f64()).collect::<Option<Vec<f64>>>();
            let base: Vec<Vec<f64>> = (0..5).map(|_| column(&mut r)).collect::<Option<_>>()?;
            let [t, reflected, transmitted, trapped, energy] =
                <[Vec<f64>; 5]>::try_from(base).ok()?;
            let (mut striker, mut dissipated) = (None, None);
            if legacy_striker {
                striker = Some(column(&mut r)?);
            }
            while !r.bytes.is_empty() {
                match r.take(1)?[0] {
                    b'S' if striker.is_none() => striker = Some(column(&mut r)?),
                    b'D' if dissipated.is_none() => dissipated = Some(column(&mut r)?),
                    _ => return None,
                }
            }
            Ok(PointData {
                method,
                dt,
                steps,
                rhs_evals,
                error_estimate,
                energy_drift,
                e_initial,
                e_final,
                end_reached_at,
                t,
                reflected,
                transmitted,
                trapped,
                energy,
                striker,
                dissipated,
            })
        }
        _ => return None,
    };
    r.bytes.is_empty().then_some(result)
}

struct Reader<'a> {
    bytes: &'a [u8],
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Option<&'a [u8]> {
        let (head, tail) = self.bytes.split_at_checked(n)?;
        self.bytes = tail;
        Some(head)
    }

    fn u64(&mut self) -> Option<u64> {
        Some(u64::from_le_bytes(self.take(8)?.try_into().ok()?))
    }

    fn f64(&mut self) -> Option<f64> {
        Some(f64::from_bits(self.u64()?))
    }

    fn str(&mut self) -> Option<String> {
        let n = usize::try_from(self.u64()?).ok()?;
        String::from_utf8(self.take(n)?.to_vec()).ok()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> PointData {
        PointData {
            method: "rk4".into(),
            dt: Some(0.01),
            steps: 15000,
            rhs_evals: 90000,
            error_estimate: Some(1.5e-9),
            energy_drift: None,
            e_initial: 0.5,
            e_final: 0.5000000001,
            end_reached_at: Some(12.5),
            t: vec![0.0, 1.0],
            reflected: vec![0.0, 0.1],
            transmitted: vec![0.0, 0.2],
            trapped: vec![1.0, 0.7],
            energy: vec![0.5, 0.5],
            striker: None,
            dissipated: None,
        }
    }

    /// A store in a fresh temporary folder (kept alive by the returned guard) holding
    /// [`sample`] under the key of `name`.
    fn store_with_sample(name: &str) -> (tempfile::TempDir, PointStore, Key) {
        let dir = tempfile::tempdir().unwrap();
        let store = PointStore::new(dir.path());
        let key = Key::of(&serde_json::json!(name));
        store.save(&key, &Ok(sample())).unwrap();
        (dir, store, key)
    }

    /// Every single-bit flip of a point file reads as absent (and is recomputed), never as a
    /// different point, a panic or an abort.
    #[test]
    fn every_flipped_bit_of_a_point_file_reads_as_absent() {
        let (_dir, store, key) = store_with_sample("flip");
        let bytes = std::fs::read(store.path(&key)).unwrap();
        for byte in 0..bytes.len() {
            for bit in 0..8 {
                let mut copy = bytes.clone();
                copy[byte] ^= 1 << bit;
                std::fs::write(store.path(&key), &copy).unwrap();
                assert_eq!(store.load(&key), None, "byte {byte} bit {bit}");
            }
        }
    }

    /// A point of the format before `end_reached_at`, intact under its own checksum, reads as
    /// absent: it is simulated again rather than give its table a null the fresh run would
    /// not.
    #[test]
    fn a_point_of_an_older_format_reads_as_absent() {
        let (_dir, store, key) = store_with_sample("old");
        let bytes = std::fs::read(store.path(&key)).unwrap();
        let resealed = |body: &[u8]| {
            let mut out = body.to_vec();
            out.extend_from_slice(blake3::hash(body).as_bytes());
            out
        };
        let mut body = bytes[..bytes.len() - 32].to_vec();
        assert_eq!(decode(&resealed(&body), &key), Some(Ok(sample())));
        body[4] = 1;
        assert_eq!(decode(&resealed(&body), &key), None);
    }

    #[test]
    fn points_round_trip_bit_for_bit() {
        let (_dir, store, key) = store_with_sample("1");
        assert_eq!(store.load(&key), Some(Ok(sample())));
        let failed = Key::of(&serde_json::json!(2));
        assert_eq!(store.load(&failed), None);
        store
            .save(&failed, &Err("blew up at t = 3".into()))
            .unwrap();
        assert_eq!(store.load(&failed), Some(Err("blew up at t = 3".into())));
    }

    /// A striker's S and the dissipated D are extra columns, read back as such, alone or
    /// together; a point without them keeps five.
    #[test]
    fn the_strikers_and_dissipated_shares_round_trip() {
        let (_dir, store, _) = store_with_sample("five");
        let share = || Some(vec![0.0, 0.25]);
        for (name, striker, dissipated) in [
            ("s", share(), None),
            ("d", None, share()),
            ("sd", share(), share()),
        ] {
            let key = Key::of(&serde_json::json!(name));
            let with = PointData {
                striker,
                dissipated,
                ..sample()
            };
            store.save(&key, &Ok(with.clone())).unwrap();
            assert_eq!(store.load(&key), Some(Ok(with)));
        }
    }

    #[test]
    fn damaged_or_misnamed_files_read_as_absent() {
        let (_dir, store, key) = store_with_sample("a");
        let path = store.path(&key);
        let mut bytes = std::fs::read(&path).unwrap();
        // Truncated (a torn copy) and bit-flipped files are both rejected.
        assert_eq!(decode(&bytes[..bytes.len() - 1], &key), None);
        bytes[40] ^= 1;
        assert_eq!(decode(&bytes, &key), None);
        // A valid file under another key's name is rejected too.
        let good = std::fs::read(&path).unwrap();
        assert_eq!(decode(&good, &Key::of(&serde_json::json!("b"))), None);
    }
}
