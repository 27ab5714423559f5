//! The formulas of the shading model (SPEC §2) that both renderers share: written once,
//! generic over the precision, so the fast `f32` tracer and the `f64` reference cannot
//! drift apart in what they compute, only in how precisely and how fast.

use std::fmt::Debug;
use std::ops::{Add, Div, Mul, Neg, Sub};

use glam::{DVec3, Vec3};

/// `f32` or `f64`.
pub trait Real:
    Copy
    + Debug
    + PartialOrd
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// 0.
    const ZERO: Self;
    /// 1.
    const ONE: Self;
    /// ½.
    const HALF: Self;
    /// 2.
    const TWO: Self;
    /// The square root.
    fn sqrt(self) -> Self;
    /// The nearest value to `x`.
    fn from_f64(x: f64) -> Self;
}

macro_rules! impl_real {
    ($t:ty) => {
        impl Real for $t {
            const ZERO: Self = 0.0;
            const ONE: Self = 1.0;
            const HALF: Self = 0.5;
            const TWO: Self = 2.0;
            #[inline(always)]
            fn sqrt(self) -> Self {
                <$t>::sqrt(self)
            }
            #[inline(always)]
            fn from_f64(x: f64) -> Self {
                x as $t
            }
        }
    };
}
impl_real!(f32);
impl_real!(f64);

/// glam's `Vec3` or `DVec3`.
pub trait Vector:
    Copy
    + Debug
    + Add<Output = Self>
    + Sub<Output = Self>
    + Neg<Output = Self>
    + Mul<Output = Self>
    + Mul<Self::R, Output = Self>
    + Div<Self::R, Output = Self>
{
    /// The type of a component.
    type R: Real;
    /// The dot product.
    fn dot(self, other: Self) -> Self::R;
    /// The y component.
    fn y(self) -> Self::R;
    /// All three components `x`.
    fn splat(x: Self::R) -> Self;
    /// The nearest vector to `v`.
    fn from_dvec3(v: DVec3) -> Self;
    /// One division and three products (three divisions would each wait on the square
    /// root and on the divider).
    fn normalize(self) -> Self {
        self * (Self::R::ONE / self.dot(self).sqrt())
    }
}

macro_rules! impl_vector {
    ($v:ty, $r:ty) => {
        impl Vector for $v {
            type R = $r;
            #[inline(always)]
            fn dot(self, o: Self) -> $r {
                // Written out so that both precisions sum in the same order.
                (self.x * o.x + self.y * o.y) + self.z * o.z
            }
            #[inline(always)]
            fn y(self) -> $r {
                self.y
            }
            #[inline(always)]
            fn splat(x: $r) -> Self {
                <$v>::splat(x)
            }
            #[inline(always)]
            fn from_dvec3(v: DVec3) -> Self {
                <$v>::new(v.x as $r, v.y as $r, v.z as $r)
            }
        }
    };
}
impl_vector!(Vec3, f32);
impl_vector!(DVec3, f64);

/// Step 1–2: the sky seen along the unit direction `d`.
#[inline]
pub fn sky<V: Vector>(d: V, down: V, up: V) -> V {
    let t = V::R::HALF * (d.y() + V::R::ONE);
    down * (V::R::ONE - t) + up * t
}

/// Step 5: mirror `d` about the normal `n`.
#[inline]
pub fn reflect<V: Vector>(d: V, n: V) -> V {
    d - n * (V::R::TWO * d.dot(n))
}

/// Step 6: the transmitted direction (normalised) for a ray `d` hitting a surface with
/// outward normal `n`, from outside when `front`. The flag says whether the ray crosses
/// the surface (`false`: total internal reflection, it stays on the incoming side).
#[inline]
pub fn transmit<V: Vector>(d: V, n: V, front: bool, ior: V::R) -> (V, bool) {
    let (eta, normal) = if front {
        (V::R::ONE / ior, n)
    } else {
        (ior, -n)
    };
    let cosi = -d.dot(normal);
    let k = V::R::ONE - eta * eta * (V::R::ONE - cosi * cosi);
    if k < V::R::ZERO {
        (reflect(d, normal).normalize(), false)
    } else {
        (
            (d * eta + normal * (eta * cosi - k.sqrt())).normalize(),
            true,
        )
    }
}

/// Step 4: the light an occluder lets through, from its outward normal `n_k` at the
/// shadow ray's first crossing (`L` the unit direction to the light).
#[inline]
pub fn occluder_factor<V: Vector>(l: V, n_k: V) -> V::R {
    (V::R::ONE + l.dot(n_k)) * V::R::HALF
}

/// Step 4: one light's diffuse term `kd ⊙ I · cos · s`.
#[inline]
pub fn diffuse<V: Vector>(kd: V, intensity: V, cos: V::R, shadow: V::R) -> V {
    kd * intensity * cos * shadow
}

/// Step 7: `(1 − w_t)·((1 − w_r)·local + w_r·reflected) + w_t·transmitted`.
#[inline]
pub fn combine<V: Vector>(w_r: V::R, w_t: V::R, local: V, reflected: V, transmitted: V) -> V {
    (local * (V::R::ONE - w_r) + reflected * w_r) * (V::R::ONE - w_t) + transmitted * w_t
}

/// Which branches of step 7 carry weight: the others are not traced at all.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Branches {
    /// The local term (diffuse and shadows): `(1 − w_t)(1 − w_r) ≠ 0`.
    pub local: bool,
    /// The reflected ray: `(1 − w_t)·w_r ≠ 0` (a clear surface, `w_t = 1`, reflects
    /// nothing whatever its `w_r`).
    pub reflect: bool,
    /// The transmitted ray: `w_t ≠ 0`.
    pub transmit: bool,
}

impl Branches {
    /// Only the local term: a diffuse surface.
    pub fn only_local(&self) -> bool {
        self.local && !self.reflect && !self.transmit
    }

    /// The branches of a sphere with reflect weight `w_r` and transmit weight `w_t`.
    pub fn of(w_r: f64, w_t: f64) -> Self {
        Branches {
            local: (1.0 - w_t) * (1.0 - w_r) != 0.0,
            reflect: (1.0 - w_t) * w_r != 0.0,
            transmit: w_t != 0.0,
        }
    }
}

/// The primary ray direction through film position `(s, t)` ∈ \[0, 1\]²:
/// `normalize(LL + s·H + t·V − O)`, given `corner = LL − O` (computed once, in `f64`,
/// so that a camera far from the world's origin loses nothing to cancellation).
#[inline]
pub fn primary_direction<V: Vector>(corner: V, h: V, v: V, s: V::R, t: V::R) -> V {
    ((corner + h * s) + v * t).normalize()
}

/// Which way a spawned ray leaves the sphere it starts on. An outward ray cannot meet
/// its own (convex) sphere again; an inward ray meets only its far side. Knowing this
/// exactly is what lets the tracers spawn rays with no epsilon on their own sphere.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// Away from the sphere, on the side its outward normal points to.
    Outward,
    /// Into the sphere.
    Inward,
}

impl Side {
    /// `Inward` for a ray that goes inside, else `Outward`.
    pub fn inside(inside: bool) -> Side {
        if inside {
            Side::Inward
        } else {
            Side::Outward
        }
    }
}

/// How far within rounding of a shadow segment's end a crossing is decided by the
/// light's side of the sphere instead of by the root: 2⁻¹⁸ of the segment. The
/// fast tracer's `f32` direction passes the light at up to ~1.2·10⁻⁷ of the distance,
/// which moves the root by that over the sine of the angle to the surface: the band
/// holds it down to angles of about 2°.
const NEAR_LIGHT: f64 = 1.0 / (1 << 18) as f64;

/// Whether a shadow segment of length `dist` that meets a sphere at `t`, entering it
/// or leaving it, crosses it before its end at the light (SPEC §2 step 4: the segment
/// is open there). Away from the light the root decides. Within `NEAR_LIGHT` of it,
/// where the root and the light's distance agree only up to rounding (a light on the
/// sphere), the light's side does, from its power `|P − c|² − r²`: an entering
/// segment crosses first iff the light is strictly inside, a leaving one iff strictly
/// outside.
#[inline]
pub fn crosses_before_light(
    t: f64,
    dist: f64,
    entering: bool,
    light_power: impl FnOnce() -> f64,
) -> bool {
    if t < dist * (1.0 - NEAR_LIGHT) {
        return true;
    }
    let power = light_power();
    if entering {
        power < 0.0
    } else {
        power > 0.0
    }
}
