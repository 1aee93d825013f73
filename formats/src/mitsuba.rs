//! Writing a scene for Mitsuba 3 (`scene.xml`, OBJ meshes, EXR textures), with visgate's
//! conventions spelled out so that Mitsuba's `path` integrator renders what visgate's CPU
//! reference converges to: a box pixel filter, the horizontal field of view (`fov_axis` x),
//! two-sided Lambertian surfaces with the same albedos (material × texture, nearest texel,
//! repeated, baked into linear EXR textures), the meshes' own normals (interpolated by both),
//! point and spot lights in W/sr with Mitsuba's spot falloff (visgate's is the same), and
//! direct light plus one bounce (`max_depth` 3) without Russian roulette.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::scene::{Light, Scene};

/// What the exported scene renders.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MitsubaOptions {
    /// Film size. [Units: px]
    pub size: [u32; 2],
    /// Samples per pixel.
    pub spp: u32,
    /// Path depth: 2 is direct light only, 3 adds one bounce (visgate's one-bounce VPLs).
    pub max_depth: u32,
}

impl Default for MitsubaOptions {
    fn default() -> Self {
        MitsubaOptions {
            size: [512, 512],
            spp: 1024,
            max_depth: 3,
        }
    }
}

/// What was written.
#[derive(Debug, Clone, PartialEq)]
pub struct MitsubaFiles {
    /// The scene file.
    pub xml: PathBuf,
    /// OBJ files (one per mesh and material).
    pub shapes: usize,
    /// EXR textures (one per textured material).
    pub textures: usize,
    /// The sensors, in the scene's camera order (Mitsuba's `sensor` index).
    pub sensors: Vec<String>,
}

/// Writes `scene` for Mitsuba 3 into `dir` (created if missing).
pub fn write(scene: &Scene, dir: &Path, opts: &MitsubaOptions) -> std::io::Result<MitsubaFiles> {
    std::fs::create_dir_all(dir.join("meshes"))?;
    let mut xml = String::from("<scene version=\"3.0.0\">\n");
    let _ = writeln!(
        xml,
        "  <!-- written by visgate from '{}': direct light + one bounce, box filter, fov along x \
         -->\n  <integrator type=\"path\">\n    <integer name=\"max_depth\" value=\"{}\"/>\n    \
         <integer name=\"rr_depth\" value=\"{}\"/>\n  </integrator>",
        escape(&scene.name),
        opts.max_depth,
        opts.max_depth + 1
    );
    let diagonal = scene
        .bounds()
        .map_or(1.0, |(lo, hi)| (hi - lo).length().max(1e-6));
    for c in &scene.cameras {
        sensor(&mut xml, c, diagonal, opts);
    }
    let textures = materials(scene, dir, &mut xml)?;
    let shapes = meshes(scene, dir, &mut xml)?;
    for l in &scene.lights {
        light(&mut xml, l);
    }
    xml += "</scene>\n";
    let path = dir.join("scene.xml");
    std::fs::write(&path, xml)?;
    Ok(MitsubaFiles {
        xml: path,
        shapes,
        textures,
        sensors: scene.cameras.iter().map(|c| c.name.clone()).collect(),
    })
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
        .replace("--", "- -")
}

fn v3(v: glam::Vec3) -> String {
    format!("{}, {}, {}", v.x, v.y, v.z)
}

fn sensor(xml: &mut String, c: &crate::scene::Camera, diagonal: f32, opts: &MitsubaOptions) {
    let [w, h] = opts.size;
    let _ = writeln!(
        xml,
        "  <sensor type=\"perspective\" id=\"{}\">\n    <string name=\"fov_axis\" value=\"x\"/>\n    \
         <float name=\"fov\" value=\"{}\"/>\n    <float name=\"near_clip\" value=\"{}\"/>\n    \
         <float name=\"far_clip\" value=\"{}\"/>\n    <transform name=\"to_world\">\n      \
         <lookat origin=\"{}\" target=\"{}\" up=\"{}\"/>\n    </transform>\n    \
         <sampler type=\"independent\">\n      <integer name=\"sample_count\" value=\"{}\"/>\n    \
         </sampler>\n    <film type=\"hdrfilm\">\n      <integer name=\"width\" value=\"{w}\"/>\n      \
         <integer name=\"height\" value=\"{h}\"/>\n      <string name=\"pixel_format\" value=\"rgb\"/>\n      \
         <rfilter type=\"box\"/>\n    </film>\n  </sensor>",
        escape(&c.name),
        c.fov_x_rad.to_degrees(),
        diagonal * 1e-5,
        diagonal * 10.0,
        v3(c.eye),
        v3(c.target),
        v3(c.up),
        opts.spp
    );
}

/// A two-sided diffuse BSDF per material; textured ones get `textures/matN.exr`, the albedo ×
/// the sRGB-decoded texels in linear RGB. Returns the textures written.
fn materials(scene: &Scene, dir: &Path, xml: &mut String) -> std::io::Result<usize> {
    let mut written = 0;
    for (i, m) in scene.materials.iter().enumerate() {
        let tex = m.texture.and_then(|t| scene.textures.get(t as usize));
        let reflectance = match tex {
            Some(t) if t.width > 0 && t.height > 0 => {
                std::fs::create_dir_all(dir.join("textures"))?;
                let file = format!("textures/mat{i}.exr");
                let decode = |v: u8| {
                    let c = v as f32 / 255.0;
                    match c <= 0.04045 {
                        true => c / 12.92,
                        false => ((c + 0.055) / 1.055).powf(2.4),
                    }
                };
                let img = image::Rgb32FImage::from_fn(t.width, t.height, |x, y| {
                    let k = ((y * t.width + x) * 4) as usize;
                    image::Rgb(std::array::from_fn(|c| {
                        m.albedo[c] * decode(t.rgba8[k + c])
                    }))
                });
                img.save(dir.join(&file)).map_err(std::io::Error::other)?;
                written += 1;
                format!(
                    "<texture type=\"bitmap\" name=\"reflectance\">\n        <string name=\"filename\" \
                     value=\"{file}\"/>\n        <boolean name=\"raw\" value=\"true\"/>\n        \
                     <string name=\"filter_type\" value=\"nearest\"/>\n        <string \
                     name=\"wrap_mode\" value=\"repeat\"/>\n      </texture>"
                )
            }
            _ => format!("<rgb name=\"reflectance\" value=\"{}\"/>", v3(m.albedo)),
        };
        let _ = writeln!(
            xml,
            "  <bsdf type=\"twosided\" id=\"mat{i}\">\n    <bsdf type=\"diffuse\">\n      \
             {reflectance}\n    </bsdf>\n  </bsdf>"
        );
    }
    Ok(written)
}

/// One OBJ per mesh and material (positions, the mesh's normals, texture coordinates in OBJ's
/// convention, which Mitsuba flips back). Returns the shapes written.
fn meshes(scene: &Scene, dir: &Path, xml: &mut String) -> std::io::Result<usize> {
    let mut shapes = 0;
    for (mi, mesh) in scene.meshes.iter().enumerate() {
        let mut mats: Vec<u32> = mesh.material.clone();
        mats.sort_unstable();
        mats.dedup();
        for mat in mats {
            let mut remap = vec![u32::MAX; mesh.positions.len()];
            let (mut verts, mut faces) = (String::new(), String::new());
            let mut next = 1u32;
            for (t, tri) in mesh.triangles.iter().enumerate() {
                if mesh.material.get(t) != Some(&mat) {
                    continue;
                }
                // Mitsuba refuses a zero normal: such a vertex takes its triangle's.
                let [a, b, c] = tri.map(|v| mesh.positions[v as usize]);
                let face = (b - a).cross(c - a).normalize_or(glam::Vec3::Y);
                let ids = tri.map(|v| {
                    let r = &mut remap[v as usize];
                    if *r == u32::MAX {
                        let p = mesh.positions[v as usize];
                        let n = mesh.normals[v as usize].try_normalize().unwrap_or(face);
                        let uv = mesh.uvs.get(v as usize).copied().unwrap_or_default();
                        let _ = writeln!(
                            verts,
                            "v {} {} {}\nvn {} {} {}\nvt {} {}",
                            p.x,
                            p.y,
                            p.z,
                            n.x,
                            n.y,
                            n.z,
                            uv.x,
                            1.0 - uv.y
                        );
                        *r = next;
                        next += 1;
                    }
                    *r
                });
                let [a, b, c] = ids;
                let _ = writeln!(faces, "f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}");
            }
            let file = format!("meshes/{mi}-{mat}.obj");
            std::fs::write(dir.join(&file), verts + &faces)?;
            let _ = writeln!(
                xml,
                "  <shape type=\"obj\">\n    <string name=\"filename\" value=\"{file}\"/>\n    \
                 <ref id=\"mat{mat}\"/>\n  </shape>"
            );
            shapes += 1;
        }
    }
    Ok(shapes)
}

fn light(xml: &mut String, l: &Light) {
    match *l {
        Light::Point {
            position,
            intensity,
        } => {
            let _ = writeln!(
                xml,
                "  <emitter type=\"point\">\n    <point name=\"position\" value=\"{}\"/>\n    \
                 <rgb name=\"intensity\" value=\"{}\"/>\n  </emitter>",
                v3(position),
                v3(intensity)
            );
        }
        Light::Spot {
            position,
            direction,
            intensity,
            cutoff_rad,
            beam_rad,
        } => {
            // Any up vector not along the axis: the spot is round.
            let up = match direction.normalize().y.abs() > 0.9 {
                true => glam::Vec3::X,
                false => glam::Vec3::Y,
            };
            let _ = writeln!(
                xml,
                "  <emitter type=\"spot\">\n    <transform name=\"to_world\">\n      <lookat \
                 origin=\"{}\" target=\"{}\" up=\"{}\"/>\n    </transform>\n    <rgb \
                 name=\"intensity\" value=\"{}\"/>\n    <float name=\"cutoff_angle\" value=\"{}\"/>\n    \
                 <float name=\"beam_width\" value=\"{}\"/>\n  </emitter>",
                v3(position),
                v3(position + direction),
                v3(up),
                v3(intensity),
                cutoff_rad.to_degrees(),
                beam_rad.to_degrees()
            );
        }
    }
}
