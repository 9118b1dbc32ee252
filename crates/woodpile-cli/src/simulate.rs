//! `woodpile simulate SCENE.toml`: the contract of docs/scene.md. One JSON object on stdout, or one error
//! on stderr and a non-zero exit. `--series` and `--field` also write the scene's time series
//! and its space-time field as parquet tables, sealed as pipeline tables are.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{anyhow, Context};
use serde_json::{json, Value};
use woodpile_files::key::{code_version, Key};
use woodpile_pipeline::manifest::Manifest;
use woodpile_pipeline::table::{self, Columns};
use woodpile_points::canonical::scene_json;
use woodpile_scene::report::{cost_note, simulate_report, unverified_report, wall_note};
use woodpile_scene::units_out::{SiFactors, Units};
use woodpile_scene::Scene;
use woodpile_sim::observe::{FractionSeries, SiteField};
use woodpile_sim::simulation::simulate;
use woodpile_sim::{ShareSet, SimError};

use crate::Failure;

/// Arguments of `woodpile simulate`.
#[derive(Debug, clap::Args)]
pub(crate) struct Args {
    /// The scene file (TOML; the format is in docs/scene.md).
    scene: PathBuf,
    /// Indent the JSON for reading.
    #[arg(long)]
    pretty: bool,
    /// Also write R, T, E_tr and E at every `run.sample_every` to this parquet file
    /// (columns t, R, T, E_tr, E; S, the striker's share, with a `[striker]`; D, the dissipated
    /// share, with damping).
    #[arg(long, value_name = "OUT.parquet")]
    series: Option<PathBuf>,
    /// Also write every site's displacement and velocity at every sample to this parquet file
    /// (columns t, site, velocity, displacement; one row per sample and site).
    #[arg(long, value_name = "OUT.parquet")]
    field: Option<PathBuf>,
    /// The paper sites the field keeps, inclusive (default: the whole chain).
    #[arg(
        long,
        value_name = "LO,HI",
        requires = "field",
        allow_hyphen_values = true
    )]
    sites: Option<String>,
    /// Give times in s, displacements in m, velocities in m/s and energies in J, in the JSON
    /// object and the --series and --field tables (a `[physical]` scene only; shares have no
    /// unit).
    #[arg(long)]
    si: bool,
}

pub(crate) fn run(args: &Args) -> Result<(), Failure> {
    let scene = woodpile_scene::load(&args.scene).map_err(Failure::input)?;
    check_outputs(args).map_err(Failure::input)?;
    let s = &scene.scenario;
    let sites = field_sites(&scene, args.sites.as_deref()).map_err(Failure::input)?;
    let units = if args.si { Units::Si } else { Units::Scaled };
    let si = SiFactors::of(&scene, units)
        .map_err(|reason| Failure::input(anyhow!("--si: {}: {reason}", args.scene.display())))?;
    if args.field.is_some() {
        woodpile_sim::simulation::check_field_size(s, sites.1 - sites.0 + 1)
            .map_err(|reason| Failure::input(anyhow!("--field: {reason}")))?;
    }
    let mut observers = (
        FractionSeries::new(&s.model, s.region),
        SiteField::new(&s.model, sites.0, sites.1),
    );
    if let Some(note) = cost_note(&scene) {
        eprintln!("note: {}: {note}", args.scene.display());
    }
    let started = Instant::now();
    let outcome = if args.series.is_some() || args.field.is_some() {
        simulate(s, &mut observers)
    } else {
        simulate(s, &mut ())
    };
    if let Err(SimError::NotConverged {
        finest: Some(finest),
        ..
    }) = &outcome
    {
        // The minutes the finest run took are not thrown away: its numbers, marked so.
        let kept = serde_json::json!({ "unverified": unverified_report(&scene, finest) });
        say!(
            "{}",
            crate::reports::json_text(&kept, args.pretty).map_err(Failure::simulation)?
        );
    }
    let outcome = outcome
        .with_context(|| format!("{}: simulation failed", args.scene.display()))
        .map_err(Failure::simulation)?;
    let wall_s = started.elapsed().as_secs_f64();
    let mut report = simulate_report(&scene, &outcome, wall_s);
    if let Some(note) = wall_note(&scene, &outcome) {
        eprintln!("note: {}: {note}", args.scene.display());
    }
    let (mut series, mut field) = observers;
    if let Some(si) = si {
        si.report(&mut report);
        si.series(&mut series, false);
        si.field(&mut field);
    }
    if let Some(path) = &args.series {
        write_series(path, &args.scene, &scene, &report, &series)?;
    }
    if let Some(path) = &args.field {
        write_field(path, &args.scene, &scene, &report, &field)?;
    }
    let text = crate::reports::json_text(&report, args.pretty);
    say!("{}", text.map_err(Failure::simulation)?);
    Ok(())
}

/// Refuses `--series` and `--field` targets that a write (a rename over the path) would
/// wrongly replace: anything but a regular file (a device, a FIFO, a folder), a symbolic link,
/// the scene being read, or the other output (one table would silently lose the other).
fn check_outputs(args: &Args) -> anyhow::Result<()> {
    let outputs = [("--series", &args.series), ("--field", &args.field)];
    for (flag, path) in outputs.iter().filter_map(|(f, p)| Some((*f, p.as_ref()?))) {
        if let Ok(meta) = std::fs::symlink_metadata(path) {
            let what = match meta.file_type() {
                t if t.is_symlink() => Some("a symbolic link"),
                t if !t.is_file() => Some("not a regular file"),
                _ => None,
            };
            if let Some(what) = what {
                return Err(anyhow!(
                    "{flag} {}: {what}; name a new file or a regular one to replace",
                    path.display()
                ));
            }
        }
        if same_file(path, &args.scene) {
            return Err(anyhow!(
                "{flag} {}: is the scene being read",
                path.display()
            ));
        }
    }
    if let (Some(series), Some(field)) = (&args.series, &args.field) {
        if same_file(series, field) {
            return Err(anyhow!(
                "--series and --field name the same file, {}: one table would replace the other",
                field.display()
            ));
        }
    }
    Ok(())
}

/// Whether `a` and `b` are one file: the same inode when both exist, else the same absolute
/// path.
fn same_file(a: &Path, b: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (std::fs::metadata(a), std::fs::metadata(b)) {
        (Ok(x), Ok(y)) => x.dev() == y.dev() && x.ino() == y.ino(),
        _ => resolved(a).is_some() && resolved(a) == resolved(b),
    }
}

/// Where a file that may not exist yet would be: its folder resolved (`a/../o.parquet` is
/// `o.parquet`), then its name.
fn resolved(path: &Path) -> Option<std::path::PathBuf> {
    let name = path.file_name()?;
    let folder = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    Some(std::fs::canonicalize(folder).ok()?.join(name))
}

/// The internal site range of `--sites LO,HI` (paper numbering), or the whole chain.
fn field_sites(scene: &Scene, spec: Option<&str>) -> anyhow::Result<(usize, usize)> {
    let (first, last) = (scene.first_site, scene.last_site);
    let Some(spec) = spec else {
        return Ok((0, (last - first) as usize));
    };
    let parsed = spec
        .split_once(',')
        .and_then(|(a, b)| Some((a.trim().parse::<i64>().ok()?, b.trim().parse::<i64>().ok()?)));
    let Some((lo, hi)) = parsed else {
        return Err(anyhow!(
            "--sites `{spec}`: expected LO,HI (two paper site numbers)"
        ));
    };
    scene
        .site_range(lo, hi)
        .map_err(|reason| anyhow!("--sites {lo},{hi}: {reason}"))
}

/// A table's manifest: what was simulated (the resolved scene, which the key hashes) and what
/// came of it (the JSON report, without its wall time, so the same scene writes the same bytes).
/// The manifest of a `--series` or `--field` table: its key from the scene, the table and its
/// units (SI tables only, so scaled ones keep their keys), its summary the run's JSON object
/// without its wall time.
fn manifest(what: &str, file: &Path, scene: &Scene, report: &Value, extra: Value) -> Manifest {
    let mut params = json!({"scene": scene_json(scene), "table": what, "extra": extra});
    if report["units"] == Units::Si.name() {
        params["units"] = json!(Units::Si.name());
    }
    let mut summary = report.clone();
    if let Value::Object(map) = &mut summary {
        map.remove("wall_s");
    }
    scene_table_manifest(file, format!("simulate {what}"), params, summary)
}

/// The manifest of a table a command writes from the scene `file`: named after the file, keyed
/// by the code and `params`, with `summary`.
pub(crate) fn scene_table_manifest(
    file: &Path,
    kind: String,
    params: Value,
    summary: Value,
) -> Manifest {
    Manifest {
        stage: file
            .file_stem()
            .map_or_else(|| "scene".into(), |s| s.to_string_lossy().into_owned()),
        kind,
        key: Key::of(&json!({"code": code_version(), "params": params}))
            .as_str()
            .to_string(),
        code_version: code_version(),
        params,
        inputs: Default::default(),
        summary,
        files: Default::default(),
        checksum: None,
    }
}

fn write_series(
    path: &Path,
    file: &Path,
    scene: &Scene,
    report: &Value,
    series: &FractionSeries,
) -> Result<(), Failure> {
    let some = |v: &[f64]| v.iter().map(|x| Some(*x)).collect::<Vec<_>>();
    let mut columns = Columns::new();
    columns.f64("t", some(&series.t));
    let scenario = &scene.scenario;
    for share in ShareSet::of(&scenario.model, &scenario.region).iter() {
        columns.f64(share.name(), some(share.in_series(series)));
    }
    columns.f64("E", some(&series.energy));
    let frame = columns.into_frame().map_err(Failure::simulation)?;
    table::write(
        path,
        frame,
        &manifest("series", file, scene, report, Value::Null),
    )
    .map_err(Failure::input)
}

fn write_field(
    path: &Path,
    file: &Path,
    scene: &Scene,
    report: &Value,
    field: &SiteField,
) -> Result<(), Failure> {
    let width = field.width();
    let rows = field.t.len() * width;
    let first = scene.first_site + *field.sites().start() as i64;
    let all = |values: &[f64]| values.iter().map(|v| Some(*v)).collect();
    let mut columns = Columns::new();
    columns
        .f64(
            "t",
            field
                .t
                .iter()
                .flat_map(|t| std::iter::repeat_n(Some(*t), width))
                .collect(),
        )
        .i64(
            "site",
            (0..rows)
                .map(|i| Some(first + (i % width) as i64))
                .collect(),
        )
        .f64("velocity", all(&field.velocity))
        .f64("displacement", all(&field.displacement))
        .f64("energy", all(&field.energy))
        .f64("kinetic", all(&field.kinetic))
        .f64(
            "resonator_displacement",
            per_site(scene, field, &field.resonator_displacement),
        )
        .f64(
            "resonator_velocity",
            per_site(scene, field, &field.resonator_velocity),
        );
    let frame = columns.into_frame().map_err(Failure::simulation)?;
    let sites = json!([first, first + width as i64 - 1]);
    table::write(path, frame, &manifest("field", file, scene, report, sites))
        .map_err(Failure::input)
}

/// A resonator column (time × resonator) in the field's long form (time × site): each site's
/// resonator, null where a site has none (a site hosts at most one).
fn per_site(scene: &Scene, field: &SiteField, values: &[f64]) -> Vec<Option<f64>> {
    let resonators = scene.scenario.model.resonators();
    let mut on_site: Vec<Option<usize>> = vec![None; field.width()];
    for (j, r) in resonators.iter().enumerate() {
        if let Some(k) = r.site.checked_sub(*field.sites().start()) {
            if k < on_site.len() {
                on_site[k] = Some(j);
            }
        }
    }
    let count = resonators.len();
    (0..field.t.len())
        .flat_map(|i| {
            on_site
                .iter()
                .map(move |j| j.map(|j| values[i * count + j]))
        })
        .collect()
}
