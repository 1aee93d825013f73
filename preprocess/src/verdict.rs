//! Why an empty component is kept or dropped (empty.rs's module notes give the rules).

use crate::empty::{EmptySpaceParams, INSIDE, UNSEEN};

/// What keeps or drops a component (see empty.rs's module notes).
pub(crate) struct Why<'a> {
    /// Per component, the cameras and lights in it.
    pub(crate) seeds_in: &'a [Vec<String>],
    /// Whether any component holds a camera or a light.
    pub(crate) seeded_any: bool,
    /// A bare mesh's inside.
    pub(crate) inside_component: Option<u32>,
    /// Its point, where its openings were looked for. [Units: m]
    pub(crate) inside_point: Option<[f32; 3]>,
    /// Whether the faces were read turned.
    pub(crate) faces_turned: bool,
    /// Per component, the triangles whose front and whose back face it from their first open
    /// voxel, the faces read turned where they are (the fronts chose a bare mesh's inside).
    pub(crate) first_open: &'a [[u64; 2]],
    /// Per component, the triangles whose front and whose back lie 0.75 voxel off on its side.
    pub(crate) faced: &'a [[u64; 2]],
    /// Per component, its voxels.
    pub(crate) voxels: &'a [u64],
    /// Per component, whether it reaches the bounds.
    pub(crate) at_bounds: &'a [bool],
    /// The stage's parameters.
    pub(crate) params: &'a EmptySpaceParams,
}

impl Why<'_> {
    /// Whether component `c` is kept, and why.
    pub(crate) fn verdict(&self, c: usize) -> (bool, String) {
        let (params, faced) = (self.params, self.faced[c]);
        if !self.seeds_in[c].is_empty() {
            return (true, format!("holds {}", self.seeds_in[c].join(", ")));
        }
        if self.inside_component == Some(c as u32) {
            let point = self.inside_point.map_or(String::new(), |p| {
                format!("; its point ({:.2}, {:.2}, {:.2}) m", p[0], p[1], p[2])
            });
            let turned = if self.faces_turned {
                ", their faces turned"
            } else {
                ""
            };
            let fronts = self.first_open[c][0];
            let why = format!(
                "{INSIDE}: the most triangles face it ({fronts} of them{turned}; no camera or \
                 light named){point}"
            );
            return (true, why);
        }
        let dropped = |why: String| (false, why);
        if params.closed && self.at_bounds[c] {
            return dropped(
                "outside the closed level: reaches the bounds and holds no camera or light".into(),
            );
        }
        if self.voxels[c] < params.min_component_voxels {
            let min = params.min_component_voxels;
            return dropped(format!("no camera or light and smaller than {min} voxels"));
        }
        if params.closed && faced == [0, 0] {
            return dropped(
                "inside closed geometry: a closed level's space that no triangle faces or turns \
                 its back to (a void within a thick wall)"
                    .into(),
            );
        }
        // Where the scene's cameras and lights are elsewhere: a room the voxels cut off from
        // theirs (an opening narrower than two voxels) is kept, faced by its walls; the space
        // around and over the rooms, which sees the backs of their walls, is dropped.
        let [f, b] = self.first_open[c];
        if self.seeded_any && b >= f {
            return dropped(format!(
                "{UNSEEN}, and from their first open voxel {b} triangles turn their back to it, \
                 {f} face it (the space around the rooms, or inside walls)"
            ));
        }
        if self.seeded_any {
            return (
                true,
                format!(
                    "faced by its walls, though no camera or light is in it: from their first \
                     open voxel {f} triangles face it, {b} turn their back to it"
                ),
            );
        }
        if faced[1] > faced[0] {
            return dropped(format!(
                "inside closed geometry: {} triangles turn their back to it, {} face it",
                faced[1], faced[0]
            ));
        }
        if faced == [0, 0] {
            // Kept, as before, but not said to be faced: a space that no triangle lies beside
            // (within 0.75 voxel), a slit or a pocket of the voxels.
            return (
                true,
                "large, and no triangle faces it or turns its back to it".to_string(),
            );
        }
        (true, "large and faced by the geometry".to_string())
    }
}
