//! The assembly map read back as a builder uses it: its views, each with the
//! projection written on its group, and the panel ids written in them; a ray cast into
//! the model at a page point names the face seen there.

use glam::{DVec2, DVec3};
use unfold::mesh::{FaceId, Mesh};

/// One view of the map: its projection and the ids written in it.
pub struct MapView {
    pub name: String,
    pub toward: DVec3,
    pub up: DVec3,
    pub scale: f64,
    pub origin: DVec2,
    /// A close-up's cut: the depth along `toward` beyond which the model is cut away.
    pub cut: Option<f64>,
    pub ids: Vec<(String, DVec2)>,
}

/// Every page of the map a build wrote (`NAME-map.svg`, then `NAME-map-2.svg`…), in
/// page order, from the manifest's list of files.
pub fn map_pages(out: &std::path::Path, files: &[&str]) -> Vec<String> {
    let stem = super::build::model_stem(files);
    let mut names: Vec<(usize, &str)> = files
        .iter()
        .filter_map(|n| super::build::map_page_number(&stem, n).map(|k| (k, *n)))
        .collect();
    names.sort();
    let names: Vec<&str> = names.into_iter().map(|(_, n)| n).collect();
    names
        .into_iter()
        .map(|n| std::fs::read_to_string(out.join(n)).unwrap())
        .collect()
}

pub fn attribute<'a>(tag: &'a str, name: &str) -> &'a str {
    let key = format!(" {name}=\"");
    let start = tag
        .find(&key)
        .unwrap_or_else(|| panic!("{name} missing in {tag}"))
        + key.len();
    let end = tag[start..].find('"').unwrap() + start;
    &tag[start..end]
}

pub fn numbers(text: &str) -> Vec<f64> {
    text.split_whitespace()
        .map(|n| n.parse().unwrap_or_else(|_| panic!("number {n}")))
        .collect()
}

pub fn vector(text: &str) -> DVec3 {
    let n = numbers(text);
    DVec3::new(n[0], n[1], n[2])
}

/// The views of a map and the panel ids in each (the `<text>`s centred on a point).
pub fn read_map(svg: &str) -> Vec<MapView> {
    let mut views = Vec::new();
    for chunk in svg.split("<g id=\"view-").skip(1) {
        let head_end = chunk.find('>').unwrap();
        let head = &chunk[..head_end];
        let body = &chunk[head_end..chunk.find("</g>").unwrap()];
        let origin = numbers(attribute(head, "data-origin"));
        let mut ids = Vec::new();
        for text in body.split("<text").skip(1) {
            let tag_end = text.find('>').unwrap();
            let tag = &text[..tag_end];
            if !tag.contains("text-anchor=\"middle\"") {
                continue;
            }
            let content = &text[tag_end + 1..text.find("</text>").unwrap()];
            let at = DVec2::new(
                attribute(tag, "x").parse().unwrap(),
                attribute(tag, "y").parse().unwrap(),
            );
            ids.push((content.to_string(), at));
        }
        views.push(MapView {
            name: attribute(head, "data-view").to_string(),
            toward: vector(attribute(head, "data-toward")),
            up: vector(attribute(head, "data-up")),
            scale: attribute(head, "data-scale").parse().unwrap(),
            origin: DVec2::new(origin[0], origin[1]),
            cut: head
                .contains(" data-cut=\"")
                .then(|| attribute(head, "data-cut").parse().unwrap()),
            ids,
        });
    }
    views
}

/// The face a ray from the viewer meets first, cast at a page point of a view; in a
/// close-up cut open, from the cut on, and none where it meets the back of a closed
/// model's face first (its inside, which names no panel).
pub fn face_seen(mesh: &Mesh, view: &MapView, at: DVec2) -> Option<u32> {
    let right = (-view.toward).cross(view.up);
    let u = (at.x - view.origin.x) / view.scale;
    let v = -(at.y - view.origin.y) / view.scale;
    let start = u * right + v * view.up + view.cut.unwrap_or(1e7) * view.toward;
    let dir = -view.toward;
    let mut best: Option<(f64, u32)> = None;
    for f in mesh.faces() {
        let pts: Vec<DVec3> = mesh.face_positions(f).collect();
        for k in 1..pts.len() - 1 {
            if let Some(t) = ray_triangle(start, dir, pts[0], pts[k], pts[k + 1]) {
                if best.is_none_or(|(b, _)| t < b) {
                    best = Some((t, f.0));
                }
            }
        }
    }
    let closed = mesh.edges().all(|e| !mesh.is_boundary_edge(e));
    best.map(|(_, f)| f).filter(|&f| {
        !(view.cut.is_some() && closed && mesh.face_normal(FaceId(f)).dot(view.toward) <= 1e-9)
    })
}

/// Möller–Trumbore: the distance along the ray to the triangle, if it meets it.
pub fn ray_triangle(o: DVec3, d: DVec3, a: DVec3, b: DVec3, c: DVec3) -> Option<f64> {
    let (e1, e2) = (b - a, c - a);
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-12 {
        return None;
    }
    let s = o - a;
    let u = s.dot(p) / det;
    let q = s.cross(e1);
    let v = d.dot(q) / det;
    if u < 0.0 || v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = e2.dot(q) / det;
    (t > 0.0).then_some(t)
}

impl MapView {
    /// Where a model point shows on the page in this view.
    pub fn page_point(&self, p: DVec3) -> DVec2 {
        let right = (-self.toward).cross(self.up);
        self.origin + self.scale * DVec2::new(p.dot(right), -p.dot(self.up))
    }
}
