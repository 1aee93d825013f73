//! WGSL composition: a small include step and constants injected from Rust.
//!
//! WGSL has no includes. A pass's shader names what it needs on its first line,
//!
//! ```wgsl
//! //! include: vpl.wgsl grid.wgsl
//! ```
//!
//! and [`compose`] puts in front of it: first the constants of [`constants`] (generated from
//! the Rust definitions below, so a workgroup size, a mode id or a bit count has one home),
//! then each include once, after its own includes, in the order named. Include files live in
//! `gpu/shaders/`; they declare structs, constants and functions, **never bindings**: a
//! function that reads a binding (grid.wgsl's `cluster_of` reads `grid` and `voxel_words`)
//! says so in its header, and each pass declares that binding at the number it chooses. Pass
//! shaders live beside their pass in `gpu/passes/`.

use crate::RenderError;

/// The include files (`gpu/shaders/`).
const INCLUDES: [(&str, &str); 17] = [
    ("globals.wgsl", include_str!("shaders/globals.wgsl")),
    ("lights.wgsl", include_str!("shaders/lights.wgsl")),
    (
        "shadow_lookup.wgsl",
        include_str!("shaders/shadow_lookup.wgsl"),
    ),
    ("vpl.wgsl", include_str!("shaders/vpl.wgsl")),
    ("face.wgsl", include_str!("shaders/face.wgsl")),
    ("grid.wgsl", include_str!("shaders/grid.wgsl")),
    ("gates.wgsl", include_str!("shaders/gates.wgsl")),
    ("portals.wgsl", include_str!("shaders/portals.wgsl")),
    ("sight.wgsl", include_str!("shaders/sight.wgsl")),
    ("far.wgsl", include_str!("shaders/far.wgsl")),
    ("walk.wgsl", include_str!("shaders/walk.wgsl")),
    ("near.wgsl", include_str!("shaders/near.wgsl")),
    ("val.wgsl", include_str!("shaders/val.wgsl")),
    ("ratio.wgsl", include_str!("shaders/ratio.wgsl")),
    ("lc.wgsl", include_str!("shaders/lc.wgsl")),
    ("pcss.wgsl", include_str!("shaders/pcss.wgsl")),
    ("ism.wgsl", include_str!("shaders/ism.wgsl")),
];

/// The pass shaders (`gpu/passes/`), before composition.
pub const SOURCES: [(&str, &str); 19] = [
    ("gbuffer.wgsl", include_str!("passes/gbuffer.wgsl")),
    ("shadow.wgsl", include_str!("passes/shadow.wgsl")),
    ("shade.wgsl", include_str!("passes/shade.wgsl")),
    ("sight_ends.wgsl", include_str!("passes/sight_ends.wgsl")),
    ("rsm_vpls.wgsl", include_str!("passes/rsm_vpls.wgsl")),
    ("vpl_shadow.wgsl", include_str!("passes/vpl_shadow.wgsl")),
    (
        "gather_batch.wgsl",
        include_str!("passes/gather_batch.wgsl"),
    ),
    ("clusters.wgsl", include_str!("passes/clusters.wgsl")),
    ("vals.wgsl", include_str!("passes/vals.wgsl")),
    ("val_gather.wgsl", include_str!("passes/val_gather.wgsl")),
    ("blur.wgsl", include_str!("passes/blur.wgsl")),
    ("unshadowed.wgsl", include_str!("passes/unshadowed.wgsl")),
    ("cssm.wgsl", include_str!("passes/cssm.wgsl")),
    (
        "light_cluster.wgsl",
        include_str!("passes/light_cluster.wgsl"),
    ),
    ("lc_shadows.wgsl", include_str!("passes/lc_shadows.wgsl")),
    ("ism_maps.wgsl", include_str!("passes/ism_maps.wgsl")),
    ("ism_gather.wgsl", include_str!("passes/ism_gather.wgsl")),
    ("starved.wgsl", include_str!("passes/starved.wgsl")),
    ("display.wgsl", include_str!("passes/display.wgsl")),
];

/// What the shading pass adds to the direct light (`Globals::shade_mode`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u32)]
pub enum ShadeIndirect {
    /// Every VPL at every pixel, no visibility (`SHADE_ALL`).
    All = 0,
    /// Nothing: direct light only; another pass may add indirect light (`SHADE_DIRECT`).
    DirectOnly = 1,
    /// Every VPL through the gates, per pixel (`SHADE_GATES_PER_PIXEL`).
    GatesPerPixel = 2,
    /// The clustered light lists (`SHADE_GATES_CLUSTERED`).
    GatesClustered = 3,
    /// Every VPL with its LightCluster cluster's visibility (`SHADE_VPL_CLUSTERS`).
    VplClusters = 4,
}

/// `Globals::direct_mode`: each light's own shadow maps.
pub const DIRECT_PER_LIGHT: u32 = 0;
/// `Globals::direct_mode`: each light's LightCluster cluster's visibility.
pub const DIRECT_LIGHTCLUSTER: u32 = 1;

/// Workgroup size of the 1D compute passes (VPLs, VALs, RSM samples).
pub const WG_LINEAR: u32 = 64;
/// Side of the clustered passes' square workgroups; also the largest tile side. [Units: px]
pub const WG_TILE: u32 = 16;
/// Workgroup size of the tile scan and of the CSSM depth-range reduction.
pub const WG_WIDE: u32 = 256;
/// Workgroup size of the starved pixels' walks (shade.wgsl's `cs_starved_walks`: a (pixel,
/// subset) pair an invocation), which starved.wgsl's `cs_starved_args` dispatches.
pub const WG_STARVED_WALKS: u32 = 64;
/// Side of the CSSM basis and mip passes' square workgroups. [Units: texels]
pub const WG_CSSM: u32 = 8;
/// Bits of a visibility cluster in a geometry-cluster key (depth slice above them).
pub const CLUSTER_BITS: u32 = 23;
/// The "no cluster" value of every cluster field.
pub const NONE: u32 = u32::MAX;
/// CSSM depths are normalised into [0, this] of the period-2 Fourier step, so that a
/// receiver–blocker difference never reaches ±1, where the step reads ½ (a guard band).
pub const CSSM_DEPTH_SCALE: f32 = 0.9;
/// The normalised depth of a CSSM texel that sees no surface: beyond every receiver, and less
/// than 1 from each (no wrap-around).
pub const CSSM_EMPTY_DEPTH: f32 = 0.95;

/// The constants every composed shader starts with, generated from the Rust definitions.
pub fn constants() -> String {
    let u = |name: &str, v: u32| format!("const {name}: u32 = {v}u;\n");
    let mut s =
        String::from("// Injected from runtime::gpu::shaders (one Rust definition each).\n");
    s += &format!("const PI: f32 = {:?};\n", std::f32::consts::PI);
    s += &u("NONE", NONE);
    s += &u("CLUSTER_BITS", CLUSTER_BITS);
    s += &u("CLUSTER_MASK", (1 << CLUSTER_BITS) - 1);
    s += &u("WG_LINEAR", WG_LINEAR);
    s += &u("WG_TILE", WG_TILE);
    s += &u("WG_WIDE", WG_WIDE);
    s += &u("WG_CSSM", WG_CSSM);
    s += &u("STARVED_WALKS_GROUP", WG_STARVED_WALKS);
    s += &u("RATIO_RUN", super::passes::unshadowed::RATIO_RUN);
    s += &u("SHADE_ALL", ShadeIndirect::All as u32);
    s += &u("SHADE_DIRECT", ShadeIndirect::DirectOnly as u32);
    s += &u("SHADE_GATES_PER_PIXEL", ShadeIndirect::GatesPerPixel as u32);
    s += &u(
        "SHADE_GATES_CLUSTERED",
        ShadeIndirect::GatesClustered as u32,
    );
    s += &u("SHADE_VPL_CLUSTERS", ShadeIndirect::VplClusters as u32);
    s += &u("DIRECT_PER_LIGHT", DIRECT_PER_LIGHT);
    s += &u("DIRECT_LIGHTCLUSTER", DIRECT_LIGHTCLUSTER);
    s += &u(
        "MAX_LC_CLUSTERS",
        super::passes::light_cluster::MAX_LC_CLUSTERS,
    );
    s += "const LIGHT_POINT: f32 = 0.0;\nconst LIGHT_SPOT: f32 = 1.0;\n";
    s += &format!("const CSSM_DEPTH_SCALE: f32 = {CSSM_DEPTH_SCALE:?};\n");
    s += &format!("const CSSM_EMPTY_DEPTH: f32 = {CSSM_EMPTY_DEPTH:?};\n");
    s += &format!("const SIGHT_BRICK: i32 = {};\n", crate::cpu::sight::BRICK);
    s += &u("SIGHT_BITS", crate::cpu::sight::SIGHT_HEADER_WORDS as u32);
    s += &u(
        "PORTAL_RECORD",
        crate::cpu::portal_walk::PORTAL_RECORD_WORDS,
    );
    s += &u("PORTAL_NODE", crate::cpu::portal_walk::NODE_WORDS);
    s += &u("PORTAL_INNER", crate::cpu::portal_walk::INNER);
    s += &u(
        "PORTAL_STACK",
        crate::cpu::portal_walk::MAX_DEPTH as u32 + 1,
    );
    s += &format!(
        "const EDGE_SLACK: f32 = {:?};\n",
        visgate_formats::vgate::EDGE_SLACK
    );
    s
}

/// The includes a source names on its first line (`//! include: a.wgsl b.wgsl`).
fn includes_of(source: &str) -> Vec<&str> {
    source
        .lines()
        .next()
        .and_then(|l| l.trim().strip_prefix("//! include:"))
        .map(|l| l.split_whitespace().collect())
        .unwrap_or_default()
}

/// `source` with the constants and its includes in front, reading includes through `lookup`.
pub fn compose_with(
    name: &str,
    source: &str,
    lookup: &dyn Fn(&str) -> Option<String>,
) -> Result<String, RenderError> {
    fn visit(
        name: &str,
        source: &str,
        lookup: &dyn Fn(&str) -> Option<String>,
        done: &mut Vec<String>,
        out: &mut String,
        depth: usize,
    ) -> Result<(), RenderError> {
        if depth > 8 {
            return Err(RenderError::Param(format!(
                "{name}: includes nest deeper than 8 (a cycle?)"
            )));
        }
        for inc in includes_of(source) {
            if done.iter().any(|d| d == inc) {
                continue;
            }
            let text = lookup(inc).ok_or_else(|| {
                RenderError::Param(format!("{name}: includes {inc}, which does not exist"))
            })?;
            visit(inc, &text, lookup, done, out, depth + 1)?;
            done.push(inc.to_string());
            *out += &format!("// ---- {inc}\n{text}\n");
        }
        Ok(())
    }
    let mut out = constants();
    let mut done = Vec::new();
    visit(name, source, lookup, &mut done, &mut out, 0)?;
    out += &format!("// ---- {name}\n{source}");
    Ok(out)
}

/// The WGSL the pipelines are built from: the built-in files, each replaceable by a copy read
/// from disk (`visgate view --shader-dir`, for the people who work on the methods).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ShaderSources {
    /// Files read from disk, by name (`shade.wgsl`, `portals.wgsl`), and where they came from.
    files: std::collections::BTreeMap<String, (std::path::PathBuf, String)>,
}

impl ShaderSources {
    /// The built-in shaders alone.
    pub fn builtin() -> ShaderSources {
        ShaderSources::default()
    }

    /// Every shader file name: the pass shaders, then the includes.
    pub fn names() -> impl Iterator<Item = &'static str> {
        SOURCES.iter().chain(INCLUDES.iter()).map(|(n, _)| *n)
    }

    /// The built-in shaders, with each file that `dir` holds — as `dir/NAME`,
    /// `dir/passes/NAME` or `dir/shaders/NAME`, so both a flat folder and a copy of (or the
    /// repository's own) `runtime/src/gpu` work — read in its place. A folder that holds none
    /// of them is refused: it is the wrong folder.
    pub fn read_dir(dir: &std::path::Path) -> Result<ShaderSources, RenderError> {
        let mut files = std::collections::BTreeMap::new();
        for name in ShaderSources::names() {
            let Some(path) = ShaderSources::path_in(dir, name) else {
                continue;
            };
            let text = std::fs::read_to_string(&path)
                .map_err(|e| RenderError::Param(format!("{}: {e}", path.display())))?;
            files.insert(name.to_string(), (path, text));
        }
        if files.is_empty() {
            return Err(RenderError::Param(format!(
                "{} holds none of visgate's shaders (looked for {} in it and in its passes/ and \
                 shaders/ folders; the repository's are in runtime/src/gpu)",
                dir.display(),
                ShaderSources::names().collect::<Vec<_>>().join(", ")
            )));
        }
        Ok(ShaderSources { files })
    }

    /// Where `dir` holds shader `name`, if it does.
    pub fn path_in(dir: &std::path::Path, name: &str) -> Option<std::path::PathBuf> {
        [
            dir.join(name),
            dir.join("passes").join(name),
            dir.join("shaders").join(name),
        ]
        .into_iter()
        .find(|p| p.is_file())
    }

    /// The files read from disk: name and path.
    pub fn overridden(&self) -> impl Iterator<Item = (&str, &std::path::Path)> {
        self.files
            .iter()
            .map(|(n, (p, _))| (n.as_str(), p.as_path()))
    }

    /// The text of shader file `name` (read from disk, else built in).
    pub fn text(&self, name: &str) -> Option<String> {
        if let Some((_, t)) = self.files.get(name) {
            return Some(t.clone());
        }
        SOURCES
            .iter()
            .chain(INCLUDES.iter())
            .find(|(n, _)| *n == name)
            .map(|(_, s)| s.to_string())
    }

    /// Pass shader `name`, composed.
    pub fn compose(&self, name: &str) -> Result<String, RenderError> {
        if !SOURCES.iter().any(|(n, _)| *n == name) {
            return Err(RenderError::Param(format!("no shader {name}")));
        }
        let source = self.text(name).unwrap_or_default();
        compose_with(name, &source, &|n| {
            INCLUDES
                .iter()
                .any(|(i, _)| *i == n)
                .then(|| self.text(n))?
        })
    }

    /// Parses and validates every pass shader with naga, as the GPU's compiler will: the
    /// first error, at its file and line (`shade.wgsl:120:9: …`).
    pub fn validate(&self) -> Result<(), RenderError> {
        for (name, _) in SOURCES {
            let src = self.compose(name)?;
            let fail = |message: String, at: Option<wgpu::naga::SourceLocation>| {
                let place = at.map_or_else(|| name.to_string(), |l| source_line(&src, l));
                RenderError::Param(format!("{place}: {message}"))
            };
            let module = wgpu::naga::front::wgsl::parse_str(&src)
                .map_err(|e| fail(e.message().to_string(), e.location(&src)))?;
            wgpu::naga::valid::Validator::new(
                wgpu::naga::valid::ValidationFlags::all(),
                wgpu::naga::valid::Capabilities::all(),
            )
            .validate(&module)
            .map_err(|e| fail(e.as_inner().to_string(), e.location(&src)))?;
        }
        Ok(())
    }
}

/// `file:line:column` of a place in a composed shader: the file whose `// ---- NAME` marker
/// comes last before it (the constants before the first marker are `constants`).
fn source_line(composed: &str, at: wgpu::naga::SourceLocation) -> String {
    let mut file = ("constants", 0u32);
    for (i, line) in composed.lines().enumerate().take(at.line_number as usize) {
        if let Some(name) = line.strip_prefix("// ---- ") {
            file = (name, i as u32 + 1);
        }
    }
    format!(
        "{}:{}:{}",
        file.0,
        at.line_number - file.1,
        at.line_position
    )
}

/// The built-in pass shader `name`, composed.
pub fn compose(name: &str) -> Result<String, RenderError> {
    ShaderSources::builtin().compose(name)
}

/// Every pass shader, composed (for validation without a GPU).
pub fn all() -> Vec<(&'static str, String)> {
    SOURCES
        .iter()
        .map(|(n, _)| (*n, compose(n).unwrap_or_else(|e| format!("// {e}"))))
        .collect()
}

/// A shader module of pass shader `name` from `sources`.
pub fn module(
    d: &wgpu::Device,
    sources: &ShaderSources,
    name: &str,
) -> Result<wgpu::ShaderModule, RenderError> {
    let source = sources.compose(name)?;
    Ok(d.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(name),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn includes_come_once_after_their_own_includes() {
        let lookup = |n: &str| match n {
            "a.wgsl" => Some("//! include: b.wgsl\nfn a() {}".to_string()),
            "b.wgsl" => Some("fn b() {}".to_string()),
            _ => None,
        };
        let s = compose_with("m.wgsl", "//! include: a.wgsl b.wgsl\nfn m() {}", &lookup)
            .expect("composes");
        let (a, b, m) = (
            s.find("fn a()").expect("a"),
            s.find("fn b()").expect("b"),
            s.find("fn m()").expect("m"),
        );
        assert!(b < a && a < m, "{s}");
        assert_eq!(s.matches("fn b()").count(), 1);
        assert!(compose_with("m.wgsl", "//! include: nope.wgsl\n", &lookup).is_err());
    }

    #[test]
    fn include_files_declare_no_bindings() {
        for (name, text) in INCLUDES {
            assert!(!text.contains("@binding"), "{name} declares a binding");
        }
    }
}
