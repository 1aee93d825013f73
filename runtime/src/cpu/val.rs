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
//!   its normal (the frame of [`crate::vpl::basis`]); and the area of the disk with the same
//!   second moment, 2π·mean(s² + t²) (the point-to-disk form factor's A_c of `val-ism`).
//!
//! Weinzierl-Heigl's clustering (`val-ism`, [`ValParams::ism`]) changes three things: the
//! seeds are a Halton sequence warped by importance — the radical inverse in base 2 of k
//! through the cumulative flux of the VPLs (r + g + b), so that VALs gather where the light is;
//! the metric adds a flux term `w_f·|Φ_i − Φ_c| / (|Φ_i| + |Φ_c|)` (Φ_c the mean flux of the
//! VAL's VPLs); and a VPL joins only the centres whose point splat reaches it (within `splat`
//! × D), the nearest of all where none does (no light is dropped). Iterated frame to frame
//! (warm start), a VAL that held no VPL last frame starts again from its seed (the paper's
//! initialisation "whenever there are no RSM-pixels assigned to a cluster").

use glam::Vec3;

use crate::RenderError;
use crate::vpl::{Vpl, basis};
use crate::vpl_order::dealt_position;

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
    /// Where the centres start.
    pub seeding: ValSeeding,
    /// Weight of the flux term (Weinzierl-Heigl's μ). [Limit: ≥ 0]
    pub w_f: f32,
    /// A VPL joins only the centres within this distance (the point splats), as a fraction of
    /// D; `None`: every centre. [Limit: > 0]
    pub splat: Option<f32>,
}

/// Where the VAL centres start.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ValSeeding {
    /// VAL k at VPL ⌊k·N/M⌋ (Dong et al. §5.2).
    Restart,
    /// VAL k at the VPL where the cumulative flux crosses the radical inverse of k in base 2
    /// (Weinzierl-Heigl §4: Halton seeds with importance warping).
    HaltonFlux,
}

impl Default for ValParams {
    fn default() -> Self {
        ValParams {
            count: 30,
            iterations: 8,
            w_x: 0.7,
            w_alpha: 0.3,
            warm_start: false,
            seeding: ValSeeding::Restart,
            w_f: 0.0,
            splat: None,
        }
    }
}

impl ValParams {
    /// Weinzierl-Heigl's clustering (mode `val-ism`): 64 VALs, Halton seeds warped by flux,
    /// μ = 0.6·d_p + 0.3·d_n + 0.1·d_f, splats of a quarter of D, iterated frame to frame.
    pub fn ism() -> ValParams {
        ValParams {
            count: 64,
            iterations: 8,
            w_x: 0.6,
            w_alpha: 0.3,
            warm_start: true,
            seeding: ValSeeding::HaltonFlux,
            w_f: 0.1,
            splat: Some(0.25),
        }
    }

    /// Checks the limits.
    pub fn check(&self) -> Result<(), RenderError> {
        let w_ok = |w: f32| w.is_finite() && w >= 0.0;
        if !(1..=4096).contains(&self.count)
            || self.iterations > 256
            || !w_ok(self.w_x)
            || !w_ok(self.w_alpha)
            || !w_ok(self.w_f)
            || self.w_x + self.w_alpha + self.w_f <= 0.0
        {
            return Err(RenderError::Param(format!(
                "VALs {} must be 1..=4096, iterations {} 0..=256, weights w_x {}, w_alpha {} and \
                 w_f {} ≥ 0 and not all 0",
                self.count, self.iterations, self.w_x, self.w_alpha, self.w_f
            )));
        }
        if let Some(r) = self.splat.filter(|r| !(r.is_finite() && *r > 0.0)) {
            return Err(RenderError::Param(format!(
                "VAL splat {r} must be > 0 (a fraction of the VPLs' diagonal)"
            )));
        }
        Ok(())
    }

    /// The splat radius over D the GPU reads (0: every centre).
    pub fn splat_or_zero(&self) -> f32 {
        self.splat.unwrap_or(0.0)
    }
}

/// A VAL centre while clustering: position, unit normal, mean flux of its VPLs.
pub type Centre = (Vec3, Vec3, Vec3);

/// One virtual area light, shared with WGSL (`Val` in vals.wgsl). 64 bytes.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Val {
    /// xyz centre (m), w its VPLs (a count, as f32).
    pub position: [f32; 4],
    /// xyz unit normal, w area (m²).
    pub normal: [f32; 4],
    /// rgb summed flux of its VPLs (W), w the area of the disk of the same second moment
    /// (m²).
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

    /// The area of the disk with its VPLs' second moment about the centre, in its plane.
    /// [Units: m²]
    pub fn disk_area(&self) -> f32 {
        self.flux[3]
    }

    /// Mean flux of its VPLs (0 for none).
    pub fn mean_flux(&self) -> Vec3 {
        match self.vpl_count() {
            0 => Vec3::ZERO,
            c => Vec3::from_slice(&self.flux[..3]) / c as f32,
        }
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

/// The clustering distance between a VPL and a centre, with `inv_d` = 1 / D.
pub fn distance(v: &Vpl, (c, m, f): Centre, inv_d: f32, params: &ValParams) -> f32 {
    let (p, n) = (Vec3::from(v.position), Vec3::from(v.normal));
    let dx = (p - c).length() * inv_d;
    let da = n.dot(m).clamp(-1.0, 1.0).acos() / std::f32::consts::PI;
    let mut d = params.w_x * dx + params.w_alpha * da;
    if params.w_f > 0.0 {
        let fv = Vec3::from(v.flux);
        let sum = fv.length() + f.length();
        if sum > 0.0 {
            d += params.w_f * ((fv - f).length() / sum);
        }
    }
    d
}

/// A VPL's importance for the seeds: r + g + b of its flux.
fn importance(v: &Vpl) -> f32 {
    v.flux[0] + v.flux[1] + v.flux[2]
}

/// The inclusive prefix sums of the VPLs' importance in the GPU's order (vals.wgsl `cdf`):
/// [`LANES`] contiguous chunks of ⌈N / LANES⌉, each summed in order, the chunks' totals
/// added in order before them.
pub fn importance_cdf(vpls: &[Vpl]) -> Vec<f32> {
    let chunk = vpls.len().div_ceil(LANES).max(1);
    let mut out = vec![0.0f32; vpls.len()];
    let mut totals = [0.0f32; LANES];
    for (t, total) in totals.iter_mut().enumerate() {
        for v in vpls.iter().skip(t * chunk).take(chunk) {
            *total += importance(v);
        }
    }
    let mut base = 0.0f32;
    for (t, total) in totals.iter().enumerate() {
        let mut run = base;
        for (i, v) in vpls.iter().enumerate().skip(t * chunk).take(chunk) {
            run += importance(v);
            out[i] = run;
        }
        base += total;
    }
    out
}

/// The centre of a VPL.
fn centre_at(v: &Vpl) -> Centre {
    (v.position.into(), v.normal.into(), v.flux.into())
}

/// The initial centres: VAL k starts at VPL ⌊k·N/M⌋ (§5.2) of the lights' merged sequence
/// (read through [`dealt_position`]: the list is dealt out for interleaving,
/// [`crate::vpl_order`]), or the next live VPL after it in the sequence;
/// with [`ValSeeding::HaltonFlux`] at the first VPL whose cumulative importance exceeds
/// h₂(k) × the total.
pub fn initial_centres(vpls: &[Vpl], params: &ValParams) -> Vec<Centre> {
    let (n, count) = (vpls.len(), params.count);
    if params.seeding == ValSeeding::HaltonFlux {
        let cdf = importance_cdf(vpls);
        let total = cdf.last().copied().unwrap_or(0.0);
        return (0..count as u64)
            .map(|k| {
                let target = crate::vpl::radical_inverse(k, 2) * total;
                let i = cdf.partition_point(|&c| c <= target).min(n - 1);
                centre_at(&vpls[i])
            })
            .collect();
    }
    (0..count as u64)
        .map(|k| {
            let j = (k * n as u64 / count as u64) as usize;
            let at = |s: usize| &vpls[dealt_position(((j + s) % n) as u32, n as u32) as usize];
            let v = (0..n).map(at).find(|v| is_live(v)).unwrap_or(at(0));
            centre_at(v)
        })
        .collect()
}

/// Index of the nearest centre (the lower index on ties) among those whose splat reaches the
/// VPL (all of them when none does, or without splats); [`NO_VAL`] for a VPL of zero flux.
pub fn nearest(v: &Vpl, centres: &[Centre], inv_d: f32, params: &ValParams) -> u32 {
    if !is_live(v) {
        return NO_VAL;
    }
    let p = Vec3::from(v.position);
    let reach = params.splat_or_zero();
    let mut best = (f32::INFINITY, 0u32);
    let mut splat_best = (f32::INFINITY, NO_VAL);
    for (k, &c) in centres.iter().enumerate() {
        let d = distance(v, c, inv_d, params);
        if d < best.0 {
            best = (d, k as u32);
        }
        if reach > 0.0 && (p - c.0).length() * inv_d <= reach && d < splat_best.0 {
            splat_best = (d, k as u32);
        }
    }
    if splat_best.1 != NO_VAL {
        return splat_best.1;
    }
    best.1
}

/// Clusters `vpls` into `params.count` VALs from `start` centres (none: the restart of
/// [`initial_centres`]).
pub fn cluster(
    vpls: &[Vpl],
    params: &ValParams,
    start: Option<&[Centre]>,
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
        // The paper's warm start seeds again the VALs that held no VPL (flux 0) last frame.
        Some(s) if s.len() == m && params.seeding == ValSeeding::HaltonFlux => {
            let seeds = initial_centres(vpls, params);
            s.iter()
                .zip(seeds)
                .map(|(&c, seed)| if c.2 == Vec3::ZERO { seed } else { c })
                .collect()
        }
        Some(s) if s.len() == m => s.to_vec(),
        Some(s) => {
            return Err(RenderError::Param(format!(
                "{} start centres for {m} VALs",
                s.len()
            )));
        }
        None => initial_centres(vpls, params),
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
        let fluxes = lane_sums(vpls, &mapping, m, |v| v.flux);
        let counts = counts_of(&mapping, m);
        for (k, c) in centres.iter_mut().enumerate() {
            if counts[k] > 0 {
                // As the GPU divides (not normalize's reciprocal), for the same bits.
                let l = normals[k].length();
                *c = (
                    positions[k] / counts[k] as f32,
                    if l > 0.0 { normals[k] / l } else { c.1 },
                    fluxes[k] / counts[k] as f32,
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
    lanes.iter_mut().map(fold).collect()
}

/// Lane 0 after the GPU's tree fold of `lanes` (t += t + o for o = 32, 16, …, 1).
fn fold<T: Copy + std::ops::AddAssign>(lanes: &mut [T; LANES]) -> T {
    let mut o = LANES / 2;
    while o > 0 {
        for t in 0..o {
            let add = lanes[t + o];
            lanes[t] += add;
        }
        o /= 2;
    }
    lanes[0]
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
fn vals_of(vpls: &[Vpl], mapping: &[u32], centres: &[Centre]) -> Vec<Val> {
    let mut vals: Vec<Val> = centres
        .iter()
        .map(|&(c, n, _)| Val {
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
    let moments = second_moments(vpls, mapping, &vals);
    for ((val, flux), moment) in vals.iter_mut().zip(fluxes).zip(moments) {
        let count = val.position[3];
        let area = match count {
            0.0 => 0.0,
            c => 2.0 * std::f32::consts::PI * (moment / c),
        };
        val.flux = flux.extend(area).to_array();
        if count == 0.0 {
            val.rect = [0.0; 4];
        }
        val.normal[3] = (val.rect[1] - val.rect[0]) * (val.rect[3] - val.rect[2]);
    }
    vals
}

/// Each VAL's sum of s² + t² over its VPLs (their offsets from its centre in its plane), in
/// the GPU's lane order.
fn second_moments(vpls: &[Vpl], mapping: &[u32], vals: &[Val]) -> Vec<f32> {
    let mut lanes = vec![[0.0f32; LANES]; vals.len()];
    for (i, (v, &k)) in vpls.iter().zip(mapping).enumerate() {
        if k != NO_VAL {
            let val = &vals[k as usize];
            let (t, b) = basis(val.unit_normal());
            let q = Vec3::from(v.position) - val.centre();
            let (s, u) = (q.dot(t), q.dot(b));
            lanes[k as usize][i % LANES] += s * s + u * u;
        }
    }
    lanes.iter_mut().map(fold).collect()
}

/// The centres of a clustering (to start the next frame from, or to compare).
pub fn centres_of(c: &Clustering) -> Vec<Centre> {
    c.vals
        .iter()
        .map(|v| (v.centre(), v.unit_normal(), v.mean_flux()))
        .collect()
}
