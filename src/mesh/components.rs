//! Removing small connected components (`--min-component N`): scans come with stray
//! fragments, and a loose part of a few faces is not worth cutting.

use super::build::{build_mesh, BuildError};
use super::{Mesh, Polygons};

/// What [`drop_small_components`] removed.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DroppedComponents {
    /// Face counts of the removed components, largest first.
    pub sizes: Vec<usize>,
    /// Components kept.
    pub kept: usize,
}

/// What `--min-component` does to a mesh.
#[derive(Clone, Debug)]
pub enum SmallComponents {
    /// Every component is large enough: the mesh stays as it is.
    NoneSmall,
    /// The mesh without the small components.
    Dropped(Box<Mesh>, DroppedComponents),
    /// Every component is small: nothing would be left.
    AllSmall {
        /// Faces of the largest component.
        largest: usize,
    },
}

/// Removes the components of fewer than `min_faces` faces. Vertices and faces keep
/// their sources (file numbering), so later messages still point at the user's lines.
pub fn drop_small_components(mesh: &Mesh, min_faces: usize) -> Result<SmallComponents, BuildError> {
    let (component_of_face, size) = component_sizes(mesh);
    let keep: Vec<bool> = size.iter().map(|&n| n >= min_faces).collect();
    if keep.iter().all(|&k| k) {
        return Ok(SmallComponents::NoneSmall);
    }
    if !keep.iter().any(|&k| k) {
        return Ok(SmallComponents::AllSmall {
            largest: size.into_iter().max().unwrap_or(0),
        });
    }
    let mut new_index = vec![u32::MAX; mesh.vertex_count()];
    let mut polys = Polygons::new();
    let mut vertex_source = Vec::new();
    let mut face_source = Vec::new();
    for f in mesh.faces() {
        if !keep[component_of_face[f.index()] as usize] {
            continue;
        }
        let corners: Vec<u32> = mesh
            .face_vertices(f)
            .map(|v| {
                if new_index[v.index()] == u32::MAX {
                    new_index[v.index()] = polys.positions.len() as u32;
                    polys.positions.push(mesh.position(v));
                    vertex_source.push(mesh.vertex_source(v));
                }
                new_index[v.index()]
            })
            .collect();
        polys.push_face(&corners);
        face_source.push(mesh.face_source(f));
    }
    let (kept_mesh, _) = build_mesh(&polys, Some(&vertex_source), Some(&face_source))?;
    let mut sizes: Vec<usize> = size
        .iter()
        .zip(&keep)
        .filter(|(_, &k)| !k)
        .map(|(&n, _)| n)
        .collect();
    sizes.sort_unstable_by(|a, b| b.cmp(a));
    Ok(SmallComponents::Dropped(
        Box::new(kept_mesh),
        DroppedComponents {
            sizes,
            kept: keep.iter().filter(|&&k| k).count(),
        },
    ))
}

/// The component of every face and the face count of every component.
fn component_sizes(mesh: &Mesh) -> (Vec<u32>, Vec<usize>) {
    let (component_of_face, count) = mesh.face_components();
    let mut size = vec![0usize; count];
    for &c in &component_of_face {
        size[c as usize] += 1;
    }
    (component_of_face, size)
}
