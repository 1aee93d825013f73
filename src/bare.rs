//! A bare mesh made visible: `visgate_scenes::bare` at the centre of the level's largest empty
//! ball (`visgate_preprocess::ball`), with the scene's own rays as its probe.

use visgate_formats::Scene;
use visgate_runtime::cpu::tracer::Tracer;
use visgate_scenes::bare::{light_a_bare_scene, probe_directions};

/// Gives a scene without a light or a camera both (see `visgate_scenes::bare`) and prints
/// what it added, prefixed with the scene's argument. The place depends on the scene alone,
/// not on whether a baked level is given, so that every render of it looks from one place.
pub fn light_if_bare(scene: &mut Scene, arg: &str) {
    if !scene.lights.is_empty() && !scene.cameras.is_empty() {
        return;
    }
    let tracer = Tracer::new(scene);
    let dirs = probe_directions();
    let probe = |p: glam::Vec3| {
        let mut near = f32::INFINITY;
        let mut sum = 0.0;
        for &d in &dirs {
            let t = tracer.trace(p, d)?.t;
            near = near.min(t);
            sum += t;
        }
        Some((near, sum / dirs.len() as f32))
    };
    let reach = |p: glam::Vec3, d: glam::Vec3| tracer.trace(p, d).map(|h| h.t);
    let ball = visgate_preprocess::ball::largest_empty_ball(scene).map(|(centre, _)| centre);
    if let Some(note) = light_a_bare_scene(scene, ball, &probe, &reach) {
        println!("{arg}: {note}");
    }
}
