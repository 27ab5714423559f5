//! The directions a camera looks in: the pyramid from the eye through its film. An eye
//! grid lists only the spheres that reach into it, since only primary rays, whose
//! directions go through the film, query that grid.

use glam::DVec3;

/// How far the film is widened on each side, as a fraction of its span: far more than
/// the rounding of a primary ray's `f32` direction, which moves it by a few 1e-7 of
/// its length.
const FILM_MARGIN: f64 = 1e-3;

/// The pyramid of directions from the eye through the camera's film, widened by
/// [`FILM_MARGIN`]: its four side planes through the eye, as inward unit normals.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ViewPyramid {
    normals: [DVec3; 4],
}

impl ViewPyramid {
    /// The pyramid from `eye` through the film `lower_left + u·horizontal +
    /// v·vertical`, `u` and `v` in `[0, 1]`; `None` when the film and the eye do not
    /// make a proper pyramid (the eye in the film's plane, or spans not finite), in
    /// which case the grid keeps every sphere.
    pub(crate) fn new(
        eye: DVec3,
        lower_left: DVec3,
        horizontal: DVec3,
        vertical: DVec3,
    ) -> Option<ViewPyramid> {
        let (lo, hi) = (-FILM_MARGIN, 1.0 + FILM_MARGIN);
        let corner = |u: f64, v: f64| lower_left + u * horizontal + v * vertical - eye;
        // Around the film, so that consecutive corners bound one side each.
        let corners = [
            corner(lo, lo),
            corner(hi, lo),
            corner(hi, hi),
            corner(lo, hi),
        ];
        let centre = corner(0.5, 0.5);
        let mut normals = [DVec3::ZERO; 4];
        for (i, normal) in normals.iter_mut().enumerate() {
            let n = corners[i].cross(corners[(i + 1) % 4]).normalize_or_zero();
            let n = if n.dot(centre) < 0.0 { -n } else { n };
            // Every corner on the inner side (or on the plane, up to rounding), and the
            // centre strictly inside: a proper pyramid.
            let scale = corners.iter().map(|c| c.length()).fold(0.0, f64::max);
            let proper = n != DVec3::ZERO
                && n.dot(centre) > 1e-9 * centre.length()
                && corners.iter().all(|c| n.dot(*c) >= -1e-9 * scale);
            if !proper || !n.is_finite() {
                return None;
            }
            *normal = n;
        }
        Some(ViewPyramid { normals })
    }

    /// `false` when no ray from the eye through the pyramid can meet the sphere of
    /// radius `r` whose centre is at `rel` from the eye: the sphere lies wholly outside
    /// one of the side planes (by more than a generous rounding allowance).
    pub(crate) fn may_see(&self, rel: DVec3, r: f64) -> bool {
        let reach = r * (1.0 + 1e-6) + 1e-9 * (rel.abs().max_element() + r);
        self.normals.iter().all(|n| n.dot(rel) >= -reach)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The assignment's camera: eye at the origin, film from (−2, −1.125, −1) spanning
    /// 4 across and 2.25 up. Side planes by hand: the left one holds the eye and the
    /// film's left edge x = −2, z = −1, so its inward normal is (1, 0, −2)/√5.
    #[test]
    fn a_sphere_is_kept_exactly_when_it_reaches_into_the_pyramid() {
        let view = ViewPyramid::new(
            DVec3::ZERO,
            DVec3::new(-2.0, -1.125, -1.0),
            DVec3::new(4.0, 0.0, 0.0),
            DVec3::new(0.0, 2.25, 0.0),
        )
        .expect("a proper pyramid");
        // Straight ahead, and just inside each edge.
        assert!(view.may_see(DVec3::new(0.0, 0.0, -5.0), 0.1));
        assert!(view.may_see(DVec3::new(-9.9, 0.0, -5.0), 0.01));
        // Behind the eye: 10.02/2.2397 = 4.47 outside the left plane.
        assert!(!view.may_see(DVec3::new(0.0, 0.0, 5.0), 1.0));
        // The margin widens the film by 0.004 (0.1% of its 4) on each side, so the
        // left plane holds (−2.004, y, −1): normal (1, 0, −2.004)/2.2397. The point
        // (−12, 0, −5) lies (−12 + 10.02)/2.2397 = 0.884 outside it (0.894 outside
        // the unwidened plane).
        let left = DVec3::new(-12.0, 0.0, -5.0);
        assert!(!view.may_see(left, 0.88));
        assert!(view.may_see(left, 0.89));
        // A sphere around the eye is seen from inside, in every direction.
        assert!(view.may_see(DVec3::new(0.0, 0.0, 0.5), 1.0));
    }

    /// The eye in the film's plane gives no pyramid: the grid then keeps every sphere.
    #[test]
    fn an_eye_in_the_film_s_plane_makes_no_pyramid() {
        let flat = ViewPyramid::new(
            DVec3::new(0.0, 0.0, -1.0),
            DVec3::new(-2.0, -1.0, -1.0),
            DVec3::new(4.0, 0.0, 0.0),
            DVec3::new(0.0, 2.0, 0.0),
        );
        assert!(flat.is_none());
    }
}
