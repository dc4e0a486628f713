//! Small geometric measures on polygons in 3D.

use glam::{DMat3, DVec2, DVec3};

/// A plane with axes, to carry 3D points on it into 2D and back.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlaneFrame {
    /// The point at (0, 0).
    pub origin: DVec3,
    /// Unit normal.
    pub normal: DVec3,
    /// Unit x axis, in the plane.
    pub x: DVec3,
    /// Unit y axis, normal × x.
    pub y: DVec3,
}

impl PlaneFrame {
    /// The frame at `origin` of the plane of unit `normal`, with `x` (a unit vector in
    /// the plane) as its x axis.
    pub fn with_x(origin: DVec3, normal: DVec3, x: DVec3) -> Self {
        PlaneFrame {
            origin,
            normal,
            x,
            y: normal.cross(x),
        }
    }

    /// The frame at `origin` of the plane of unit `normal`, with any x axis: for
    /// shapes whose 2D orientation does not matter.
    pub fn new(origin: DVec3, normal: DVec3) -> Self {
        Self::with_x(origin, normal, normal.any_orthonormal_vector())
    }

    /// `p` projected onto the plane, in the frame's 2D coordinates.
    pub fn flat(&self, p: DVec3) -> DVec2 {
        let d = p - self.origin;
        DVec2::new(d.dot(self.x), d.dot(self.y))
    }

    /// The point of the plane at 2D coordinates `q`.
    pub fn lift(&self, q: DVec2) -> DVec3 {
        self.origin + q.x * self.x + q.y * self.y
    }
}

/// Half the sum of the corner cross products: for a planar polygon, its length is the
/// area and its direction the normal (right-hand rule), concave polygons included.
pub fn vector_area(corners: impl IntoIterator<Item = DVec3>) -> DVec3 {
    let mut iter = corners.into_iter();
    let Some(first) = iter.next() else {
        return DVec3::ZERO;
    };
    // Cross products taken relative to the first corner keep precision for polygons far
    // from the origin.
    let mut sum = DVec3::ZERO;
    let mut prev = DVec3::ZERO;
    for p in iter {
        let d = p - first;
        sum += prev.cross(d);
        prev = d;
    }
    0.5 * sum
}

/// The axis-aligned bounding box of points: (lower corner, upper corner). Empty input
/// gives (+∞, −∞).
pub fn bounding_box(points: impl IntoIterator<Item = DVec3>) -> (DVec3, DVec3) {
    points.into_iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(p), hi.max(p)),
    )
}

/// The least-squares plane through points: (centroid, unit normal). The normal is the
/// eigenvector of the covariance matrix with the smallest eigenvalue, oriented to agree
/// with the polygon's vector area so it points outward for a face.
pub fn best_fit_plane(points: &[DVec3]) -> (DVec3, DVec3) {
    let n = points.len().max(1) as f64;
    let centroid = points.iter().copied().sum::<DVec3>() / n;
    let mut cov = DMat3::ZERO;
    for &p in points {
        let d = p - centroid;
        cov += DMat3::from_cols(d * d.x, d * d.y, d * d.z);
    }
    let (values, vectors) = symmetric_eigen(cov);
    let smallest = (0..3)
        .min_by(|&a, &b| values[a].total_cmp(&values[b]))
        .unwrap_or(0);
    let mut normal = vectors.col(smallest).normalize_or_zero();
    if normal.dot(vector_area(points.iter().copied())) < 0.0 {
        normal = -normal;
    }
    (centroid, normal)
}

/// The largest distance between two of the points (the polygon's diameter). Exact up
/// to 64 points; beyond that the bounding-box diagonal (within a factor √3), so a
/// polygon with thousands of corners costs O(n), not O(n²).
pub fn diameter(points: &[DVec3]) -> f64 {
    if points.len() > 64 {
        let (lo, hi) = bounding_box(points.iter().copied());
        return (hi - lo).length();
    }
    let mut best = 0.0f64;
    for (i, a) in points.iter().enumerate() {
        for b in &points[i + 1..] {
            best = best.max(a.distance_squared(*b));
        }
    }
    best.sqrt()
}

/// Planarity error of a polygon: the largest distance of a corner to its best-fit
/// plane, divided by the polygon's diameter (0 for triangles and planar polygons).
pub fn planarity_error(points: &[DVec3]) -> f64 {
    if points.len() <= 3 {
        return 0.0;
    }
    let size = diameter(points);
    if size == 0.0 {
        return 0.0;
    }
    let (centroid, normal) = best_fit_plane(points);
    let off_plane = points
        .iter()
        .map(|&p| (p - centroid).dot(normal).abs())
        .fold(0.0, f64::max);
    off_plane / size
}

/// Eigen-decomposition of a symmetric 3×3 matrix by cyclic Jacobi rotations: returns
/// eigenvalues and the matrix whose columns are the matching unit eigenvectors. Jacobi
/// is slower than a closed form but accurate for the nearly singular covariance
/// matrices of nearly planar faces, which is exactly where planarity is decided.
pub fn symmetric_eigen(m: DMat3) -> ([f64; 3], DMat3) {
    let mut a = m.to_cols_array_2d(); // a[col][row]; symmetric, so a[i][j] = a[j][i]
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _sweep in 0..32 {
        let off = a[0][1].abs() + a[0][2].abs() + a[1][2].abs();
        let scale = a[0][0].abs() + a[1][1].abs() + a[2][2].abs();
        if off == 0.0 || off <= f64::EPSILON * f64::EPSILON * scale {
            break;
        }
        for (p, q) in [(0usize, 1usize), (0, 2), (1, 2)] {
            if a[p][q] == 0.0 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let t = if theta == 0.0 { 1.0 } else { t };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            for col in a.iter_mut() {
                let (akp, akq) = (col[p], col[q]);
                col[p] = c * akp - s * akq;
                col[q] = s * akp + c * akq;
            }
            let (row_p, row_q) = (a[p], a[q]);
            for k in 0..3 {
                a[p][k] = c * row_p[k] - s * row_q[k];
                a[q][k] = s * row_p[k] + c * row_q[k];
            }
            for row in &mut v {
                let (vp, vq) = (row[p], row[q]);
                row[p] = c * vp - s * vq;
                row[q] = s * vp + c * vq;
            }
        }
    }
    let values = [a[0][0], a[1][1], a[2][2]];
    // v[row][col]: column k is the k-th eigenvector.
    let vectors = DMat3::from_cols(
        DVec3::new(v[0][0], v[1][0], v[2][0]),
        DVec3::new(v[0][1], v[1][1], v[2][1]),
        DVec3::new(v[0][2], v[1][2], v[2][2]),
    );
    (values, vectors)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vector_area_of_concave_l_shape() {
        // An L made of three unit squares, counter-clockwise in the z = 0 plane.
        let l = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(2.0, 1.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(1.0, 2.0, 0.0),
            DVec3::new(0.0, 2.0, 0.0),
        ];
        let a = vector_area(l);
        assert!((a - DVec3::new(0.0, 0.0, 3.0)).length() < 1e-12);
    }

    #[test]
    fn eigen_decomposition_reconstructs_matrix() {
        let m = DMat3::from_cols(
            DVec3::new(4.0, 1.0, -2.0),
            DVec3::new(1.0, 3.0, 0.5),
            DVec3::new(-2.0, 0.5, 1.0),
        );
        let (values, vectors) = symmetric_eigen(m);
        for (k, &value) in values.iter().enumerate() {
            let v = vectors.col(k);
            assert!((m * v - value * v).length() < 1e-12, "eigenpair {k}");
            assert!((v.length() - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn planarity_of_tilted_planar_and_warped_quads() {
        let rotation = DMat3::from_euler(glam::EulerRot::XYZ, 0.3, -1.1, 2.0);
        let flat = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
        ]
        .map(|p| rotation * p + DVec3::new(100.0, -50.0, 7.0));
        assert!(planarity_error(&flat) < 1e-12);
        // Lift two opposite corners by h: the best-fit plane sits halfway, so every
        // corner is h/2 off it; the diameter is a diagonal, whose ends are at the same
        // height, so √2.
        let h = 0.1;
        let warped = [
            DVec3::new(0.0, 0.0, h),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, h),
            DVec3::new(0.0, 1.0, 0.0),
        ];
        let expected = (h / 2.0) / 2.0f64.sqrt();
        assert!((planarity_error(&warped) - expected).abs() < 1e-9);
    }
}
