//! `woodpile spectrum SCENE.toml`: the scene's linear picture about its static state (bands of
//! its host cell, modes, transmission of its defect region) as one JSON object on stdout, and
//! with `--out DIR` its tables as parquet files, sealed as pipeline tables are
//! (docs/spectrum.md).

use std::path::{Path, PathBuf};

use anyhow::anyhow;
use serde_json::json;
use woodpile_pipeline::table;
use woodpile_points::canonical::scene_json;
use woodpile_spectrum::measured::measure;
use woodpile_spectrum::scene::{
    scene_spectrum, Asked, Frequency, Refusal, SceneRequest, SceneSpectrum,
};
use woodpile_spectrum::tables::{summary, table, Part};

use crate::simulate::scene_table_manifest;
use crate::Failure;

/// Arguments of `woodpile spectrum`.
#[derive(Debug, clap::Args)]
pub(crate) struct Args {
    /// The scene file (TOML, docs/scene.md); it needs a static load (a precompression).
    scene: PathBuf,
    /// The host cell, paper sites LO,HI inclusive (default: the shortest period the chain
    /// repeats, else its lead's one site).
    #[arg(long, value_name = "LO,HI", allow_hyphen_values = true)]
    cell: Option<String>,
    /// The transmission's lowest frequency (Hz, or with a unit such as `2 kHz`, for a
    /// physical scene; cycles per unit time otherwise). With --to.
    #[arg(long, value_name = "F", requires = "to")]
    from: Option<String>,
    /// Its highest frequency. With --from.
    #[arg(long, value_name = "F", requires = "from")]
    to: Option<String>,
    /// How many frequencies, evenly spaced from --from to --to.
    #[arg(long, value_name = "N", default_value_t = 400, requires = "from")]
    points: usize,
    /// Also write the tables (bands, wavenumber, modes, damped, shapes, transmission, and
    /// measured with --measure) as parquet files into this folder.
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Also run the scene (a small impulse on the precompressed chain) and measure its
    /// transmission from the run, beside the linear one (`measured` in the JSON and tables).
    #[arg(long)]
    measure: bool,
    /// The measuring probe, a paper site past the defect region (default: as far past it as
    /// the impulse is before it).
    #[arg(
        long,
        value_name = "SITE",
        requires = "measure",
        allow_hyphen_values = true
    )]
    probe: Option<i64>,
    /// Indent the JSON for reading.
    #[arg(long)]
    pretty: bool,
}

pub(crate) fn run(args: &Args) -> Result<(), Failure> {
    let scene = woodpile_scene::load(&args.scene).map_err(Failure::input)?;
    let request = request(args).map_err(Failure::input)?;
    let refused = |refusal: Refusal| {
        let key = match refusal.asked {
            Asked::Scene => "",
            Asked::Cell => "--cell: ",
            Asked::Frequencies => "--from/--to/--points: ",
            Asked::Probe => "--probe: ",
            Asked::Sampling => "run.sample_every: ",
            Asked::Window => "run.t_end: ",
            Asked::Run => {
                let e = anyhow!("{}: {}", args.scene.display(), refusal.reason);
                return Failure::simulation(e);
            }
        };
        Failure::input(anyhow!("{}: {key}{}", args.scene.display(), refusal.reason))
    };
    let mut spectrum = scene_spectrum(&scene, &request).map_err(refused)?;
    if args.measure {
        spectrum.measured =
            Some(measure(&scene, &spectrum, args.probe, &|| false).map_err(refused)?);
    }
    let report = summary(&spectrum);
    if let Some(out) = &args.out {
        write_tables(out, &args.scene, &scene, &spectrum, &report)?;
    }
    let text = crate::reports::json_text(&report, args.pretty);
    say!("{}", text.map_err(Failure::simulation)?);
    Ok(())
}

/// The request the flags make.
fn request(args: &Args) -> anyhow::Result<SceneRequest> {
    let cell = match &args.cell {
        None => None,
        Some(spec) => {
            let pair = spec.split_once(',').and_then(|(a, b)| {
                Some([a.trim().parse::<i64>().ok()?, b.trim().parse::<i64>().ok()?])
            });
            Some(pair.ok_or_else(|| anyhow!("--cell `{spec}`: expected LO,HI (paper sites)"))?)
        }
    };
    let frequency = |text: &str| match text.trim().parse::<f64>() {
        Ok(x) => Frequency::Number(x),
        Err(_) => Frequency::Text(text.to_string()),
    };
    let frequencies = match (&args.from, &args.to) {
        (Some(from), Some(to)) => Some((frequency(from), frequency(to), args.points)),
        _ => None,
    };
    Ok(SceneRequest { cell, frequencies })
}

/// Each table the scene has, as `DIR/<part>.parquet`; a part the scene has not (no dashpots,
/// no leads) is not written, and a stale file of that name is removed.
fn write_tables(
    out: &Path,
    file: &Path,
    scene: &woodpile_scene::Scene,
    spectrum: &SceneSpectrum,
    report: &serde_json::Value,
) -> Result<(), Failure> {
    std::fs::create_dir_all(out)
        .map_err(|e| Failure::input(anyhow!("--out {}: {e}", out.display())))?;
    for part in Part::LINEAR.into_iter().chain([Part::Measured]) {
        let path = out.join(format!("{}.parquet", part.name()));
        let Ok(columns) = table(spectrum, part) else {
            if path.is_file() {
                std::fs::remove_file(&path)
                    .map_err(|e| Failure::input(anyhow!("{}: {e}", path.display())))?;
            }
            continue;
        };
        let frame = woodpile_stages::spectrum::frame_of(columns).map_err(Failure::simulation)?;
        let params = json!({"scene": scene_json(scene), "table": part.name()});
        let kind = format!("spectrum {}", part.name());
        let manifest = scene_table_manifest(file, kind, params, report.clone());
        table::write(&path, frame, &manifest).map_err(Failure::input)?;
    }
    Ok(())
}
