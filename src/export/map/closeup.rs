//! The assembly map's close-ups: where the overview's six views leave a panel unnamed
//! (its region too crowded for its id, or hidden from every side), the region around
//! it drawn larger, seen from square to the panel or as near to that as shows it, with
//! the model in front cut away where nothing else does; one close-up after another
//! until every panel is named.

use std::fmt::Write;

use glam::{DVec2, DVec3};

use super::draw::{draw_frame, Frame};
use super::layout::{text_lines, CloseUpCells, MapContext, CAPTION_TEXT, GAP};
use super::page::{fit, text_width};
use super::view::{project, views, View};
use crate::export::fmt_mm;
use crate::panel::surface::Patch;

/// The least a close-up enlarges on the overview.
const CLOSER: f64 = 1.25;

/// The most the first enlargement exceeds what the panel's room asks (a panel seen
/// nearly edge on would ask for far more).
const MOST_ENLARGED: f64 = 8.0;

/// Enlargements tried in turn when a panel's id finds no room at the first.
const ZOOMS: [f64; 4] = [1.0, 1.6, 2.6, 4.2];

/// Close-ups, each an SVG fragment in its cell of its page (`cells`), until every
/// panel is `named`: the first panel not named gets the next close-up, which names it
/// and every other it has room for.
pub(super) fn close_ups(map: &MapContext, cells: &CloseUpCells, named: &mut [bool]) -> Vec<String> {
    let mut drawn = Vec::new();
    for target in 0..named.len() {
        if named[target] {
            continue;
        }
        if let Some(svg) = close_up(map, cells, drawn.len(), target, named) {
            drawn.push(svg);
        }
    }
    drawn
}

/// Close-up `k` of the panel `target`: from the first side that shows it at the first
/// enlargement that gives its id room; `None` if none does.
fn close_up(
    map: &MapContext,
    cells: &CloseUpCells,
    k: usize,
    target: usize,
    named: &mut [bool],
) -> Option<String> {
    let patches = &map.input.surface.patches;
    let own: Vec<&Patch> = map.panel_patches[target]
        .iter()
        .map(|&i| &patches[i])
        .collect();
    let size = extent(own.iter().flat_map(|p| &p.points));
    // The id goes best at the middle of the patch with the most room round it.
    let id = map.input.panels.get(target).id().to_string();
    let diagonal = DVec2::new(text_width(&id, map.text), map.text).length();
    let (roomiest, room) = own
        .iter()
        .map(|p| (*p, room(p)))
        .max_by(|a, b| a.1.total_cmp(&b.1))?;
    let centre = roomiest.points.iter().sum::<DVec3>() / roomiest.points.len() as f64;
    // Seen square to it, its id fits about the middle from this scale on.
    let fits = (0.5 * diagonal + ROOM_SPARE) / room.max(1e-9);
    let normal = own
        .iter()
        .map(|p| area(p) * p.normal)
        .sum::<DVec3>()
        .try_normalize()
        .unwrap_or(roomiest.normal);
    // Square to the panel as a whole, or, where it folds so sharply that its parts are
    // seen edge on from there, square to its roomiest part.
    let sights = [
        Aim {
            map,
            target,
            centre,
            normal,
            size,
        }
        .sight(),
        cut_sight(&own, normal, size),
        cut_sight(&own, roomiest.normal, size),
    ];
    let model_front = |toward: DVec3| {
        patches
            .iter()
            .flat_map(|p| &p.points)
            .map(|q| q.dot(toward))
            .fold(f64::NEG_INFINITY, f64::max)
    };
    let mut tried: Vec<(DVec3, Option<f64>)> = Vec::new();
    for (toward, cut) in sights {
        // A cut in front of the whole model cuts nothing away.
        let cut = cut.filter(|&c| c < model_front(toward));
        if tried.contains(&(toward, cut)) {
            continue;
        }
        tried.push((toward, cut));
        let view = view_toward(toward);
        let first = first_scale(map, &own, &view, &id)
            .max(fits)
            .min(MOST_ENLARGED * fits.max(CLOSER * map.grid.scale));
        for zoom in ZOOMS {
            let shot = Shot {
                k,
                target,
                id: &id,
                view: &view,
                centre,
                scale: first * zoom,
                cut,
            };
            if let Some(svg) = shot.draw(map, cells, named) {
                return Some(svg);
            }
        }
    }
    None
}

/// One try at a close-up.
struct Shot<'a> {
    /// The close-up's number (from 0) over all pages.
    k: usize,
    target: usize,
    id: &'a str,
    view: &'a View,
    /// The model point at the middle of the drawing.
    centre: DVec3,
    /// Page mm per model mm.
    scale: f64,
    /// The depth along the view beyond which the model is cut away, if it is.
    cut: Option<f64>,
}

impl Shot<'_> {
    /// The close-up in its cell, if it names its panel; then `named` marks every panel
    /// it names.
    fn draw(&self, map: &MapContext, cells: &CloseUpCells, named: &mut [bool]) -> Option<String> {
        let corner = cells.corner(self.k);
        let caption = fit(
            &self.caption(),
            cells.cell.x - 4.0,
            CAPTION_TEXT[0],
            CAPTION_TEXT[1],
            2,
        );
        let top = caption.height() + GAP;
        let area = (
            corner + DVec2::new(GAP, top),
            cells.cell - DVec2::new(2.0 * GAP, top + GAP),
        );
        let middle = project(self.centre, self.view);
        let frame = Frame {
            view: self.view,
            origin: area.0 + 0.5 * area.1 - self.scale * DVec2::new(middle.x, -middle.y),
            scale: self.scale,
            area,
            contain: true,
            cut_open: self.cut.is_some(),
        };
        let patches = self.patches(map, &frame);
        let mut trial = named.to_vec();
        let mut out = String::new();
        let number = self.k + 1;
        let rect = format!(
            "x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\"",
            fmt_mm(area.0.x),
            fmt_mm(area.0.y),
            fmt_mm(area.1.x),
            fmt_mm(area.1.y)
        );
        let _ = writeln!(
            out,
            "<clipPath id=\"clip-close-up-{number}\"><rect {rect}/></clipPath>"
        );
        text_lines(&mut out, &caption, corner + DVec2::new(2.0, 0.0));
        let _ = writeln!(
            out,
            "<rect {rect} fill=\"none\" stroke=\"#909090\" stroke-width=\"0.2\"/>"
        );
        let cut = self
            .cut
            .map_or(String::new(), |c| format!(" data-cut=\"{c}\""));
        let _ = writeln!(
            out,
            "<g id=\"view-close-up-{number}\" data-view=\"close-up {number}\" {}{cut} clip-path=\"url(#clip-close-up-{number})\">",
            frame.projection()
        );
        if !draw_frame(
            &mut out,
            map,
            &frame,
            &patches,
            &mut trial,
            Some(self.target),
        ) {
            return None;
        }
        out.push_str("</g>\n");
        named.copy_from_slice(&trial);
        Some(out)
    }

    /// The caption: the close-up's number, its panel and the side it is seen from.
    fn caption(&self) -> String {
        let cut = if self.cut.is_some() {
            ", the model in front cut away"
        } else {
            ""
        };
        format!(
            "close-up {}: around {}, from {}{cut}",
            self.k + 1,
            self.id,
            side_words(self.view.toward)
        )
    }

    /// The model's patches this close-up may show: cut where it cuts, and only those
    /// whose page box meets the drawing.
    fn patches(&self, map: &MapContext, frame: &Frame) -> Vec<Patch> {
        let (lo, hi) = (frame.area.0, frame.area.0 + frame.area.1);
        // Cutting only shrinks a patch: those whose whole box misses go first.
        map.input
            .surface
            .patches
            .iter()
            .filter(|p| {
                let page: Vec<DVec2> = p.points.iter().map(|&q| frame.to_page(q)).collect();
                let a = page.iter().copied().fold(DVec2::INFINITY, DVec2::min);
                let b = page.iter().copied().fold(DVec2::NEG_INFINITY, DVec2::max);
                a.x < hi.x && lo.x < b.x && a.y < hi.y && lo.y < b.y
            })
            .filter_map(|p| match self.cut {
                Some(cut) => cut_away(p, self.view.toward, cut),
                None => Some(p.clone()),
            })
            .collect()
    }
}

/// The side a close-up is seen from, in the overview's words: +Z is the front, +X
/// the right, +Y above.
fn side_words(toward: DVec3) -> String {
    // A component counts from about 22° off square to its axis.
    const COUNTS: f64 = 0.38;
    let pick = |c: f64, plus: &'static str, minus: &'static str| {
        if c > COUNTS {
            Some(plus)
        } else if c < -COUNTS {
            Some(minus)
        } else {
            None
        }
    };
    let level: Vec<&str> = [
        pick(toward.z, "front", "back"),
        pick(toward.x, "right", "left"),
    ]
    .into_iter()
    .flatten()
    .collect();
    let height = pick(toward.y, "above", "below");
    match (level.is_empty(), height) {
        (false, Some(h)) => format!("the {}, {h}", level.join(" ")),
        (false, None) => format!("the {}", level.join(" ")),
        (true, Some(h)) => h.to_string(),
        (true, None) => "the front".to_string(),
    }
}

/// A view looking back along `toward`, up on the page as near the model's +Y as
/// the direction allows (+Z or -Z when it looks along Y).
fn view_toward(toward: DVec3) -> View {
    let up = if toward.y.abs() > 0.9 {
        DVec3::new(0.0, 0.0, -toward.y.signum())
    } else {
        DVec3::Y
    };
    View {
        name: "close-up",
        axis: "",
        turn: "",
        toward,
        up: (up - up.dot(toward) * toward).normalize(),
    }
}

/// A panel a close-up is for, as the sides it may be seen from are tried.
struct Aim<'a> {
    map: &'a MapContext<'a>,
    target: usize,
    /// The middle of its roomiest patch, where the sight lines start.
    centre: DVec3,
    /// Its area-weighted normal.
    normal: DVec3,
    /// The diagonal of its box (mm).
    size: f64,
}

impl Aim<'_> {
    /// A side the panel is seen from with nothing in front of `centre`: square to it,
    /// or between that and one of the overview's directions (`None` as the cut); else
    /// square to it with the model cut away in front ([`Aim::cut_near`]).
    fn sight(&self) -> (DVec3, Option<f64>) {
        let normal = self.normal;
        let blends = views()
            .into_iter()
            .filter(|v| v.toward.dot(normal) > 0.0)
            .filter_map(|v| (normal + v.toward).try_normalize());
        std::iter::once(normal)
            .chain(blends)
            .find(|&toward| self.clear(toward, f64::INFINITY))
            .map_or_else(|| self.cut_near(), |t| (t, None))
    }

    /// Square to the panel, the model cut away as far in front of `centre` as leaves
    /// nothing between it and the viewer: a few panel sizes where that is clear, else
    /// just in front of it.
    fn cut_near(&self) -> (DVec3, Option<f64>) {
        let reach = [4.0, 2.0, 1.0, 0.5, 0.25]
            .into_iter()
            .map(|r| r * self.size)
            .find(|&r| self.clear(self.normal, r))
            .unwrap_or(0.05 * self.size);
        (self.normal, Some(self.centre.dot(self.normal) + reach))
    }

    /// Whether nothing of the model is in front of `centre` seen along `toward`, up
    /// to `reach` in front of it: the ray from it toward the viewer meets no other
    /// panel's patch the view would draw (a closed model's back faces never are).
    fn clear(&self, toward: DVec3, reach: f64) -> bool {
        let surface = self.map.input.surface;
        let start = self.centre + 1e-6 * self.size * toward;
        !surface.patches.iter().any(|p| {
            p.panel != self.target
                && (!surface.closed || p.normal.dot(toward) > 1e-9)
                && hits(p, start, toward).is_some_and(|t| t < reach)
        })
    }
}

/// Square to the panel with the model cut away just in front of all of it: the last
/// resort, which nothing of the model can hide.
fn cut_sight(own: &[&Patch], normal: DVec3, size: f64) -> (DVec3, Option<f64>) {
    let front = own
        .iter()
        .flat_map(|p| &p.points)
        .map(|q| q.dot(normal))
        .fold(f64::NEG_INFINITY, f64::max);
    (normal, Some(front + 1e-3 * size))
}

/// Where the ray `start + t·dir` (t > 0) meets the convex patch `p`, if it does.
fn hits(p: &Patch, start: DVec3, dir: DVec3) -> Option<f64> {
    let across = p.normal.dot(dir);
    if across.abs() < 1e-12 {
        return None;
    }
    let t = p.normal.dot(p.points[0] - start) / across;
    if t <= 0.0 {
        return None;
    }
    let at = start + t * dir;
    let n = p.points.len();
    let inside = (0..n).all(|i| {
        let (a, b) = (p.points[i], p.points[(i + 1) % n]);
        (b - a).cross(at - a).dot(p.normal) >= -1e-12
    });
    inside.then_some(t)
}

/// The patch `p` with what lies nearer the viewer than `cut` (depth along `toward`)
/// cut off; `None` if nothing is left.
fn cut_away(p: &Patch, toward: DVec3, cut: f64) -> Option<Patch> {
    let depth = |q: DVec3| q.dot(toward) - cut;
    let n = p.points.len();
    let mut points = Vec::with_capacity(n + 1);
    for i in 0..n {
        let (a, b) = (p.points[i], p.points[(i + 1) % n]);
        let (da, db) = (depth(a), depth(b));
        if da <= 0.0 {
            points.push(a);
        }
        if (da <= 0.0) != (db <= 0.0) {
            points.push(a + (b - a) * (da / (da - db)));
        }
    }
    // A corner on the cut is met twice: once itself, once as where an edge crosses.
    points.dedup();
    if points.len() > 1 && points.first() == points.last() {
        points.pop();
    }
    (points.len() >= 3).then_some(Patch {
        points,
        normal: p.normal,
        panel: p.panel,
    })
}

/// The first enlargement to try: the panel's id about half as wide and a third as
/// tall as the panel seen, and at least [`CLOSER`] times the overview.
fn first_scale(map: &MapContext, own: &[&Patch], view: &View, id: &str) -> f64 {
    let seen: Vec<DVec2> = own
        .iter()
        .flat_map(|p| &p.points)
        .map(|&q| project(q, view))
        .collect();
    let lo = seen.iter().copied().fold(DVec2::INFINITY, DVec2::min);
    let hi = seen.iter().copied().fold(DVec2::NEG_INFINITY, DVec2::max);
    let span = (hi - lo).max(DVec2::splat(1e-9));
    let (width, height) = (text_width(id, map.text), map.text);
    (2.0 * width / span.x)
        .max(3.0 * height / span.y)
        .max(CLOSER * map.grid.scale)
}

/// Room (mm of page) kept round an id inside its patch: more than the raster's cell and
/// its neighbours that must show the panel.
const ROOM_SPARE: f64 = 0.5;

/// The room about the middle of a convex patch: the distance from its centroid to
/// its nearest side.
fn room(p: &Patch) -> f64 {
    let n = p.points.len();
    let centre = p.points.iter().sum::<DVec3>() / n as f64;
    (0..n)
        .map(|i| {
            let (a, b) = (p.points[i], p.points[(i + 1) % n]);
            let side = (b - a).normalize_or_zero();
            let off = centre - a;
            (off - off.dot(side) * side).length()
        })
        .fold(f64::INFINITY, f64::min)
}

/// A convex patch's area.
fn area(p: &Patch) -> f64 {
    let a = p.points[0];
    p.points
        .windows(2)
        .skip(1)
        .map(|w| (w[0] - a).cross(w[1] - a).dot(p.normal))
        .sum::<f64>()
        * 0.5
}

/// The diagonal of the box round `points`.
fn extent<'a>(points: impl Iterator<Item = &'a DVec3>) -> f64 {
    let (lo, hi) = points.fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &p| {
        (lo.min(p), hi.max(p))
    });
    if lo.x > hi.x {
        0.0
    } else {
        lo.distance(hi)
    }
}
