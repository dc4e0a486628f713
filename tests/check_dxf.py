#!/usr/bin/env python3
"""Independent checker for the R12 DXF sheets written by `unfold`.

Usage: python3 tests/check_dxf.py FILE.dxf
       python3 tests/check_dxf.py --serve

With --serve it reads one path per line on stdin and answers each with one line
of JSON on stdout: {"entities": [...]} or {"rejected": "reason"}; the tests keep
such processes for all their reads, which spares them starting Python and
importing ezdxf for every file.

Reads FILE.dxf with ezdxf in its normal (strict, non-recover) mode, runs the
auditor, checks the conventions of docs/LASER.md and prints the entities as
JSON on stdout:

    [{"layer": "CUT", "type": "POLYLINE", "closed": true,
      "points": [[x, y], ...], "center": null, "radius": null, "color": 1}, ...]

CIRCLE entities have "points": [], "closed": true, "center": [x, y] and "radius".
LINE entities are reported as open two-point polylines (type "LINE").

Exit status: 0 ok, 1 the file is rejected (reason on stderr), 2 usage error,
3 ezdxf is not installed (install it with `pip install ezdxf`).

Checks, beyond what ezdxf itself enforces:
  * the file is 7-bit ASCII and its HEADER sets $ACADVER to AC1009, and
    doc.dxfversion == "AC1009";
  * doc.audit() reports no errors and no fixes (a fix means the file as
    written needed repairing);
  * layers CUT, SCORE, SCORE-VALLEY, ENGRAVE exist with colours 1, 5, 3, 7;
  * raw tag structure of the ENTITIES section: every POLYLINE is followed by
    its VERTEX entities and a SEQEND (ezdxf would silently accept a missing
    SEQEND), and no R13+ subclass markers (group code 100) appear anywhere;
  * modelspace holds only POLYLINE (2D/3D, no bulges), LINE and CIRCLE; paper
    space is empty and there are no user blocks.
"""

import json
import sys

LAYER_COLOURS = {"CUT": 1, "SCORE": 5, "SCORE-VALLEY": 3, "ENGRAVE": 7}


class Rejected(Exception):
    """The file breaks a rule; the message says which."""


def fail(msg):
    raise Rejected(msg)


def raw_tags(data):
    """(code, value) pairs of an ASCII DXF."""
    lines = data.split("\n")
    if lines and lines[-1] == "":
        lines.pop()
    if len(lines) % 2 != 0:
        fail(f"odd number of lines ({len(lines)}): group codes and values must pair up")
    tags = []
    for i in range(0, len(lines), 2):
        code = lines[i].strip()
        try:
            code = int(code)
        except ValueError:
            fail(f"line {i + 1}: invalid group code {lines[i]!r}")
        tags.append((code, lines[i + 1].strip(), i + 1))
    return tags


def check_raw(path):
    with open(path, "rb") as f:
        data = f.read()
    if data.startswith(b"AutoCAD Binary DXF"):
        fail("binary DXF; expected ASCII")
    if not data.isascii():
        i = next(i for i, b in enumerate(data) if b >= 128)
        fail(f"non-ASCII byte 0x{data[i]:02X} at offset {i}: the file must be 7-bit ASCII")
    tags = raw_tags(data.decode("ascii"))

    # $ACADVER in the HEADER
    acadver = None
    for k, (code, value, _) in enumerate(tags):
        if code == 9 and value == "$ACADVER" and k + 1 < len(tags):
            acadver = tags[k + 1][1]
            break
    if acadver is None:
        fail("HEADER does not set $ACADVER (expected AC1009)")
    if acadver != "AC1009":
        fail(f"$ACADVER is {acadver}, expected AC1009 (R12)")

    for code, value, line in tags:
        if code == 100:
            fail(f"line {line}: subclass marker (group 100 {value!r}) is not R12")

    # POLYLINE ... VERTEX* ... SEQEND structure in ENTITIES
    in_entities = False
    open_polyline = None  # line number of the POLYLINE waiting for SEQEND
    prev = None
    for code, value, line in tags:
        if code == 2 and prev == (0, "SECTION"):
            in_entities = value == "ENTITIES"
        if code == 0:
            prev = (0, value)
            if not in_entities:
                continue
            if open_polyline is not None:
                if value == "SEQEND":
                    open_polyline = None
                elif value != "VERTEX":
                    fail(f"line {line}: POLYLINE from line {open_polyline} is not ended by SEQEND (found {value})")
            else:
                if value == "VERTEX":
                    fail(f"line {line}: VERTEX outside a POLYLINE")
                if value == "SEQEND":
                    fail(f"line {line}: SEQEND without POLYLINE")
                if value == "POLYLINE":
                    open_polyline = line
        else:
            prev = (code, value)
    if open_polyline is not None:
        fail(f"POLYLINE from line {open_polyline} is not ended by SEQEND")


def xy(v):
    return [float(v[0]), float(v[1])]


def check(path, ezdxf):
    """The entities of the DXF at `path` after every check; raises Rejected."""
    try:
        check_raw(path)
    except OSError as e:
        fail(f"cannot read {path}: {e}")

    try:
        doc = ezdxf.readfile(path)
    except IOError as e:
        fail(f"cannot read {path}: {e}")
    except ezdxf.DXFStructureError as e:
        fail(f"ezdxf.readfile rejected {path}: {e}")
    except Exception as e:  # any other reader failure
        fail(f"ezdxf.readfile failed on {path}: {type(e).__name__}: {e}")

    if doc.dxfversion != "AC1009":
        fail(f"dxfversion is {doc.dxfversion}, expected AC1009 (R12)")

    auditor = doc.audit()
    problems = [f"error: {e.message}" for e in auditor.errors]
    problems += [f"fix: {e.message}" for e in auditor.fixes]
    if problems:
        fail("audit reported problems:\n  " + "\n  ".join(problems))

    for name, colour in LAYER_COLOURS.items():
        if not doc.layers.has_entry(name):
            fail(f"layer {name} is not defined in the LAYER table")
        layer = doc.layers.get(name)
        if layer.dxf.name != name:
            fail(f"layer {layer.dxf.name!r} should be spelt {name!r}")
        if layer.dxf.color != colour:
            fail(f"layer {name} has colour {layer.dxf.color}, expected {colour}")

    for layout in doc.layouts:
        if not layout.is_modelspace and len(layout) > 0:
            fail(f"layout {layout.name!r} (paper space) holds {len(layout)} entities; expected none")
    for block in doc.blocks:
        if not block.is_any_layout:
            fail(f"unexpected block definition {block.name!r}")

    out = []
    for e in doc.modelspace():
        t = e.dxftype()
        layer = e.dxf.layer
        color = e.dxf.color if e.dxf.hasattr("color") else None
        if not doc.layers.has_entry(layer):
            fail(f"{t} on layer {layer!r}, which is not defined in the LAYER table")
        item = {"layer": layer, "type": t, "closed": False, "points": [],
                "center": None, "radius": None, "color": color}
        if t == "POLYLINE":
            if not (e.is_2d_polyline or e.is_3d_polyline):
                fail(f"POLYLINE on layer {layer} is a polyface/mesh, expected a 2D/3D polyline")
            for v in e.vertices:
                if v.dxf.hasattr("bulge") and v.dxf.bulge != 0:
                    fail(f"POLYLINE on layer {layer} has a vertex with bulge {v.dxf.bulge}; arcs are not expected")
            item["closed"] = bool(e.is_closed)
            item["points"] = [xy(v.dxf.location) for v in e.vertices]
            if len(item["points"]) < 2:
                fail(f"POLYLINE on layer {layer} has {len(item['points'])} vertices, expected at least 2")
        elif t == "LINE":
            item["points"] = [xy(e.dxf.start), xy(e.dxf.end)]
        elif t == "CIRCLE":
            item["closed"] = True
            item["center"] = xy(e.dxf.center)
            item["radius"] = float(e.dxf.radius)
            if not item["radius"] > 0:
                fail(f"CIRCLE on layer {layer} has radius {item['radius']}, expected > 0")
        else:
            fail(f"unexpected entity type {t} on layer {layer} (only POLYLINE, LINE, CIRCLE allowed)")
        out.append(item)

    return out


def serve(ezdxf):
    for line in sys.stdin:
        path = line.rstrip("\n")
        try:
            answer = {"entities": check(path, ezdxf)}
        except Rejected as e:
            answer = {"rejected": str(e)}
        except Exception as e:  # a reader failure the checks do not name
            answer = {"rejected": f"{type(e).__name__}: {e}"}
        # One string: json.dump streams through the pure-Python encoder, dumps uses the C one.
        sys.stdout.write(json.dumps(answer))
        sys.stdout.write("\n")
        sys.stdout.flush()


def main():
    if len(sys.argv) != 2:
        print("usage: check_dxf.py FILE.dxf | --serve", file=sys.stderr)
        sys.exit(2)
    try:
        import ezdxf
    except ImportError:
        print("check_dxf: the Python package ezdxf is not installed; install it with `pip install ezdxf`",
              file=sys.stderr)
        sys.exit(3)
    if sys.argv[1] == "--serve":
        serve(ezdxf)
        return
    try:
        out = check(sys.argv[1], ezdxf)
    except Rejected as e:
        print(f"check_dxf: {e}", file=sys.stderr)
        sys.exit(1)
    sys.stdout.write(json.dumps(out))
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
