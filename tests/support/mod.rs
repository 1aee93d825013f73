//! What the command-line tests share: scenes written to a scratch folder.

use std::path::{Path, PathBuf};

/// A floor and a box sliding across it, lit by a light on an orbit: a dynamic scene.
pub fn dynamic_scene(dir: &Path) -> PathBuf {
    let w = |n: &str, t: &str| std::fs::write(dir.join(n), t).expect("write");
    w(
        "floor.obj",
        "v -3 0 -3\nv 3 0 -3\nv 3 0 3\nv -3 0 3\nf 1 4 3 2\n",
    );
    w(
        "box.obj",
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
         f 1 2 3 4\nf 5 8 7 6\nf 1 5 6 2\nf 2 6 7 3\nf 3 7 8 4\nf 4 8 5 1\n",
    );
    w(
        "scene.toml",
        r#"
[[mesh]]
path = "floor.obj"

[[mesh]]
path = "box.obj"
static = false
animate = [{ t = 0, translate = [-2, 0, -0.5] }, { t = 2, translate = [1, 0, -0.5] }]

[[light]]
type = "point"
position = [0, 3, 0]
intensity = [10, 10, 10]
orbit = { centre = [0, 3, 0], radius = 1, period_s = 4 }

[[camera]]
name = "main"
eye = [0, 4, 6]
target = [0, 0, 0]
fov_deg = 60
"#,
    );
    dir.join("scene.toml")
}
