//! Reading the DXF sheets back, on every machine: [`read_dxf`] checks the R12
//! conventions of docs/LASER.md on the file's raw group codes, then reads it with the
//! `dxf` crate and lists its entities. [`read_dxf_with_ezdxf`] is the extra strict read
//! by a third party (`tests/check_dxf.py`, ezdxf), run when python3 has ezdxf, and
//! required when `UNFOLD_REQUIRE_EZDXF=1` (see [`ezdxf_wanted`]).
//!
//! Both give the same [`DxfEntity`] list; `check_dxf_matches_svg` compares each with the
//! SVG.

use std::collections::HashSet;
use std::io::{BufRead, BufReader, Write};
use std::path::Path;
use std::process::{Child, ChildStdout, Command, Stdio};
use std::sync::{Mutex, Once, OnceLock};

use dxf::entities::EntityType;
use dxf::enums::AcadVersion;
use dxf::{Color, Drawing};

use super::Pt;

/// The layers of an unfold sheet without a `[layers]` config, with their ACI colours.
pub const DEFAULT_LAYERS: [(&str, i64); 4] = [
    ("CUT", 1),
    ("SCORE", 5),
    ("SCORE-VALLEY", 3),
    ("ENGRAVE", 7),
];

/// One modelspace entity. LINEs are open two-point polylines; CIRCLEs have no points, a
/// centre and a radius.
#[derive(Debug, Clone, PartialEq)]
pub struct DxfEntity {
    /// "POLYLINE", "LINE" or "CIRCLE".
    pub kind: String,
    pub layer: String,
    pub closed: bool,
    pub points: Vec<Pt>,
    pub center: Option<Pt>,
    pub radius: Option<f64>,
    /// The entity's own ACI colour (group 62); `None` when it has none of its own.
    pub color: Option<i64>,
}

/// A DXF sheet as read back.
#[derive(Debug, Clone)]
pub struct DxfSheet {
    /// The LAYER table: name and colour (negative for a layer turned off), in file order.
    pub layers: Vec<(String, i64)>,
    /// The modelspace entities, in file order.
    pub entities: Vec<DxfEntity>,
}

/// Reads `path` strictly: the checks of `tests/check_dxf.py` without ezdxf.
///
/// * the file is 7-bit ASCII text (not binary DXF), its lines pair up as integer group
///   codes and values, every SECTION is named and ended by ENDSEC, and the file ends with
///   `0 EOF`;
/// * its HEADER sets `$ACADVER` to AC1009 (the `dxf` crate reads it as R12), and no R13+
///   subclass marker (group 100) appears anywhere;
/// * in ENTITIES every POLYLINE is followed by its VERTEX entities and a SEQEND, and the
///   only entities are POLYLINE, LINE and CIRCLE;
/// * the `dxf` crate reads the file, and finds the same number of entities;
/// * the LAYER table holds `layers` (name, colour), spelt exactly, and every entity is on
///   a layer of the table;
/// * paper space is empty and there are no user blocks;
/// * POLYLINEs are 2D/3D polylines (no polyface or mesh) of at least two vertices
///   without bulges, and CIRCLEs have a positive radius.
pub fn read_dxf(path: &Path, layers: &[(&str, i64)]) -> Result<DxfSheet, String> {
    let fail = |msg: String| format!("DXF {} rejected by the Rust reader: {msg}", path.display());
    let data = std::fs::read(path).map_err(|e| fail(format!("cannot read: {e}")))?;
    let raw = check_raw(&data).map_err(fail)?;
    let drawing = Drawing::load(&mut data.as_slice())
        .map_err(|e| fail(format!("the dxf crate cannot read it: {e}")))?;
    check_drawing(&drawing, raw, layers).map_err(fail)
}

/// One group code and its value, with the line number of the code (from 1).
struct Tag<'a> {
    code: i32,
    value: &'a str,
    line: usize,
}

/// The (code, value) pairs of an ASCII DXF.
fn raw_tags(text: &str) -> Result<Vec<Tag<'_>>, String> {
    let mut lines: Vec<&str> = text.split('\n').collect();
    if lines.last() == Some(&"") {
        lines.pop();
    }
    if !lines.len().is_multiple_of(2) {
        return Err(format!(
            "odd number of lines ({}): group codes and values must pair up",
            lines.len()
        ));
    }
    lines
        .chunks(2)
        .enumerate()
        .map(|(k, pair)| {
            let code = pair[0]
                .trim()
                .parse()
                .map_err(|_| format!("line {}: invalid group code {:?}", 2 * k + 1, pair[0]))?;
            Ok(Tag {
                code,
                value: pair[1].trim(),
                line: 2 * k + 1,
            })
        })
        .collect()
}

/// What the raw group codes say beyond the checks.
struct Raw {
    /// The LAYER table: name and colour (group 62, 7 when absent), in file order. Read
    /// here because the `dxf` crate adds a layer for every layer name an entity uses.
    layers: Vec<(String, i64)>,
    /// The number of entities in ENTITIES (VERTEX and SEQEND belong to their POLYLINE).
    entities: usize,
}

/// The checks on the raw group codes.
fn check_raw(data: &[u8]) -> Result<Raw, String> {
    if data.starts_with(b"AutoCAD Binary DXF") {
        return Err("binary DXF; expected ASCII".into());
    }
    if let Some(i) = data.iter().position(|&b| b >= 128) {
        return Err(format!(
            "non-ASCII byte 0x{:02X} at offset {i}: the file must be 7-bit ASCII",
            data[i]
        ));
    }
    let text = std::str::from_utf8(data).expect("ASCII is UTF-8");
    let tags = raw_tags(text)?;

    // $ACADVER in the HEADER
    let acadver = tags
        .iter()
        .position(|t| t.code == 9 && t.value == "$ACADVER")
        .and_then(|k| tags.get(k + 1))
        .map(|t| t.value)
        .ok_or("HEADER does not set $ACADVER (expected AC1009)")?;
    if acadver != "AC1009" {
        return Err(format!("$ACADVER is {acadver}, expected AC1009 (R12)"));
    }

    if let Some(t) = tags.iter().find(|t| t.code == 100) {
        return Err(format!(
            "line {}: subclass marker (group 100 {:?}) is not R12",
            t.line, t.value
        ));
    }

    // SECTION name ... ENDSEC, then EOF as the last pair
    let mut section: Option<(&str, usize)> = None;
    let mut seen = HashSet::new();
    for (k, t) in tags.iter().enumerate() {
        if t.code != 0 {
            continue;
        }
        match t.value {
            "SECTION" => {
                if let Some((name, line)) = section {
                    return Err(format!(
                        "line {}: SECTION {name} from line {line} is not ended by ENDSEC",
                        t.line
                    ));
                }
                let name = match tags.get(k + 1) {
                    Some(n) if n.code == 2 => n.value,
                    _ => return Err(format!("line {}: SECTION without a name (group 2)", t.line)),
                };
                if !["HEADER", "TABLES", "BLOCKS", "ENTITIES"].contains(&name) {
                    return Err(format!("line {}: unexpected section {name} in R12", t.line));
                }
                if !seen.insert(name) {
                    return Err(format!("line {}: a second {name} section", t.line));
                }
                section = Some((name, t.line));
            }
            "ENDSEC" if section.is_none() => {
                return Err(format!("line {}: ENDSEC outside a section", t.line));
            }
            "ENDSEC" => section = None,
            "EOF" => {
                if let Some((name, line)) = section {
                    return Err(format!(
                        "line {}: SECTION {name} from line {line} is not ended by ENDSEC",
                        t.line
                    ));
                }
                if k + 1 != tags.len() {
                    return Err(format!("line {}: group codes after EOF", t.line));
                }
            }
            _ if section.is_none() => {
                return Err(format!("line {}: {} outside a section", t.line, t.value));
            }
            _ => {}
        }
    }
    if !tags.last().is_some_and(|t| t.code == 0 && t.value == "EOF") {
        return Err("missing EOF tag: the file must end with 0 EOF".into());
    }

    // POLYLINE ... VERTEX* ... SEQEND structure and the entity types in ENTITIES
    let mut in_entities = false;
    let mut open_polyline: Option<usize> = None; // line of the POLYLINE waiting for SEQEND
    let mut entities = 0;
    for (k, t) in tags.iter().enumerate() {
        if t.code == 2 && k > 0 && tags[k - 1].code == 0 && tags[k - 1].value == "SECTION" {
            in_entities = t.value == "ENTITIES";
        }
        if t.code != 0 || !in_entities {
            continue;
        }
        if let Some(start) = open_polyline {
            match t.value {
                "SEQEND" => open_polyline = None,
                "VERTEX" => {}
                other => {
                    return Err(format!(
                    "line {}: POLYLINE from line {start} is not ended by SEQEND (found {other})",
                    t.line
                ))
                }
            }
            continue;
        }
        match t.value {
            "VERTEX" => return Err(format!("line {}: VERTEX outside a POLYLINE", t.line)),
            "SEQEND" => return Err(format!("line {}: SEQEND without POLYLINE", t.line)),
            "POLYLINE" => open_polyline = Some(t.line),
            "LINE" | "CIRCLE" => {}
            "ENDSEC" => {
                in_entities = false;
                continue;
            }
            other => {
                let layer = tags[k + 1..]
                    .iter()
                    .take_while(|t| t.code != 0)
                    .find(|t| t.code == 8)
                    .map_or("?", |t| t.value);
                return Err(format!(
                    "unexpected entity type {other} on layer {layer} (only POLYLINE, LINE, CIRCLE allowed)"
                ));
            }
        }
        entities += 1;
    }
    if let Some(start) = open_polyline {
        return Err(format!("POLYLINE from line {start} is not ended by SEQEND"));
    }
    Ok(Raw {
        layers: layer_table(&tags)?,
        entities,
    })
}

/// The entries of the LAYER table in TABLES: name (group 2) and colour (group 62).
fn layer_table(tags: &[Tag<'_>]) -> Result<Vec<(String, i64)>, String> {
    let mut layers = Vec::new();
    let mut section = "";
    let mut table = "";
    for (k, t) in tags.iter().enumerate() {
        let next = tags.get(k + 1);
        match (t.code, t.value) {
            (0, "SECTION") => section = next.map_or("", |n| n.value),
            (0, "ENDSEC") => section = "",
            (0, "TABLE") => table = next.map_or("", |n| n.value),
            (0, "ENDTAB") => table = "",
            (0, "LAYER") if section == "TABLES" && table == "LAYER" => {
                let fields: Vec<&Tag<'_>> =
                    tags[k + 1..].iter().take_while(|f| f.code != 0).collect();
                let name = fields
                    .iter()
                    .find(|f| f.code == 2)
                    .ok_or(format!("line {}: a LAYER entry without a name", t.line))?
                    .value;
                let colour = match fields.iter().find(|f| f.code == 62) {
                    Some(f) => f.value.parse().map_err(|_| {
                        format!("line {}: layer {name} has colour {:?}", f.line, f.value)
                    })?,
                    None => 7,
                };
                layers.push((name.to_string(), colour));
            }
            _ => {}
        }
    }
    Ok(layers)
}

/// An ACI colour as written (0 BYBLOCK, 256 BYLAYER).
fn aci(color: &Color) -> i64 {
    if let Some(i) = color.index() {
        i64::from(i)
    } else if color.is_by_layer() {
        256
    } else if color.is_by_block() {
        0
    } else {
        257
    }
}

fn xy(p: &dxf::Point) -> Pt {
    (p.x, p.y)
}

fn check_drawing(drawing: &Drawing, raw: Raw, layers: &[(&str, i64)]) -> Result<DxfSheet, String> {
    if drawing.header.version != AcadVersion::R12 {
        return Err(format!(
            "the dxf crate reads version {:?}, expected R12 (AC1009)",
            drawing.header.version
        ));
    }

    let table = raw.layers;
    let find = |name: &str| table.iter().find(|(n, _)| n.eq_ignore_ascii_case(name));
    for &(name, colour) in layers {
        let Some((spelt, c)) = find(name) else {
            return Err(format!("layer {name} is not defined in the LAYER table"));
        };
        if spelt != name {
            return Err(format!("layer {spelt:?} should be spelt {name:?}"));
        }
        if *c != colour {
            return Err(format!("layer {name} has colour {c}, expected {colour}"));
        }
    }

    let paper = drawing
        .entities()
        .filter(|e| e.common.is_in_paper_space)
        .count();
    if paper > 0 {
        return Err(format!("paper space holds {paper} entities; expected none"));
    }
    for block in drawing.blocks() {
        let name = block.name.to_ascii_uppercase();
        if name.starts_with("*PAPER_SPACE") && !block.entities.is_empty() {
            return Err(format!(
                "layout {:?} (paper space) holds {} entities; expected none",
                block.name,
                block.entities.len()
            ));
        }
        if name != "*MODEL_SPACE" && !name.starts_with("*PAPER_SPACE") {
            return Err(format!("unexpected block definition {:?}", block.name));
        }
    }

    let mut entities = Vec::new();
    for e in drawing.entities() {
        let layer = e.common.layer.clone();
        let color = match aci(&e.common.color) {
            256 => None,
            c => Some(c),
        };
        let mut item = DxfEntity {
            kind: String::new(),
            layer: layer.clone(),
            closed: false,
            points: Vec::new(),
            center: None,
            radius: None,
            color,
        };
        match &e.specific {
            EntityType::Polyline(p) => {
                item.kind = "POLYLINE".into();
                if p.flags & (16 | 64) != 0 {
                    return Err(format!(
                        "POLYLINE on layer {layer} is a polyface/mesh (flags {}), expected a 2D/3D polyline",
                        p.flags
                    ));
                }
                if let Some(v) = p.vertices().find(|v| v.bulge != 0.0) {
                    return Err(format!(
                        "POLYLINE on layer {layer} has a vertex with bulge {}; arcs are not expected",
                        v.bulge
                    ));
                }
                item.closed = p.is_closed();
                item.points = p.vertices().map(|v| xy(&v.location)).collect();
                if item.points.len() < 2 {
                    return Err(format!(
                        "POLYLINE on layer {layer} has {} vertices, expected at least 2",
                        item.points.len()
                    ));
                }
            }
            EntityType::Line(l) => {
                item.kind = "LINE".into();
                item.points = vec![xy(&l.p1), xy(&l.p2)];
            }
            EntityType::Circle(c) => {
                item.kind = "CIRCLE".into();
                item.closed = true;
                item.center = Some(xy(&c.center));
                item.radius = Some(c.radius);
                if c.radius.is_nan() || c.radius <= 0.0 {
                    return Err(format!(
                        "CIRCLE on layer {layer} has radius {}, expected > 0",
                        c.radius
                    ));
                }
            }
            other => {
                let name = format!("{other:?}");
                let name = name.split(['(', ' ', '{']).next().unwrap_or("?");
                return Err(format!(
                    "unexpected entity type {name} on layer {layer} (only POLYLINE, LINE, CIRCLE allowed)"
                ));
            }
        }
        if find(&layer).is_none() {
            return Err(format!(
                "{} on layer {layer:?}, which is not defined in the LAYER table",
                item.kind
            ));
        }
        entities.push(item);
    }
    if entities.len() != raw.entities {
        return Err(format!(
            "the dxf crate reads {} entities where the ENTITIES section holds {}",
            entities.len(),
            raw.entities
        ));
    }
    Ok(DxfSheet {
        layers: table,
        entities,
    })
}

// ezdxf
// =======================================================================================

const REQUIRE: &str = "UNFOLD_REQUIRE_EZDXF";

/// Whether `python3 -c "import ezdxf"` works (asked once per test process); the reason
/// when it does not.
pub fn ezdxf_available() -> Result<(), String> {
    static AVAILABLE: OnceLock<Result<(), String>> = OnceLock::new();
    AVAILABLE
        .get_or_init(|| {
            let out = Command::new("python3")
                .args(["-c", "import ezdxf"])
                .output()
                .map_err(|e| format!("cannot run python3: {e}"))?;
            if out.status.success() {
                Ok(())
            } else {
                let stderr = String::from_utf8_lossy(&out.stderr);
                Err(format!(
                    "python3 cannot import ezdxf: {}",
                    stderr.lines().last().unwrap_or("").trim()
                ))
            }
        })
        .clone()
}

/// Whether to run ezdxf's strict read as well as the Rust reader: yes when python3 has
/// ezdxf. Without it, an error when `UNFOLD_REQUIRE_EZDXF=1` (as in CI); otherwise no,
/// with one notice per test process.
pub fn ezdxf_wanted() -> Result<bool, String> {
    let Err(why) = ezdxf_available() else {
        return Ok(true);
    };
    if std::env::var(REQUIRE).is_ok_and(|v| v == "1") {
        return Err(format!(
            "{REQUIRE}=1 but the strict DXF read by ezdxf cannot run ({why}): \
             install python3 and `python3 -m pip install ezdxf`"
        ));
    }
    static NOTICE: Once = Once::new();
    NOTICE.call_once(|| {
        eprintln!(
            "ezdxf not found ({why}): the strict third-party DXF read is skipped \
             (pip install ezdxf, or {REQUIRE}=1 to require it)"
        );
    });
    Ok(false)
}

/// A `python3 tests/check_dxf.py --serve` process: a path in, a line of JSON out.
struct Ezdxf {
    child: Child,
    answers: BufReader<ChildStdout>,
}

impl Ezdxf {
    fn start() -> Result<Self, String> {
        let script = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests")
            .join("check_dxf.py");
        // ezdxf imports numpy, whose OpenBLAS otherwise starts a spinning thread per
        // core: a share of the suite's time for no work.
        let mut child = Command::new("python3")
            .arg(&script)
            .arg("--serve")
            .env("OPENBLAS_NUM_THREADS", "1")
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            // Rejections come back as answers; an inherited stderr would keep the
            // test's output open after the test, until the process ends.
            .stderr(Stdio::null())
            .spawn()
            .map_err(|e| format!("cannot run python3 for tests/check_dxf.py: {e}"))?;
        let answers = BufReader::new(child.stdout.take().expect("a piped stdout"));
        Ok(Self { child, answers })
    }

    /// ezdxf's answer for `path`: its entities or why it rejects the file.
    fn ask(&mut self, path: &Path) -> Result<String, String> {
        let stdin = self.child.stdin.as_mut().expect("a piped stdin");
        let gone = |e: std::io::Error| format!("tests/check_dxf.py --serve stopped: {e}");
        writeln!(stdin, "{}", path.display()).map_err(gone)?;
        stdin.flush().map_err(gone)?;
        let mut line = String::new();
        match self.answers.read_line(&mut line) {
            // Its stderr is closed, so its exit status is what is left to name.
            Ok(0) => Err(format!(
                "tests/check_dxf.py --serve stopped without an answer ({})",
                self.child
                    .wait()
                    .map_or_else(|e| e.to_string(), |status| status.to_string())
            )),
            Ok(_) => Ok(line),
            Err(e) => Err(gone(e)),
        }
    }
}

/// Reads `path` with ezdxf (`tests/check_dxf.py`: its strict read and audit, and the
/// R12 conventions with the default layers) and returns the entities it lists. The
/// test process keeps its ezdxf processes for later reads: starting Python and
/// importing ezdxf takes longer than reading most sheets.
pub fn read_dxf_with_ezdxf(path: &Path) -> Result<Vec<DxfEntity>, String> {
    static IDLE: Mutex<Vec<Ezdxf>> = Mutex::new(Vec::new());
    let idle = IDLE.lock().unwrap_or_else(|e| e.into_inner()).pop();
    let mut ezdxf = match idle {
        Some(ezdxf) => ezdxf,
        None => Ezdxf::start()?,
    };
    let answer = ezdxf.ask(path)?;
    IDLE.lock().unwrap_or_else(|e| e.into_inner()).push(ezdxf);
    let json: serde_json::Value = serde_json::from_str(&answer)
        .map_err(|e| format!("check_dxf.py printed invalid JSON: {e}"))?;
    if let Some(why) = json.get("rejected") {
        return Err(format!(
            "DXF {} rejected by tests/check_dxf.py (ezdxf): {}",
            path.display(),
            why.as_str().unwrap_or_default()
        ));
    }
    let list = json
        .get("entities")
        .and_then(|l| l.as_array())
        .ok_or("check_dxf.py answered without an entities list")?;
    let pt = |v: &serde_json::Value| -> Option<Pt> {
        let a = v.as_array()?;
        Some((a.first()?.as_f64()?, a.get(1)?.as_f64()?))
    };
    list.iter()
        .enumerate()
        .map(|(i, e)| {
            let bad = || format!("check_dxf.py entity #{i}: malformed output {e}");
            let field = |k: &str| e.get(k).unwrap_or(&serde_json::Value::Null);
            Ok(DxfEntity {
                kind: field("type").as_str().ok_or_else(bad)?.to_string(),
                layer: field("layer").as_str().ok_or_else(bad)?.to_string(),
                closed: field("closed").as_bool().ok_or_else(bad)?,
                points: field("points")
                    .as_array()
                    .ok_or_else(bad)?
                    .iter()
                    .map(pt)
                    .collect::<Option<_>>()
                    .ok_or_else(bad)?,
                center: match field("center") {
                    serde_json::Value::Null => None,
                    c => Some(pt(c).ok_or_else(bad)?),
                },
                radius: match field("radius") {
                    serde_json::Value::Null => None,
                    r => Some(r.as_f64().ok_or_else(bad)?),
                },
                color: field("color").as_i64(),
            })
        })
        .collect()
}
