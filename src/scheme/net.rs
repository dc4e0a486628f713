//! The net scheme: islands of many faces joined along folds, the way paper modellers
//! unfold a mesh. Every face is in one island; an edge inside an island is a fold and
//! every other interior edge a cut, glued by one tab. The island engine
//! ([`super::island`]) grows the islands and places the tabs; in rigid sheet each
//! island is a flat region of the model.

use glam::{DVec2, DVec3};

use super::island::{
    fits_sheet, grow_islands, island_net, FlatFoldArgs, IslandNames, IslandOptions, FLAT_FOLD_DEG,
    ISLAND,
};
use super::kit::tab::{tab_defaults, TabArgs, TAB_DEFAULTS};
use super::rigid::sheet::{
    rigid_defaults, rigid_output, Connectors, PanelNames, RigidArgs, RigidSheet,
};
use super::{args_of, Configured, Configuring, OptionValues, PanelOptions, SchemeInfo};
use super::{Scheme, SchemeError, SchemeOutput};
use crate::mesh::coplanar::{flat_regions, RegionRules};
use crate::mesh::{FaceId, Mesh};
use crate::option_default::{state_defaults, OptionDefault};
use crate::panel::surface::group_anchor;
use crate::panel::{Covers, FaceGroup, Name, Source};
use crate::plane::convex_hull;
use crate::record::{round4, Params};

/// The default `--island-spread`: islands whose convex hull is at most one and a half
/// times their area pack on fewer sheets than sprawling ones, at the cost of more
/// (smaller) islands.
pub const ISLAND_SPREAD: f64 = 1.5;

/// The net scheme: islands of faces joined along folds, glue tabs on the cuts.
pub struct Net;

/// The net scheme's options as given.
#[derive(Clone, Debug, Default, clap::Args)]
struct NetArgs {
    #[command(flatten)]
    tab: TabArgs,

    #[command(flatten)]
    rigid: RigidArgs,

    /// Most faces in one island (net scheme), for builders who want small pieces.
    #[arg(long, value_name = "N")]
    max_island_faces: Option<usize>,

    #[command(flatten)]
    flat_fold: FlatFoldArgs,

    /// Largest ratio of an island's convex hull to its area (net scheme, at least 1):
    /// smaller keeps islands compact so they pack on fewer sheets, larger makes fewer
    /// islands.
    #[arg(long, value_name = "R")]
    island_spread: Option<f64>,
}

/// The net scheme's options, resolved (lengths in mm).
#[derive(Clone, Debug, PartialEq)]
pub struct NetOptions {
    /// The tabs, the sheet and the folds, as the island engine takes them.
    pub islands: IslandOptions,
    /// Rigid sheet: above zero thickness nothing folds, and each island is a flat
    /// region of the model.
    pub rigid: RigidSheet,
}

const INFO: SchemeInfo = SchemeInfo {
    name: "net",
    about: "islands of many faces joined along folds, glue tabs on the cuts",
    defaults: TAB_DEFAULTS,
    // The overlap test separates convex polygons.
    needs_convex_faces: true,
    overlap_fix: "a smaller --island-spread or --max-island-faces (smaller islands)",
};

impl Scheme for Net {
    fn info(&self) -> &SchemeInfo {
        &INFO
    }

    fn options(&self) -> Vec<clap::Arg> {
        state_defaults(
            args_of::<NetArgs>(),
            &[
                tab_defaults(),
                OptionDefault::words("max-island-faces", "no limit"),
                OptionDefault::value("flat-fold", FLAT_FOLD_DEG),
                OptionDefault::value("island-spread", ISLAND_SPREAD),
            ]
            .into_iter()
            .chain(rigid_defaults())
            .collect::<Vec<_>>(),
        )
    }

    fn configure(&self, values: &OptionValues, panel: PanelOptions) -> Configuring {
        Ok(Box::new(resolve(values, panel)?))
    }
}

/// Checks the net options' `values` and fills in their defaults.
fn resolve(values: &OptionValues, panel: PanelOptions) -> Result<NetOptions, String> {
    let args: NetArgs = values.parse()?;
    if panel.face_scale != 1.0 {
        return Err(format!(
            "--face-scale: the net scheme keeps its faces whole (1), not {}; leave it out",
            panel.face_scale
        ));
    }
    if args.max_island_faces == Some(0) {
        return Err("--max-island-faces: an island holds at least 1 face".into());
    }
    let island_spread = args.island_spread.unwrap_or(ISLAND_SPREAD);
    if !(island_spread >= 1.0 && island_spread.is_finite()) {
        return Err(format!(
            "--island-spread: {island_spread} must be a number of at least 1 (a convex island has 1)"
        ));
    }
    let rigid = args.rigid.resolve(&panel)?;
    if rigid.connectors == Connectors::None && rigid.thickness == 0.0 {
        return Err("--connectors none: the net scheme glues its cuts with tabs in card; none is for rigid sheet (--thickness)".into());
    }
    if rigid.thickness > 0.0 && args.island_spread.is_some() {
        return Err("--island-spread: in rigid sheet (--thickness) nothing folds, so each island is a flat region of the model, whatever its shape; leave --island-spread out".into());
    }
    Ok(NetOptions {
        islands: IslandOptions {
            island_spread,
            panel,
            tab_height: args.tab.height()?,
            max_island_faces: args.max_island_faces,
            flat_fold: args.flat_fold.angle()?,
        },
        rigid,
    })
}

impl Configured for NetOptions {
    fn panel(&self) -> &PanelOptions {
        &self.islands.panel
    }

    fn build(&self, mesh: &Mesh) -> Result<SchemeOutput, SchemeError> {
        if self.rigid.thickness > 0.0 {
            rigid_panels(mesh, self)
        } else {
            Ok(panels(mesh, self))
        }
    }

    fn params(&self) -> Params {
        let mut params = Params::default();
        params.push("tab_height", round4(self.islands.tab_height));
        match self.islands.max_island_faces {
            Some(n) => params.push("max_island_faces", n),
            None => params.push("max_island_faces", "none"),
        }
        params.push("flat_fold_deg", round4(self.islands.flat_fold.to_degrees()));
        params.push("island_spread", self.islands.island_spread);
        params.push("connectors", self.rigid.connectors_name());
        self.rigid.sheet_params(&mut params);
        params
    }

    fn least_scored_fold(&self) -> f64 {
        self.islands.flat_fold
    }
}

/// Builds the islands of a mesh whose faces are planar and convex.
pub fn panels(mesh: &Mesh, options: &NetOptions) -> SchemeOutput {
    let (islands, order) = grow_islands(mesh, &options.islands);
    let net = island_net(
        mesh,
        &options.islands,
        islands,
        &order,
        &IslandNames::Numbered,
    );
    let mut output = net.output;
    output.report = net.summary.report("net", "islands");
    output.manifest.push("net", net.summary.section("islands"));
    output
}

/// How far (mm) a face's corners may lie off the plane of its flat region in rigid
/// sheet: the panel is flat, so this is how far it may stand off the model.
const FLAT_REGION_TOLERANCE: f64 = 0.005;

/// The net in rigid sheet: nothing folds, so each island is a flat region of the model
/// (neighbouring faces in one plane), cut back and held like the half-edge scheme's
/// faces.
fn rigid_panels(mesh: &Mesh, options: &NetOptions) -> Result<SchemeOutput, SchemeError> {
    let fits = |corners: &[DVec2]| {
        let hull = convex_hull(corners);
        fits_sheet(&hull, &options.islands, 0.0).then_some(hull)
    };
    let rules = RegionRules {
        tolerance: FLAT_REGION_TOLERANCE,
        max_faces: options.islands.max_island_faces.unwrap_or(usize::MAX),
        fits: &fits,
    };
    let regions = flat_regions(mesh, &rules).map_err(|e| {
        SchemeError::Model(format!(
            "the net scheme could not merge the model's flat regions ({e}); --scheme half-edge builds each face on its own"
        ))
    })?;
    let anchors: Vec<DVec3> = regions
        .faces
        .iter()
        .enumerate()
        .map(|(k, faces)| region_anchor(&regions.mesh, FaceId(k as u32), mesh, faces))
        .collect();
    let names = PanelNames {
        sources: (0..regions.faces.len() as u32)
            .map(|k| Source {
                id: Name::new(&ISLAND, k + 1),
                covers: Covers::Faces(k),
            })
            .collect(),
        anchors: anchors.iter().copied().map(Some).collect(),
        edge_numbers: regions.edge_source.clone(),
        noun: "island",
    };
    let mut output = rigid_output(
        &regions.mesh,
        mesh,
        &options.rigid,
        &options.islands.panel,
        &names,
    )?;
    let mut sizes: Vec<usize> = regions.faces.iter().map(Vec::len).collect();
    sizes.sort_unstable();
    let merged = regions.faces.iter().filter(|f| f.len() > 1).count();
    output.report.insert(
        0,
        format!(
            "net in rigid sheet: {} islands, each a flat region of the model ({} of several faces, largest {} faces)",
            regions.faces.len(),
            merged,
            sizes.last().copied().unwrap_or(0)
        ),
    );
    output.manifest.push(
        "net",
        serde_json::json!({
            "islands": regions.faces.len(),
            "largest_island_faces": sizes.last().copied().unwrap_or(0),
            "median_island_faces": sizes.get(sizes.len() / 2).copied().unwrap_or(0),
        }),
    );
    output.face_groups = regions
        .faces
        .into_iter()
        .zip(anchors)
        .map(|(faces, anchor)| FaceGroup { anchor, faces })
        .collect();
    Ok(output)
}

/// Where a flat region's id goes: the centroid of its polygon (face `k` of `merged`)
/// when that lies inside it, else the centre of its middle face.
fn region_anchor(merged: &Mesh, k: FaceId, mesh: &Mesh, faces: &[u32]) -> DVec3 {
    let corners: Vec<DVec3> = merged.face_positions(k).collect();
    let normal = merged.face_normal(k);
    let x = normal.any_orthonormal_vector();
    let y = normal.cross(x);
    let flat: Vec<DVec2> = corners
        .iter()
        .map(|&p| DVec2::new((p - corners[0]).dot(x), (p - corners[0]).dot(y)))
        .collect();
    let (mut weighted, mut total) = (DVec2::ZERO, 0.0);
    for i in 1..flat.len().saturating_sub(1) {
        let area = (flat[i] - flat[0]).perp_dot(flat[i + 1] - flat[0]);
        weighted += area * (flat[0] + flat[i] + flat[i + 1]) / 3.0;
        total += area;
    }
    let centroid = weighted / total;
    if total > 0.0 && crate::plane::contains(&flat, centroid) {
        corners[0] + centroid.x * x + centroid.y * y
    } else {
        group_anchor(mesh, faces)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    use crate::mesh::{build_from_faces, EdgeId};
    use crate::scheme::island::MATCH;

    /// Squares 40 mm on a side: room for a full 5 mm tab on every edge.
    const SIDE: f64 = 40.0;

    /// Net options: whole faces, no holes, 5 mm tabs, at most `max_island_faces` faces
    /// an island, folds under 1° unscored, the default spread, no sheet limit.
    fn options(max_island_faces: Option<usize>) -> NetOptions {
        NetOptions {
            islands: crate::scheme::island::test_options(max_island_faces, ISLAND_SPREAD),
            rigid: crate::scheme::rigid::sheet::RigidSheet::CARD,
        }
    }

    /// A closed cube of side [`SIDE`], faces bottom, top, front, back, left, right.
    fn cube() -> Mesh {
        crate::mesh::build::cube(SIDE)
    }

    /// Flat squares of side [`SIDE`] in z = 0, face k on cell `cells[k]` (column, row).
    fn squares(cells: &[(u32, u32)]) -> Mesh {
        let mut index: HashMap<(u32, u32), u32> = HashMap::new();
        let mut p = Vec::new();
        let mut corner = |c: u32, r: u32| {
            *index.entry((c, r)).or_insert_with(|| {
                p.push(SIDE * DVec3::new(f64::from(c), f64::from(r), 0.0));
                (p.len() - 1) as u32
            })
        };
        let faces: Vec<[u32; 4]> = cells
            .iter()
            .map(|&(c, r)| {
                [
                    corner(c, r),
                    corner(c + 1, r),
                    corner(c + 1, r + 1),
                    corner(c, r + 1),
                ]
            })
            .collect();
        build_from_faces(p, &faces).unwrap()
    }

    /// A flat grid of `cols` × `rows` squares, faces row by row.
    fn grid(cols: u32, rows: u32) -> Mesh {
        let cells: Vec<(u32, u32)> = (0..rows)
            .flat_map(|r| (0..cols).map(move |c| (c, r)))
            .collect();
        squares(&cells)
    }

    /// A flat L: faces 0 to 6 in a row along x, faces 7 to 15 in a column up from
    /// face 0.
    fn ell() -> Mesh {
        let cells: Vec<(u32, u32)> = (0..7)
            .map(|c| (c, 0))
            .chain((1..10).map(|r| (0, r)))
            .collect();
        squares(&cells)
    }

    /// Two squares side by side in z = 0 (faces 0 and 1, flat across edge 1) and a
    /// third standing up from face 1's far side (face 2, at 90° across edge 5).
    fn step() -> Mesh {
        let s = SIDE;
        let p = vec![
            DVec3::ZERO,
            DVec3::new(s, 0.0, 0.0),
            DVec3::new(2.0 * s, 0.0, 0.0),
            DVec3::new(0.0, s, 0.0),
            DVec3::new(s, s, 0.0),
            DVec3::new(2.0 * s, s, 0.0),
            DVec3::new(2.0 * s, 0.0, s),
            DVec3::new(2.0 * s, s, s),
        ];
        build_from_faces(p, &[[0u32, 1, 4, 3], [1, 2, 5, 4], [5, 2, 6, 7]]).unwrap()
    }

    /// The faces of each island of `out`.
    fn islands(out: &SchemeOutput) -> Vec<Vec<u32>> {
        out.face_groups.iter().map(|g| g.faces.clone()).collect()
    }

    /// Every match label: (match number, panel index).
    fn match_labels(out: &SchemeOutput) -> Vec<(u32, usize)> {
        let mut found = Vec::new();
        for (k, panel) in out.panels.iter().enumerate() {
            for label in panel.labels {
                if label.text.kind == &MATCH {
                    found.push((label.text.number, k));
                }
            }
        }
        found.sort_unstable();
        found
    }

    /// The interior edges whose faces lie in different islands of `out`.
    fn edges_between_islands(mesh: &Mesh, out: &SchemeOutput) -> usize {
        let mut island = vec![0usize; mesh.face_count()];
        for (k, faces) in islands(out).iter().enumerate() {
            for &f in faces {
                island[f as usize] = k + 1;
            }
        }
        mesh.edges()
            .filter_map(|e| Some((mesh.face(e.half_edge())?, mesh.face(e.half_edge().twin())?)))
            .filter(|(f, g)| island[f.index()] != island[g.index()])
            .count()
    }

    #[test]
    fn a_flat_grid_is_one_island_with_no_cut() {
        let out = panels(&grid(3, 3), &options(None));
        // Every edge is flat: all nine faces join, each interior edge a fold.
        assert_eq!(islands(&out), vec![(0..9).collect::<Vec<u32>>()]);
        assert_eq!((out.panels.len(), out.connections), (1, 0));
        assert_eq!(out.panels.get(0).id().to_string(), "N1");
        // 12 interior edges (2 rows of 3 plus 2 columns of 3), all folds; nothing to
        // score.
        assert_eq!(
            out.report,
            ["net: 1 islands (largest 9 faces, median 9); folds 0 mountain, 0 valley, 12 too flat to score, 480 mm in all; 0 cut edges, 0 mm in all, with 0 tabs"]
        );
    }

    #[test]
    fn the_flattest_edges_fold_first_and_the_sharp_one_is_cut() {
        let mesh = step();
        // With two faces an island, the flat edge 1 joins faces 0 and 1 before the
        // 90° edge 5 is looked at; edge 5 is cut.
        let out = panels(&mesh, &options(Some(2)));
        assert_eq!(islands(&out), vec![vec![0, 1], vec![2]]);
        assert_eq!(out.connections, 1);
        // Both sides of the cut carry match number 1: N1 on face 1, N2 on its tab.
        assert_eq!(match_labels(&out), [(1, 0), (1, 1)]);
        assert_eq!(out.panels.get(1).facets.len(), 2, "face 2 and its tab");
        // Without the cap the 90° edge folds too, as the join completes the part.
        let out = panels(&mesh, &options(None));
        assert_eq!(islands(&out), vec![vec![0, 1, 2]]);
        assert_eq!(out.connections, 0);
    }

    #[test]
    fn a_sprawling_join_waits_unless_it_completes_the_part() {
        let mesh = ell();
        // Edge ids follow the faces, so the row joins first, with face 7 (above face
        // 0): hull (0,0), (7,0), (7,1), (1,2), (0,2) in sides, area 11 over 8 faces,
        // 1.375 ≤ 1.5. Face 8 would make it (0,0), (7,0), (7,1), (1,3), (0,3), area 15
        // over 9 faces, 1.67 > 1.5: faces 8 to 15 grow a second island, and 8 + 8
        // faces pass the cap of 15.
        let out = panels(&mesh, &options(Some(15)));
        assert_eq!(
            islands(&out),
            vec![(0..8).collect::<Vec<u32>>(), (8..16).collect()]
        );
        assert_eq!(out.connections, 1);
        // Uncapped, joining the two makes the whole part one island: made whatever its
        // shape.
        let out = panels(&mesh, &options(None));
        assert_eq!(islands(&out), vec![(0..16).collect::<Vec<u32>>()]);
        assert_eq!(out.connections, 0);
    }

    #[test]
    fn the_island_cap_is_honoured_and_every_other_edge_is_cut() {
        let mesh = grid(3, 3);
        for cap in [1, 2, 3, 4] {
            let out = panels(&mesh, &options(Some(cap)));
            assert!(
                islands(&out).iter().all(|f| f.len() <= cap),
                "cap {cap}: {:?}",
                islands(&out)
            );
            let mut all: Vec<u32> = islands(&out).concat();
            all.sort_unstable();
            assert_eq!(all, (0..9).collect::<Vec<u32>>(), "cap {cap}");
            // At most `cap` faces each: at least ⌈9 / cap⌉ islands.
            assert!(islands(&out).len() >= 9usize.div_ceil(cap), "cap {cap}");
            assert_eq!(
                out.connections,
                edges_between_islands(&mesh, &out),
                "cap {cap}"
            );
        }
        // One face an island: every one of the 12 interior edges is a cut.
        let out = panels(&mesh, &options(Some(1)));
        assert_eq!((islands(&out).len(), out.connections), (9, 12));
    }

    #[test]
    fn islands_are_numbered_from_1_in_the_order_of_their_lowest_face() {
        let out = panels(&cube(), &options(Some(1)));
        // One face an island: face k is island k + 1.
        let expected: Vec<Vec<u32>> = (0..6).map(|f| vec![f]).collect();
        assert_eq!(islands(&out), expected);
        let ids: Vec<String> = out.panels.iter().map(|p| p.id().to_string()).collect();
        assert_eq!(ids, ["N1", "N2", "N3", "N4", "N5", "N6"]);
    }

    #[test]
    fn both_sides_of_every_cut_carry_its_match_number() {
        let mesh = cube();
        let out = panels(&mesh, &options(Some(1)));
        // All 12 edges are cuts, numbered 1 to 12 in edge order.
        assert_eq!(out.connections, 12);
        let found = match_labels(&out);
        assert_eq!(found.len(), 24);
        for m in 1..=12u32 {
            let e = EdgeId(m - 1);
            let h = e.half_edge();
            let sides = [mesh.face(h).unwrap().0, mesh.face(h.twin()).unwrap().0];
            // Panel k is face k's island: the label is on the two faces of edge m − 1.
            let mut on: Vec<u32> = found
                .iter()
                .filter(|(n, _)| *n == m)
                .map(|&(_, k)| k as u32)
                .collect();
            on.sort_unstable();
            let mut sides = sides.to_vec();
            sides.sort_unstable();
            assert_eq!(on, sides, "match {m}");
        }
        // The 12 tabs fit: a 40 mm face's centre is 20 mm from each edge.
        assert!(out.notes.is_empty(), "{:?}", out.notes);
    }

    #[test]
    fn a_closed_cube_unfolds_into_one_net_of_five_folds() {
        let out = panels(&cube(), &options(None));
        // A net of 6 faces is a tree: 5 of the 12 edges fold, 7 are cut.
        assert_eq!(islands(&out), vec![(0..6).collect::<Vec<u32>>()]);
        assert_eq!(out.connections, 7);
    }

    #[test]
    fn the_options_refuse_an_empty_island_and_shrunk_faces() {
        let panel = options(None).islands.panel;
        let mut values = OptionValues::default();
        values.set("max-island-faces", "0");
        let refused = resolve(&values, panel.clone()).unwrap_err();
        assert_eq!(
            refused,
            "--max-island-faces: an island holds at least 1 face"
        );
        values.set("max-island-faces", "7");
        let net = resolve(&values, panel.clone()).unwrap();
        assert_eq!(net.islands.max_island_faces, Some(7));
        let shrunk = PanelOptions {
            face_scale: 0.5,
            ..panel
        };
        assert!(resolve(&OptionValues::default(), shrunk)
            .unwrap_err()
            .starts_with("--face-scale: the net scheme keeps its faces whole"));
    }
}
