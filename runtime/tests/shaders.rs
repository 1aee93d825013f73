//! Every composed WGSL shader parses and validates with naga (no GPU needed), and every struct
//! shared with Rust has, in every shader that declares it, the size, member names, offsets and
//! types that Rust gives it (runtime::gpu::layout).

use std::collections::BTreeSet;

use visgate_runtime::gpu::{layout, shaders};

fn parse(name: &str, src: &str) -> naga::Module {
    let module = naga::front::wgsl::parse_str(src)
        .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(src)));
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::all(),
    )
    .validate(&module)
    .unwrap_or_else(|e| panic!("{name}: {e:?}"));
    module
}

#[test]
fn every_shader_parses_and_validates_without_a_gpu() {
    let all = shaders::all();
    assert_eq!(all.len(), shaders::SOURCES.len());
    for (name, src) in &all {
        parse(name, src);
    }
}

/// A naga type as WGSL writes it.
fn wgsl_name(module: &naga::Module, ty: naga::Handle<naga::Type>) -> String {
    let scalar = |s: &naga::Scalar| match (s.kind, s.width) {
        (naga::ScalarKind::Float, 4) => "f32".to_string(),
        (naga::ScalarKind::Uint, 4) => "u32".to_string(),
        (naga::ScalarKind::Sint, 4) => "i32".to_string(),
        other => format!("{other:?}"),
    };
    match &module.types[ty].inner {
        naga::TypeInner::Scalar(s) => scalar(s),
        naga::TypeInner::Vector { size, scalar: s } => format!("vec{}<{}>", *size as u8, scalar(s)),
        naga::TypeInner::Matrix {
            columns,
            rows,
            scalar: s,
        } => format!("mat{}x{}<{}>", *columns as u8, *rows as u8, scalar(s)),
        other => format!("{other:?}"),
    }
}

#[test]
fn every_shared_struct_matches_rust_in_every_shader_by_name_offset_and_type() {
    let rust = layout::all();
    let mut seen = BTreeSet::new();
    for (shader, src) in shaders::all() {
        let module = parse(shader, &src);
        let mut layouter = naga::proc::Layouter::default();
        layouter.update(module.to_ctx()).expect("layout");
        for (h, ty) in module.types.iter() {
            let naga::TypeInner::Struct { members, .. } = &ty.inner else {
                continue;
            };
            let Some(want) = rust.iter().find(|l| Some(l.name) == ty.name.as_deref()) else {
                continue;
            };
            seen.insert(want.name);
            let got: Vec<(String, usize, String)> = members
                .iter()
                .map(|m| {
                    (
                        m.name.clone().unwrap_or_default(),
                        m.offset as usize,
                        wgsl_name(&module, m.ty),
                    )
                })
                .collect();
            let want_fields: Vec<(String, usize, String)> = want
                .fields
                .iter()
                .map(|(n, o, t)| (n.to_string(), *o, t.to_string()))
                .collect();
            assert_eq!(got, want_fields, "{} in {shader}", want.name);
            assert_eq!(
                layouter[h].size as usize, want.size,
                "size of {} in {shader}",
                want.name
            );
        }
    }
    let missing: Vec<_> = rust.iter().filter(|l| !seen.contains(l.name)).collect();
    assert!(missing.is_empty(), "declared in no shader: {missing:?}");
}

#[test]
fn a_field_of_another_type_fails_the_layout_check() {
    // The check above compares types, not only offsets: a u32 where Rust has an f32 differs.
    let src = "struct Batch { first: u32, count: u32, map_size: u32, pad0: u32, g_max: u32, \
               normal_offset: f32, bias: f32, pad1: f32 };";
    let module = naga::front::wgsl::parse_str(src).expect("parses");
    let (_, ty) = module
        .types
        .iter()
        .find(|(_, t)| t.name.as_deref() == Some("Batch"))
        .expect("Batch");
    let naga::TypeInner::Struct { members, .. } = &ty.inner else {
        panic!("not a struct")
    };
    let want = layout::all()
        .into_iter()
        .find(|l| l.name == "Batch")
        .expect("Batch layout");
    let differs = members
        .iter()
        .zip(&want.fields)
        .any(|(m, f)| wgsl_name(&module, m.ty) != f.2);
    assert!(differs);
}
