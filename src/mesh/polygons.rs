//! A polygon soup: positions plus faces as index lists, the form every reader produces
//! and every repair step works on before the half-edge mesh is built.

use glam::DVec3;

/// Faces stored flat: face `f` has corners `indices[offsets[f]..offsets[f + 1]]`.
/// Flat storage keeps a million-face mesh in two allocations instead of a million.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Polygons {
    /// Vertex positions, in model units.
    pub positions: Vec<DVec3>,
    /// Start of each face in `indices`, plus a final entry equal to `indices.len()`.
    pub offsets: Vec<u32>,
    /// Vertex indices (0-based) of all faces, one run per face.
    pub indices: Vec<u32>,
}

impl Polygons {
    /// An empty soup.
    pub fn new() -> Self {
        Self {
            positions: Vec::new(),
            offsets: vec![0],
            indices: Vec::new(),
        }
    }

    /// A soup from positions and faces given as index lists (convenient in tests).
    pub fn from_faces<F: AsRef<[u32]>>(positions: Vec<DVec3>, faces: &[F]) -> Self {
        let mut soup = Self {
            positions,
            ..Self::new()
        };
        for face in faces {
            soup.push_face(face.as_ref());
        }
        soup
    }

    /// Appends a face.
    pub fn push_face(&mut self, corners: &[u32]) {
        self.indices.extend_from_slice(corners);
        self.offsets.push(self.indices.len() as u32);
    }

    /// Number of faces.
    pub fn face_count(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    /// The corners of face `f`.
    pub fn face(&self, f: usize) -> &[u32] {
        &self.indices[self.offsets[f] as usize..self.offsets[f + 1] as usize]
    }

    /// Iterates over all faces in order.
    pub fn faces(&self) -> impl Iterator<Item = &[u32]> + '_ {
        (0..self.face_count()).map(move |f| self.face(f))
    }

    /// Reverses the corner order of face `f` (flips its orientation) in place.
    pub fn flip_face(&mut self, f: usize) {
        let (a, b) = (self.offsets[f] as usize, self.offsets[f + 1] as usize);
        self.indices[a..b].reverse();
    }
}
