//! Ray/sphere intersection in the numerically stable form (Ray Tracing Gems ch. 7):
//! the discriminant from the closest point of the line to the centre, and roots that
//! never subtract nearly equal numbers. Generic over the precision.

use crate::model::{Real, Vector};

/// The two roots `t_near ≤ t_far` of a unit-direction ray `o + t·d` with the sphere
/// (`f = o − c`), and the sphere's outward normals there, or `None` on a miss.
#[derive(Clone, Copy, Debug)]
pub struct Roots<V: Vector> {
    /// The near root `t_near`.
    pub near: V::R,
    /// The far root `t_far`.
    pub far: V::R,
    /// `l = f + (−f·d)·d`: centre to the closest point of the line.
    pub closest: V,
    /// `√(r² − l·l)`: half the chord.
    pub half_chord: V::R,
}

impl<V: Vector> Roots<V> {
    /// Outward unit normal at the near root: `(l − half_chord·d)/r`, no cancellation.
    #[inline]
    pub fn normal_near(&self, d: V, radius: V::R) -> V {
        self.normal_near_scaled(d, V::R::ONE / radius)
    }

    /// Outward unit normal at the far root.
    #[inline]
    pub fn normal_far(&self, d: V, radius: V::R) -> V {
        self.normal_far_scaled(d, V::R::ONE / radius)
    }

    /// [`Roots::normal_near`] given `1/r` worked out beforehand: the same value, without
    /// a division at the end of the hit's critical path.
    #[inline]
    pub fn normal_near_scaled(&self, d: V, inv_radius: V::R) -> V {
        (self.closest - d * self.half_chord) * inv_radius
    }

    /// [`Roots::normal_far`] given `1/r`.
    #[inline]
    pub fn normal_far_scaled(&self, d: V, inv_radius: V::R) -> V {
        (self.closest + d * self.half_chord) * inv_radius
    }
}

/// The power of point `p` with respect to the sphere `(c, r)`: `|p − c|² − r²`,
/// negative inside, 0 on the sphere, positive outside.
#[inline]
pub fn power<V: Vector>(p: V, c: V, r: V::R) -> V::R {
    let f = p - c;
    f.dot(f) - r * r
}

/// Both roots of the unit-direction ray `o + t·d` with the sphere `(c, r)`.
#[inline]
pub fn roots<V: Vector>(o: V, d: V, c: V, r: V::R) -> Option<Roots<V>> {
    roots_from(o - c, power(o, c, r), d, r)
}

/// [`roots`] given `f = o − c` and `cterm`, the origin's [`power`] (worked out once for
/// rays that share an origin; the same values, so the same roots).
#[inline]
pub fn roots_from<V: Vector>(f: V, cterm: V::R, d: V, r: V::R) -> Option<Roots<V>> {
    let bp = -f.dot(d);
    let l = f + d * bp;
    let disc = r * r - l.dot(l);
    if disc < V::R::ZERO {
        return None;
    }
    let half_chord = disc.sqrt();
    // q = bp + sign(bp)·√disc; the roots are c/q and q (with a = d·d = 1).
    let q = if bp >= V::R::ZERO {
        bp + half_chord
    } else {
        bp - half_chord
    };
    let (t0, t1) = if q == V::R::ZERO {
        (V::R::ZERO, V::R::ZERO)
    } else {
        (cterm / q, q)
    };
    let (near, far) = if t0 <= t1 { (t0, t1) } else { (t1, t0) };
    Some(Roots {
        near,
        far,
        closest: l,
        half_chord,
    })
}
