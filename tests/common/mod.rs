//! Independent checker for the laser-cutter sheets written by `unfold`.
//!
//! Written from the file conventions (docs/LASER.md, SPEC.md §4–5) only, without looking
//! at the exporter. Integration tests use it with `mod common;`.
//!
//! * [`check_svg_sheet`] — parses one SVG sheet with a small hand-written XML scanner and
//!   checks syntax (declaration, root, groups, attributes, colours, number format) and
//!   geometry (closed simple CUT loops, panels apart by `spacing`, margins, holes before
//!   outlines, SCORE/SCORE-VALLEY/ENGRAVE inside panels, nothing drawn twice). Returns [`SheetStats`].
//! * [`parse_svg`] — the parser alone (syntax checks only), returning an [`SvgSheet`].
//! * [`svg_geometry`] / [`svg_circles`] — paths and circles of a sheet (panic on a
//!   malformed file: for tests that already checked the sheet).
//! * [`check_dxf_matches_svg`] — reads a DXF back with the Rust reader of [`dxf_read`]
//!   (R12 conventions on the raw group codes, then the `dxf` crate) and, when python3 has
//!   ezdxf, with `tests/check_dxf.py` (ezdxf, strict read + audit), and compares the
//!   entities of each read with the SVG geometry (y flipped).
//! * [`build`] — helpers for the end-to-end build tests of every scheme (running the
//!   binary, reading the manifest, checking an output folder, the library's pipeline up
//!   to the flat panels, golden files).
//!
//! Terminology: a *panel* is a closed CUT path not contained in another closed CUT path;
//! closed CUT paths inside a panel are *inner cuts*; CUT circles are *holes*.
#![allow(dead_code)]

pub mod build;
pub mod corpus;
pub mod dxf_read;
pub mod map;

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use dxf_read::DxfEntity;

/// A point in sheet millimetres (SVG coordinates: y down unless said otherwise).
pub type Pt = (f64, f64);

/// Geometric tolerance (mm) for margins, "on the outline", spacing and DXF comparison.
pub const TOL: f64 = 1e-3;
/// Distance (mm) below which two segments count as touching / intersecting.
const HIT: f64 = 1e-6;
/// The only stroke width allowed (mm, a hairline).
pub const STROKE_WIDTH: &str = "0.0254";
/// At most this many problems are listed in one error message.
const MAX_ERRORS: usize = 20;

/// Sheet size and layout parameters, all in mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SheetSpec {
    pub width: f64,
    pub height: f64,
    pub margin: f64,
    pub spacing: f64,
}

/// What one sheet holds.
///
/// * `panels`: closed CUT paths not inside another closed CUT path.
/// * `holes`: CUT circles (inner closed CUT paths are not counted here).
/// * `cut_paths`: CUT `<path>` elements (panel outlines + inner cuts; circles excluded).
/// * `score_paths`, `engrave_paths`: `<path>` elements of those groups (score: SCORE
///   and SCORE-VALLEY); `valley_paths`: those of SCORE-VALLEY alone.
/// * `panel_area`: Σ |shoelace area| of panel outlines − Σ area of inner closed CUT
///   paths (circles are *not* subtracted).
/// * `cut_length`: perimeters of all CUT paths (closing edge included) + circumferences
///   2πr of the circles; `score_length`, `valley_length`, `engrave_length`: polyline
///   lengths.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SheetStats {
    pub panels: usize,
    pub holes: usize,
    pub cut_paths: usize,
    pub score_paths: usize,
    pub valley_paths: usize,
    pub engrave_paths: usize,
    pub panel_area: f64,
    pub cut_length: f64,
    pub score_length: f64,
    pub valley_length: f64,
    pub engrave_length: f64,
}

/// The kinds of laser geometry, in the order their groups must appear.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Layer {
    Engrave,
    Score,
    ScoreValley,
    Cut,
}

impl Layer {
    pub const ALL: [Layer; 4] = [Layer::Engrave, Layer::Score, Layer::ScoreValley, Layer::Cut];

    /// Inkscape label and DXF layer name.
    pub fn name(self) -> &'static str {
        match self {
            Layer::Engrave => "ENGRAVE",
            Layer::Score => "SCORE",
            Layer::ScoreValley => "SCORE-VALLEY",
            Layer::Cut => "CUT",
        }
    }

    /// SVG group id.
    pub fn id(self) -> &'static str {
        match self {
            Layer::Engrave => "engrave",
            Layer::Score => "score",
            Layer::ScoreValley => "score-valley",
            Layer::Cut => "cut",
        }
    }

    /// Exact SVG stroke colour.
    pub fn stroke(self) -> &'static str {
        match self {
            Layer::Engrave => "#000000",
            Layer::Score => "#0000FF",
            Layer::ScoreValley => "#00FF00",
            Layer::Cut => "#FF0000",
        }
    }

    /// DXF ACI colour of the layer and of its entities (group 62).
    pub fn dxf_color(self) -> i64 {
        match self {
            Layer::Engrave => 7,
            Layer::Score => 5,
            Layer::ScoreValley => 3,
            Layer::Cut => 1,
        }
    }

    pub fn from_name(name: &str) -> Option<Layer> {
        Layer::ALL.into_iter().find(|l| l.name() == name)
    }

    fn from_id(id: &str) -> Option<Layer> {
        Layer::ALL.into_iter().find(|l| l.id() == id)
    }
}

/// One `<path>`: its group, whether it ends with `Z`, and its points.
///
/// `points` are normalised: consecutive duplicates removed and, for a closed path, a last
/// point equal to the first dropped (the `Z` closes the loop).
#[derive(Debug, Clone)]
pub struct SvgPath {
    pub layer: Layer,
    pub closed: bool,
    pub points: Vec<Pt>,
    /// Position among all `<path>`/`<circle>` elements of the document (0-based).
    pub order: usize,
    /// 1-based number among the `<path>` elements of its group (for messages).
    pub number: usize,
    pub d: String,
}

/// One `<circle>`.
#[derive(Debug, Clone)]
pub struct SvgCircle {
    pub layer: Layer,
    pub cx: f64,
    pub cy: f64,
    pub r: f64,
    /// Position among all `<path>`/`<circle>` elements of the document (0-based).
    pub order: usize,
    /// 1-based number among the `<circle>` elements of its group (for messages).
    pub number: usize,
}

/// A parsed sheet.
#[derive(Debug, Clone)]
pub struct SvgSheet {
    pub width: f64,
    pub height: f64,
    pub paths: Vec<SvgPath>,
    pub circles: Vec<SvgCircle>,
}

// =======================================================================================
// Number format
// =======================================================================================

/// Parses one number of the file, enforcing the format rules: optional `-`, integer part
/// without leading zeros, optional `.` and 1–4 decimals without trailing zero, no
/// exponent, never a negative zero.
pub fn parse_number(s: &str, what: &str) -> Result<f64, String> {
    if s.contains(['e', 'E']) {
        return Err(format!("number {s:?} in {what} uses exponent notation"));
    }
    let body = s.strip_prefix('-').unwrap_or(s);
    let negative = body.len() != s.len();
    if body.is_empty() || !body.chars().all(|c| c.is_ascii_digit() || c == '.') {
        return Err(format!("{s:?} in {what} is not a plain decimal number"));
    }
    if negative && body.chars().all(|c| c == '0' || c == '.') {
        return Err(format!("number {s:?} in {what} is a negative zero (-0)"));
    }
    let (int, frac) = match body.split_once('.') {
        Some((i, f)) => (i, Some(f)),
        None => (body, None),
    };
    if int.is_empty() {
        return Err(format!(
            "number {s:?} in {what} has no digit before the point"
        ));
    }
    if int.len() > 1 && int.starts_with('0') {
        return Err(format!("number {s:?} in {what} has a leading zero"));
    }
    if let Some(f) = frac {
        if f.is_empty() || f.contains('.') {
            return Err(format!("{s:?} in {what} is not a plain decimal number"));
        }
        if f.len() > 4 {
            return Err(format!(
                "number {s:?} in {what} has {} decimals (at most 4 decimals allowed)",
                f.len()
            ));
        }
        if f.ends_with('0') {
            return Err(format!(
                "number {s:?} in {what} has a trailing zero (trim trailing zeros)"
            ));
        }
    }
    s.parse::<f64>()
        .map_err(|e| format!("number {s:?} in {what}: {e}"))
}

// =======================================================================================
// A tiny XML scanner
// =======================================================================================

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum TagKind {
    Open,
    SelfClosing,
    Close,
    /// Non-whitespace character data; `name` holds the text.
    Text,
}

#[derive(Debug, Clone)]
struct Tag {
    name: String,
    attrs: Vec<(String, String)>,
    kind: TagKind,
    /// Byte offset of the `<`.
    pos: usize,
}

impl Tag {
    fn attr(&self, name: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.as_str())
    }
}

const XML_DECL: &str = r#"<?xml version="1.0" encoding="UTF-8"?>"#;

fn is_name_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || matches!(c, ':' | '-' | '_' | '.')
}

/// Splits the document into tags; text content (other than whitespace), DOCTYPE, CDATA
/// and processing instructions are errors; comments are skipped.
fn tokenize(text: &str) -> Result<Vec<Tag>, String> {
    if !text.starts_with("<?xml") {
        return Err(format!(
            "missing XML declaration: the file must start with {XML_DECL}"
        ));
    }
    let end = text
        .find("?>")
        .ok_or("unterminated XML declaration".to_string())?;
    let decl = &text[..end + 2];
    if !decl.contains(r#"version="1.0""#) || !decl.contains(r#"encoding="UTF-8""#) {
        return Err(format!(
            "XML declaration {decl:?} should be {XML_DECL} (version 1.0, UTF-8)"
        ));
    }
    let mut tags = Vec::new();
    let mut i = end + 2;
    while i < text.len() {
        let start = i;
        i += text[i..].find('<').unwrap_or(text.len() - i);
        let between = text[start..i].trim();
        if !between.is_empty() {
            tags.push(Tag {
                name: between.chars().take(40).collect(),
                attrs: Vec::new(),
                kind: TagKind::Text,
                pos: start,
            });
        }
        if i >= text.len() {
            break;
        }
        let rest = &text[i..];
        if rest.starts_with("<!--") {
            let e = rest
                .find("-->")
                .ok_or(format!("unterminated comment at byte {i}"))?;
            i += e + 3;
            continue;
        }
        if rest.starts_with("<!") || rest.starts_with("<?") {
            let shown: String = rest.chars().take(20).collect();
            return Err(format!(
                "unexpected markup {shown:?} at byte {i} (no DOCTYPE, CDATA or processing instructions)"
            ));
        }
        let close = rest
            .find('>')
            .ok_or(format!("unterminated tag at byte {i}"))?;
        let inner = &rest[1..close];
        tags.push(parse_tag(inner, i)?);
        i += close + 1;
    }
    Ok(tags)
}

fn parse_tag(inner: &str, pos: usize) -> Result<Tag, String> {
    if let Some(name) = inner.strip_prefix('/') {
        let name = name.trim_end();
        if name.is_empty() || !name.chars().all(is_name_char) {
            return Err(format!("malformed closing tag </{name}> at byte {pos}"));
        }
        return Ok(Tag {
            name: name.to_string(),
            attrs: Vec::new(),
            kind: TagKind::Close,
            pos,
        });
    }
    let (body, kind) = match inner.strip_suffix('/') {
        Some(b) => (b, TagKind::SelfClosing),
        None => (inner, TagKind::Open),
    };
    let name_end = body.find(|c: char| !is_name_char(c)).unwrap_or(body.len());
    let name = &body[..name_end];
    if name.is_empty() {
        return Err(format!("malformed tag <{inner}> at byte {pos}"));
    }
    let mut attrs: Vec<(String, String)> = Vec::new();
    let mut rest = &body[name_end..];
    loop {
        let trimmed = rest.trim_start();
        if trimmed.is_empty() {
            break;
        }
        if trimmed.len() == rest.len() {
            return Err(format!(
                "malformed tag <{name}> at byte {pos}: expected whitespace before {:?}",
                trimmed.chars().take(20).collect::<String>()
            ));
        }
        rest = trimmed;
        let eq = rest
            .find('=')
            .ok_or(format!("malformed attribute in <{name}> at byte {pos}"))?;
        let key = rest[..eq].trim_end();
        if key.is_empty() || !key.chars().all(is_name_char) {
            return Err(format!(
                "malformed attribute name {key:?} in <{name}> at byte {pos}"
            ));
        }
        rest = rest[eq + 1..].trim_start();
        let quote = rest
            .chars()
            .next()
            .filter(|&c| c == '"' || c == '\'')
            .ok_or(format!(
                "attribute {key} of <{name}> at byte {pos} is not quoted"
            ))?;
        let vend = rest[1..].find(quote).ok_or(format!(
            "unterminated value of attribute {key} in <{name}> at byte {pos}"
        ))?;
        let value = &rest[1..1 + vend];
        if value.contains('<') {
            return Err(format!(
                "'<' inside attribute {key} of <{name}> at byte {pos}"
            ));
        }
        if attrs.iter().any(|(k, _)| k == key) {
            return Err(format!(
                "attribute {key} appears twice in <{name}> at byte {pos}"
            ));
        }
        attrs.push((key.to_string(), value.to_string()));
        rest = &rest[1 + vend + 1..];
    }
    Ok(Tag {
        name: name.to_string(),
        attrs,
        kind,
        pos,
    })
}

// =======================================================================================
// SVG parsing with the syntactic checks
// =======================================================================================

fn check_allowed_attrs(tag: &Tag, allowed: &[&str]) -> Result<(), String> {
    for (k, _) in &tag.attrs {
        let namespace = tag.name == "svg" && k.starts_with("xmlns:");
        if !(allowed.contains(&k.as_str()) || namespace) {
            return Err(format!(
                "unexpected attribute {k}= on <{}> at byte {} (allowed: {})",
                tag.name,
                tag.pos,
                allowed.join(", ")
            ));
        }
    }
    Ok(())
}

fn required<'a>(tag: &'a Tag, name: &str) -> Result<&'a str, String> {
    tag.attr(name).ok_or(format!(
        "<{}> at byte {} lacks the {name}= attribute",
        tag.name, tag.pos
    ))
}

/// fill="none", the layer's exact stroke and the hairline width.
fn check_paint(tag: &Tag, layer: Layer) -> Result<(), String> {
    let what = format!(
        "<{}> at byte {} in group {}",
        tag.name,
        tag.pos,
        layer.name()
    );
    let fill = required(tag, "fill")?;
    if fill != "none" {
        return Err(format!(
            "{what} has fill=\"{fill}\", expected fill=\"none\""
        ));
    }
    let stroke = required(tag, "stroke")?;
    if stroke != layer.stroke() {
        return Err(format!(
            "{what} has wrong stroke colour {stroke:?}, expected exactly {:?}",
            layer.stroke()
        ));
    }
    let width = required(tag, "stroke-width")?;
    parse_number(width, &format!("stroke-width of {what}"))?;
    if width != STROKE_WIDTH {
        return Err(format!(
            "{what} has stroke-width=\"{width}\", expected \"{STROKE_WIDTH}\""
        ));
    }
    Ok(())
}

/// Parses `d`: `M x y (L x y [x y …])* [Z]`, absolute commands only, one subpath.
/// Returns (closed, normalised points).
fn parse_d(d: &str, what: &str) -> Result<(bool, Vec<Pt>), String> {
    if d.contains(',') {
        return Err(format!(
            "{what}: d uses commas; numbers must be space-separated"
        ));
    }
    let toks: Vec<&str> = d.split_whitespace().collect();
    let num = |k: usize| -> Result<f64, String> {
        let t = toks
            .get(k)
            .ok_or(format!("{what}: d ends in the middle of a coordinate pair"))?;
        parse_number(t, &format!("{what} d"))
    };
    if toks.first() != Some(&"M") {
        return Err(format!(
            "{what}: d must start with an absolute \"M\" (got {:?})",
            toks.first().unwrap_or(&"")
        ));
    }
    let mut pts = vec![(num(1)?, num(2)?)];
    let mut k = 3;
    let mut closed = false;
    let mut in_l = false;
    while k < toks.len() {
        match toks[k] {
            "L" => {
                pts.push((num(k + 1)?, num(k + 2)?));
                k += 3;
                in_l = true;
            }
            "Z" => {
                if k + 1 != toks.len() {
                    return Err(format!(
                        "{what}: \"Z\" must be the last token (one polyline per <path>)"
                    ));
                }
                closed = true;
                k += 1;
            }
            t if in_l && t.starts_with(|c: char| c == '-' || c.is_ascii_digit()) => {
                // implicit repetition of L
                pts.push((num(k)?, num(k + 1)?));
                k += 2;
            }
            t if t.starts_with(|c: char| c == '-' || c == '.' || c.is_ascii_digit()) => {
                return Err(format!("{what}: number {t:?} where a command was expected"));
            }
            t => {
                return Err(format!(
                    "{what}: path command {t:?} not allowed (only absolute M, L, Z; one polyline per <path>)"
                ));
            }
        }
    }
    Ok((closed, normalize(pts, closed)))
}

/// Drops consecutive duplicate points and, for a closed loop, a last point equal to the
/// first.
pub fn normalize(pts: Vec<Pt>, closed: bool) -> Vec<Pt> {
    let mut out: Vec<Pt> = Vec::with_capacity(pts.len());
    for p in pts {
        if out.last() != Some(&p) {
            out.push(p);
        }
    }
    if closed && out.len() > 1 && out.first() == out.last() {
        out.pop();
    }
    out
}

fn parse_mm(value: &str, what: &str) -> Result<f64, String> {
    let n = value.strip_suffix("mm").ok_or(format!(
        "{what}=\"{value}\" must be in millimetres with an \"mm\" suffix"
    ))?;
    parse_number(n, what)
}

/// Parses a sheet and performs every check that does not need the sheet spec or
/// geometry: XML declaration, single `<svg>` root, allowed elements/attributes (no
/// `<text>`, `<style>`, `style=`, `transform=`, `stroke-dasharray`), group ids/labels and
/// order ENGRAVE, SCORE, SCORE-VALLEY, CUT, paint attributes, number format, path syntax.
pub fn parse_svg(text: &str) -> Result<SvgSheet, String> {
    if text.contains("stroke-dasharray") {
        return Err("stroke-dasharray found: no dashes allowed".to_string());
    }
    let tags = tokenize(text)?;
    let mut stack: Vec<String> = Vec::new();
    let mut seen_root = false;
    let mut size: Option<(f64, f64)> = None;
    let mut group: Option<Layer> = None;
    let mut last_group: Option<Layer> = None;
    let mut paths = Vec::new();
    let mut circles = Vec::new();
    let mut order = 0usize;
    let mut numbers: HashMap<(Layer, bool), usize> = HashMap::new();

    for tag in &tags {
        if tag.kind == TagKind::Text {
            return Err(format!(
                "unexpected text content {:?} at byte {} (nothing but elements allowed)",
                tag.name, tag.pos
            ));
        }
        if tag.kind == TagKind::Close {
            match stack.pop() {
                Some(open) if open == tag.name => {}
                Some(open) => {
                    return Err(format!(
                        "</{}> at byte {} closes <{open}>",
                        tag.name, tag.pos
                    ))
                }
                None => return Err(format!("stray </{}> at byte {}", tag.name, tag.pos)),
            }
            if tag.name == "g" {
                group = None;
            }
            continue;
        }
        // element-independent attribute bans
        for (k, _) in &tag.attrs {
            if k == "style" {
                return Err(format!(
                    "style= attribute on <{}> at byte {} (use fill/stroke attributes, no CSS)",
                    tag.name, tag.pos
                ));
            }
            if k == "transform" {
                return Err(format!(
                    "transform= attribute on <{}> at byte {} (coordinates must be final)",
                    tag.name, tag.pos
                ));
            }
        }
        let parent = stack.last().map(String::as_str);
        // <path ...></path> is fine, but nothing may sit inside a path or circle
        if let Some(p @ ("path" | "circle")) = parent {
            return Err(format!("<{}> at byte {} inside <{p}>", tag.name, tag.pos));
        }
        match tag.name.as_str() {
            "text" | "tspan" => {
                return Err(format!(
                    "<{}> element at byte {}: no <text> allowed, labels must be stroke paths",
                    tag.name, tag.pos
                ))
            }
            "style" => {
                return Err(format!(
                    "<style> element at byte {}: no CSS allowed",
                    tag.pos
                ))
            }
            "svg" => {
                if seen_root || parent.is_some() {
                    return Err(format!(
                        "second <svg> element at byte {}: exactly one <svg> root expected",
                        tag.pos
                    ));
                }
                seen_root = true;
                check_allowed_attrs(tag, &["xmlns", "version", "width", "height", "viewBox"])?;
                let ns = required(tag, "xmlns")?;
                if ns != "http://www.w3.org/2000/svg" {
                    return Err(format!("<svg> has xmlns=\"{ns}\""));
                }
                if let Some(v) = tag.attr("version") {
                    if v != "1.1" {
                        return Err(format!("<svg> has version=\"{v}\", expected 1.1"));
                    }
                }
                let w = parse_mm(required(tag, "width")?, "width")?;
                let h = parse_mm(required(tag, "height")?, "height")?;
                let vb: Vec<&str> = required(tag, "viewBox")?.split(' ').collect();
                if vb.len() != 4 {
                    return Err(format!(
                        "viewBox {:?} must be four space-separated numbers \"0 0 W H\"",
                        tag.attr("viewBox").unwrap_or("")
                    ));
                }
                let vb: Vec<f64> = vb
                    .iter()
                    .map(|s| parse_number(s, "viewBox"))
                    .collect::<Result<_, _>>()?;
                if vb[0] != 0.0 || vb[1] != 0.0 || vb[2] != w || vb[3] != h {
                    return Err(format!(
                        "viewBox \"{} {} {} {}\" must be \"0 0 {w} {h}\" (user unit = 1 mm, matching width/height)",
                        vb[0], vb[1], vb[2], vb[3]
                    ));
                }
                size = Some((w, h));
            }
            "g" => {
                if parent != Some("svg") {
                    return Err(format!(
                        "<g> at byte {} must be a direct child of <svg> (no nested groups)",
                        tag.pos
                    ));
                }
                check_allowed_attrs(tag, &["id", "inkscape:groupmode", "inkscape:label"])?;
                let id = required(tag, "id")?;
                let layer = Layer::from_id(id).ok_or(format!(
                    "group id=\"{id}\" at byte {}: expected engrave, score, score-valley or cut",
                    tag.pos
                ))?;
                if let Some(label) = tag.attr("inkscape:label") {
                    if label != layer.name() {
                        return Err(format!(
                            "group id=\"{id}\" has inkscape:label=\"{label}\", expected \"{}\"",
                            layer.name()
                        ));
                    }
                }
                if let Some(mode) = tag.attr("inkscape:groupmode") {
                    if mode != "layer" {
                        return Err(format!(
                            "group id=\"{id}\" has inkscape:groupmode=\"{mode}\", expected \"layer\""
                        ));
                    }
                }
                if let Some(last) = last_group {
                    if layer == last {
                        return Err(format!("group {} appears twice", layer.name()));
                    }
                    if layer < last {
                        return Err(format!(
                            "group {} after group {}: groups must be in the order ENGRAVE, SCORE, SCORE-VALLEY, CUT",
                            layer.name(),
                            last.name()
                        ));
                    }
                }
                last_group = Some(layer);
                group = Some(layer);
            }
            "path" | "circle" => {
                let layer = match (parent, group) {
                    (Some("g"), Some(l)) => l,
                    _ => {
                        return Err(format!(
                            "<{}> at byte {} is not inside an ENGRAVE/SCORE/SCORE-VALLEY/CUT group",
                            tag.name, tag.pos
                        ))
                    }
                };
                check_paint(tag, layer)?;
                let is_path = tag.name == "path";
                let number = numbers.entry((layer, is_path)).or_insert(0);
                *number += 1;
                if is_path {
                    check_allowed_attrs(tag, &["id", "d", "fill", "stroke", "stroke-width"])?;
                    let d = required(tag, "d")?;
                    let what = format!("{} path #{} (byte {})", layer.name(), number, tag.pos);
                    let (closed, points) = parse_d(d, &what)?;
                    if points.len() < 2 {
                        return Err(format!("{what} has fewer than 2 distinct points: {d:?}"));
                    }
                    paths.push(SvgPath {
                        layer,
                        closed,
                        points,
                        order,
                        number: *number,
                        d: d.to_string(),
                    });
                } else {
                    check_allowed_attrs(
                        tag,
                        &["id", "cx", "cy", "r", "fill", "stroke", "stroke-width"],
                    )?;
                    let what = format!("{} circle #{} (byte {})", layer.name(), number, tag.pos);
                    let cx = parse_number(required(tag, "cx")?, &format!("cx of {what}"))?;
                    let cy = parse_number(required(tag, "cy")?, &format!("cy of {what}"))?;
                    let r = parse_number(required(tag, "r")?, &format!("r of {what}"))?;
                    if r <= 0.0 {
                        return Err(format!("{what} has radius {r}, expected > 0"));
                    }
                    circles.push(SvgCircle {
                        layer,
                        cx,
                        cy,
                        r,
                        order,
                        number: *number,
                    });
                }
                order += 1;
            }
            other => {
                return Err(format!(
                    "unexpected element <{other}> at byte {} (only svg, g, path, circle allowed)",
                    tag.pos
                ))
            }
        }
        if tag.kind == TagKind::Open {
            stack.push(tag.name.clone());
        } else if tag.name == "g" {
            group = None;
        }
    }
    if let Some(open) = stack.last() {
        return Err(format!("<{open}> is never closed"));
    }
    let (width, height) = size.ok_or("no <svg> root element".to_string())?;
    Ok(SvgSheet {
        width,
        height,
        paths,
        circles,
    })
}

// =======================================================================================
// Geometry helpers
// =======================================================================================

#[derive(Debug, Clone, Copy)]
struct BBox {
    x0: f64,
    y0: f64,
    x1: f64,
    y1: f64,
}

impl BBox {
    fn of(pts: &[Pt]) -> BBox {
        let mut b = BBox {
            x0: f64::INFINITY,
            y0: f64::INFINITY,
            x1: f64::NEG_INFINITY,
            y1: f64::NEG_INFINITY,
        };
        for &(x, y) in pts {
            b.x0 = b.x0.min(x);
            b.y0 = b.y0.min(y);
            b.x1 = b.x1.max(x);
            b.y1 = b.y1.max(y);
        }
        b
    }
    fn circle(cx: f64, cy: f64, r: f64) -> BBox {
        BBox {
            x0: cx - r,
            y0: cy - r,
            x1: cx + r,
            y1: cy + r,
        }
    }
    /// Boxes closer than `d` (or overlapping).
    fn near(&self, o: &BBox, d: f64) -> bool {
        o.x0 <= self.x1 + d && self.x0 <= o.x1 + d && o.y0 <= self.y1 + d && self.y0 <= o.y1 + d
    }
    fn contains_pt(&self, p: Pt, d: f64) -> bool {
        p.0 >= self.x0 - d && p.0 <= self.x1 + d && p.1 >= self.y0 - d && p.1 <= self.y1 + d
    }
    fn contains_box(&self, o: &BBox) -> bool {
        o.x0 >= self.x0 && o.x1 <= self.x1 && o.y0 >= self.y0 && o.y1 <= self.y1
    }
}

fn sub(a: Pt, b: Pt) -> Pt {
    (a.0 - b.0, a.1 - b.1)
}
fn dot(a: Pt, b: Pt) -> f64 {
    a.0 * b.0 + a.1 * b.1
}
fn cross(a: Pt, b: Pt) -> f64 {
    a.0 * b.1 - a.1 * b.0
}
fn dist(a: Pt, b: Pt) -> f64 {
    (a.0 - b.0).hypot(a.1 - b.1)
}
/// Twice the signed area of triangle abc.
fn orient(a: Pt, b: Pt, c: Pt) -> f64 {
    cross(sub(b, a), sub(c, a))
}

/// Distance from p to segment ab and the closest point.
fn point_segment(p: Pt, a: Pt, b: Pt) -> (f64, Pt) {
    let ab = sub(b, a);
    let len2 = dot(ab, ab);
    let t = if len2 == 0.0 {
        0.0
    } else {
        (dot(sub(p, a), ab) / len2).clamp(0.0, 1.0)
    };
    let q = (a.0 + t * ab.0, a.1 + t * ab.1);
    (dist(p, q), q)
}

/// Distance between segments ab and cd and a point where it is attained (the crossing
/// point when they cross).
fn segment_segment(a: Pt, b: Pt, c: Pt, d: Pt) -> (f64, Pt) {
    let o1 = orient(a, b, c);
    let o2 = orient(a, b, d);
    let o3 = orient(c, d, a);
    let o4 = orient(c, d, b);
    let opposite = |u: f64, v: f64| (u > 0.0 && v < 0.0) || (u < 0.0 && v > 0.0);
    if opposite(o1, o2) && opposite(o3, o4) {
        let t = o3 / (o3 - o4);
        return (0.0, (a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1)));
    }
    let mut best = point_segment(a, c, d);
    for cand in [
        point_segment(b, c, d),
        point_segment(c, a, b),
        point_segment(d, a, b),
    ] {
        if cand.0 < best.0 {
            best = cand;
        }
    }
    best
}

/// Even-odd point-in-polygon (points on the boundary may go either way).
fn point_in_polygon(p: Pt, poly: &[Pt]) -> bool {
    let mut inside = false;
    let n = poly.len();
    let mut j = n - 1;
    for i in 0..n {
        let (a, b) = (poly[i], poly[j]);
        if (a.1 > p.1) != (b.1 > p.1) {
            let x = a.0 + (p.1 - a.1) / (b.1 - a.1) * (b.0 - a.0);
            if p.0 < x {
                inside = !inside;
            }
        }
        j = i;
    }
    inside
}

/// Distance from p to the boundary of a closed polygon.
fn boundary_distance(p: Pt, poly: &[Pt]) -> f64 {
    let n = poly.len();
    (0..n)
        .map(|i| point_segment(p, poly[i], poly[(i + 1) % n]).0)
        .fold(f64::INFINITY, f64::min)
}

fn signed_area(poly: &[Pt]) -> f64 {
    let n = poly.len();
    (0..n)
        .map(|i| cross(poly[i], poly[(i + 1) % n]))
        .sum::<f64>()
        / 2.0
}

fn polyline_length(pts: &[Pt], closed: bool) -> f64 {
    let open: f64 = pts.windows(2).map(|w| dist(w[0], w[1])).sum();
    if closed && pts.len() > 2 {
        open + dist(pts[pts.len() - 1], pts[0])
    } else {
        open
    }
}

fn fmt_pt(p: Pt) -> String {
    format!("({:.4}, {:.4})", p.0, p.1)
}

fn describe(p: &SvgPath) -> String {
    let short: String = p.d.chars().take(60).collect();
    let ell = if p.d.len() > 60 { "…" } else { "" };
    format!("{} path #{} (d=\"{short}{ell}\")", p.layer.name(), p.number)
}

fn describe_circle(c: &SvgCircle) -> String {
    format!(
        "{} circle #{} (cx={} cy={} r={})",
        c.layer.name(),
        c.number,
        c.cx,
        c.cy,
        c.r
    )
}

/// Collects problems; turns them into one error message.
#[derive(Default)]
struct Problems(Vec<String>);

impl Problems {
    fn push(&mut self, s: String) {
        self.0.push(s);
    }
    fn result(&self) -> Result<(), String> {
        if self.0.is_empty() {
            return Ok(());
        }
        let mut msg: Vec<String> = self.0.iter().take(MAX_ERRORS).cloned().collect();
        if self.0.len() > MAX_ERRORS {
            msg.push(format!("… and {} more problems", self.0.len() - MAX_ERRORS));
        }
        Err(msg.join("\n"))
    }
}

/// A closed CUT path prepared for the geometric checks.
struct Loop {
    /// Index into `SvgSheet::paths`.
    path: usize,
    pts: Vec<Pt>,
    bb: BBox,
}

/// Segment of a closed CUT path for the sweep.
struct Seg {
    lp: usize,
    k: usize,
    a: Pt,
    b: Pt,
    bb: BBox,
}

/// Canonical key of a path for duplicate detection (independent of direction and, for
/// closed paths, of the starting vertex); coordinates rounded to 1e-4 mm.
fn path_key(p: &SvgPath) -> (bool, Vec<(i64, i64)>) {
    let q: Vec<(i64, i64)> = p
        .points
        .iter()
        .map(|&(x, y)| ((x * 1e4).round() as i64, (y * 1e4).round() as i64))
        .collect();
    if !p.closed {
        let mut r = q.clone();
        r.reverse();
        return (false, q.min(r));
    }
    let n = q.len();
    let m = *q.iter().min().expect("non-empty path");
    let mut best: Option<Vec<(i64, i64)>> = None;
    for s in (0..n).filter(|&s| q[s] == m) {
        let fwd: Vec<_> = (0..n).map(|i| q[(s + i) % n]).collect();
        let bwd: Vec<_> = (0..n).map(|i| q[(s + n - i) % n]).collect();
        for cand in [fwd, bwd] {
            if best.as_ref().is_none_or(|b| cand < *b) {
                best = Some(cand);
            }
        }
    }
    (true, best.expect("a minimum exists"))
}

// =======================================================================================
// The sheet checker
// =======================================================================================

/// Checks one SVG sheet against the conventions and `spec`; see the module docs.
pub fn check_svg_sheet(text: &str, spec: &SheetSpec) -> Result<SheetStats, String> {
    let sheet = parse_svg(text)?;

    // --- sheet size -------------------------------------------------------------------
    if (sheet.width - spec.width).abs() > 1e-3 || (sheet.height - spec.height).abs() > 1e-3 {
        return Err(format!(
            "sheet size: width/height {}mm x {}mm, expected {}mm x {}mm",
            sheet.width, sheet.height, spec.width, spec.height
        ));
    }

    let mut problems = Problems::default();

    // --- margins ----------------------------------------------------------------------
    let (lo_x, hi_x) = (spec.margin - TOL, spec.width - spec.margin + TOL);
    let (lo_y, hi_y) = (spec.margin - TOL, spec.height - spec.margin + TOL);
    let inside_margin = |p: Pt| p.0 >= lo_x && p.0 <= hi_x && p.1 >= lo_y && p.1 <= hi_y;
    for p in &sheet.paths {
        if let Some(&q) = p.points.iter().find(|&&q| !inside_margin(q)) {
            problems.push(format!(
                "{}: point {} is outside the margin (usable area [{}, {}] x [{}, {}])",
                describe(p),
                fmt_pt(q),
                spec.margin,
                spec.width - spec.margin,
                spec.margin,
                spec.height - spec.margin
            ));
        }
    }
    for c in &sheet.circles {
        let bb = BBox::circle(c.cx, c.cy, c.r);
        if bb.x0 < lo_x || bb.x1 > hi_x || bb.y0 < lo_y || bb.y1 > hi_y {
            problems.push(format!(
                "{} reaches outside the margin (usable area [{}, {}] x [{}, {}])",
                describe_circle(c),
                spec.margin,
                spec.width - spec.margin,
                spec.margin,
                spec.height - spec.margin
            ));
        }
    }

    // --- nothing drawn twice -------------------------------------------------------------
    let mut seen: HashMap<(bool, Vec<(i64, i64)>), usize> = HashMap::new();
    for (i, p) in sheet.paths.iter().enumerate() {
        if let Some(&j) = seen.get(&path_key(p)) {
            problems.push(format!(
                "line drawn twice: {} repeats {}",
                describe(p),
                describe(&sheet.paths[j])
            ));
        } else {
            seen.insert(path_key(p), i);
        }
    }
    let mut seen_c: HashMap<(i64, i64, i64), usize> = HashMap::new();
    for (i, c) in sheet.circles.iter().enumerate() {
        let key = (
            (c.cx * 1e4).round() as i64,
            (c.cy * 1e4).round() as i64,
            (c.r * 1e4).round() as i64,
        );
        if let Some(&j) = seen_c.get(&key) {
            problems.push(format!(
                "line drawn twice: {} repeats {}",
                describe_circle(c),
                describe_circle(&sheet.circles[j])
            ));
        } else {
            seen_c.insert(key, i);
        }
    }

    // --- CUT paths: closed, ≥ 3 distinct points, no fold-back ----------------------------
    let mut loops: Vec<Loop> = Vec::new();
    for (i, p) in sheet.paths.iter().enumerate() {
        if p.layer != Layer::Cut {
            continue;
        }
        if !p.closed {
            problems.push(format!(
                "{} is an open CUT path (does not end with Z); every CUT path must be closed",
                describe(p)
            ));
            continue;
        }
        if p.points.len() < 3 {
            problems.push(format!(
                "{} has {} distinct points; a closed CUT path needs at least 3",
                describe(p),
                p.points.len()
            ));
            continue;
        }
        let n = p.points.len();
        let mut degenerate = false;
        for k in 0..n {
            let (a, b, c) = (
                p.points[(k + n - 1) % n],
                p.points[k],
                p.points[(k + 1) % n],
            );
            let (u, v) = (sub(a, b), sub(c, b));
            let sin = cross(u, v).abs() / (dot(u, u).sqrt() * dot(v, v).sqrt());
            if sin < 1e-9 && dot(u, v) > 0.0 {
                problems.push(format!(
                    "{} is not a simple polygon: it folds back on itself (self-intersection) at {}",
                    describe(p),
                    fmt_pt(b)
                ));
                degenerate = true;
                break;
            }
        }
        if degenerate {
            continue;
        }
        loops.push(Loop {
            path: i,
            bb: BBox::of(&p.points),
            pts: p.points.clone(),
        });
    }
    problems.result()?;

    // --- sweep over all loop segments: self-intersections, intersections, distances ------
    let window = spec.spacing.max(0.0) + HIT;
    let mut segs: Vec<Seg> = Vec::new();
    for (li, l) in loops.iter().enumerate() {
        let n = l.pts.len();
        for k in 0..n {
            let (a, b) = (l.pts[k], l.pts[(k + 1) % n]);
            segs.push(Seg {
                lp: li,
                k,
                a,
                b,
                bb: BBox::of(&[a, b]),
            });
        }
    }
    segs.sort_by(|s, t| s.bb.x0.total_cmp(&t.bb.x0));
    let mut self_hit: BTreeMap<usize, Pt> = BTreeMap::new();
    // closest approach of each pair of loops within `window`
    let mut near: BTreeMap<(usize, usize), (f64, Pt)> = BTreeMap::new();
    for i in 0..segs.len() {
        let si = &segs[i];
        for sj in &segs[i + 1..] {
            if sj.bb.x0 > si.bb.x1 + window {
                break;
            }
            if sj.bb.y0 > si.bb.y1 + window || si.bb.y0 > sj.bb.y1 + window {
                continue;
            }
            if si.lp == sj.lp {
                let n = loops[si.lp].pts.len();
                if (si.k + 1) % n == sj.k || (sj.k + 1) % n == si.k {
                    continue; // adjacent edges: fold-backs were checked above
                }
                let (d, at) = segment_segment(si.a, si.b, sj.a, sj.b);
                if d < HIT {
                    self_hit.entry(si.lp).or_insert(at);
                }
            } else {
                let (d, at) = segment_segment(si.a, si.b, sj.a, sj.b);
                let key = (si.lp.min(sj.lp), si.lp.max(sj.lp));
                let e = near.entry(key).or_insert((f64::INFINITY, at));
                if d < e.0 {
                    *e = (d, at);
                }
            }
        }
    }
    for (&li, &at) in &self_hit {
        problems.push(format!(
            "{} is not a simple polygon: self-intersection near {}",
            describe(&sheet.paths[loops[li].path]),
            fmt_pt(at)
        ));
    }
    for (&(a, b), &(d, at)) in &near {
        if d < HIT {
            problems.push(format!(
                "overlapping panels: closed CUT paths {} and {} intersect near {}",
                describe(&sheet.paths[loops[a].path]),
                describe(&sheet.paths[loops[b].path]),
                fmt_pt(at)
            ));
        }
    }
    if self_hit.is_empty() {
        for l in &loops {
            if signed_area(&l.pts).abs() < 1e-9 {
                problems.push(format!(
                    "{} encloses zero area",
                    describe(&sheet.paths[l.path])
                ));
            }
        }
    }
    problems.result()?;

    // --- containment: panels and inner cuts -------------------------------------------
    let nl = loops.len();
    let mut containers: Vec<Vec<usize>> = vec![Vec::new(); nl];
    for (p, lp) in loops.iter().enumerate() {
        for (q, lq) in loops.iter().enumerate() {
            if p != q && lq.bb.contains_box(&lp.bb) && point_in_polygon(lp.pts[0], &lq.pts) {
                containers[p].push(q);
            }
        }
    }
    let is_panel: Vec<bool> = containers.iter().map(Vec::is_empty).collect();
    let order_of = |li: usize| sheet.paths[loops[li].path].order;
    // the panel an inner loop belongs to
    let owner: Vec<Option<usize>> = containers
        .iter()
        .map(|cs| cs.iter().copied().find(|&q| is_panel[q]))
        .collect();
    for p in 0..nl {
        for &q in &containers[p] {
            if order_of(p) > order_of(q) {
                problems.push(format!(
                    "inner cut {} comes after the outline {} that contains it; holes and inner cuts must come before their panel's outline",
                    describe(&sheet.paths[loops[p].path]),
                    describe(&sheet.paths[loops[q].path])
                ));
            }
        }
    }

    // --- circles: inside a panel, not crossing any loop, before their outlines ----------
    let mut circle_owner: Vec<Option<usize>> = vec![None; sheet.circles.len()];
    for (ci, c) in sheet.circles.iter().enumerate() {
        let centre = (c.cx, c.cy);
        let cbb = BBox::circle(c.cx, c.cy, c.r);
        let mut in_panel = None;
        for (q, lq) in loops.iter().enumerate() {
            if !lq.bb.near(&cbb, 0.0) {
                continue;
            }
            let d = boundary_distance(centre, &lq.pts);
            if d < c.r - TOL {
                problems.push(format!(
                    "{} crosses {} (its centre is {:.4} from it)",
                    describe_circle(c),
                    describe(&sheet.paths[lq.path]),
                    d
                ));
            }
            if lq.bb.contains_pt(centre, 0.0) && point_in_polygon(centre, &lq.pts) {
                if is_panel[q] {
                    in_panel = Some(q);
                }
                if c.order > order_of(q) {
                    problems.push(format!(
                        "hole {} comes after the outline {} that contains it; holes must come before their panel's outline",
                        describe_circle(c),
                        describe(&sheet.paths[lq.path])
                    ));
                }
            }
        }
        if in_panel.is_none() {
            problems.push(format!(
                "{} lies outside every panel outline",
                describe_circle(c)
            ));
        }
        circle_owner[ci] = in_panel;
    }

    // --- spacing between panels --------------------------------------------------------
    for (&(a, b), &(d, at)) in &near {
        if is_panel[a] && is_panel[b] && d < spec.spacing - TOL {
            problems.push(format!(
                "panels {} and {} are closer than the spacing: distance {:.4} < {} near {}",
                describe(&sheet.paths[loops[a].path]),
                describe(&sheet.paths[loops[b].path]),
                d,
                spec.spacing,
                fmt_pt(at)
            ));
        }
    }

    // --- SCORE, SCORE-VALLEY and ENGRAVE inside panels ------------------------------------------------
    let panels: Vec<usize> = (0..nl).filter(|&q| is_panel[q]).collect();
    let inner_of: Vec<Vec<usize>> = (0..nl)
        .map(|q| (0..nl).filter(|&p| owner[p] == Some(q)).collect())
        .collect();
    let circles_of: Vec<Vec<usize>> = (0..nl)
        .map(|q| {
            (0..sheet.circles.len())
                .filter(|&c| circle_owner[c] == Some(q))
                .collect()
        })
        .collect();
    let in_loop = |p: Pt, q: usize| {
        let l = &loops[q];
        l.bb.contains_pt(p, TOL)
            && (point_in_polygon(p, &l.pts) || boundary_distance(p, &l.pts) <= TOL)
    };
    let mut last_panel: Option<usize> = None;
    for p in sheet.paths.iter().filter(|p| p.layer != Layer::Cut) {
        for &pt in &p.points {
            let found = match last_panel {
                Some(q) if in_loop(pt, q) => Some(q),
                _ => panels.iter().copied().find(|&q| in_loop(pt, q)),
            };
            let Some(q) = found else {
                problems.push(format!(
                    "{}: point {} lies outside every panel outline",
                    describe(p),
                    fmt_pt(pt)
                ));
                break;
            };
            last_panel = Some(q);
            let in_cutout = inner_of[q].iter().any(|&h| {
                let l = &loops[h];
                l.bb.contains_pt(pt, 0.0)
                    && point_in_polygon(pt, &l.pts)
                    && boundary_distance(pt, &l.pts) > TOL
            }) || circles_of[q].iter().any(|&c| {
                let c = &sheet.circles[c];
                dist(pt, (c.cx, c.cy)) < c.r - TOL
            });
            if in_cutout {
                problems.push(format!(
                    "{}: point {} lies in a cut-out (inner cut or hole) of its panel",
                    describe(p),
                    fmt_pt(pt)
                ));
                break;
            }
        }
    }
    problems.result()?;

    // --- stats ---------------------------------------------------------------------------
    let mut stats = SheetStats {
        panels: panels.len(),
        holes: sheet.circles.len(),
        ..SheetStats::default()
    };
    for p in &sheet.paths {
        let len = polyline_length(&p.points, p.closed);
        match p.layer {
            Layer::Cut => {
                stats.cut_paths += 1;
                stats.cut_length += len;
            }
            Layer::Score => {
                stats.score_paths += 1;
                stats.score_length += len;
            }
            Layer::ScoreValley => {
                stats.score_paths += 1;
                stats.score_length += len;
                stats.valley_paths += 1;
                stats.valley_length += len;
            }
            Layer::Engrave => {
                stats.engrave_paths += 1;
                stats.engrave_length += len;
            }
        }
    }
    for c in &sheet.circles {
        stats.cut_length += 2.0 * std::f64::consts::PI * c.r;
    }
    for (q, l) in loops.iter().enumerate() {
        let a = signed_area(&l.pts).abs();
        if is_panel[q] {
            stats.panel_area += a;
        } else {
            stats.panel_area -= a;
        }
    }
    Ok(stats)
}

/// Paths of a sheet as (layer name "CUT"/"SCORE"/"SCORE-VALLEY"/"ENGRAVE", closed, normalised points in
/// SVG coordinates), in document order. Circles are not included: see [`svg_circles`].
/// Panics if the sheet does not parse (call [`check_svg_sheet`] first).
pub fn svg_geometry(text: &str) -> Vec<(String, bool, Vec<Pt>)> {
    let sheet = parse_svg(text).unwrap_or_else(|e| panic!("SVG does not parse: {e}"));
    sheet
        .paths
        .into_iter()
        .map(|p| (p.layer.name().to_string(), p.closed, p.points))
        .collect()
}

/// Circles of a sheet as (layer name, cx, cy, r) in SVG coordinates, in document order.
/// Panics if the sheet does not parse.
pub fn svg_circles(text: &str) -> Vec<(String, f64, f64, f64)> {
    let sheet = parse_svg(text).unwrap_or_else(|e| panic!("SVG does not parse: {e}"));
    sheet
        .circles
        .into_iter()
        .map(|c| (c.layer.name().to_string(), c.cx, c.cy, c.r))
        .collect()
}

// =======================================================================================
// DXF versus SVG
// =======================================================================================

/// A polyline or circle for the comparison; circles carry [(cx, cy), (r, r)].
#[derive(Debug, Clone)]
struct Item {
    layer: Layer,
    circle: bool,
    closed: bool,
    pts: Vec<Pt>,
}

impl Item {
    fn key(&self) -> (Layer, bool, bool, usize) {
        (self.layer, self.circle, self.closed, self.pts.len())
    }
    fn describe(&self) -> String {
        if self.circle {
            format!(
                "{} circle centre {} r {:.4}",
                self.layer.name(),
                fmt_pt(self.pts[0]),
                self.pts[1].0
            )
        } else {
            let shown: Vec<String> = self.pts.iter().take(4).map(|&p| fmt_pt(p)).collect();
            format!(
                "{} {} polyline of {} points {}{}",
                self.layer.name(),
                if self.closed { "closed" } else { "open" },
                self.pts.len(),
                shown.join(" "),
                if self.pts.len() > 4 { " …" } else { "" }
            )
        }
    }
}

/// The comparison items of a DXF's entities: every entity on a layer of the default
/// names and with that layer's colour as its own.
fn dxf_items(entities: &[DxfEntity]) -> Result<Vec<Item>, String> {
    let mut items = Vec::new();
    for (i, e) in entities.iter().enumerate() {
        let ty = e.kind.as_str();
        let layer_name = e.layer.as_str();
        let layer = Layer::from_name(layer_name).ok_or(format!(
            "DXF entity #{i} ({ty}) is on layer {layer_name:?}; expected CUT, SCORE, SCORE-VALLEY or ENGRAVE"
        ))?;
        match e.color {
            Some(c) if c == layer.dxf_color() => {}
            Some(c) => {
                return Err(format!(
                    "DXF entity #{i} ({ty}) on layer {layer_name} has colour {c}, expected {}",
                    layer.dxf_color()
                ))
            }
            None => {
                return Err(format!(
                    "DXF entity #{i} ({ty}) on layer {layer_name} has no colour of its own (group 62); expected {}",
                    layer.dxf_color()
                ))
            }
        }
        match ty {
            "POLYLINE" | "LINE" => items.push(Item {
                layer,
                circle: false,
                closed: e.closed,
                pts: normalize(e.points.clone(), e.closed),
            }),
            "CIRCLE" => {
                let (Some(c), Some(r)) = (e.center, e.radius) else {
                    return Err(format!(
                        "DXF entity #{i}: a CIRCLE without centre or radius"
                    ));
                };
                items.push(Item {
                    layer,
                    circle: true,
                    closed: true,
                    pts: vec![c, (r, r)],
                });
            }
            other => return Err(format!("DXF entity #{i}: unexpected type {other}")),
        }
    }
    Ok(items)
}

/// Matches two multisets of items, coordinates equal within [`TOL`]. Returns the
/// unmatched items of each side.
fn match_items(left: &[Item], right: &[Item]) -> (Vec<Item>, Vec<Item>) {
    type Bucket = Vec<(usize, bool)>;
    let mut buckets: HashMap<(Layer, bool, bool, usize), Bucket> = HashMap::new();
    for (i, it) in right.iter().enumerate() {
        buckets.entry(it.key()).or_default().push((i, false));
    }
    for b in buckets.values_mut() {
        b.sort_by(|x, y| right[x.0].pts[0].0.total_cmp(&right[y.0].pts[0].0));
    }
    let mut unmatched_left = Vec::new();
    for it in left {
        let Some(bucket) = buckets.get_mut(&it.key()) else {
            unmatched_left.push(it.clone());
            continue;
        };
        let x0 = it.pts[0].0;
        let start = bucket.partition_point(|&(j, _)| right[j].pts[0].0 < x0 - TOL);
        let mut found = false;
        for entry in &mut bucket[start..] {
            let cand = &right[entry.0];
            if cand.pts[0].0 > x0 + TOL {
                break;
            }
            if !entry.1
                && cand
                    .pts
                    .iter()
                    .zip(&it.pts)
                    .all(|(p, q)| (p.0 - q.0).abs() <= TOL && (p.1 - q.1).abs() <= TOL)
            {
                entry.1 = true;
                found = true;
                break;
            }
        }
        if !found {
            unmatched_left.push(it.clone());
        }
    }
    let unmatched_right = buckets
        .values()
        .flatten()
        .filter(|(_, used)| !used)
        .map(|&(j, _)| right[j].clone())
        .collect();
    (unmatched_left, unmatched_right)
}

/// Which reader [`check_dxf_matches_svg_read_by`] reads the DXF with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DxfReader {
    /// [`dxf_read::read_dxf`]: R12 conventions on the raw group codes, then the `dxf` crate.
    Rust,
    /// `tests/check_dxf.py`: ezdxf's strict read and audit, and the R12 conventions.
    Ezdxf,
}

/// Checks that a DXF sheet holds the same geometry as its SVG, read back by the Rust
/// reader on every machine and, when python3 has ezdxf, by ezdxf as well (see
/// [`check_dxf_matches_svg_read_by`]). Without ezdxf this fails when
/// `UNFOLD_REQUIRE_EZDXF=1` (as in CI) and otherwise prints one notice per test process.
pub fn check_dxf_matches_svg(dxf_path: &Path, svg_text: &str, height: f64) -> Result<(), String> {
    check_dxf_matches_svg_read_by(DxfReader::Rust, dxf_path, svg_text, height)?;
    if dxf_read::ezdxf_wanted()? {
        check_dxf_matches_svg_read_by(DxfReader::Ezdxf, dxf_path, svg_text, height)?;
    }
    Ok(())
}

/// Reads the DXF with `reader` (which also checks the R12 conventions: 7-bit ASCII,
/// $ACADVER AC1009, no group 100, POLYLINE … VERTEX* … SEQEND, layers CUT, SCORE,
/// SCORE-VALLEY, ENGRAVE with colours 1, 5, 3, 7, only POLYLINE, LINE and CIRCLE in
/// modelspace) and checks that it holds the same geometry as the SVG: the same multiset
/// of (layer, closed, points) polylines — LINE entities count as open two-point
/// polylines — and (layer, centre, radius) circles, with SVG y flipped to `height − y`
/// and coordinates equal within 1e-3 mm, points in the same order. Every entity must
/// carry its layer's colour.
pub fn check_dxf_matches_svg_read_by(
    reader: DxfReader,
    dxf_path: &Path,
    svg_text: &str,
    height: f64,
) -> Result<(), String> {
    let sheet = parse_svg(svg_text).map_err(|e| format!("SVG does not parse: {e}"))?;
    let (entities, by) = match reader {
        DxfReader::Rust => (
            dxf_read::read_dxf(dxf_path, &dxf_read::DEFAULT_LAYERS)?.entities,
            "the Rust reader",
        ),
        DxfReader::Ezdxf => (dxf_read::read_dxf_with_ezdxf(dxf_path)?, "ezdxf"),
    };
    let dxf =
        dxf_items(&entities).map_err(|e| format!("{} (read by {by}): {e}", dxf_path.display()))?;

    let mut svg: Vec<Item> = sheet
        .paths
        .iter()
        .map(|p| Item {
            layer: p.layer,
            circle: false,
            closed: p.closed,
            pts: p.points.iter().map(|&(x, y)| (x, height - y)).collect(),
        })
        .collect();
    svg.extend(sheet.circles.iter().map(|c| Item {
        layer: c.layer,
        circle: true,
        closed: true,
        pts: vec![(c.cx, height - c.cy), (c.r, c.r)],
    }));

    let (only_svg, only_dxf) = match_items(&svg, &dxf);
    if only_svg.is_empty() && only_dxf.is_empty() {
        return Ok(());
    }
    let mut msg = format!(
        "DXF {} (read by {by}) does not match the SVG ({} SVG items, {} DXF entities; coordinates compared after y' = {height} - y, tolerance {TOL}):",
        dxf_path.display(),
        svg.len(),
        dxf.len()
    );
    for (side, list) in [("only in SVG", &only_svg), ("only in DXF", &only_dxf)] {
        for it in list.iter().take(5) {
            msg.push_str(&format!("\n  {side}: {}", it.describe()));
        }
        if list.len() > 5 {
            msg.push_str(&format!("\n  {side}: … {} more", list.len() - 5));
        }
    }
    Err(msg)
}
