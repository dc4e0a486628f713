//! The hot functions of the pipeline, one criterion group per stage: the schemes'
//! panel building, unrolling with label fitting, nesting (true-shape and shelf) and
//! drawing a sheet as SVG. On spot at 4 ft when ../shared/models is present, and on the
//! project's genus-2 model always. Run with `cargo bench --bench stages`.

use std::path::{Path, PathBuf};

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use glam::DVec2;

use unfold::config::{BuildOptions, Job, ModelOptions};
use unfold::export::{draw_sheet, svg, Layers, PathOrder};
use unfold::flatten::unroll_and_fit;
use unfold::labels::LabelOptions;
use unfold::mesh::Mesh;
use unfold::nest::{lay_out, NestSettings, NesterName, SheetSpec};
use unfold::panel::{FlatPanel, FlatPanels};

fn job(model: &Path, scheme: &str, size: &str) -> Job {
    BuildOptions {
        scheme: Some(scheme.to_string()),
        model: ModelOptions {
            size: Some(size.into()),
            ..Default::default()
        },
        ..Default::default()
    }
    .resolve(model)
    .expect("options resolve")
}

/// The mesh the scheme works on (loaded, prepared, scaled and split).
fn scheme_mesh(job: &Job) -> Mesh {
    let loaded = unfold::run::load(job).expect("model loads");
    unfold::run::prepare(job, loaded)
        .expect("scheme mesh")
        .scheme_mesh
        .mesh
}

fn flat_panels(job: &Job, mesh: &Mesh) -> Vec<FlatPanel> {
    let output = job.scheme.build(mesh).expect("scheme");
    output
        .panels
        .iter()
        .map(|p| {
            unroll_and_fit(p, LabelOptions::default())
                .expect("unrolls")
                .0
        })
        .collect()
}

fn models() -> Vec<(String, PathBuf, &'static str)> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut list = vec![(
        "genus2".to_string(),
        root.join("models/genus2.obj"),
        "300mm",
    )];
    let spot = root.join("../shared/models/spot.obj");
    if spot.is_file() {
        list.push(("spot".to_string(), spot, "4ft"));
    } else {
        eprintln!("skipping spot: {} is absent", spot.display());
    }
    list
}

fn schemes_and_flatten(c: &mut Criterion) {
    let mut scheme_group = c.benchmark_group("scheme");
    scheme_group.sample_size(10);
    for (name, path, size) in models() {
        for scheme in ["half-edge", "quad-edge", "winged-edge", "woven"] {
            let job = job(&path, scheme, size);
            let mesh = scheme_mesh(&job);
            scheme_group.bench_function(BenchmarkId::new(scheme.to_string(), &name), |b| {
                b.iter(|| job.scheme.build(&mesh).unwrap())
            });
        }
    }
    scheme_group.finish();

    let mut flatten_group = c.benchmark_group("flatten+labels");
    flatten_group.sample_size(10);
    for (name, path, size) in models() {
        for scheme in ["half-edge", "quad-edge"] {
            let job = job(&path, scheme, size);
            let mesh = scheme_mesh(&job);
            let output = job.scheme.build(&mesh).unwrap();
            flatten_group.bench_function(BenchmarkId::new(scheme.to_string(), &name), |b| {
                b.iter(|| {
                    for p in &output.panels {
                        unroll_and_fit(p, LabelOptions::default()).unwrap();
                    }
                })
            });
        }
    }
    flatten_group.finish();
}

fn nesting_and_export(c: &mut Criterion) {
    let mut group = c.benchmark_group("nest");
    group.sample_size(10);
    let mut drawn = Vec::new();
    for (name, path, size) in models() {
        let job = job(&path, "half-edge", size);
        let flat = flat_panels(&job, &scheme_mesh(&job));
        // The largest 400 panels: a job of a few sheets, so a sample takes seconds.
        let mut by_area: Vec<&FlatPanel> = flat.iter().collect();
        by_area.sort_by(|a, b| b.area.total_cmp(&a.area).then(a.id().cmp(&b.id())));
        by_area.truncate(400);
        let outlines: Vec<Vec<DVec2>> = by_area.iter().map(|p| p.outer()).collect();
        let areas: Vec<f64> = by_area.iter().map(|p| p.area).collect();
        let sheet = SheetSpec {
            width: job.sheet.width,
            height: job.sheet.height,
            margin: job.margin,
            spacing: job.spacing,
        };
        for nester in [NesterName::Shelf, NesterName::TrueShape] {
            let settings = NestSettings {
                nester,
                search: job.nest.search,
            };
            group.bench_function(BenchmarkId::new(nester.as_str(), &name), |b| {
                b.iter(|| lay_out(&outlines, &areas, sheet, &settings).unwrap())
            });
        }

        let layout = lay_out(&outlines, &areas, sheet, &job.nest).unwrap().layout;
        let owned: FlatPanels = by_area.iter().map(|p| (*p).clone()).collect();
        drawn.push((name, layout, owned, sheet));
    }
    group.finish();

    let mut group = c.benchmark_group("svg-first-sheet");
    for (name, layout, panels, sheet) in &drawn {
        group.bench_function(name.as_str(), |b| {
            b.iter(|| {
                let layers = Layers::standard(0.0254);
                let mut sink = svg::SvgSheet::new(sheet.width, sheet.height, &layers);
                draw_sheet(layout, 0, panels, false, PathOrder::Shortest, &mut sink);
                sink.finish()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, schemes_and_flatten, nesting_and_export);
criterion_main!(benches);
