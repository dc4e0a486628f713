//! What a layout is made of, below both nesters: the sheet and its clearances, where a
//! part goes, the finished layout, the progress the search reports and the part that
//! cannot fit.

use std::sync::atomic::{AtomicU32, Ordering};

use glam::DVec2;

/// The sheet and the clearances every layout must respect (mm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SheetSpec {
    /// Width.
    pub width: f64,
    /// Height.
    pub height: f64,
    /// Empty border on every edge.
    pub margin: f64,
    /// Smallest gap between two parts.
    pub spacing: f64,
}

impl SheetSpec {
    /// Usable width inside the margins.
    pub fn usable_width(&self) -> f64 {
        self.width - 2.0 * self.margin
    }

    /// Usable height inside the margins.
    pub fn usable_height(&self) -> f64 {
        self.height - 2.0 * self.margin
    }
}

/// A `w` × `h` rectangle with a corner at the origin (counter-clockwise), for the
/// nesters' tests.
#[cfg(test)]
pub(crate) fn test_rectangle(w: f64, h: f64) -> Vec<DVec2> {
    vec![
        DVec2::new(0.0, 0.0),
        DVec2::new(w, 0.0),
        DVec2::new(w, h),
        DVec2::new(0.0, h),
    ]
}

/// Where one part goes: rotate about the part's origin, then translate.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Placement {
    /// Index of the part in the input list.
    pub part: usize,
    /// Sheet index (0-based).
    pub sheet: usize,
    /// Rotation, radians counter-clockwise.
    pub rotation: f64,
    /// Translation after rotation (mm).
    pub translation: DVec2,
    /// Mirrored (y negated) before the rotation: the part is cut face down.
    pub mirrored: bool,
}

impl Placement {
    /// A part point on the sheet.
    pub fn apply(&self, p: DVec2) -> DVec2 {
        self.apply_direction(p) + self.translation
    }

    /// A part direction on the sheet.
    pub fn apply_direction(&self, d: DVec2) -> DVec2 {
        let d = if self.mirrored {
            DVec2::new(d.x, -d.y)
        } else {
            d
        };
        DVec2::from_angle(self.rotation).rotate(d)
    }
}

/// A finished layout: every part placed once.
#[derive(Clone, Debug, PartialEq)]
pub struct Layout {
    /// The sheet.
    pub sheet: SheetSpec,
    /// Number of sheets used.
    pub sheets: usize,
    /// One placement per part, in part order.
    pub placements: Vec<Placement>,
}

impl Layout {
    /// Renumbers the sheets so the fullest (by the parts' `areas`) comes first, the
    /// emptiest last; equal sheets keep their order.
    pub fn fullest_first(&mut self, areas: &[f64]) {
        let mut fill = vec![0.0; self.sheets];
        for p in &self.placements {
            fill[p.sheet] += areas[p.part];
        }
        let mut order: Vec<usize> = (0..self.sheets).collect();
        order.sort_by(|&a, &b| fill[b].total_cmp(&fill[a]).then(a.cmp(&b)));
        let mut rank = vec![0; self.sheets];
        for (r, &s) in order.iter().enumerate() {
            rank[s] = r;
        }
        for p in &mut self.placements {
            p.sheet = rank[p.sheet];
        }
    }
}

/// How far a layout has got, for a progress display: the share done of each of the
/// true-shape nester's three phases (two searches, each a construction and its
/// improvement, then the squeeze of the better one), in thousandths, and whom to tell
/// when it grows. The layout never reads it back, so a display changes
/// nothing in the result.
pub struct NestProgress<'a> {
    shares: [AtomicU32; 3],
    tell: &'a (dyn Fn(f64) + Sync),
}

impl<'a> NestProgress<'a> {
    /// Nothing done yet; `tell` hears the fraction done (0 to 1) each time it grows.
    pub fn new(tell: &'a (dyn Fn(f64) + Sync)) -> Self {
        NestProgress {
            shares: Default::default(),
            tell,
        }
    }

    /// Phase `phase` (0 to 2) has done `thousandths` of its work.
    pub(crate) fn set(&self, phase: usize, thousandths: u32) {
        let thousandths = thousandths.min(1000);
        if self.shares[phase].fetch_max(thousandths, Ordering::Relaxed) < thousandths {
            let done: u32 = self.shares.iter().map(|s| s.load(Ordering::Relaxed)).sum();
            (self.tell)(f64::from(done) / 3000.0);
        }
    }
}

/// A part too large for the sheet.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("part {part} is {width:.1} x {height:.1} mm at its most compact rotation and does not fit the usable {usable_width:.1} x {usable_height:.1} mm of the sheet")]
pub struct TooLarge {
    /// Index of the part.
    pub part: usize,
    /// Its smallest bounding box.
    pub width: f64,
    /// Its smallest bounding box.
    pub height: f64,
    /// The sheet's usable width.
    pub usable_width: f64,
    /// The sheet's usable height.
    pub usable_height: f64,
}
