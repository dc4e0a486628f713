//! Generators shared by the broken-input corpora (`tests/bad_inputs.rs` through
//! `unfold inspect`, `tests/bad_builds.rs` through the main command) and the check of
//! what a refused run prints.

use super::build::Run;

/// A unit cube: 8 vertices, 6 quads, outward.
pub const CUBE: &str = "\
v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1
f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8
";

/// Pseudo-random bytes (xorshift), the same on every run.
pub fn random_bytes(len: usize, mut seed: u64) -> Vec<u8> {
    (0..len)
        .map(|_| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 24) as u8
        })
        .collect()
}

/// A binary STL: 80-byte header, the announced triangle count, then 50-byte records
/// (normal, three corners, attribute count).
pub fn binary_stl(header: &[u8], announced: u32, triangles: &[[[f32; 3]; 3]]) -> Vec<u8> {
    let mut bytes = header.to_vec();
    bytes.resize(80, b' ');
    bytes.extend_from_slice(&announced.to_le_bytes());
    for triangle in triangles {
        for x in [0.0f32, 0.0, 1.0].iter().chain(triangle.iter().flatten()) {
            bytes.extend_from_slice(&x.to_le_bytes());
        }
        bytes.extend_from_slice(&[0, 0]);
    }
    bytes
}

pub const TWO_TRIANGLES: [[[f32; 3]; 3]; 2] = [
    [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
    [[1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
];

/// A Möbius strip of `n` quads: a band whose ends are joined with a half twist
/// (`2n` vertices, faces on lines `2n+1`…`3n`).
pub fn moebius_obj(n: usize) -> String {
    let mut s = String::new();
    for i in 0..n {
        let a = std::f64::consts::TAU * i as f64 / n as f64;
        let t = a / 2.0;
        for side in [-1.0, 1.0] {
            let r = 2.0 + 0.5 * side * t.cos();
            s += &format!(
                "v {} {} {}\n",
                r * a.cos(),
                r * a.sin(),
                0.5 * side * t.sin()
            );
        }
    }
    for i in 0..n {
        let (a0, a1) = (2 * i + 1, 2 * i + 2);
        // The last quad joins the first rung upside down: the half twist.
        let (b0, b1) = if i + 1 < n {
            (2 * i + 3, 2 * i + 4)
        } else {
            (2, 1)
        };
        s += &format!("f {a0} {b0} {b1} {a1}\n");
    }
    s
}

/// The first lines of a long stderr (a panic's backtrace), for failure messages.
pub fn head(text: &str) -> String {
    text.lines().take(12).collect::<Vec<_>>().join("\n")
}

/// No panic, exit `code`, nothing on stdout, one line `unfold: error: …` on stderr
/// containing every fragment of `says`.
pub fn assert_clean_error(case: &str, run: &Run, code: i32, says: &[&str]) {
    let err = &run.stderr;
    assert!(
        !err.contains("panicked") && !run.stdout.contains("panicked"),
        "{case}: panic (exit {:?}):\n{}",
        run.code,
        head(err)
    );
    assert_eq!(
        run.code,
        Some(code),
        "{case}: exit code; stderr:\n{}",
        head(err)
    );
    assert!(run.stdout.is_empty(), "{case}: stdout: {}", run.stdout);
    assert_eq!(
        err.lines().count(),
        1,
        "{case}: stderr is not one line: {err:?}"
    );
    assert!(
        err.ends_with('\n'),
        "{case}: stderr does not end the line: {err:?}"
    );
    assert!(
        err.starts_with("unfold: error: "),
        "{case}: prefix: {err:?}"
    );
    for fragment in says {
        assert!(
            err.contains(fragment),
            "{case}: does not say {fragment:?}: {err}"
        );
    }
}
