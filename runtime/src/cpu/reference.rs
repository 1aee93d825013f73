//! The CPU reference renderer: exact visibility by ray casting. Direct light with a shadow ray
//! per light, and the same VPLs the GPU gathers, each with a shadow ray (or without, for the
//! `none` mode's twin), jittered pixel samples, rayon over rows.
//!
//! Radiance of a primary hit `x`: `L = L_direct(x) + Σ_j V(x, y_j) · ρ/π · Φ_j/π · G_j`, with
//! the geometry term clamped as the GPU does ([`GatherParams`]). Emitters are points, so camera
//! rays that miss see black.

use std::sync::atomic::{AtomicU64, Ordering};

use glam::{Vec2, Vec3};
use rayon::prelude::*;
use visgate_formats::Light;

use crate::RenderError;
use crate::camera::View;
use crate::cpu::gates::{End, GateLevel, GateParams};
use crate::cpu::tracer::{Surface, Tracer};
use crate::hdr::HdrImage;
use crate::lights::direct_radiance;
use crate::vpl::{GatherParams, Vpl, gather_one, halton2};

/// What the reference renders.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReferenceParams {
    /// Pixel samples (jittered on a Halton pattern). [Limit: 1..=4096]
    pub samples_per_pixel: u32,
    /// Include direct light.
    pub direct: bool,
    /// Include the VPLs' indirect light.
    pub indirect: bool,
    /// Shadow rays for the VPLs (false: every VPL lights every point, the `none` mode).
    pub indirect_visibility: bool,
    /// The gather's clamp.
    pub gather: GatherParams,
}

impl Default for ReferenceParams {
    fn default() -> Self {
        ReferenceParams {
            samples_per_pixel: 4,
            direct: true,
            indirect: true,
            indirect_visibility: true,
            gather: GatherParams::default(),
        }
    }
}

/// What a reference render counted.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReferenceStats {
    /// Shadow rays cast (direct and indirect).
    pub shadow_rays: u64,
    /// Camera rays cast.
    pub camera_rays: u64,
    /// Wall time. [Units: s]
    pub seconds: f64,
}

/// Visibility of VPL light, for [`render_with`].
#[derive(Clone, Copy)]
pub enum IndirectVisibility<'a> {
    /// A shadow ray per VPL and sample.
    Exact,
    /// Every VPL lights every point.
    Unoccluded,
    /// The gate test of a baked level (the CPU twin of the `gates` mode, per point).
    Gates(&'a GateLevel, GateParams),
}

/// Renders the reference image of `view`. `progress(rows_done, rows)` is called as rows end.
pub fn render_reference(
    tracer: &Tracer,
    lights: &[Light],
    vpls: &[Vpl],
    view: &View,
    params: &ReferenceParams,
    progress: &(dyn Fn(u32, u32) + Sync),
) -> Result<(HdrImage, ReferenceStats), RenderError> {
    let vis = if params.indirect_visibility {
        IndirectVisibility::Exact
    } else {
        IndirectVisibility::Unoccluded
    };
    render_with(tracer, lights, vpls, view, params, vis, progress)
}

/// [`render_reference`] with any [`IndirectVisibility`] (`params.indirect_visibility` is not
/// read).
pub fn render_with(
    tracer: &Tracer,
    lights: &[Light],
    vpls: &[Vpl],
    view: &View,
    params: &ReferenceParams,
    vis: IndirectVisibility,
    progress: &(dyn Fn(u32, u32) + Sync),
) -> Result<(HdrImage, ReferenceStats), RenderError> {
    let never = std::sync::atomic::AtomicBool::new(false);
    render_cancellable(tracer, lights, vpls, view, params, vis, progress, &never)
}

/// [`render_with`] that stops, with an error, soon after `cancel` is set (rows not yet begun
/// are skipped): for a viewer whose camera moved on.
#[allow(clippy::too_many_arguments)]
pub fn render_cancellable(
    tracer: &Tracer,
    lights: &[Light],
    vpls: &[Vpl],
    view: &View,
    params: &ReferenceParams,
    vis: IndirectVisibility,
    progress: &(dyn Fn(u32, u32) + Sync),
    cancel: &std::sync::atomic::AtomicBool,
) -> Result<(HdrImage, ReferenceStats), RenderError> {
    check(params)?;
    let t0 = std::time::Instant::now();
    // The visibility cluster of every VPL, for the gate test.
    let vpl_cluster: Vec<Option<u32>> = match vis {
        IndirectVisibility::Gates(level, _) => vpls
            .iter()
            .map(|v| level.cluster_at(Vec3::from(v.position), Vec3::from(v.normal)))
            .collect(),
        _ => Vec::new(),
    };
    let indirect = Indirect {
        tracer,
        vpls,
        gather: &params.gather,
        vis,
        vpl_cluster: &vpl_cluster,
    };
    let [w, h] = view.size;
    let shadow = AtomicU64::new(0);
    let done = AtomicU64::new(0);
    let spp = params.samples_per_pixel;
    let rows: Vec<Vec<Vec3>> = (0..h)
        .into_par_iter()
        .map(|y| {
            let mut row = Vec::with_capacity(w as usize);
            if cancel.load(Ordering::Relaxed) {
                return row;
            }
            let mut rays = 0u64;
            for x in 0..w {
                let mut sum = Vec3::ZERO;
                for s in 0..spp {
                    let dir = view.ray_dir(Vec2::new(x as f32, y as f32) + sample(s, spp));
                    let Some(surf) = tracer.trace(view.eye, dir) else {
                        continue;
                    };
                    if params.direct {
                        sum += direct_radiance(tracer, lights, &surf);
                        rays += lights.len() as u64;
                    }
                    if params.indirect {
                        rays += indirect.add(&surf, &mut sum);
                    }
                }
                row.push(sum / spp as f32);
            }
            shadow.fetch_add(rays, Ordering::Relaxed);
            let d = done.fetch_add(1, Ordering::Relaxed) + 1;
            progress(d as u32, h);
            row
        })
        .collect();
    if cancel.load(Ordering::Relaxed) {
        return Err(RenderError::Param(
            "the reference render was cancelled".into(),
        ));
    }
    let img = HdrImage {
        width: w,
        height: h,
        pixels: rows.into_iter().flatten().collect(),
    };
    Ok((
        img,
        ReferenceStats {
            shadow_rays: shadow.into_inner(),
            camera_rays: w as u64 * h as u64 * spp as u64,
            seconds: t0.elapsed().as_secs_f64(),
        },
    ))
}

/// Refuses samples per pixel outside 1..=4096 and a geometry-term clamp that is not > 0.
fn check(params: &ReferenceParams) -> Result<(), RenderError> {
    if !(1..=4096).contains(&params.samples_per_pixel) {
        return Err(RenderError::Param(format!(
            "{} samples per pixel: give 1 to 4096",
            params.samples_per_pixel
        )));
    }
    if params.gather.g_max.is_nan() || params.gather.g_max <= 0.0 {
        return Err(RenderError::Param(format!(
            "geometry-term clamp {} must be > 0",
            params.gather.g_max
        )));
    }
    Ok(())
}

/// The VPLs' light at a surface, each VPL shadowed by the visibility asked for.
struct Indirect<'a> {
    tracer: &'a Tracer,
    vpls: &'a [Vpl],
    gather: &'a GatherParams,
    vis: IndirectVisibility<'a>,
    /// Each VPL's visibility cluster, for the gate test.
    vpl_cluster: &'a [Option<u32>],
}

impl Indirect<'_> {
    /// Adds each VPL's light at `surf` to `sum` where it is visible, VPL after VPL; returns
    /// the shadow rays cast.
    fn add(&self, surf: &Surface, sum: &mut Vec3) -> u64 {
        let tracer = self.tracer;
        let mut rays = 0;
        let from = surf.position + surf.geometric_normal * tracer.epsilon_m;
        let here = match self.vis {
            IndirectVisibility::Gates(level, _) => level.cluster_at(surf.position, surf.normal),
            _ => None,
        };
        for (j, v) in self.vpls.iter().enumerate() {
            let l = gather_one(v, surf.position, surf.normal, surf.albedo, self.gather);
            if l == Vec3::ZERO {
                continue;
            }
            let lit = match self.vis {
                IndirectVisibility::Unoccluded => true,
                IndirectVisibility::Exact => {
                    rays += 1;
                    let to = Vec3::from(v.position) + Vec3::from(v.normal) * tracer.epsilon_m;
                    !tracer.occluded(from, to)
                }
                // Gates, portals or voxels (GateLevel::visible: a point or VPL outside every
                // cluster meets no gate, unoccluded).
                IndirectVisibility::Gates(level, gp) => {
                    let vpl = End::of_vpl(v, self.vpl_cluster[j]);
                    let point = End {
                        position: surf.position,
                        normal: surf.geometric_normal,
                        cluster: here,
                    };
                    level.visible(&vpl, &point, &gp)
                }
            };
            if lit {
                *sum += l;
            }
        }
        rays
    }
}

/// Where in its pixel the reference's sample `s` of `spp` lies: the centre for one, else a
/// Halton pattern. [Units: pixels]
fn sample(s: u32, spp: u32) -> Vec2 {
    if spp == 1 {
        Vec2::splat(0.5)
    } else {
        halton2(s as u64 + 1, 2, 3, Vec2::ZERO)
    }
}

/// Normals of one surface agree to this cosine (25°): a column's facets within a pixel do, a
/// wall and the floor it stands on do not.
const SAME_SURFACE_COS: f32 = 0.9;
/// A sample lies on the centre's surface when within this share of the centre's distance from
/// its tangent plane: a pillar's edge before a wall is metres off it. [Units: ratio]
const SAME_SURFACE_DEPTH: f32 = 0.01;

/// Albedos (summed over the channels) within this ratio cannot make a pixel black where lit
/// by themselves: the method's point under a tenth of the reference's mean takes a wider one.
const SAME_ALBEDO_RATIO: f32 = 10.0;

/// The pixels of `view` whose `spp` reference samples (the pattern [`render_reference`]
/// takes) and centre (the point a method shades) see more than one surface: some hit and
/// some miss, or their geometric normals or planes differ — silhouettes and creases —, or
/// their albedos differ more than tenfold (a dark texel under a bright one's neighbours):
/// there the reference averages what a method that shades one point a pixel shows one of.
/// All false for one sample a pixel (it is the centre). Rows from the top.
pub fn mixed_pixels(tracer: &Tracer, view: &View, spp: u32) -> Vec<bool> {
    let [w, h] = view.size;
    let pixel = |x: u32, y: u32| {
        let hit =
            |at: Vec2| tracer.trace(view.eye, view.ray_dir(Vec2::new(x as f32, y as f32) + at));
        let centre = hit(Vec2::splat(0.5));
        let albedo = |s: &Surface| s.albedo.element_sum();
        (0..spp).any(|s| match (centre, hit(sample(s, spp))) {
            (None, None) => false,
            (Some(a), Some(b)) => {
                let (pa, pb) = (albedo(&a), albedo(&b));
                let (lo, hi) = (pa.min(pb), pa.max(pb));
                a.geometric_normal.dot(b.geometric_normal) < SAME_SURFACE_COS
                    || a.geometric_normal.dot(b.position - a.position).abs()
                        > SAME_SURFACE_DEPTH * a.t
                    || hi > SAME_ALBEDO_RATIO * lo
            }
            _ => true,
        })
    };
    (0..h)
        .into_par_iter()
        .flat_map_iter(|y| (0..w).map(move |x| pixel(x, y)))
        .collect()
}

/// The radiance of one surface point seen along a ray, for tests: direct (with shadow rays)
/// plus the VPLs with or without visibility.
pub fn shade_point(
    tracer: &Tracer,
    lights: &[Light],
    vpls: &[Vpl],
    origin: Vec3,
    dir: Vec3,
    params: &ReferenceParams,
) -> Option<Vec3> {
    let surf = tracer.trace(origin, dir)?;
    let mut sum = Vec3::ZERO;
    if params.direct {
        sum += direct_radiance(tracer, lights, &surf);
    }
    if params.indirect {
        let from = surf.position + surf.geometric_normal * tracer.epsilon_m;
        for v in vpls {
            let l = gather_one(v, surf.position, surf.normal, surf.albedo, &params.gather);
            if l != Vec3::ZERO
                && !(params.indirect_visibility
                    && tracer.occluded(
                        from,
                        Vec3::from(v.position) + Vec3::from(v.normal) * tracer.epsilon_m,
                    ))
            {
                sum += l;
            }
        }
    }
    Some(sum)
}
