//! Helpers for the unit tests (compiled only for them): a seeded generator of uniform
//! numbers, so that random tests repeat.

/// Uniform numbers in `[0, 1)` from a 64-bit linear congruential generator seeded with
/// `seed` (the top 53 bits of each state).
pub fn uniform(mut seed: u64) -> impl FnMut() -> f64 {
    move || {
        seed = seed
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    }
}
