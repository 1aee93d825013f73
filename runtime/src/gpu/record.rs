//! The frame as its passes, recorded in order (after the VPLs): shadow maps, G-buffer, the
//! mode's passes, shading, and what the frame reads back.

use super::context::Pool;
use super::passes;
use super::passes::clustered_gates::ListBuffers;
use super::passes::interleave_blur::InterleaveBlur;
use super::passes::shade::Gathers;
use super::passes::val_gather::ValPasses;
use super::timing::Recorder;
use super::{DirectLight, Frame, GpuMode, Pipelines};
use crate::RenderError;
use crate::cpu::gates::GateShape;

/// What [`record_passes`] leaves: the image, and the light lists of mode gates.
pub(super) struct Recorded {
    pub(super) hdr: wgpu::Texture,
    pub(super) lists: Option<ListBuffers>,
    /// The VAL clustering's convergence words, in the VAL modes.
    pub(super) val_state: Option<wgpu::Buffer>,
    /// LightCluster's args (its counts), with `--direct lightcluster`.
    pub(super) lc_args: Option<wgpu::Buffer>,
    /// The same of the VPLs' clusters (mode vpl-clusters).
    pub(super) vpl_lc_args: Option<wgpu::Buffer>,
    /// Interleaved gates' starved pixels, with `--starved-taps`.
    pub(super) starved: Option<passes::starved::StarvedOutput>,
    /// Interleaved walks' ratio estimator's unshadowed light.
    pub(super) unshadowed: Option<passes::unshadowed::UnshadowedOutput>,
}

/// The frame as its passes (after the VPLs): shadow maps, G-buffer, the mode's passes,
/// shading. `warm`: the VAL clustering may start from last frame's centres.
pub(super) fn record_passes(
    p: &Pipelines,
    f: &Frame,
    pool: &mut Pool,
    rec: &mut Recorder,
    warm: bool,
) -> Result<Recorded, RenderError> {
    let lc_params = match f.params.direct {
        DirectLight::LightCluster(lp) => Some(lp),
        DirectLight::PerLight => None,
    };
    let shadows = p.shadow_maps.record(f, pool, rec, lc_params.is_none())?;
    let g = p.gbuffer.record(f, pool, rec);
    let lc = match &lc_params {
        Some(lp) => Some(
            p.light_cluster
                .record(f, lp, &shadows.lights, &g, pool, rec)?,
        ),
        None => None,
    };
    let vpl_lc = match &f.params.mode {
        GpuMode::VplClusters(vp, _) => Some(p.light_cluster.record_vpls(f, vp, &g, pool, rec)?),
        _ => None,
    };
    // The voxel walk needs no geometry clusters, lists or VPL clusters: the VPLs' ends.
    let (lists, vpl_ends) = match &f.params.mode {
        GpuMode::Gates(gp) if gp.gates.shape == GateShape::Voxels => {
            let level = passes::clustered_gates::LevelBuffers::of(f)?;
            let ends =
                p.sight_ends
                    .record(f, (&level.sight_words, &level.sight_extra), pool, rec)?;
            (None, Some(ends))
        }
        GpuMode::Gates(gp) => (
            Some(p.clustered.record(f, gp, pool, rec, &g.views[0])?),
            None,
        ),
        _ => (None, None),
    };
    let shading = match f.params.mode {
        GpuMode::Gates(gp) if gp.gathers_apart() => "shading: direct lighting",
        GpuMode::VplClusters(_, i) if i.block > 1 => "shading: direct lighting",
        GpuMode::None
        | GpuMode::Gates(_)
        | GpuMode::GatesPerPixel(_)
        | GpuMode::VplClusters(..) => "shading: direct + indirect lighting",
        _ => "shading: direct lighting",
    };
    let gathers = Gathers {
        lists: lists.as_ref(),
        vpl_ends: vpl_ends.as_ref(),
    };
    let inputs = (&shadows, &g, gathers, lc.as_ref(), vpl_lc.as_ref());
    let mut hdr = p.shade.record(f, pool, rec, inputs, shading);
    let mut val_state = None;
    let mut starved = None;
    let mut unshadowed = None;
    match &f.params.mode {
        GpuMode::Gates(gp) if gp.gathers_apart() => {
            let indirect = p
                .shade
                .record_indirect(f, pool, rec, inputs, Some(gp.gates.shape));
            let il = &gp.interleave;
            starved = il.walks_starved().then(|| {
                p.shade
                    .record_starved(f, pool, rec, inputs, (gp.gates.shape, il, &indirect))
            });
            if f.near_scale > 0.0 {
                hdr = p
                    .shade
                    .record_near(f, pool, rec, inputs, (gp.gates.shape, &hdr));
            }
            unshadowed = f.ratio.then(|| p.unshadowed.record(f, pool, rec, &g));
            let uniform = InterleaveBlur::uniform(f, il, pool, true);
            let targets = (&g, &uniform, &indirect, &hdr);
            let sums = starved.as_ref().map(|s| &s.sums);
            p.blur.record(
                f,
                il,
                pool,
                rec,
                targets,
                (sums, unshadowed.as_ref().map(|u| &u.image)),
            );
        }
        GpuMode::VplClusters(_, il) if il.block > 1 => {
            let indirect = p.shade.record_indirect(f, pool, rec, inputs, None);
            let uniform = InterleaveBlur::uniform(f, il, pool, true);
            let targets = (&g, &uniform, &indirect, &hdr);
            p.blur.record(f, il, pool, rec, targets, (None, None));
        }
        GpuMode::PerVplShadowMaps(pv) => p.maps.record(f, pv, pool, rec, (&g, &hdr)),
        GpuMode::PerVplIsm(pi) => p.isms.record_vpls(f, pi, &p.blur, pool, rec, (&g, &hdr))?,
        GpuMode::ValIsm(vi) => {
            val_state = p
                .isms
                .record_vals(f, vi, &p.vals, &p.blur, warm, pool, rec, (&g, &hdr))?;
        }
        GpuMode::ValHard(v) | GpuMode::ValCssm(v, _) => {
            let cssm = match &f.params.mode {
                GpuMode::ValCssm(_, c) => Some(c),
                _ => None,
            };
            let passes = ValPasses {
                clustering: &p.vals,
                maps: &p.maps,
                cssm: &p.cssm,
                blur: &p.blur,
            };
            val_state = p
                .val_gather
                .record(f, v, cssm, warm, &passes, pool, rec, (&g, &hdr))?;
        }
        _ => {}
    }
    Ok(Recorded {
        hdr,
        lists,
        val_state,
        lc_args: lc.map(|o| o.clusters.args),
        vpl_lc_args: vpl_lc.map(|o| o.clusters.args),
        starved,
        unshadowed,
    })
}
