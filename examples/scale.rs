//! Load → flatten at scale: reads a model, prepares it, builds the scheme's panels and
//! unrolls them, printing the time of each stage and the peak memory, without nesting
//! or writing sheets (a million panels would fill thousands of sheets). For the
//! scale figures in docs/benchmarks.md:
//!
//! ```text
//! cargo run --release --example large_torus -- 1000 1000 target/torus-1M.obj
//! cargo run --release --example scale -- target/torus-1M.obj half-edge
//! ```

use std::path::PathBuf;
use std::time::Instant;

use unfold::config::{BuildOptions, ModelOptions};

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let usage = "usage: scale MODEL [half-edge|quad-edge|winged-edge]";
    let model = PathBuf::from(args.get(1).expect(usage));
    let scheme = match args.get(2).map(String::as_str) {
        None | Some("half-edge") => "half-edge",
        Some("quad-edge") => "quad-edge",
        Some("winged-edge") => "winged-edge",
        Some(other) => anyhow::bail!("{usage} (not {other})"),
    };
    let job = BuildOptions {
        scheme: Some(scheme.to_string()),
        model: ModelOptions {
            size: Some("4ft".into()),
            ..Default::default()
        },
        ..Default::default()
    }
    .resolve(&model)?;
    let input_bytes = std::fs::metadata(&model)?.len();

    let start = Instant::now();
    let mut last = start;
    let mut lap = |stage: &str| {
        let now = Instant::now();
        println!(
            "{stage:<8} {:>8.0} ms   resident {:>6} MiB   peak so far {:>6} MiB",
            (now - last).as_secs_f64() * 1e3,
            memory_kib("VmRSS:").unwrap_or(0) / 1024,
            memory_kib("VmHWM:").unwrap_or(0) / 1024
        );
        last = now;
    };
    let loaded = unfold::run::load(&job)?;
    let faces = loaded.prepared.mesh.face_count();
    lap("load");
    let prepared = unfold::run::prepare(&job, loaded)?;
    lap("split");
    let output = unfold::run::scheme(&job, &prepared)?;
    lap("scheme");
    // The pipeline's flatten stage: unrolling and label fitting.
    let flat = unfold::run::flatten(&job, &prepared, &output)?.panels;
    lap("flatten");
    let total = start.elapsed().as_secs_f64();
    let per_panel = |count: &dyn Fn(unfold::panel::PanelRef) -> usize| {
        output.panels.iter().map(count).sum::<usize>() as f64 / output.panels.len().max(1) as f64
    };
    println!(
        "per panel: {:.1} vertices, {:.1} facets, {:.1} holes, {:.1} labels kept ({:.1} dropped as too large for any facet; {:.1} fitted)",
        per_panel(&|p| p.vertices.len()),
        per_panel(&|p| p.facets.len()),
        per_panel(&|p| p.holes.len()),
        per_panel(&|p| p.labels.len()),
        per_panel(&|p| p.labels_dropped.total()),
        flat.iter().map(|p| p.labels.len()).sum::<usize>() as f64 / flat.len().max(1) as f64,
    );
    let peak_kib = memory_kib("VmHWM:").unwrap_or(0);
    println!(
        "{faces} faces, {} panels, {} flat; load → flatten {total:.2} s; peak memory {} MiB ({:.1} × the {} MiB input file)",
        output.panels.len(),
        flat.len(),
        peak_kib / 1024,
        peak_kib as f64 * 1024.0 / input_bytes as f64,
        input_bytes / (1024 * 1024)
    );
    Ok(())
}

/// A memory figure of this process (`VmRSS:` now, `VmHWM:` peak) on Linux, in KiB.
fn memory_kib(key: &str) -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with(key))?;
    line.split_whitespace().nth(1)?.parse().ok()
}
