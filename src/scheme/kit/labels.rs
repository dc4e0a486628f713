//! The labels of a panel cut from one flat outline (a face, or a face cut back in
//! rigid sheet): its id along its longest side, each partner's id inside the side it
//! joins at.

use glam::DVec3;

use crate::panel::{Label, LabelKind, Name};

/// The labels of a panel of outline `points`: its id at `anchor`, along the longest
/// side; each partner's id inside the side `(k, partner)` it joins at.
pub(in crate::scheme) fn outline_labels(
    id: Name,
    anchor: DVec3,
    points: &[DVec3],
    partners: impl Iterator<Item = (usize, Name)>,
    height: f64,
) -> Vec<Label> {
    let n = points.len();
    let mut labels = vec![Label {
        text: id,
        anchor,
        direction: longest_side_direction(points),
        height,
        facet: 0,
        kind: LabelKind::Panel,
        on_edge: false,
        slide: 0.0,
    }];
    for (k, partner) in partners {
        let (a, b) = (points[k], points[(k + 1) % n]);
        labels.push(Label {
            text: partner,
            anchor: 0.5 * (a + b),
            direction: (b - a).normalize(),
            height,
            facet: 0,
            kind: LabelKind::Partner,
            on_edge: true,
            // Room to dodge the holes of a tab arriving on this edge.
            slide: 0.3 * a.distance(b),
        });
    }
    labels
}

/// The direction of a polygon's longest side (the first of equal ones), along which a
/// panel's id reads: the side a builder sees first.
pub(in crate::scheme) fn longest_side_direction(points: &[DVec3]) -> DVec3 {
    let n = points.len();
    let longest = (0..n)
        .max_by(|&i, &j| {
            let li = points[i].distance(points[(i + 1) % n]);
            let lj = points[j].distance(points[(j + 1) % n]);
            li.total_cmp(&lj).then(j.cmp(&i))
        })
        .unwrap_or(0);
    (points[(longest + 1) % n] - points[longest]).normalize()
}
