//! The strips welded into one surface, the mesh the net scheme grows the pieces on,
//! and the pieces' names along their strips.

use std::collections::{BTreeMap, HashMap};

use glam::DVec3;

use super::band::Strip;
use super::distance::has_area;
use crate::mesh::{EdgeId, FaceId, Mesh};
use crate::panel::{IdKind, Name};

/// Strip pieces: `S3.2`, piece 2 of strip 3; `S3` for a strip in one piece.
pub static STRIP: IdKind = IdKind {
    letter: "S",
    legend: "strip piece (strip.piece)",
    noun: "strip",
    part_noun: "piece",
    layer: "",
};

/// The strips as one surface: a vertex per point they share (their curves' samples
/// are the same points on both sides), a face per triangle, strip after strip.
pub(super) struct Welded {
    pub(super) mesh: Mesh,
    /// The strip (from 0, counting strips with triangles) of each face.
    pub(super) strip_of_face: Vec<u32>,
    /// The rungs between each strip's consecutive triangles, strip after strip.
    folds: Vec<EdgeId>,
    /// How many strips have triangles.
    pub(super) strips: u32,
}

impl Welded {
    pub(super) fn new(strips: &[Strip]) -> Result<Welded, String> {
        let mut vertex: HashMap<[u64; 3], u32> = HashMap::new();
        let mut positions = Vec::new();
        let mut faces: Vec<[u32; 3]> = Vec::new();
        let mut strip_of_face = Vec::new();
        let mut count = 0;
        for strip in strips.iter().filter(|s| !s.triangles.is_empty()) {
            let ids: Vec<u32> = strip
                .points
                .iter()
                .map(|p| {
                    *vertex
                        .entry(p.to_array().map(f64::to_bits))
                        .or_insert_with(|| {
                            positions.push(*p);
                            positions.len() as u32 - 1
                        })
                })
                .collect();
            for t in &strip.triangles {
                // A triangle whose corners weld together or lie on a line (where two
                // curves touch) covers nothing; its strip goes on from the next one.
                if !has_area(t.map(|i| strip.points[i as usize])) {
                    continue;
                }
                faces.push(t.map(|i| ids[i as usize]));
                strip_of_face.push(count);
            }
            count += 1;
        }
        let mesh = crate::mesh::build::build_from_faces(positions, &faces).map_err(|e| {
            format!(
                "the strips do not join into one surface ({e}): a different --max-deviation may join them, or use --scheme net"
            )
        })?;
        let mut folds = Vec::new();
        for f in 1..faces.len() {
            if strip_of_face[f] != strip_of_face[f - 1] {
                continue;
            }
            folds.extend(shared_edge(&mesh, FaceId(f as u32 - 1), FaceId(f as u32)));
        }
        Ok(Welded {
            mesh,
            strip_of_face,
            folds,
            strips: count,
        })
    }

    /// The folds of the strips, less the rungs that cut each strip longer than
    /// `length` (along its faces' centres) into equal pieces no longer: a long ring
    /// unrolls into an arc that nests as badly as it is long.
    pub(super) fn shorter_than(&self, length: f64) -> Vec<EdgeId> {
        if !length.is_finite() {
            return self.folds.clone();
        }
        // The middle of the rung between faces f - 1 and f (or of face f's corners).
        let centre = |f: usize| {
            let rung = (f > 0)
                .then(|| shared_edge(&self.mesh, FaceId(f as u32 - 1), FaceId(f as u32)))
                .flatten();
            match rung {
                Some(e) => {
                    let (a, b) = self.mesh.edge_vertices(e);
                    0.5 * (self.mesh.position(a) + self.mesh.position(b))
                }
                None => self.mesh.face_positions(FaceId(f as u32)).sum::<DVec3>() / 3.0,
            }
        };
        let mut cuts = std::collections::BTreeSet::new();
        let mut start = 0;
        while start < self.strip_of_face.len() {
            let strip = self.strip_of_face[start];
            let end = (start..self.strip_of_face.len())
                .find(|&f| self.strip_of_face[f] != strip)
                .unwrap_or(self.strip_of_face.len());
            let mut along = vec![0.0];
            for f in start + 1..end {
                along.push(along[along.len() - 1] + centre(f - 1).distance(centre(f)));
            }
            let total = along[along.len() - 1];
            let pieces = (total / length).ceil() as usize;
            for k in 1..pieces {
                let target = total * k as f64 / pieces as f64;
                let f = start + along.partition_point(|&a| a < target).max(1);
                if let Some(e) = shared_edge(&self.mesh, FaceId(f as u32 - 1), FaceId(f as u32)) {
                    cuts.insert(e);
                }
            }
            start = end;
        }
        self.folds
            .iter()
            .copied()
            .filter(|e| !cuts.contains(e))
            .collect()
    }

    /// The strip most of `faces` lie on (the lower on a tie): a piece with no room
    /// for its id that was joined to a neighbour goes by the neighbour's strip.
    fn strip_of(&self, faces: &[u32]) -> u32 {
        let mut counts: BTreeMap<u32, usize> = BTreeMap::new();
        for &f in faces {
            *counts.entry(self.strip_of_face[f as usize]).or_default() += 1;
        }
        let most = counts.values().copied().max().unwrap_or(0);
        counts
            .into_iter()
            .find_map(|(strip, n)| (n == most).then_some(strip))
            .unwrap_or(0)
    }

    /// The pieces' names: `S<strip>.<piece>` along each strip (in the order of each
    /// piece's lowest face on it), `S<strip>` for a strip in one piece.
    pub(super) fn names(&self, members: &[Vec<u32>]) -> Vec<Name> {
        let strips: Vec<u32> = members.iter().map(|faces| self.strip_of(faces)).collect();
        let first_on = |k: usize| {
            members[k]
                .iter()
                .copied()
                .find(|&f| self.strip_of_face[f as usize] == strips[k])
        };
        let mut order: Vec<usize> = (0..members.len()).collect();
        order.sort_by_key(|&k| (strips[k], first_on(k)));
        let mut pieces = vec![0u32; self.strips as usize];
        for &s in &strips {
            pieces[s as usize] += 1;
        }
        let mut names = vec![Name::new(&STRIP, 0); members.len()];
        let mut seen = vec![0u32; self.strips as usize];
        for k in order {
            let s = strips[k] as usize;
            seen[s] += 1;
            names[k] = match pieces[s] {
                1 => Name::new(&STRIP, s as u32 + 1),
                _ => Name::with_part(&STRIP, s as u32 + 1, seen[s]),
            };
        }
        names
    }

    /// The faces of each piece that lie on another strip than the one it is named
    /// after (pieces with no room for their id, joined to it), as (piece, strip from
    /// 1, faces).
    pub(super) fn joined(&self, members: &[Vec<u32>]) -> Vec<(usize, u32, Vec<u32>)> {
        let mut joined = Vec::new();
        for (k, faces) in members.iter().enumerate() {
            let own = self.strip_of(faces);
            let mut others: BTreeMap<u32, Vec<u32>> = BTreeMap::new();
            for &f in faces {
                let strip = self.strip_of_face[f as usize];
                if strip != own {
                    others.entry(strip).or_default().push(f);
                }
            }
            joined.extend(others.into_iter().map(|(s, faces)| (k, s + 1, faces)));
        }
        joined
    }
}

/// The edge faces `a` and `b` share, if they are neighbours.
pub(super) fn shared_edge(mesh: &Mesh, a: FaceId, b: FaceId) -> Option<EdgeId> {
    mesh.face_half_edges(a)
        .find(|h| mesh.face(h.twin()) == Some(b))
        .map(|h| h.edge())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The band from height `y` to `y + 1`, from x = 0 to `length`, zigzagging along x with a rung
    /// at every unit: two triangles per unit.
    fn zigzag(length: u32, y: f64) -> Strip {
        let points = (0..=length)
            .flat_map(|i| {
                [
                    DVec3::new(i as f64, y, 0.0),
                    DVec3::new(i as f64, y + 1.0, 0.0),
                ]
            })
            .collect::<Vec<_>>();
        let triangles = (0..2 * length)
            .map(|i| match i % 2 {
                0 => [i, i + 2, i + 1],
                _ => [i, i + 1, i + 2],
            })
            .collect();
        Strip { points, triangles }
    }

    #[test]
    fn a_piece_goes_by_the_strip_most_of_it_lies_on() {
        // Two strips of six triangles each, side by side along y = 1: the band
        // 0 ≤ y ≤ 1 and the band 1 ≤ y ≤ 2, both zigzagging along x.
        let band = |y: f64| zigzag(3, y);
        let welded = Welded::new(&[band(0.0), band(1.0)]).expect("welded");
        assert_eq!(welded.strip_of_face, [0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1]);
        // A face of the first strip joined to a run of the second, after another run
        // of the second that comes first along it.
        let members = vec![vec![0, 8, 9, 10, 11], vec![1, 2, 3, 4, 5], vec![6, 7]];
        let names: Vec<String> = welded
            .names(&members)
            .iter()
            .map(|n| n.to_string())
            .collect();
        assert_eq!(names, ["S2.2", "S1", "S2.1"]);
        assert_eq!(welded.joined(&members), [(0, 1, vec![0])]);
    }

    #[test]
    fn a_long_strip_is_cut_into_equal_pieces_no_longer_than_asked() {
        // A band 1 wide and 100 long, a rung at every unit: 200 triangles, 199 folds.
        let welded = Welded::new(&[zigzag(100, 0.0)]).expect("welded");
        assert_eq!(welded.folds.len(), 199);
        assert_eq!(welded.shorter_than(f64::INFINITY), welded.folds);
        assert_eq!(welded.shorter_than(100.0), welded.folds);
        // 100 long in pieces of at most 30: four, cut near 25, 50 and 75.
        let folds = welded.shorter_than(30.0);
        let cut: Vec<EdgeId> = welded
            .folds
            .iter()
            .copied()
            .filter(|e| !folds.contains(e))
            .collect();
        assert_eq!(cut.len(), 3);
        let mut at: Vec<f64> = cut
            .iter()
            .map(|&e| {
                let (a, b) = welded.mesh.edge_vertices(e);
                0.5 * (welded.mesh.position(a).x + welded.mesh.position(b).x)
            })
            .collect();
        at.sort_by(f64::total_cmp);
        for (x, target) in at.iter().zip([25.0, 50.0, 75.0]) {
            assert!((x - target).abs() <= 1.0, "cut at {x}, not near {target}");
        }
    }
}
