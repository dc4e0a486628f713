//! The nest stage alone, on a job's own parts: builds the panels of a model as the
//! command line would (or reads them from a file written by an earlier run), then lays
//! them out once per effort and seed asked, printing sheets, effective sheets (full
//! sheets plus the last one's share of the sheet area, as `scripts/bench` prints them),
//! the search's sheets after each phase, the time and a fingerprint of the layout
//! (equal fingerprints: the same placements, bit for bit). For tuning the nester
//! without building the panels each time:
//!
//! ```text
//! cargo run --release --example nest_only -- ../shared/models/decimated-knight.off \
//!     --scheme net --size 4ft --sheet 18x24in --parts target/knight-net.json --efforts 5,10
//! ```
//!
//! `--parts FILE` is read when it exists and written otherwise. The file holds the
//! parts' outlines and the sheet: once it exists, the options that shape the parts or
//! the sheet are not used, and the nesting options (nester, rotations, mirror, effort,
//! seed) still are.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{anyhow, Context};
use clap::{CommandFactory, FromArgMatches, Parser};
use glam::DVec2;
use serde_json::{json, Value};
use unfold::nest::{lay_out, NestSettings, SheetSpec};
use unfold::scheme::Registry;
use unfold::BuildOptions;

#[derive(Debug, Parser)]
#[command(name = "nest_only")]
struct Args {
    /// The model whose panels are nested.
    model: PathBuf,

    /// Parts file: read when it exists, else written from the built panels.
    #[arg(long, value_name = "FILE")]
    parts: Option<PathBuf>,

    /// Efforts to nest at, comma separated (default: the job's).
    #[arg(long, value_name = "LIST", value_delimiter = ',')]
    efforts: Vec<u32>,

    /// Seeds to nest with, comma separated (default: the job's).
    #[arg(long, value_name = "LIST", value_delimiter = ',')]
    seeds: Vec<u64>,

    #[command(flatten)]
    build: BuildOptions,
}

/// A job's parts as the nest stage sees them.
struct Parts {
    outlines: Vec<Vec<DVec2>>,
    areas: Vec<f64>,
    sheet: SheetSpec,
}

fn main() -> anyhow::Result<()> {
    let registry = Registry::default();
    let matches = BuildOptions::with_registry(Args::command(), &registry).get_matches();
    let mut args = Args::from_arg_matches(&matches)?;
    args.build.scheme_values = BuildOptions::scheme_values(&matches, &registry);
    let job = args.build.resolve_with(&args.model, &registry)?;
    let parts = match &args.parts {
        Some(file) if file.exists() => read_parts(file)?,
        _ => {
            let started = Instant::now();
            let parts = build_parts(&job)?;
            eprintln!(
                "built {} parts in {:.1} s",
                parts.outlines.len(),
                started.elapsed().as_secs_f64()
            );
            if let Some(file) = &args.parts {
                write_parts(file, &parts)?;
            }
            parts
        }
    };
    let efforts = or_job(&args.efforts, job.nest.search.effort);
    let seeds = or_job(&args.seeds, job.nest.search.seed);
    println!("parts {}", parts.outlines.len());
    println!(
        "effort\tseed\tsheets\teffective\tplaced\tmoved\tsqueezed\tbound\tnester\tseconds\tlayout"
    );
    for &effort in &efforts {
        for &seed in &seeds {
            let mut settings: NestSettings = job.nest;
            settings.search.effort = effort;
            settings.search.seed = seed;
            let started = Instant::now();
            let nested = lay_out(&parts.outlines, &parts.areas, parts.sheet, &settings)
                .map_err(|e| anyhow!("part {} does not fit the sheet", e.part))?;
            let seconds = started.elapsed().as_secs_f64();
            let layout = &nested.layout;
            let mut used = vec![0.0; layout.sheets];
            for p in &layout.placements {
                used[p.sheet] += parts.areas[p.part];
            }
            // The fullest sheets come first, so the last holds the least.
            let last = used.last().copied().unwrap_or(0.0);
            let effective = layout.sheets.saturating_sub(1) as f64
                + last / (parts.sheet.width * parts.sheet.height);
            let phases = nested
                .search_phases
                .map(|p| format!("{}\t{}\t{}", p.placed, p.moved, p.squeezed))
                .unwrap_or_else(|| "-\t-\t-".to_string());
            println!(
                "{effort}\t{seed}\t{}\t{effective:.2}\t{phases}\t{}\t{}\t{seconds:.1}\t{:016x}",
                layout.sheets,
                nested.spacing_bound,
                nested.nester.as_str(),
                layout_hash(layout)
            );
        }
    }
    Ok(())
}

/// A fingerprint of every placement's bits (FNV-1a): two runs with the same one laid
/// the parts out identically.
fn layout_hash(layout: &unfold::nest::Layout) -> u64 {
    let mut hash = 0xcbf2_9ce4_8422_2325_u64;
    for p in &layout.placements {
        let words = [
            p.part as u64,
            p.sheet as u64,
            p.rotation.to_bits(),
            p.translation.x.to_bits(),
            p.translation.y.to_bits(),
            u64::from(p.mirrored),
        ];
        for byte in words.iter().flat_map(|w| w.to_le_bytes()) {
            hash = (hash ^ u64::from(byte)).wrapping_mul(0x0100_0000_01b3);
        }
    }
    hash
}

/// `asked`, or the job's own value when none was asked.
fn or_job<T: Copy>(asked: &[T], job: T) -> Vec<T> {
    if asked.is_empty() {
        vec![job]
    } else {
        asked.to_vec()
    }
}

/// The job's panels built and unrolled as the command line does, as the nest stage's
/// outlines and areas.
fn build_parts(job: &unfold::Job) -> anyhow::Result<Parts> {
    let loaded = unfold::run::load(job)?;
    let prepared = unfold::run::prepare(job, loaded)?;
    let output = unfold::run::scheme(job, &prepared)?;
    let flat = unfold::run::flatten(job, &prepared, &output)?;
    Ok(Parts {
        outlines: flat.panels.iter().map(|p| p.outer()).collect(),
        areas: flat.panels.iter().map(|p| p.area).collect(),
        sheet: SheetSpec {
            width: job.sheet.width,
            height: job.sheet.height,
            margin: job.margin,
            spacing: job.spacing,
        },
    })
}

fn write_parts(file: &Path, parts: &Parts) -> anyhow::Result<()> {
    let outlines: Vec<Value> = parts
        .outlines
        .iter()
        .map(|o| o.iter().map(|p| json!([p.x, p.y])).collect())
        .collect();
    let s = parts.sheet;
    let value = json!({
        "sheet": [s.width, s.height, s.margin, s.spacing],
        "areas": parts.areas,
        "outlines": outlines,
    });
    std::fs::write(file, serde_json::to_string(&value)?)
        .with_context(|| format!("writing {}", file.display()))
}

fn read_parts(file: &Path) -> anyhow::Result<Parts> {
    let text =
        std::fs::read_to_string(file).with_context(|| format!("reading {}", file.display()))?;
    let value: Value = serde_json::from_str(&text)?;
    let numbers = |v: &Value| -> anyhow::Result<Vec<f64>> {
        v.as_array()
            .ok_or_else(|| anyhow!("{}: a list expected", file.display()))?
            .iter()
            .map(|x| {
                x.as_f64()
                    .ok_or_else(|| anyhow!("{}: a number expected", file.display()))
            })
            .collect()
    };
    let sheet = numbers(&value["sheet"])?;
    let [width, height, margin, spacing] = sheet[..] else {
        anyhow::bail!("{}: the sheet is four numbers", file.display());
    };
    let outlines = value["outlines"]
        .as_array()
        .ok_or_else(|| anyhow!("{}: no outlines", file.display()))?
        .iter()
        .map(|o| {
            o.as_array()
                .ok_or_else(|| anyhow!("{}: an outline is a list", file.display()))?
                .iter()
                .map(|p| match numbers(p)?[..] {
                    [x, y] => Ok(DVec2::new(x, y)),
                    _ => Err(anyhow!("{}: a point is two numbers", file.display())),
                })
                .collect()
        })
        .collect::<anyhow::Result<Vec<Vec<DVec2>>>>()?;
    Ok(Parts {
        outlines,
        areas: numbers(&value["areas"])?,
        sheet: SheetSpec {
            width,
            height,
            margin,
            spacing,
        },
    })
}
