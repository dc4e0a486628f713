//! The half-edge mesh core: handles, navigation, building from polygons, validation,
//! repair, topology and geometry facts, and the model readers.
//!
//! Every scheme is written against [`Mesh`]; quad-edge, winged-edge and the extended
//! graph rotation system are views of it, not separate structures.

pub mod build;
pub mod components;
pub mod coplanar;
pub mod decimate;
pub mod distance;
pub mod geometry;
pub mod halfedge;
pub mod holes;
pub mod ids;
pub mod planarize;
pub mod polygons;
pub mod prepare;
pub mod read;
pub mod relax;
pub mod simplify;
pub mod soup;
pub mod split;
pub mod topology;
pub mod validate;
pub mod weld;

pub use build::{build_from_faces, build_mesh, BuildError, BuildReport};
pub use halfedge::Mesh;
pub use ids::{EdgeId, FaceId, HalfedgeId, VertexId};
pub use polygons::Polygons;
pub use prepare::{prepare, Note, PrepareOptions, PreparedModel};
pub use read::{parse_model, read_model, Format, RawModel};
pub use soup::SoupFacts;
pub use topology::{ComponentFacts, GeometryFacts, Topology};
pub use validate::ConnectivityError;
