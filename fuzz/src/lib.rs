//! What the fuzz targets share: one model file's bytes through the reader, the
//! preparation (cleaning, orientation, welding) and the half-edge mesh, as
//! `unfold` does before any scheme runs. Errors are fine; panics, hangs and
//! runaway memory are what the fuzzer looks for.

use std::path::Path;

use unfold::mesh::{parse_model, prepare, Format, Polygons, PrepareOptions};

/// Reads `data` as a model file of `format`, prepares it with and without welding and
/// asks the mesh for its topology and geometry facts.
pub fn read_and_prepare(format: Format, data: &[u8]) {
    let name = match format {
        Format::Obj => "fuzz.obj",
        Format::Off => "fuzz.off",
        Format::Stl => "fuzz.stl",
    };
    let Ok(raw) = parse_model(Path::new(name), format, data) else {
        return;
    };
    for weld in [false, true] {
        if let Ok(prepared) = prepare(&raw, &PrepareOptions { weld }) {
            let _ = prepared.mesh.topology();
            let _ = prepared.mesh.geometry_facts(1e-3);
        }
    }
}

/// A polygon soup decoded from fuzz bytes: the first byte gives the vertex count
/// (1–64), then three bytes per vertex (small integer coordinates, so positions
/// repeat and faces degenerate often), then faces as a corner count (0–7) followed by
/// that many vertex indices (taken modulo the vertex count).
pub fn soup_from_bytes(data: &[u8]) -> Option<Polygons> {
    let (&count, mut rest) = data.split_first()?;
    let vertices = usize::from(count % 64) + 1;
    if rest.len() < 3 * vertices {
        return None;
    }
    let positions = rest[..3 * vertices]
        .chunks_exact(3)
        .map(|c| {
            glam::DVec3::new(
                f64::from(c[0] % 8),
                f64::from(c[1] % 8),
                f64::from(c[2] % 8),
            )
        })
        .collect();
    rest = &rest[3 * vertices..];
    let mut polys = Polygons {
        positions,
        ..Polygons::new()
    };
    while let Some((&n, tail)) = rest.split_first() {
        let n = usize::from(n % 8);
        if tail.len() < n {
            break;
        }
        let corners: Vec<u32> = tail[..n]
            .iter()
            .map(|&i| u32::from(i) % vertices as u32)
            .collect();
        polys.push_face(&corners);
        rest = &tail[n..];
    }
    Some(polys)
}
