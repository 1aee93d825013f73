//! LightCluster's clustering of many direct lights (the paper in
//! `../shared/papers/lightcluster-pcss.txt`): the CPU twin of the GPU's passes
//! (`gpu/passes/light_cluster.wgsl`), tested equal.
//!
//! 1. **Culling by range.** visgate's lights fall off as 1/d² and have no range; here a
//!    light reaches as far as its irradiance stays above `cutoff` times the irradiance the
//!    brightest light gives at a tenth of the level's diagonal D:
//!    `range = (D / 10) · sqrt(I / (cutoff · I_max))` (I the largest RGB channel of its
//!    intensity). A light whose range sphere lies outside the view frustum is culled.
//! 2. **Centres** (the paper's first pass, a minimum-distance metric): the lights left, nearest
//!    to the eye first (then by index), each becomes a cluster centre unless an existing centre
//!    lies within its minimum distance `min_distance_m · (1 + distance_scale · d)`, d its
//!    distance from the eye — so clusters are smaller near the camera. At most `max_clusters`
//!    centres.
//! 3. **Assignment** (second pass): every other light left joins its nearest centre.
//!
//! Each cluster is then shadowed as a disk-shaped area light at its centre light, of radius its
//! centre's minimum distance (the paper: "the radius of the area light source is given by the
//! minimum distance of the cluster") or — visgate's default — its extent, the distance of its
//! farthest light from the centre, so that a light alone keeps its hard shadow and a disk is
//! no wider than the lights it stands for.

use glam::Vec3;
use visgate_formats::scene::Light;

use crate::RenderError;
use crate::camera::View;

/// Marks a culled light in [`LightClusters::light_cluster`].
pub const CULLED: u32 = u32::MAX;

/// Parameters of [`cluster_lights`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightClusterParams {
    /// Minimum distance between cluster centres at the eye. [Limit: >= 0, finite] [Units: m]
    pub min_distance_m: f32,
    /// Growth of the minimum distance with the distance d from the eye:
    /// `min_distance_m · (1 + distance_scale · d)`. [Limit: >= 0, finite] [Units: 1/m]
    pub distance_scale: f32,
    /// Most clusters. [Limit: >= 1]
    pub max_clusters: u32,
    /// Irradiance where a light's range ends, as a fraction of the brightest light's at a
    /// tenth of the level's diagonal. [Limit: (0, 1]] [Units: ratio]
    pub cutoff: f32,
}

impl Default for LightClusterParams {
    fn default() -> Self {
        LightClusterParams {
            min_distance_m: 1.0,
            distance_scale: 0.1,
            max_clusters: 64,
            cutoff: 1e-3,
        }
    }
}

impl LightClusterParams {
    /// Checks every limit.
    pub fn check(&self) -> Result<(), RenderError> {
        let bad = |what: &str| Err(RenderError::Param(format!("LightCluster: {what}")));
        if !(self.min_distance_m.is_finite() && self.min_distance_m >= 0.0) {
            return bad("the minimum distance must be finite and >= 0 m");
        }
        if !(self.distance_scale.is_finite() && self.distance_scale >= 0.0) {
            return bad("the distance scale must be finite and >= 0 per metre");
        }
        if self.max_clusters == 0 {
            return bad("at least one cluster is needed (max clusters >= 1)");
        }
        if !(self.cutoff > 0.0 && self.cutoff <= 1.0) {
            return bad("the range cutoff must be in (0, 1]");
        }
        Ok(())
    }
}

/// The lights' clusters for one view.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LightClusters {
    /// Each cluster's centre, a light index, in the order chosen.
    pub centres: Vec<u32>,
    /// Each cluster's disk radius: its centre's minimum distance. [Units: m]
    pub radius_m: Vec<f32>,
    /// Each cluster's extent: its farthest light from its centre (0 for a light alone).
    /// [Units: m]
    pub extent_m: Vec<f32>,
    /// Each light's cluster, or [`CULLED`].
    pub light_cluster: Vec<u32>,
    /// Lights culled by range and frustum.
    pub culled: u32,
}

fn intensity(l: &Light) -> f32 {
    match *l {
        Light::Point { intensity, .. } | Light::Spot { intensity, .. } => intensity.max_element(),
    }
}

/// A light's range (see the module notes): `diagonal_m` is the level's diagonal, `brightest`
/// the largest intensity of any light. [Units: m]
pub fn light_range(intensity: f32, brightest: f32, diagonal_m: f32, cutoff: f32) -> f32 {
    range_scale(brightest, diagonal_m, cutoff) * intensity.max(0.0).sqrt()
}

/// `range_scale · sqrt(I)` is a light's range (as the GPU computes it).
fn range_scale(brightest: f32, diagonal_m: f32, cutoff: f32) -> f32 {
    if brightest <= 0.0 {
        return 0.0;
    }
    0.1 * diagonal_m / (cutoff * brightest).sqrt()
}

/// The factor of `sqrt(I)` in every range of `lights` (I the largest RGB channel of a
/// light's intensity) in a level of diagonal `diagonal_m`. [Units: m / sqrt(W/sr)]
pub fn light_range_scale(lights: &[Light], diagonal_m: f32, cutoff: f32) -> f32 {
    let brightest = lights.iter().map(intensity).fold(0.0f32, f32::max);
    range_scale(brightest, diagonal_m, cutoff)
}

/// Whether the sphere at `p` of radius `r` meets `view`'s frustum (no far plane).
pub fn sphere_in_view(view: &View, p: Vec3, r: f32) -> bool {
    let d = p - view.eye;
    let (x, y, z) = (d.dot(view.right), d.dot(view.up), d.dot(view.forward));
    let half_x = 0.5 * view.fov_x_rad;
    let half_y = view.tan_half().y.atan();
    let outside = |lateral: f32, half: f32| lateral * half.cos() - z * half.sin() > r;
    !(z < -r
        || outside(x, half_x)
        || outside(-x, half_x)
        || outside(y, half_y)
        || outside(-y, half_y))
}

/// Clusters `lights` for `view` in a level of diagonal `diagonal_m` (the renderer's is
/// `Scene::diagonal_m`; see the module notes).
pub fn cluster_lights(
    lights: &[Light],
    view: &View,
    diagonal_m: f32,
    params: &LightClusterParams,
) -> Result<LightClusters, RenderError> {
    params.check()?;
    let scale = light_range_scale(lights, diagonal_m, params.cutoff);
    let mut out = LightClusters {
        light_cluster: vec![CULLED; lights.len()],
        ..LightClusters::default()
    };
    let mut live: Vec<(f32, u32)> = Vec::new();
    for (i, l) in lights.iter().enumerate() {
        let range = scale * intensity(l).max(0.0).sqrt();
        if range > 0.0 && sphere_in_view(view, l.position(), range) {
            live.push(((l.position() - view.eye).length(), i as u32));
        } else {
            out.culled += 1;
        }
    }
    live.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let min_distance = |d: f32| params.min_distance_m * (1.0 + params.distance_scale * d);
    let at = |i: u32| lights[i as usize].position();
    for &(d, i) in &live {
        if out.centres.len() >= params.max_clusters as usize {
            break;
        }
        let r = min_distance(d);
        if out.centres.iter().all(|&c| at(c).distance(at(i)) >= r) {
            out.light_cluster[i as usize] = out.centres.len() as u32;
            out.centres.push(i);
            out.radius_m.push(r);
            out.extent_m.push(0.0);
        }
    }
    for &(_, i) in &live {
        if out.light_cluster[i as usize] != CULLED {
            continue;
        }
        let nearest = (0..out.centres.len())
            .min_by(|&a, &b| {
                let da = at(out.centres[a]).distance_squared(at(i));
                let db = at(out.centres[b]).distance_squared(at(i));
                da.total_cmp(&db).then(a.cmp(&b))
            })
            .expect("a live light makes a centre");
        out.light_cluster[i as usize] = nearest as u32;
        let d = at(out.centres[nearest]).distance(at(i));
        out.extent_m[nearest] = out.extent_m[nearest].max(d);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use visgate_formats::scene::Camera;

    fn point(x: f32, y: f32, z: f32) -> Light {
        Light::Point {
            position: Vec3::new(x, y, z),
            intensity: Vec3::splat(10.0),
        }
    }

    /// Looking down −z from the origin, 90° wide, 64×64.
    fn view() -> View {
        let camera = Camera {
            name: "c".into(),
            eye: Vec3::ZERO,
            target: Vec3::new(0.0, 0.0, -1.0),
            up: Vec3::Y,
            fov_x_rad: std::f32::consts::FRAC_PI_2,
        };
        View::new(&camera, [64, 64]).expect("view")
    }

    fn params(min_distance_m: f32, distance_scale: f32) -> LightClusterParams {
        LightClusterParams {
            min_distance_m,
            distance_scale,
            ..LightClusterParams::default()
        }
    }

    #[test]
    fn a_light_alone_is_its_own_cluster_and_close_lights_merge() {
        let v = view();
        let one = cluster_lights(&[point(0.0, 0.0, -5.0)], &v, 100.0, &params(1.0, 0.0))
            .expect("clusters");
        assert_eq!((one.centres, one.light_cluster), (vec![0], vec![0]));
        assert_eq!(one.radius_m, vec![1.0]);
        let lights = [
            point(0.0, 0.0, -5.0),
            point(0.5, 0.0, -5.0),
            point(3.0, 0.0, -5.0),
        ];
        let c = cluster_lights(&lights, &v, 100.0, &params(1.0, 0.0)).expect("clusters");
        assert_eq!(c.centres.len(), 2);
        assert_eq!(c.light_cluster[0], c.light_cluster[1]);
        assert_ne!(c.light_cluster[0], c.light_cluster[2]);
        // No minimum distance: every light its own cluster; a huge one: one cluster.
        let each = cluster_lights(&lights, &v, 100.0, &params(0.0, 0.0)).expect("clusters");
        assert_eq!(each.centres.len(), 3);
        let all = cluster_lights(&lights, &v, 100.0, &params(1e6, 0.0)).expect("clusters");
        assert_eq!(all.light_cluster, vec![0, 0, 0]);
    }

    #[test]
    fn lights_out_of_the_frustum_are_culled_unless_their_range_reaches_in() {
        let v = view();
        // Behind the camera, far to the side, and a dim light beside the frustum's edge.
        let dim = Light::Point {
            position: Vec3::new(7.0, 0.0, -5.0),
            intensity: Vec3::splat(1e-3),
        };
        let lights = [
            point(0.0, 0.0, -5.0),
            point(0.0, 0.0, 50.0),
            point(90.0, 0.0, -5.0),
            dim,
        ];
        // Cutoff 1: the brightest light reaches a tenth of the 20 m diagonal, 2 m.
        let p = LightClusterParams {
            cutoff: 1.0,
            ..params(1.0, 0.0)
        };
        assert_eq!(light_range(10.0, 10.0, 20.0, 1.0), 2.0);
        let c = cluster_lights(&lights, &v, 20.0, &p).expect("clusters");
        assert_eq!(c.culled, 3, "{c:?}");
        assert_eq!(c.light_cluster[1..], [CULLED; 3]);
        // The same dim light as bright as the others: its range reaches into the frustum.
        let mut lights = lights;
        lights[3] = point(7.0, 0.0, -5.0);
        let c = cluster_lights(&lights, &v, 20.0, &p).expect("clusters");
        assert_ne!(c.light_cluster[3], CULLED);
        // At the default cutoff the bright light behind the camera reaches it: kept.
        let c = cluster_lights(&lights, &v, 20.0, &params(1.0, 0.0)).expect("clusters");
        assert_ne!(c.light_cluster[1], CULLED);
    }

    #[test]
    fn nearer_clusters_are_smaller() {
        // 200 lights 0.25 m apart along the view axis, 1 to 51 m away.
        let lights: Vec<Light> = (0..200)
            .map(|k| point(0.0, 0.0, -1.0 - 0.25 * k as f32))
            .collect();
        let c = cluster_lights(&lights, &view(), 1000.0, &params(0.5, 0.2)).expect("clusters");
        let near = c.light_cluster[..40]
            .iter()
            .collect::<std::collections::BTreeSet<_>>();
        let far = c.light_cluster[160..]
            .iter()
            .collect::<std::collections::BTreeSet<_>>();
        assert!(
            near.len() > 2 * far.len(),
            "{} near, {} far",
            near.len(),
            far.len()
        );
        assert!(c.radius_m.windows(2).all(|w| w[0] <= w[1]));
        // Every light joined the nearest centre.
        for (i, &k) in c.light_cluster.iter().enumerate() {
            let p = lights[i].position();
            let d = |c: u32| lights[c as usize].position().distance(p);
            let best = c
                .centres
                .iter()
                .map(|&c| d(c))
                .fold(f32::INFINITY, f32::min);
            assert_eq!(d(c.centres[k as usize]), best);
        }
    }

    #[test]
    fn no_lights_many_lights_and_the_cluster_cap() {
        let v = view();
        let none = cluster_lights(&[], &v, 10.0, &LightClusterParams::default()).expect("clusters");
        assert_eq!(none, LightClusters::default());
        let lights: Vec<Light> = (0..1024)
            .map(|k| point((k % 32) as f32 - 16.0, (k / 32) as f32 - 16.0, -20.0))
            .collect();
        let capped = LightClusterParams {
            max_clusters: 10,
            ..params(0.1, 0.0)
        };
        let c = cluster_lights(&lights, &v, 100.0, &capped).expect("clusters");
        assert_eq!(c.centres.len(), 10);
        assert!(c.light_cluster.iter().all(|&k| k < 10));
        let bad = LightClusterParams {
            max_clusters: 0,
            ..LightClusterParams::default()
        };
        assert!(cluster_lights(&lights, &v, 100.0, &bad).is_err());
    }
}
