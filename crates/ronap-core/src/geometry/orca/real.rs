//! The numbers ORCA computes in, and its 2-vectors, each operation as RVO2 does it (so that the
//! `f32` instance repeats RVO2's arithmetic step by step and the `f64` one is the same algorithm
//! in double precision).

use std::ops::{Add, Div, Mul, Neg, Sub};

/// A float ORCA can compute in: `f32` (RVO2's own precision, for checking against it) or `f64`.
pub trait Real:
    Copy
    + PartialOrd
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + std::fmt::Debug
{
    /// 0.
    const ZERO: Self;
    /// 1.
    const ONE: Self;
    /// 0.5.
    const HALF: Self;
    /// RVO2's `RVO_EPSILON` (0.00001).
    const EPSILON: Self;
    /// Positive infinity.
    const INFINITY: Self;
    /// The square root.
    fn sqrt(self) -> Self;
    /// The absolute value.
    fn abs(self) -> Self;
    /// The nearest value to `v`.
    fn of(v: f64) -> Self;
    /// As an `f64`.
    fn to_f64(self) -> f64;
}

impl Real for f32 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    const HALF: Self = 0.5;
    const EPSILON: Self = 0.00001;
    const INFINITY: Self = f32::INFINITY;
    fn sqrt(self) -> Self {
        f32::sqrt(self)
    }
    fn abs(self) -> Self {
        f32::abs(self)
    }
    fn of(v: f64) -> Self {
        v as f32
    }
    fn to_f64(self) -> f64 {
        f64::from(self)
    }
}

impl Real for f64 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    const HALF: Self = 0.5;
    const EPSILON: Self = 0.00001;
    const INFINITY: Self = f64::INFINITY;
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    fn abs(self) -> Self {
        f64::abs(self)
    }
    fn of(v: f64) -> Self {
        v
    }
    fn to_f64(self) -> f64 {
        self
    }
}

/// A 2-vector.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct V2<T> {
    /// x.
    pub x: T,
    /// y.
    pub y: T,
}

impl<T: Real> V2<T> {
    /// `(x, y)`.
    pub fn new(x: T, y: T) -> Self {
        Self { x, y }
    }

    /// The zero vector.
    pub fn zero() -> Self {
        Self::new(T::ZERO, T::ZERO)
    }

    /// The dot product (RVO2's `operator*`).
    pub fn dot(self, o: Self) -> T {
        self.x * o.x + self.y * o.y
    }

    /// The squared length.
    pub fn abs_sq(self) -> T {
        self.dot(self)
    }

    /// The length.
    pub fn abs(self) -> T {
        self.abs_sq().sqrt()
    }

    /// `self` scaled by `s`.
    pub fn scale(self, s: T) -> Self {
        Self::new(self.x * s, self.y * s)
    }

    /// `self` divided by `s`, as RVO2 divides: times `1 / s`.
    pub fn over(self, s: T) -> Self {
        let inv = T::ONE / s;
        Self::new(self.x * inv, self.y * inv)
    }

    /// `self` of unit length.
    pub fn normalize(self) -> Self {
        self.over(self.abs())
    }

    /// The determinant `|self o|`.
    pub fn det(self, o: Self) -> T {
        self.x * o.y - self.y * o.x
    }

    /// Turned a quarter left: `(-y, x)`.
    pub fn left(self) -> Self {
        Self::new(-self.y, self.x)
    }
}

impl<T: Real> Add for V2<T> {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Self::new(self.x + o.x, self.y + o.y)
    }
}

impl<T: Real> Sub for V2<T> {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        Self::new(self.x - o.x, self.y - o.y)
    }
}

impl<T: Real> Neg for V2<T> {
    type Output = Self;
    fn neg(self) -> Self {
        Self::new(-self.x, -self.y)
    }
}

impl From<crate::geometry::Vector> for V2<f64> {
    fn from(v: crate::geometry::Vector) -> Self {
        Self::new(v.x, v.y)
    }
}

impl From<crate::geometry::Point> for V2<f64> {
    fn from(p: crate::geometry::Point) -> Self {
        Self::new(p.x, p.y)
    }
}

impl From<V2<f64>> for crate::geometry::Vector {
    fn from(v: V2<f64>) -> Self {
        Self::new(v.x, v.y)
    }
}

/// How far `c` lies left of the line from `a` to `b` (RVO2's `leftOf`: positive on the left).
pub fn left_of<T: Real>(a: V2<T>, b: V2<T>, c: V2<T>) -> T {
    (a - c).det(b - a)
}
