//! Convolution soft shadow maps (Annen et al. 2007/2008, as Dong et al. §4.1–4.2 use them on
//! paraboloid maps): the CPU side of the Fourier expansion the GPU evaluates (`cssm.wgsl`,
//! `val_gather.wgsl`), for tests and for the figures.
//!
//! The shadow test `f(d, z) = H(z − d)` (1: the stored depth z lies beyond the receiver's d,
//! lit) with d, z ∈ [0, 1] is the square wave of period 2 in `x = z − d`, so
//!
//! `f(d, z) ≈ 1/2 + 2 Σ_{k=1..K} [cos(c_k d)·sin(c_k z) − sin(c_k d)·cos(c_k z)] / c_k`,
//! `c_k = π(2k − 1)`.
//!
//! The basis images are sin(c_k z), cos(c_k z) (and z·sin, z·cos, z for the average blocker
//! depth); being linear in them, the expansion commutes with filtering, so a mip-mapped basis
//! gives the filtered shadow test. Truncation rings (Gibbs): the partial sums overshoot the
//! step by at most [`ringing_bound`] (0.092 at K = 4); the GPU clamps the visibility to [0, 1]. Depths are
//! normalised per VAL by the farthest surface its map sees, and a receiver is compared at
//! `d − offset(K)` so that the smooth step has risen before its own surface
//! ([`receiver_offset`]; blockers closer to the receiver than that are missed — the contact
//! shadows CSSM is known to lose). The reconstruction is sharpened ([`visibility`]) so that
//! K = 4 terms tell blockers a tenth of the depth range in front of a receiver.

use std::f32::consts::PI;

/// Default Fourier terms K.
pub const DEFAULT_TERMS: u32 = 4;
/// Largest overshoot of the K-term partial sums beyond [0, 1]: 0.1366 at K = 1, 0.1002 at
/// K = 2, 0.0921 at K = 4, falling to the Gibbs constant 0.0895 (plus float slack).
pub fn ringing_bound(terms: u32) -> f32 {
    match terms {
        0 | 1 => 0.1367,
        2 => 0.1003,
        3 => 0.0942,
        4 => 0.0922,
        _ => 0.0912,
    }
}

/// c_k = π(2k − 1), k from 1.
pub fn c(k: u32) -> f32 {
    PI * (2 * k - 1) as f32
}

/// The truncated expansion of H(z − d) with `terms` terms.
pub fn reconstruct(d: f32, z: f32, terms: u32) -> f32 {
    0.5 + 2.0
        * (1..=terms)
            .map(|k| {
                let c = c(k);
                ((c * d).cos() * (c * z).sin() - (c * d).sin() * (c * z).cos()) / c
            })
            .sum::<f32>()
}

/// Default sharpening s of the reconstruction.
pub const DEFAULT_SHARPNESS: f32 = 4.0;

/// The shadow test as the GPU takes it: the expansion sharpened about ½ by `sharpness`
/// (`½ + s·(f − ½)`) and clamped to [0, 1]. K terms rise with slope 2K at the step, too slowly
/// to tell a blocker 1 m in front of a receiver over a 10 m depth range; sharpening steepens
/// the rise s-fold, and the clamp swallows the ringing (away from the step |f − ½| ≥ 0.408 >
/// ½/s for s ≤ 4).
pub fn visibility(d: f32, z: f32, terms: u32, sharpness: f32) -> f32 {
    (0.5 + sharpness * (reconstruct(d, z, terms) - 0.5)).clamp(0.0, 1.0)
}

/// How far (in normalised depth) a receiver is moved towards its VAL before the test, so that
/// a surface does not shadow itself: twice the sharpened step's rise 1 / (4·K·s).
pub fn receiver_offset(terms: u32, sharpness: f32) -> f32 {
    1.0 / (2.0 * terms.max(1) as f32 * sharpness.max(1.0))
}
