//! `unfold inspect`: a model's topology, geometry and every repair the build would make,
//! as text or JSON.

use std::fmt::Write;
use std::path::Path;

use serde::Serialize;

use crate::config::{ModelSettings, NonPlanar};
use crate::error::Result;
use crate::load::load_model;
use crate::mesh::read::Group;
use crate::mesh::{self, GeometryFacts, Note, SoupFacts, Topology};
use crate::scheme::Registry;
use crate::{run, units};

/// The physical size a model will be built at.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PhysicalSize {
    /// Millimetres per model unit.
    pub mm_per_unit: f64,
    /// Bounding-box sides in mm.
    pub size_mm: [f64; 3],
    /// Surface area in mm².
    pub surface_area_mm2: f64,
}

/// What `unfold inspect` reports about a model.
#[derive(Clone, Debug, Serialize)]
pub struct Inspection {
    /// The model file as given on the command line.
    pub path: String,
    /// Its format.
    pub format: mesh::Format,
    /// Facts of the file as it is (no repair).
    pub input: SoupFacts,
    /// Facts of the welded soup, with `--weld`.
    pub welded: Option<SoupFacts>,
    /// Facts of the prepared half-edge mesh.
    pub mesh: Topology,
    /// Geometry in model units.
    pub geometry: GeometryFacts,
    /// Size when built.
    pub physical: PhysicalSize,
    /// Named groups (OBJ `o`/`g`).
    pub groups: Vec<Group>,
    /// Statements read but not used, with counts.
    pub ignored: Vec<(String, usize)>,
    /// Repairs and observations.
    pub notes: Vec<Note>,
    /// The faces each registered scheme would split before building panels (after
    /// planarization, with `--nonplanar planarize`), in the registry's order.
    pub preparation: Vec<Preparation>,
    /// The non-planar face policy the preview assumes.
    pub nonplanar: NonPlanar,
    /// What `--nonplanar planarize` would do (displacement in mm, as built).
    pub planarized: Option<mesh::planarize::PlanarizeReport>,
}

/// What preparation would do before one scheme builds its panels.
#[derive(Clone, Debug, Serialize)]
pub struct Preparation {
    /// The scheme's name.
    pub scheme: &'static str,
    /// The faces it needs: `convex`, or `star-shaped` from their centre.
    pub faces: &'static str,
    /// Faces split into triangles as non-planar.
    pub non_planar: usize,
    /// Faces split into triangles as not of the shape it needs.
    pub misshapen: usize,
}

/// Reads, checks and measures a model, and previews what preparation would do with
/// non-planar faces under `nonplanar` (planarization is run, on a copy scaled as the
/// build scales it). Errors if it cannot be built at all.
pub fn inspect(
    path: &Path,
    settings: &ModelSettings,
    nonplanar: NonPlanar,
    registry: &Registry,
) -> Result<Inspection> {
    let (raw, prepared) = load_model(path, settings)?;
    let geometry = prepared.mesh.geometry_facts(settings.planarity_tol);
    let mm = settings.checked_mm_per_unit(path, geometry.longest_side())?;
    let size_mm = [0, 1, 2].map(|k| (geometry.bbox_max[k] - geometry.bbox_min[k]) * mm);
    let mut notes = prepared.notes.clone();
    let mut planarized = None;
    let mut mesh = std::borrow::Cow::Borrowed(&prepared.mesh);
    if nonplanar == NonPlanar::Planarize && geometry.non_planar_faces > 0 {
        let mut built = prepared.mesh.clone();
        built.scale(mm);
        planarized = Some(run::planarize_faces(
            path,
            &mut built,
            settings.planarity_tol,
        )?);
        mesh = std::borrow::Cow::Owned(built);
    }
    if geometry.non_planar_faces > 0 {
        let policy = match nonplanar {
            NonPlanar::Triangulate => "they will be triangulated when panels are built",
            NonPlanar::Planarize => {
                "--nonplanar planarize moves vertices to make them planar (see the planarize line)"
            }
            NonPlanar::Error => "with --nonplanar error the build refuses this model",
        };
        notes.push(Note {
            kind: "non-planar-faces",
            message: format!(
                "{} faces are not planar within {} of their size (worst: face {} at {:.2e}); {policy}",
                geometry.non_planar_faces,
                settings.planarity_tol,
                geometry
                    .least_planar_face
                    .map(|f| prepared.mesh.face_source(mesh::FaceId(f)))
                    .unwrap_or(0),
                geometry.max_planarity_error
            ),
        });
    }
    let preparation = registry
        .schemes()
        .iter()
        .map(|scheme| {
            let convex = scheme.info().needs_convex_faces;
            let r = mesh::split::faces_to_split(&mesh, settings.planarity_tol, convex);
            Preparation {
                scheme: scheme.name(),
                faces: if convex { "convex" } else { "star-shaped" },
                non_planar: r.non_planar.len(),
                misshapen: r.not_star_shaped.len(),
            }
        })
        .collect();
    Ok(Inspection {
        preparation,
        path: path.display().to_string(),
        format: raw.format,
        input: prepared.input.clone(),
        welded: prepared.welded.clone(),
        mesh: mesh.topology(),
        physical: PhysicalSize {
            mm_per_unit: mm,
            size_mm,
            surface_area_mm2: geometry.surface_area * mm * mm,
        },
        geometry,
        groups: raw.groups.clone(),
        ignored: raw.ignored.clone(),
        notes,
        nonplanar,
        planarized,
    })
}

impl Inspection {
    /// The human-readable report.
    pub fn to_text(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(s, "{} ({:?})", self.path, self.format);
        self.write_input(&mut s);
        self.write_topology(&mut s);
        self.write_geometry(&mut s);
        self.write_preparation(&mut s);
        s
    }

    /// Writes the counts of the file as it is and, with `--weld`, of the welded soup.
    fn write_input(&self, s: &mut String) {
        let i = &self.input;
        let _ = writeln!(
            s,
            "input:       vertices {}  edges {}  faces {}  boundary edges {}  euler {}",
            i.vertices, i.edges, i.faces, i.boundary_edges, i.euler_characteristic
        );
        if i.vertices_in_file != i.vertices {
            let _ = writeln!(
                s,
                "             {} vertices in the file, {} used by no face",
                i.vertices_in_file,
                i.vertices_in_file - i.vertices
            );
        }
        let _ = writeln!(
            s,
            "             non-manifold edges {}  bow-tie vertices {}  misoriented edges {}",
            i.non_manifold_edges, i.non_manifold_vertices, i.misoriented_edges
        );
        if let Some(w) = &self.welded {
            let _ = writeln!(
                s,
                "welded:      vertices {}  edges {}  faces {}  boundary edges {}  euler {}",
                w.vertices, w.edges, w.faces, w.boundary_edges, w.euler_characteristic
            );
        }
    }

    /// Writes the prepared mesh's counts, topology and first ten components.
    fn write_topology(&self, s: &mut String) {
        let m = &self.mesh;
        let _ = writeln!(
            s,
            "mesh:        vertices {}  edges {}  faces {}  boundary edges {}  boundary loops {}",
            m.vertices, m.edges, m.faces, m.boundary_edges, m.boundary_loops
        );
        let _ = writeln!(
            s,
            "topology:    genus {}  euler {}  components {}",
            m.genus,
            m.euler_characteristic,
            m.components.len()
        );
        for (k, c) in m.components.iter().enumerate().take(10) {
            let _ = writeln!(
                s,
                "             component {}: vertices {} edges {} faces {}, {}, genus {}",
                k + 1,
                c.vertices,
                c.edges,
                c.faces,
                if c.closed {
                    "closed".to_string()
                } else {
                    format!("{} boundary loops", c.boundary_loops)
                },
                c.genus
            );
        }
        if m.components.len() > 10 {
            let _ = writeln!(
                s,
                "             … and {} more components",
                m.components.len() - 10
            );
        }
    }

    /// Writes face sizes, the size and area in model units and as built, planarity and
    /// what planarization would do.
    fn write_geometry(&self, s: &mut String) {
        let g = &self.geometry;
        let sizes: Vec<String> = self
            .mesh
            .face_sizes
            .iter()
            .map(|(n, count)| format!("{n}-gons {count}"))
            .collect();
        let _ = writeln!(s, "face sizes:  {}", sizes.join("  "));
        let size = [0, 1, 2].map(|k| g.bbox_max[k] - g.bbox_min[k]);
        let _ = writeln!(
            s,
            "size:        {} x {} x {} model units; built: {} x {} x {} mm ({} mm per unit)",
            units::fmt_num(size[0]),
            units::fmt_num(size[1]),
            units::fmt_num(size[2]),
            units::fmt_num(self.physical.size_mm[0]),
            units::fmt_num(self.physical.size_mm[1]),
            units::fmt_num(self.physical.size_mm[2]),
            units::fmt_num(self.physical.mm_per_unit)
        );
        let _ = writeln!(
            s,
            "area:        {} square model units; built: {} m²",
            units::fmt_num(g.surface_area),
            units::fmt_num(self.physical.surface_area_mm2 / 1e6)
        );
        let _ = writeln!(
            s,
            "planarity:   max error {:.3e}; {} faces above {}",
            g.max_planarity_error, g.non_planar_faces, g.planarity_tolerance
        );
        if let Some(r) = &self.planarized {
            let _ = writeln!(
                s,
                "planarize:   {} of {} faces with four or more corners over the tolerance -> {}; max error {:.3e} -> {:.3e} in {} iterations; largest vertex move {} mm built ({} model units)",
                r.non_planar_before,
                r.polygons,
                r.non_planar_after,
                r.max_error_before,
                r.max_error_after,
                r.iterations,
                units::short_number(r.max_displacement),
                units::short_number(r.max_displacement / self.physical.mm_per_unit)
            );
        }
    }

    /// Writes the faces each scheme would split, the groups, the ignored statements and
    /// the notes.
    fn write_preparation(&self, s: &mut String) {
        let splits: Vec<String> = self
            .preparation
            .iter()
            .map(|p| {
                format!(
                    "{} {} non-planar + {} not {}",
                    p.scheme, p.non_planar, p.misshapen, p.faces
                )
            })
            .collect();
        let _ = writeln!(
            s,
            "preparation: faces split into triangles: {}",
            splits.join("; ")
        );
        if !self.groups.is_empty() {
            let names: Vec<&str> = self.groups.iter().map(|g| g.name.as_str()).collect();
            let _ = writeln!(s, "groups:      {}", names.join(", "));
        }
        if !self.ignored.is_empty() {
            let ignored: Vec<String> = self
                .ignored
                .iter()
                .map(|(k, n)| format!("{k} ×{n}"))
                .collect();
            let _ = writeln!(s, "ignored:     {}", ignored.join(", "));
        }
        if self.notes.is_empty() {
            let _ = writeln!(s, "notes:       none; the mesh is clean");
        } else {
            let _ = writeln!(s, "notes:");
            for note in &self.notes {
                let _ = writeln!(s, "  - {}", note.message);
            }
        }
    }
}
