//! The CPU side of every method: the ray tracer, the exact reference renderer, and the CPU
//! twin of each GPU stage that has one (gate visibility, clustered light lists, VAL clustering,
//! the CSSM's Fourier expansion, the point-to-disk form factor). Tests hold each twin equal to its GPU pass on small inputs.

pub mod clustered;
pub mod cssm;
pub mod gates;
pub mod ism;
pub mod lightcluster;
pub mod portal_walk;
pub mod reference;
pub mod sight;
mod sight_clearance;
pub mod sight_planes;
pub mod sight_triangles;
pub mod tracer;
pub mod val;

/// A small xorshift for the tests' random cases: each call steps the state and gives it
/// modulo `n`.
#[cfg(test)]
pub(crate) fn xorshift32(mut seed: u32) -> impl FnMut(u32) -> u32 {
    move |n| {
        seed ^= seed << 13;
        seed ^= seed >> 17;
        seed ^= seed << 5;
        seed % n
    }
}
