//! Four doubles in an AVX register, and four 3-vectors, with the operations the lane
//! kernels need (`primitives::lanes`). Every operation is one instruction on each lane,
//! so a formula written with them rounds as the same formula on `f64` and `DVec3` does.
//! The operations are `inline(always)` and reach the intrinsics only inside the
//! kernels, which enable AVX (`target_feature`), where they inline.

use crate::primitives::weights::{Real, WeightScale};
use glam::DVec3;
use std::arch::x86_64::*;
use std::ops::{Add, Div, Mul, Sub};

// The lane types' operations are `inline(always)` and reach the AVX intrinsics only
// inside the `target_feature(enable = "avx")` kernels below, where they inline.

/// Four doubles.
#[derive(Clone, Copy)]
pub(super) struct F(__m256d);

/// Four 3-vectors.
#[derive(Clone, Copy)]
pub(super) struct V {
    pub x: F,
    pub y: F,
    pub z: F,
}

macro_rules! lane_op {
    ($tr:ident, $f:ident, $op:ident) => {
        impl $tr for F {
            type Output = F;
            #[inline(always)]
            fn $f(self, o: F) -> F {
                // SAFETY: called only from the AVX kernels.
                F(unsafe { $op(self.0, o.0) })
            }
        }
        impl $tr<F> for f64 {
            type Output = F;
            #[inline(always)]
            fn $f(self, o: F) -> F {
                F::splat(self).$f(o)
            }
        }
        impl $tr<V> for V {
            type Output = V;
            #[inline(always)]
            fn $f(self, o: V) -> V {
                V {
                    x: self.x.$f(o.x),
                    y: self.y.$f(o.y),
                    z: self.z.$f(o.z),
                }
            }
        }
    };
}
lane_op!(Add, add, _mm256_add_pd);
lane_op!(Sub, sub, _mm256_sub_pd);
lane_op!(Mul, mul, _mm256_mul_pd);
lane_op!(Div, div, _mm256_div_pd);

impl Mul<f64> for F {
    type Output = F;
    #[inline(always)]
    fn mul(self, k: f64) -> F {
        self * F::splat(k)
    }
}

/// `k * v` (the scalar first, as glam's `f64 * DVec3`).
impl Mul<V> for F {
    type Output = V;
    #[inline(always)]
    fn mul(self, v: V) -> V {
        V {
            x: self * v.x,
            y: self * v.y,
            z: self * v.z,
        }
    }
}
/// `v / k` (glam's `DVec3 / f64`).
impl Div<F> for V {
    type Output = V;
    #[inline(always)]
    fn div(self, k: F) -> V {
        V {
            x: self.x / k,
            y: self.y / k,
            z: self.z / k,
        }
    }
}
impl Real for F {
    #[inline(always)]
    fn lit(v: f64) -> F {
        F::splat(v)
    }
}

/// Every bit set.
#[inline(always)]
fn all_ones() -> __m256d {
    // SAFETY: called only from the AVX kernels.
    unsafe { _mm256_castsi256_pd(_mm256_set1_epi64x(-1)) }
}

impl F {
    #[inline(always)]
    pub(super) fn splat(v: f64) -> F {
        // SAFETY: called only from the AVX kernels.
        F(unsafe { _mm256_set1_pd(v) })
    }
    #[inline(always)]
    pub(super) fn load(v: &[f64; 4]) -> F {
        // SAFETY: four doubles; called only from the AVX kernels.
        F(unsafe { _mm256_loadu_pd(v.as_ptr()) })
    }
    #[inline(always)]
    pub(super) fn store(self) -> [f64; 4] {
        let mut o = [0.0; 4];
        // SAFETY: four doubles; called only from the AVX kernels.
        unsafe { _mm256_storeu_pd(o.as_mut_ptr(), self.0) };
        o
    }
    /// The lanes' sign bits, lane 0 lowest (of a comparison's mask: where it holds).
    #[inline(always)]
    pub(super) fn mask(self) -> u32 {
        // SAFETY: called only from the AVX kernels.
        unsafe { _mm256_movemask_pd(self.0) as u32 }
    }
    /// Each lane's absolute value.
    #[inline(always)]
    pub(super) fn abs(self) -> F {
        // SAFETY: called only from the AVX kernels.
        F(unsafe { _mm256_andnot_pd(_mm256_set1_pd(-0.0), self.0) })
    }
    /// Where `self < o` (all bits set).
    #[inline(always)]
    pub(super) fn lt(self, o: F) -> F {
        self.cmp::<_CMP_LT_OQ>(o)
    }
    #[inline(always)]
    pub(super) fn sqrt(self) -> F {
        // SAFETY: called only from the AVX kernels.
        F(unsafe { _mm256_sqrt_pd(self.0) })
    }
    #[inline(always)]
    pub(super) fn xor(self, o: F) -> F {
        // SAFETY: called only from the AVX kernels.
        F(unsafe { _mm256_xor_pd(self.0, o.0) })
    }
    /// The lane mask of comparison `OP` (an `_CMP_*` predicate): all bits set where it
    /// holds.
    #[inline(always)]
    fn cmp<const OP: i32>(self, o: F) -> F {
        // SAFETY: called only from the AVX kernels.
        F(unsafe { _mm256_cmp_pd::<OP>(self.0, o.0) })
    }
    /// Comparisons as in scalar code: NaN compares false, except in `ne` and `nan`.
    #[inline(always)]
    pub(super) fn le(self, o: F) -> F {
        self.cmp::<_CMP_LE_OQ>(o)
    }
    #[inline(always)]
    pub(super) fn ge(self, o: F) -> F {
        self.cmp::<_CMP_GE_OQ>(o)
    }
    #[inline(always)]
    pub(super) fn gt(self, o: F) -> F {
        self.cmp::<_CMP_GT_OQ>(o)
    }
    #[inline(always)]
    pub(super) fn ne(self, o: F) -> F {
        self.cmp::<_CMP_NEQ_UQ>(o)
    }
    #[inline(always)]
    pub(super) fn nan(self) -> F {
        self.cmp::<_CMP_UNORD_Q>(self)
    }
    #[inline(always)]
    pub(super) fn and(self, o: F) -> F {
        // SAFETY: called only from the AVX kernels.
        F(unsafe { _mm256_and_pd(self.0, o.0) })
    }
    #[inline(always)]
    pub(super) fn not(self) -> F {
        self.xor(F(all_ones()))
    }
    #[inline(always)]
    pub(super) fn or(self, o: F) -> F {
        // SAFETY: called only from the AVX kernels.
        F(unsafe { _mm256_or_pd(self.0, o.0) })
    }
    /// `a` in the lanes where this mask is set, else `b`.
    #[inline(always)]
    pub(super) fn sel(self, a: F, b: F) -> F {
        // SAFETY: called only from the AVX kernels.
        F(unsafe { _mm256_blendv_pd(b.0, a.0, self.0) })
    }
    #[inline(always)]
    pub(super) fn sel3(self, a: V, b: V) -> V {
        V {
            x: self.sel(a.x, b.x),
            y: self.sel(a.y, b.y),
            z: self.sel(a.z, b.z),
        }
    }
}

impl V {
    #[inline(always)]
    pub(super) fn splat(v: DVec3) -> V {
        V {
            x: F::splat(v.x),
            y: F::splat(v.y),
            z: F::splat(v.z),
        }
    }
    #[inline(always)]
    pub(super) fn load(v: &[[f64; 4]; 3]) -> V {
        V {
            x: F::load(&v[0]),
            y: F::load(&v[1]),
            z: F::load(&v[2]),
        }
    }
    /// glam's `dot`: `(x x' + y y') + z z'`.
    #[inline(always)]
    pub(super) fn dot(self, o: V) -> F {
        self.x * o.x + self.y * o.y + self.z * o.z
    }
    #[inline(always)]
    pub(super) fn store(self) -> [[f64; 4]; 3] {
        [self.x.store(), self.y.store(), self.z.store()]
    }
}

/// `WeightScale::apply`: `(w, dw/dW)` for the raw polynomial values.
#[inline(always)]
pub(super) fn apply(scale: &WeightScale, raw: F) -> (F, F) {
    let (zero, one) = (F::splat(0.0), F::splat(1.0));
    let under = raw.le(F::splat(1.0 / scale.max_adj));
    let over = raw.ge(one).or(raw.nan());
    let v = F::splat(scale.max_adj) * raw;
    let pw = if scale.q == 1.0 {
        v
    } else if scale.q == 0.5 {
        v.sqrt()
    } else {
        {
            let mut p = v.store();
            for v in &mut p {
                *v = v.powf(scale.q);
            }
            F::load(&p)
        }
    };
    let w = under.sel(one, over.sel(F::splat(scale.max_weight()), pw));
    let dw = under.or(over).sel(zero, scale.q * pw / raw);
    (w, dw)
}
