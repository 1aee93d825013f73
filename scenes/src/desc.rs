//! The built-ins' scene descriptions: whether each is closed, its lights and cameras.

use std::path::Path;

use visgate_formats::desc::{
    CameraDesc, LightDesc, LightLineDesc, PointLightDesc, SceneDesc, SpotLightDesc,
};

use crate::Builtin;

/// Whether a level is closed, its lights and its cameras.
type Placed = (bool, Vec<LightDesc>, Vec<CameraDesc>);

impl Builtin {
    /// The scene description. Its one mesh is `<name>.obj` beside it.
    pub fn desc(self) -> SceneDesc {
        let (closed, lights, cameras) = self.placed();
        SceneDesc {
            name: Some(self.name().into()),
            closed,
            lights,
            cameras,
            light_lines: match self {
                // Two rows of 24 lamps 3.2 m up, 1 m either side of the columns.
                Builtin::LampHall => [1.2, 3.8]
                    .map(|z| LightLineDesc {
                        from: [0.4, 3.2, z],
                        to: [15.6, 3.2, z],
                        count: 24,
                        intensity: [1.5, 1.3, 1.0],
                    })
                    .to_vec(),
                _ => vec![],
            },
            ..SceneDesc::for_mesh_file(Path::new(&self.mesh_file_name()))
        }
    }

    /// Whether the level is closed, and its lights and cameras.
    fn placed(self) -> Placed {
        match self {
            Builtin::EmptyBox => (
                true,
                vec![point([2.0, 2.7, 2.0], 8.0)],
                vec![camera("main", [0.4, 1.6, 0.4], [3.0, 1.0, 3.5], 75.0)],
            ),
            Builtin::TwoRooms => (
                true,
                vec![point([2.0, 2.7, 2.0], 8.0)],
                vec![
                    camera("main", [0.5, 1.6, 2.0], [4.1, 1.0, 2.0], 70.0),
                    camera("room-b", [7.7, 1.6, 3.5], [4.2, 1.0, 1.0], 70.0),
                ],
            ),
            Builtin::RingCorridor => (
                true,
                vec![point([0.75, 2.2, 0.75], 5.0)],
                vec![camera("main", [0.75, 1.6, 7.0], [0.75, 1.2, 0.0], 70.0)],
            ),
            Builtin::LCorridor => (
                true,
                vec![point([0.75, 2.2, 0.75], 5.0)],
                vec![camera("main", [0.5, 1.6, 0.75], [6.0, 1.0, 0.75], 70.0)],
            ),
            Builtin::FourRooms => (
                true,
                vec![
                    point([2.0, 2.7, 2.0], 8.0),
                    LightDesc::Spot(SpotLightDesc {
                        position: [6.2, 2.8, 6.2],
                        target: Some([7.5, 0.0, 7.5]),
                        direction: None,
                        intensity: [20.0, 18.0, 15.0],
                        cutoff_deg: 40.0,
                        beam_deg: 30.0,
                        animate: vec![],
                        orbit: None,
                    }),
                ],
                vec![camera("main", [0.5, 1.6, 0.5], [4.1, 1.0, 2.0], 75.0)],
            ),
            Builtin::CornellBox => (
                false,
                // The emitter quad (0.47 × 0.38 m, radiance (17, 12, 4)) as a point light just
                // below it with I = L · A along its normal.
                vec![LightDesc::Point(PointLightDesc {
                    position: [-0.005, 1.95, -0.03],
                    intensity: [3.04, 2.14, 0.71],
                    animate: vec![],
                    orbit: None,
                })],
                vec![camera("main", [0.0, 1.0, 3.5], [0.0, 1.0, 0.0], 45.0)],
            ),
            Builtin::AjarDoor | Builtin::SunWindow | Builtin::Stairwell => self.quad_placed(),
            // One lamp in each side room (the rows are light lines); the cameras of the
            // pillared hall, and one along the south row.
            Builtin::LampHall => (
                true,
                vec![
                    point([2.0, 2.5, 7.2], 3.0),
                    point([14.0, 2.5, 7.2], 3.0),
                    point([8.0, 2.5, -2.2], 3.0),
                ],
                vec![
                    camera("main", [15.5, 1.7, 1.0], [0.0, 1.2, 4.0], 75.0),
                    camera("side-room", [15.5, 1.6, 9.0], [13.5, 1.0, 4.0], 75.0),
                    camera("south-row", [0.5, 1.5, 0.5], [16.0, 2.0, 1.5], 70.0),
                ],
            ),
            // A light at the hall's west end, a spot into the south room; one camera down the
            // hall along the columns, one in the north-east room looking out of its door.
            Builtin::PillaredHall => (
                true,
                vec![
                    point([1.0, 3.5, 1.0], 20.0),
                    LightDesc::Spot(SpotLightDesc {
                        position: [8.0, 2.8, -1.0],
                        target: Some([8.0, 0.0, -3.0]),
                        direction: None,
                        intensity: [20.0, 18.0, 15.0],
                        cutoff_deg: 45.0,
                        beam_deg: 35.0,
                        animate: vec![],
                        orbit: None,
                    }),
                ],
                vec![
                    camera("main", [15.5, 1.7, 1.0], [0.0, 1.2, 4.0], 75.0),
                    camera("side-room", [15.5, 1.6, 9.0], [13.5, 1.0, 4.0], 75.0),
                ],
            ),
        }
    }

    /// [`Builtin::placed`] for the levels of single-sided quads.
    fn quad_placed(self) -> Placed {
        match self {
            // The light in room B, the cameras in room A looking at the door wall (the light
            // reaches room A only through the door's gap) and one in room B.
            Builtin::AjarDoor => (
                true,
                vec![point([6.6, 2.5, 3.3], 10.0)],
                vec![
                    camera("main", [0.4, 1.6, 0.5], [4.0, 1.0, 2.2], 75.0),
                    camera("door", [1.8, 1.3, 3.6], [4.0, 0.9, 1.8], 70.0),
                    camera("light-room", [7.6, 1.6, 0.4], [4.0, 1.0, 2.2], 75.0),
                ],
            ),
            // A lamp 1.2 m outside the window and above it, lighting room B's floor through it
            // (the window: quads::SUN_WINDOW); the cameras in room B looking at the lit floor
            // (first: what `view` and `render` open on), and in room A looking at the door wall.
            Builtin::SunWindow => (
                false,
                vec![point([6.0, 2.8, 5.2], 40.0)],
                vec![
                    camera("window", [4.6, 1.7, 0.4], [6.2, 0.2, 3.2], 75.0),
                    camera("door", [0.4, 1.6, 0.5], [4.0, 1.0, 2.2], 75.0),
                ],
            ),
            // The lamp upstairs; a camera on the ground floor looking up the flight at the hole
            // (lit through it alone), one upstairs looking down into it.
            Builtin::Stairwell => (
                true,
                vec![point([2.0, 5.5, 3.0], 15.0)],
                vec![
                    camera("down", [0.6, 1.6, 5.4], [6.0, 2.6, 1.6], 75.0),
                    camera("up", [0.5, 4.6, 5.5], [6.0, 3.0, 1.6], 75.0),
                ],
            ),
            _ => unreachable!("{} is not a level of quads", self.name()),
        }
    }
}

/// A point light at `p` of `i` W/sr on every channel.
fn point(p: [f64; 3], i: f32) -> LightDesc {
    LightDesc::Point(PointLightDesc {
        position: p,
        intensity: [i; 3],
        animate: vec![],
        orbit: None,
    })
}

/// A camera `name` at `eye` looking at `target`, `fov` degrees across.
fn camera(name: &str, eye: [f64; 3], target: [f64; 3], fov: f32) -> CameraDesc {
    CameraDesc {
        name: name.into(),
        eye,
        target,
        up: None,
        fov_deg: fov,
    }
}
