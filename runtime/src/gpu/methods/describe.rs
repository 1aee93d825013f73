//! [`GpuMode`]'s settings in words, for reports, `render`'s first line and the viewer: as
//! given, and as a frame of a number of VPLs runs them.

use super::{DiskLight, GateParams, GateShape, GpuMode, InterleaveParams, WalkRoulette};

impl GpuMode {
    /// [`Self::describe`] for a frame of `vpls` VPLs: the gates' automatic roulette as it acts
    /// there ("roulette under 0.05 (auto)", or nothing where it is off), and an interleaving
    /// block shrunk for few VPLs ([`InterleaveParams::for_vpls`]: "2×2 interleaved (8×8 for
    /// 189 VPLs: 3.0 a pixel)").
    pub fn describe_for(&self, vpls: u32) -> String {
        let resolved = self.resolved_for(vpls);
        let mut s = resolved.describe();
        if let GpuMode::Gates(p) = *self
            && p.walk_roulette == WalkRoulette::Auto
            && p.gates.shape != GateShape::Disk
            && matches!(resolved, GpuMode::Gates(r) if r.walk_roulette.is_fixed())
        {
            s += " (auto)";
        }
        if let Some((b, g, each)) = self.shrunk_block(vpls) {
            let from = match b {
                1 => "every VPL per pixel".to_string(),
                b => format!("{b}×{b} interleaved"),
            };
            let why = format!("{g}×{g} for {vpls} VPLs: {each:.1} a pixel");
            s = s.replacen(&from, &format!("{from} ({why})"), 1);
        }
        s
    }

    /// Where a frame of `vpls` VPLs shrinks the gates' block ([`Self::interleave_for`]): the
    /// block it runs, the block set, and the VPLs a pixel the set one would leave; `None` where
    /// the block is kept (and for the modes that keep theirs).
    pub fn shrunk_block(&self, vpls: u32) -> Option<(u32, u32, f64)> {
        let (given, ran) = (self.interleave()?, self.interleave_for(vpls).interleave()?);
        let (b, g) = (ran.block, given.block);
        (b < g).then(|| (b, g, f64::from(vpls) / f64::from(g * g)))
    }

    /// The method's settings in a few words, for reports ("portals, walk ≤ 64, 8×8
    /// interleaved"); empty for methods without any.
    pub fn describe(&self) -> String {
        let il = |i: &InterleaveParams| match i.block {
            1 => "every VPL per pixel".to_string(),
            b => {
                let blur = match (i.fill, i.tent) {
                    (true, true) => ", tent blur filled",
                    (true, false) => ", blur filled",
                    (false, true) => ", tent blur",
                    (false, false) => "",
                };
                format!("{b}×{b} interleaved{blur}")
            }
        };
        let gates = |g: &GateParams| match g.shape {
            GateShape::Portal => format!("portals, walk ≤ {}", g.max_walk),
            GateShape::Disk => format!("disks ×{}, {} hop(s)", g.oversize, g.max_hops),
            GateShape::Voxels if g.triangles => "voxel walk + triangles".to_string(),
            GateShape::Voxels if !g.planes => "voxel walk, closed voxels block".to_string(),
            GateShape::Voxels => "voxel walk".to_string(),
        };
        // The VAL clustering's settings where they are not the paper's (Dong et al.'s).
        let vals = |v: &crate::cpu::val::ValParams| {
            let paper = crate::cpu::val::ValParams::default();
            let mut s = format!("{} VALs", v.count);
            if (v.w_x, v.w_alpha) != (paper.w_x, paper.w_alpha) {
                s += &format!(" (w_x {}, w_α {})", v.w_x, v.w_alpha);
            }
            if v.warm_start {
                s += ", warm start";
            }
            s
        };
        match self {
            GpuMode::None | GpuMode::DirectOnly => String::new(),
            GpuMode::PerVplShadowMaps(p) => {
                format!("{0}² maps, batches of {1}", p.map_size, p.batch)
            }
            GpuMode::Gates(p) => {
                let mut s = format!("{}, {}", gates(&p.gates), il(&p.interleave));
                let t = p.interleave.starved_taps;
                if t > 0 && p.interleave.block > 1 {
                    s += &format!(", under {t} agreeing walk the rest");
                }
                if p.interleave.starved_dark && p.interleave.block > 1 {
                    s += ", dark pixels walk the rest";
                }
                let walks = p.gates.shape != GateShape::Disk;
                if p.near_field > 0.0 && p.interleave.block > 1 && walks {
                    s += &format!(", near field {} blocks", p.near_field);
                }
                if p.ratio && p.interleave.block > 1 && walks {
                    s += ", ratio estimator";
                    if p.ratio_grid() > 1 {
                        s += &format!(" (grid {} px)", p.ratio_grid());
                    }
                }
                if p.gates.shape != GateShape::Disk {
                    match p.walk_roulette {
                        WalkRoulette::Share(r) if r > 0.0 => s += &format!(", roulette under {r}"),
                        WalkRoulette::Share(_) => {}
                        WalkRoulette::Auto => s += ", roulette auto",
                    }
                }
                s
            }
            GpuMode::GatesPerPixel(g) => gates(g),
            GpuMode::ValHard(v) => format!(
                "{}, {}² maps, {}",
                vals(&v.vals),
                v.map_size,
                il(&v.interleave)
            ),
            GpuMode::VplClusters(p, i) => format!("{}, {}", p.describe(), il(i)),
            GpuMode::PerVplIsm(p) => format!("{}, {}", p.ism.describe(), il(&p.interleave)),
            GpuMode::ValIsm(p) => format!(
                "{} VALs{}, {}, {}, {}",
                p.vals.count,
                match p.disk {
                    DiskLight::Centre => " (form factor at the centre)",
                    DiskLight::Parts => "",
                },
                p.ism.describe(),
                match p.hard_lookups {
                    true => "hard lookups".to_string(),
                    false => format!("PCSS {}/{}", p.pcss.blocker_samples, p.pcss.filter_samples),
                },
                il(&p.interleave)
            ),
            GpuMode::ValCssm(v, c) => format!(
                "{}, {}² maps, {} terms, {}",
                vals(&v.vals),
                v.map_size,
                c.terms,
                il(&v.interleave)
            ),
        }
    }
}
