//! Virtual area lights (Dong et al., "Interactive global illumination using clustered
//! visibility", §5): k-means of the N VPLs into M clusters (VALs) by position and normal. This
//! is the CPU twin of the GPU clustering (`gpu/passes/vals.wgsl`); the tests hold the two equal.
//!
//! - **Distance** `d = w_x·Δx/D + w_α·Δα/π`: Δx the distance between a VPL and a VAL centre,
//!   D the diagonal of the VPLs' bounding box (so that the weights mean the same in a 1 m room
//!   and a 100 m hall, and under any scene scale), Δα the angle between their normals. Both
//!   terms lie in [0, 1]; the paper's weights are w_x = 0.7, w_α = 0.3.
//! - **Restart** (§5.2): every frame starts from the same assignment — VAL k's centre is VPL
//!   ⌊k·N/M⌋ — so that the same light gives the same VALs and a moving light keeps all of
//!   them alive; [`cluster`] with `start` centres reuses last frame's instead (the
//!   alternative the paper rejects, kept to measure it).
//! - **Iterations**: assign each VPL to the nearest centre (ties to the lower index), then
//!   move each non-empty centre to its VPLs' mean position and (normalised) mean normal; an
//!   empty VAL keeps its centre; until the assignment repeats itself (convergence, as the
//!   paper iterates), at most `iterations` times; then the final mapping C.
//! - **Area**: the 2D bounding rectangle of the VAL's VPLs projected on the plane normal to
//!   its normal (the frame of [`crate::vpl::basis`]).

use glam::Vec3;

use crate::RenderError;
use crate::vpl::{Vpl, basis};

/// Clustering parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ValParams {
    /// Virtual area lights. [Limit: 1..=4096]
    pub count: u32,
    /// k-means iterations after the initial assignment. [Limit: 0..=256]
    pub iterations: u32,
    /// Weight of the position term. [Limit: ≥ 0]
    pub w_x: f32,
    /// Weight of the normal term. [Limit: ≥ 0]
    pub w_alpha: f32,
    /// Start from last frame's centres instead of the restart (§5.2 rejects this: VALs get
    /// lost as lights move; kept to measure it). On the GPU the renderer keeps the centres.
    pub warm_start: bool,
}

impl Default for ValParams {
    fn default() -> Self {
        ValParams {
            count: 30,
            iterations: 8,
            w_x: 0.7,
            w_alpha: 0.3,
            warm_start: false,
        }
    }
}

impl ValParams {
    /// Checks the limits.
    pub fn check(&self) -> Result<(), RenderError> {
        let w_ok = |w: f32| w.is_finite() && w >= 0.0;
        if !(1..=4096).contains(&self.count)
            || self.iterations > 256
            || !w_ok(self.w_x)
            || !w_ok(self.w_alpha)
            || self.w_x + self.w_alpha <= 0.0
        {
            return Err(RenderError::Param(format!(
                "VALs {} must be 1..=4096, iterations {} 0..=256, weights w_x {} and w_alpha {} \
                 ≥ 0 and not both 0",
                self.count, self.iterations, self.w_x, self.w_alpha
            )));
        }
        Ok(())
    }
}

/// One virtual area light, shared with WGSL (`Val` in vals.wgsl). 64 bytes.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Val {
    /// xyz centre (m), w its VPLs (a count, as f32).
    pub position: [f32; 4],
    /// xyz unit normal, w area (m²).
    pub normal: [f32; 4],
    /// rgb summed flux of its VPLs (W), w unused.
    pub flux: [f32; 4],
    /// Bounding rectangle in the plane normal to `normal`, about `position`, along
    /// [`crate::vpl::basis`]: s min, s max, t min, t max (m).
    pub rect: [f32; 4],
}

impl Val {
    /// Centre.
    pub fn centre(&self) -> Vec3 {
        Vec3::from_slice(&self.position[..3])
    }

    /// Unit normal.
    pub fn unit_normal(&self) -> Vec3 {
        Vec3::from_slice(&self.normal[..3])
    }

    /// VPLs it holds.
    pub fn vpl_count(&self) -> u32 {
        self.position[3] as u32
    }
}

/// VALs and the mapping C from each VPL to its VAL.
#[derive(Debug, Clone, PartialEq)]
pub struct Clustering {
    /// The VALs, `count` of them (empty ones included, with 0 VPLs).
    pub vals: Vec<Val>,
    /// C: the VAL of each VPL.
    pub mapping: Vec<u32>,
    /// The normalising length D of the position term. [Units: m]
    pub scale_m: f32,
    /// Centre updates run (at most `ValParams::iterations`).
    pub iterations: u32,
    /// Whether the assignment stopped changing within them (the paper's convergence).
    pub converged: bool,
}

impl Clustering {
    /// VALs that hold at least one VPL.
    pub fn live(&self) -> usize {
        self.vals.iter().filter(|v| v.vpl_count() > 0).count()
    }
}

/// Whether a VPL carries light. An RSM sample that found no surface gives a VPL of zero flux
/// (at the origin): it takes no part in the clustering — not in D, not a restart centre, in no
/// VAL (its mapping is [`NO_VAL`]) — so open scenes' VALs are not pulled towards the origin.
pub fn is_live(v: &Vpl) -> bool {
    v.flux != [0.0; 3]
}

/// The mapping of a VPL of zero flux: no VAL.
pub const NO_VAL: u32 = u32::MAX;

/// The normalising length D: the diagonal of the live VPLs' bounding box (1e-30 m at least; 1
/// when none is live).
pub fn scale_of(vpls: &[Vpl]) -> f32 {
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for v in vpls.iter().filter(|v| is_live(v)) {
        lo = lo.min(Vec3::from(v.position));
        hi = hi.max(Vec3::from(v.position));
    }
    if lo.x > hi.x {
        return 1.0;
    }
    (hi - lo).length().max(1e-30)
}

/// The clustering distance between a VPL (`p`, `n`) and a centre (`c`, `m`), with `inv_d` =
/// 1 / D.
pub fn distance(p: Vec3, n: Vec3, c: Vec3, m: Vec3, inv_d: f32, params: &ValParams) -> f32 {
    let dx = (p - c).length() * inv_d;
    let da = n.dot(m).clamp(-1.0, 1.0).acos() / std::f32::consts::PI;
    params.w_x * dx + params.w_alpha * da
}

/// The initial centres: VAL k starts at VPL ⌊k·N/M⌋ (§5.2), or the next live VPL after it.
pub fn initial_centres(vpls: &[Vpl], count: u32) -> Vec<(Vec3, Vec3)> {
    let n = vpls.len();
    (0..count as u64)
        .map(|k| {
            let j = (k * n as u64 / count as u64) as usize;
            let v = (0..n)
                .map(|s| &vpls[(j + s) % n])
                .find(|v| is_live(v))
                .unwrap_or(&vpls[j]);
            (Vec3::from(v.position), Vec3::from(v.normal))
        })
        .collect()
}

/// Index of the nearest centre (the lower index on ties); [`NO_VAL`] for a VPL of zero flux.
pub fn nearest(v: &Vpl, centres: &[(Vec3, Vec3)], inv_d: f32, params: &ValParams) -> u32 {
    if !is_live(v) {
        return NO_VAL;
    }
    let (p, n) = (Vec3::from(v.position), Vec3::from(v.normal));
    let mut best = (f32::INFINITY, 0u32);
    for (k, &(c, m)) in centres.iter().enumerate() {
        let d = distance(p, n, c, m, inv_d, params);
        if d < best.0 {
            best = (d, k as u32);
        }
    }
    best.1
}

/// Clusters `vpls` into `params.count` VALs from `start` centres (none: the restart of
/// [`initial_centres`]).
pub fn cluster(
    vpls: &[Vpl],
    params: &ValParams,
    start: Option<&[(Vec3, Vec3)]>,
) -> Result<Clustering, RenderError> {
    params.check()?;
    let m = params.count as usize;
    let scale_m = scale_of(vpls);
    if vpls.is_empty() {
        return Ok(Clustering {
            vals: vec![bytemuck::Zeroable::zeroed(); m],
            mapping: Vec::new(),
            scale_m,
            iterations: 0,
            converged: true,
        });
    }
    let inv_d = 1.0 / scale_m;
    let mut centres = match start {
        Some(s) if s.len() == m => s.to_vec(),
        Some(s) => {
            return Err(RenderError::Param(format!(
                "{} start centres for {m} VALs",
                s.len()
            )));
        }
        None => initial_centres(vpls, params.count),
    };
    // Iterate until the assignment repeats itself (then every later iteration would repeat
    // the last: the GPU stops there too), at most `params.iterations` updates.
    let (mut iterations, mut converged) = (0, false);
    let mut last: Option<Vec<u32>> = None;
    for _ in 0..params.iterations {
        let mapping: Vec<u32> = vpls
            .iter()
            .map(|v| nearest(v, &centres, inv_d, params))
            .collect();
        if last.as_ref() == Some(&mapping) {
            converged = true;
            break;
        }
        iterations += 1;
        let positions = lane_sums(vpls, &mapping, m, |v| v.position);
        let normals = lane_sums(vpls, &mapping, m, |v| v.normal);
        let counts = counts_of(&mapping, m);
        for (k, c) in centres.iter_mut().enumerate() {
            if counts[k] > 0 {
                // As the GPU divides (not normalize's reciprocal), for the same bits.
                let l = normals[k].length();
                *c = (
                    positions[k] / counts[k] as f32,
                    if l > 0.0 { normals[k] / l } else { c.1 },
                );
            }
        }
        last = Some(mapping);
    }
    let mapping: Vec<u32> = vpls
        .iter()
        .map(|v| nearest(v, &centres, inv_d, params))
        .collect();
    Ok(Clustering {
        vals: vals_of(vpls, &mapping, &centres),
        mapping,
        scale_m,
        iterations,
        converged,
    })
}

/// Lanes of the GPU's workgroup per VAL: VPL i is summed in lane i mod this.
pub const LANES: usize = 64;

/// Each VAL's sum of `f` over its VPLs (`m` VALs, one pass over the VPLs), in the GPU's
/// order: lane t of VAL k sums its VPLs i ≡ t (mod [`LANES`]) in increasing i, then the lanes
/// fold as a tree (t += t + o for o = 32, 16, …, 1) — so that the CPU twin gives the GPU's bits.
pub fn lane_sums(vpls: &[Vpl], mapping: &[u32], m: usize, f: fn(&Vpl) -> [f32; 3]) -> Vec<Vec3> {
    let mut lanes = vec![[Vec3::ZERO; LANES]; m];
    for (i, (v, &k)) in vpls.iter().zip(mapping).enumerate() {
        if k != NO_VAL {
            lanes[k as usize][i % LANES] += Vec3::from(f(v));
        }
    }
    lanes
        .iter_mut()
        .map(|l| {
            let mut o = LANES / 2;
            while o > 0 {
                for t in 0..o {
                    l[t] += l[t + o];
                }
                o /= 2;
            }
            l[0]
        })
        .collect()
}

/// VPLs per VAL (`m` VALs; [`NO_VAL`] counts nowhere).
fn counts_of(mapping: &[u32], m: usize) -> Vec<u32> {
    let mut counts = vec![0u32; m];
    for &k in mapping.iter().filter(|&&k| k != NO_VAL) {
        counts[k as usize] += 1;
    }
    counts
}

/// The VALs of a mapping: centre and normal from `centres`, count, flux and bounding rectangle
/// from their VPLs.
fn vals_of(vpls: &[Vpl], mapping: &[u32], centres: &[(Vec3, Vec3)]) -> Vec<Val> {
    let mut vals: Vec<Val> = centres
        .iter()
        .map(|&(c, n)| Val {
            position: c.extend(0.0).to_array(),
            normal: n.extend(0.0).to_array(),
            flux: [0.0; 4],
            rect: [
                f32::INFINITY,
                f32::NEG_INFINITY,
                f32::INFINITY,
                f32::NEG_INFINITY,
            ],
        })
        .collect();
    for (v, &k) in vpls.iter().zip(mapping).filter(|(_, k)| **k != NO_VAL) {
        let val = &mut vals[k as usize];
        let (t, b) = basis(val.unit_normal());
        let q = Vec3::from(v.position) - val.centre();
        let (s, u) = (q.dot(t), q.dot(b));
        val.position[3] += 1.0;
        val.rect = [
            val.rect[0].min(s),
            val.rect[1].max(s),
            val.rect[2].min(u),
            val.rect[3].max(u),
        ];
    }
    let fluxes = lane_sums(vpls, mapping, vals.len(), |v| v.flux);
    for (val, flux) in vals.iter_mut().zip(fluxes) {
        val.flux = flux.extend(0.0).to_array();
        if val.position[3] == 0.0 {
            val.rect = [0.0; 4];
        }
        val.normal[3] = (val.rect[1] - val.rect[0]) * (val.rect[3] - val.rect[2]);
    }
    vals
}

/// The centres of a clustering (to start the next frame from, or to compare).
pub fn centres_of(c: &Clustering) -> Vec<(Vec3, Vec3)> {
    c.vals
        .iter()
        .map(|v| (v.centre(), v.unit_normal()))
        .collect()
}
