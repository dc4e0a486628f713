//! STL, binary or ASCII: a triangle soup, welded by position with a tolerance relative
//! to the model size so that the triangles share vertices and edges.

use std::path::Path;

use glam::DVec3;

use super::model::{Format, RawModel};
use super::text::{binary_data_at, parse_coordinate, text_lines, MAX_COORDINATE, TOO_LARGE_FIX};
use crate::error::{InputError, Location};
use crate::mesh::polygons::Polygons;
use crate::mesh::weld::{cluster_positions, weld_tolerance};

/// Parses an STL file held in memory, binary or ASCII.
pub(super) fn parse(path: &Path, bytes: &[u8]) -> Result<RawModel, InputError> {
    // Binary headers often start with "solid" too: ASCII also needs text after it.
    let looks_ascii = bytes
        .iter()
        .skip_while(|b| b.is_ascii_whitespace())
        .take(5)
        .eq(b"solid".iter())
        && binary_data_at(bytes).is_none();
    let binary_size = (bytes.len() >= 84).then(|| {
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
        84 + 50 * n
    });
    // Many binary files also start their header with "solid": the size decides.
    let (corners, locations, binary) = if binary_size == Some(bytes.len() as u64) {
        read_binary(path, bytes)?
    } else if looks_ascii {
        read_ascii(path, bytes)?
    } else {
        let problem = match binary_size {
            Some(expected) => format!(
                "truncated binary STL: the header announces {} triangles ({expected} bytes) but the file has {} bytes",
                (expected - 84) / 50,
                bytes.len()
            ),
            None => format!(
                "truncated binary STL: {} bytes is shorter than the 84-byte header",
                bytes.len()
            ),
        };
        return Err(InputError::new(
            path,
            Location::File,
            problem,
            "the file was cut short; export or copy it again",
        ));
    };

    // Weld: corners at the same position (within a tolerance relative to the model
    // size) become one vertex.
    let tolerance = weld_tolerance(&corners);
    let representative = cluster_positions(&corners, tolerance);
    let mut vertex_of_corner = vec![u32::MAX; corners.len()];
    let mut polys = Polygons::new();
    for (c, &r) in representative.iter().enumerate() {
        if vertex_of_corner[r as usize] == u32::MAX {
            vertex_of_corner[r as usize] = polys.positions.len() as u32;
            polys.positions.push(corners[r as usize]);
        }
        vertex_of_corner[c] = vertex_of_corner[r as usize];
    }
    for tri in vertex_of_corner.chunks_exact(3) {
        polys.push_face(tri);
    }
    let welded_corners = corners.len() - polys.positions.len();
    Ok(RawModel {
        path: path.to_path_buf(),
        format: Format::Stl,
        polys,
        face_locations: locations,
        binary,
        groups: Vec::new(),
        ignored: Vec::new(),
        welded_corners,
    })
}

type Soup = (Vec<DVec3>, Vec<u64>, bool);

fn read_binary(path: &Path, bytes: &[u8]) -> Result<Soup, InputError> {
    let count = (bytes.len() - 84) / 50;
    let mut corners = Vec::with_capacity(count * 3);
    let mut locations = Vec::with_capacity(count);
    for t in 0..count {
        let start = 84 + 50 * t;
        let record = &bytes[start..start + 50];
        for k in 0..3 {
            let mut xyz = [0.0f64; 3];
            for (axis, slot) in xyz.iter_mut().enumerate() {
                let at = 12 + 12 * k + 4 * axis;
                let value = f32::from_le_bytes([
                    record[at],
                    record[at + 1],
                    record[at + 2],
                    record[at + 3],
                ]);
                if !value.is_finite() {
                    return Err(InputError::new(
                        path,
                        Location::Byte((start + at) as u64),
                        format!("triangle {t} has a coordinate that is not a finite number"),
                        "replace NaN or infinite coordinates with real positions",
                    ));
                }
                if f64::from(value).abs() > MAX_COORDINATE {
                    return Err(InputError::new(
                        path,
                        Location::Byte((start + at) as u64),
                        format!("triangle {t} has a coordinate of {value:e}, too large"),
                        TOO_LARGE_FIX,
                    ));
                }
                *slot = value as f64;
            }
            corners.push(DVec3::from_array(xyz));
        }
        locations.push(start as u64);
    }
    Ok((corners, locations, true))
}

fn read_ascii(path: &Path, bytes: &[u8]) -> Result<Soup, InputError> {
    let mut corners = Vec::new();
    let mut locations = Vec::new();
    // Vertices of the facet being read, and the line where it started.
    let mut facet: Vec<DVec3> = Vec::with_capacity(3);
    let mut facet_line = 0u64;
    let mut in_facet = false;
    for item in text_lines(path, bytes, "STL") {
        let (n, text) = item?;
        let mut tokens = text.split_ascii_whitespace();
        match tokens.next() {
            Some("facet") => {
                if in_facet {
                    return Err(InputError::new(
                        path,
                        Location::Line(n),
                        "'facet' before the previous facet's 'endfacet'",
                        "the file is malformed; export it again",
                    ));
                }
                in_facet = true;
                facet.clear();
                facet_line = n;
            }
            Some("vertex") => {
                if !in_facet {
                    return Err(InputError::new(
                        path,
                        Location::Line(n),
                        "'vertex' outside a facet",
                        "the file is malformed; export it again",
                    ));
                }
                let mut xyz = [0.0; 3];
                for (axis, slot) in xyz.iter_mut().enumerate() {
                    let token = tokens.next().ok_or_else(|| {
                        InputError::new(
                            path,
                            Location::Line(n),
                            format!("vertex has {axis} coordinates; it needs x, y and z"),
                            "write 'vertex x y z'",
                        )
                    })?;
                    *slot = parse_coordinate(path, n, token, "vertex")?;
                }
                facet.push(DVec3::from_array(xyz));
            }
            Some("endfacet") => {
                if facet.len() != 3 {
                    return Err(InputError::new(
                        path,
                        Location::Line(facet_line),
                        format!(
                            "facet has {} vertices; STL facets are triangles",
                            facet.len()
                        ),
                        "the file is malformed; export it again",
                    ));
                }
                corners.extend_from_slice(&facet);
                locations.push(facet_line);
                in_facet = false;
            }
            _ => {}
        }
    }
    if in_facet {
        return Err(InputError::new(
            path,
            Location::Line(facet_line),
            "the file ends inside a facet",
            "the file may be truncated; export it again",
        ));
    }
    Ok((corners, locations, false))
}
