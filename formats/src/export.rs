//! Writing an imported model back out as Wavefront OBJ + MTL (used by `visgate scenes export`).

use std::fmt::Write;

use crate::import::ImportedModel;

/// The OBJ and MTL texts of a model; the OBJ refers to the MTL as `mtl_file_name`.
/// Floats are written in Rust's shortest round-trip form, so reading the OBJ back gives the
/// same bits.
pub fn to_obj(model: &ImportedModel, mtl_file_name: &str) -> (String, String) {
    let mut obj = String::new();
    let mut mtl = String::new();
    let _ = writeln!(obj, "# written by visgate\nmtllib {mtl_file_name}");
    for m in &model.materials {
        let a = m.albedo;
        let _ = writeln!(mtl, "newmtl {}\nKd {} {} {}\n", m.name, a.x, a.y, a.z);
    }
    let mut base = 1usize;
    for mesh in &model.meshes {
        let _ = writeln!(obj, "\no {}", mesh.name);
        if let Some(mat) = model.materials.get(mesh.material as usize) {
            let _ = writeln!(obj, "usemtl {}", mat.name);
        }
        for p in &mesh.positions {
            let _ = writeln!(obj, "v {} {} {}", p.x, p.y, p.z);
        }
        for n in &mesh.normals {
            let _ = writeln!(obj, "vn {} {} {}", n.x, n.y, n.z);
        }
        for t in &mesh.uvs {
            // visgate's v runs down the image, OBJ's up.
            let _ = writeln!(obj, "vt {} {}", t.x, 1.0 - t.y);
        }
        for tri in &mesh.triangles {
            let [a, b, c] = tri.map(|i| i as usize + base);
            let _ = writeln!(obj, "f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}");
        }
        base += mesh.positions.len();
    }
    (obj, mtl)
}
