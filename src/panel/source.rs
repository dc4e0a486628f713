//! Where a panel comes from: the printed names of panels and marks (a kind's letter and
//! a number) and what of the model a panel covers. Every scheme writes these; the map,
//! the labels and the manifest read them without knowing the scheme.

use glam::DVec3;

/// A kind of printed id: its letter, what the map legend says of it, and the manifest
/// fields of a panel so named. The kinds every scheme may use (faces, edges, vertices)
/// are defined here; a scheme that makes its own kind of panel or mark defines its own
/// as a `static` beside it, and labels, the map and the manifest read it as they read
/// these.
#[derive(Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct IdKind {
    /// Printed before the number (`F`, `E`); empty for a bare number.
    pub letter: &'static str,
    /// What the map legend says an id of this kind is ("edge panel").
    pub legend: &'static str,
    /// The manifest field of a panel's number (`face` in `"face": 12`).
    pub noun: &'static str,
    /// The manifest field of a panel's part number, for ids with one (`C3.2`).
    pub part_noun: &'static str,
    /// The manifest's `layer` of a panel so named (`outer`, `inner`), or empty.
    pub layer: &'static str,
}

/// Faces: `F12`, a face panel's id or a face mark.
pub static FACE: IdKind = IdKind {
    letter: "F",
    legend: "face (a face panel, or the mark of a face)",
    noun: "face",
    part_noun: "",
    layer: "",
};

/// Edges: `E123`, an edge panel's id.
pub static EDGE: IdKind = IdKind {
    letter: "E",
    legend: "edge panel",
    noun: "edge",
    part_noun: "",
    layer: "",
};

/// Vertices: `V7`, a corner mark.
pub static VERTEX: IdKind = IdKind {
    letter: "V",
    legend: "vertex mark",
    noun: "vertex",
    part_noun: "",
    layer: "",
};

/// A printed name: a panel's id, or what a label says: a kind's letter, a number and,
/// for a part of a numbered whole, the part's number (`C3.2`). Kept as numbers and
/// printed on demand, so a million panels carry no strings.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Name {
    /// What it names.
    pub kind: &'static IdKind,
    /// Its number.
    pub number: u32,
    /// The part's number (from 1), or 0 for a name without one.
    pub part: u32,
}

impl Name {
    /// The name `number` of `kind`.
    pub const fn new(kind: &'static IdKind, number: u32) -> Name {
        Name {
            kind,
            number,
            part: 0,
        }
    }

    /// Part `part` (from 1) of `number` of `kind`.
    pub const fn with_part(kind: &'static IdKind, number: u32, part: u32) -> Name {
        Name { kind, number, part }
    }

    /// Face `k`: `F12`.
    pub const fn face(k: u32) -> Name {
        Name::new(&FACE, k)
    }

    /// Edge `k`: `E123`.
    pub const fn edge(k: u32) -> Name {
        Name::new(&EDGE, k)
    }

    /// Vertex `k`: `V7`.
    pub const fn vertex(k: u32) -> Name {
        Name::new(&VERTEX, k)
    }
}

impl std::fmt::Display for Name {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}{}", self.kind.letter, self.number)?;
        if self.part > 0 {
            write!(f, ".{}", self.part)?;
        }
        Ok(())
    }
}

/// What of the model a panel covers: the map draws it there and writes the panel's id
/// at its anchor, and the manifest lists the mesh elements.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Covers {
    /// One face, whole; the id at its centre.
    Face(u32),
    /// One edge: the two triangles between the edge and the centres of its faces (the
    /// edge panels of a face share it like the slices of a cake); the id at the edge's
    /// midpoint.
    Edge(u32),
    /// A group of faces, entry k of the scheme output's `face_groups`; the id at the
    /// group's anchor.
    Faces(u32),
    /// The panel's own facets, which lie over the surface (a ribbon); the id at the
    /// centre of its middle facet.
    Itself,
    /// No surface: a part inside the model at an edge (a bracket), which the map leaves
    /// out; its id names the edge.
    Inside(u32),
}

/// The faces a panel covers when it covers a group of them ([`Covers::Faces`]), and
/// where the map shows its id: the scheme's choice (for example
/// [`surface::group_anchor`](super::surface::group_anchor)).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FaceGroup {
    /// The mesh faces, in increasing order.
    pub faces: Vec<u32>,
    /// Where its id shows on the map (mm).
    pub anchor: DVec3,
}

/// Where a panel comes from: its printed id and what of the model it covers. A scheme
/// writes it; flattening, the map and the manifest read it without knowing the scheme.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Source {
    /// The id printed for users.
    pub id: Name,
    /// What of the model it covers.
    pub covers: Covers,
}

impl Source {
    /// The panel of face `f`, named `F<f>`.
    pub const fn face(f: u32) -> Source {
        Source {
            id: Name::face(f),
            covers: Covers::Face(f),
        }
    }

    /// The panel of edge `e`, named `E<e>`.
    pub const fn edge(e: u32) -> Source {
        Source {
            id: Name::edge(e),
            covers: Covers::Edge(e),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_print_as_the_ids_users_read() {
        assert_eq!(Name::face(12).to_string(), "F12");
        assert_eq!(Name::edge(123).to_string(), "E123");
        assert_eq!(Name::vertex(7).to_string(), "V7");
        static CYCLE: IdKind = IdKind {
            letter: "C",
            legend: "cycle",
            noun: "cycle",
            part_noun: "segment",
            layer: "",
        };
        assert_eq!(Name::new(&CYCLE, 3).to_string(), "C3");
        assert_eq!(Name::with_part(&CYCLE, 3, 2).to_string(), "C3.2");
        static BARE: IdKind = IdKind {
            letter: "",
            legend: "match number",
            noun: "match",
            part_noun: "",
            layer: "",
        };
        assert_eq!(Name::new(&BARE, 17).to_string(), "17");
        assert_eq!(Source::edge(5).id.to_string(), "E5");
        assert_eq!(Source::face(5).covers, Covers::Face(5));
    }
}
