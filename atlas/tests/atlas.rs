//! Invariants of built atlases on small meshes made in code.

use atlas::{build, sample, Atlas, AtlasError, AtlasOptions, Flattened, Interior, Occupancy};
use std::collections::HashSet;

/// An `n × n` quad grid (2 triangles per quad) bent over a cylinder arc,
/// shifted by `offset`, appended to `positions`/`triangles`.
fn grid(positions: &mut Vec<[f32; 3]>, triangles: &mut Vec<[u32; 3]>, n: u32, offset: [f32; 3]) {
    let base = positions.len() as u32;
    for j in 0..=n {
        for i in 0..=n {
            let a = i as f32 / n as f32 * 2.0;
            positions.push([
                a.cos() + offset[0],
                a.sin() + offset[1],
                j as f32 / n as f32 * 2.0 + offset[2],
            ]);
        }
    }
    let id = |i: u32, j: u32| base + j * (n + 1) + i;
    for j in 0..n {
        for i in 0..n {
            triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
}

/// Partition by position: left/right halves of x.
fn halves(positions: &[[f32; 3]]) -> Vec<u32> {
    positions.iter().map(|p| u32::from(p[0] > 0.3)).collect()
}

fn check_invariants(atlas: &Atlas, vertices: usize) {
    let px = atlas.vertex_pixels();
    assert_eq!(px.len(), vertices);
    let distinct: HashSet<[u16; 2]> = px.iter().copied().collect();
    assert_eq!(
        distinct.len(),
        vertices,
        "vertex → pixel map is not injective"
    );
    for (v, p) in px.iter().enumerate() {
        let (x, y) = (u32::from(p[0]), u32::from(p[1]));
        assert!(x < atlas.width() && y < atlas.height());
        assert_eq!(
            atlas.chart_at(x, y),
            Some(atlas.vertex_charts()[v]),
            "vertex {v} outside its chart's blocks"
        );
        let c = &atlas.charts()[atlas.vertex_charts()[v] as usize];
        assert!(
            x >= c.origin[0]
                && x < c.origin[0] + c.size[0]
                && y >= c.origin[1]
                && y < c.origin[1] + c.size[1]
        );
    }
    // Frames are whole blocks; each block has at most one chart, and it lies in that chart's frame.
    let b = atlas.block();
    let mut owned = vec![0usize; atlas.charts().len()];
    for by in 0..atlas.height() / b {
        for bx in 0..atlas.width() / b {
            let owner = atlas.chart_at(bx * b, by * b);
            for y in by * b..(by + 1) * b {
                for x in bx * b..(bx + 1) * b {
                    assert_eq!(
                        atlas.chart_at(x, y),
                        owner,
                        "block ({bx}, {by}) is not uniform"
                    );
                }
            }
            if let Some(ci) = owner {
                owned[ci as usize] += 1;
                let c = &atlas.charts()[ci as usize];
                assert!(bx * b >= c.origin[0] && (bx + 1) * b <= c.origin[0] + c.size[0]);
                assert!(by * b >= c.origin[1] && (by + 1) * b <= c.origin[1] + c.size[1]);
            }
        }
    }
    for (c, n) in atlas.charts().iter().zip(&owned) {
        assert!(c.origin.iter().chain(&c.size).all(|v| v % b == 0));
        assert_eq!(c.blocks, *n);
        assert!(c.blocks * (b * b) as usize >= c.vertices);
    }
    for (i, fixed) in atlas.fixed_mask().iter().enumerate() {
        let (x, y) = (i as u32 % atlas.width(), i as u32 / atlas.width());
        if *fixed {
            assert!(
                atlas.chart_at(x, y).is_some(),
                "fixed pixel ({x}, {y}) in no chart"
            );
        }
    }
    // Round trip is exact, with values that differ from vertex to vertex.
    let values: Vec<f32> = (0..vertices)
        .map(|v| (v as f32 * 0.37).sin() * 100.0 + v as f32)
        .collect();
    let image = atlas.try_splat(&values).unwrap_or_default();
    assert_eq!(image, atlas.splat(&values));
    assert!(atlas.try_splat(&values[1..]).is_err());
    let back = sample(px, atlas.width(), &image).unwrap_or_default();
    assert_eq!(back, values);
    let s = atlas.stats();
    assert!(s.packing_efficiency > 0.0 && s.packing_efficiency <= 1.0);
    assert!(
        s.l2_stretch >= 1.0 - 1e-9,
        "normalised stretch {} below 1",
        s.l2_stretch
    );
}

#[test]
fn single_grid_builds_and_round_trips() -> Result<(), AtlasError> {
    let (mut p, mut t) = (Vec::new(), Vec::new());
    grid(&mut p, &mut t, 12, [0.0; 3]);
    let atlas = build(&p, &t, &halves(&p), &AtlasOptions::default())?;
    check_invariants(&atlas, p.len());
    assert!(
        atlas.stats().charts >= 2,
        "two clusters give at least two charts"
    );
    assert!(
        atlas.stats().packing_efficiency > 0.2,
        "{:?}",
        atlas.stats()
    );
    Ok(())
}

#[test]
fn many_components_fin_isolated_and_degenerate() -> Result<(), AtlasError> {
    let (mut p, mut t) = (Vec::new(), Vec::new());
    for k in 0..6 {
        grid(&mut p, &mut t, 4, [3.0 * k as f32, 0.0, 0.0]);
    }
    // A fin: a third triangle on an existing edge (non-manifold edge).
    let fin = p.len() as u32;
    p.push([1.0, 2.0, 1.0]);
    t.push([t[0][0], t[0][1], fin]);
    // A lone triangle, a degenerate one, an isolated vertex, a duplicate position.
    let n = p.len() as u32;
    p.extend([
        [50.0, 0.0, 0.0],
        [51.0, 0.0, 0.0],
        [50.0, 1.0, 0.0],
        [60.0, 0.0, 0.0],
        [70.0, 0.0, 0.0],
    ]);
    t.push([n, n + 1, n + 2]);
    t.push([n + 3, n + 3, n + 1]);
    p.push(p[0]);
    t.push([p.len() as u32 - 1, 1, 2]);
    let part: Vec<u32> = (0..p.len() as u32).map(|v| v % 3).collect();
    for interior in [Interior::Rasterised, Interior::Free] {
        let opts = AtlasOptions {
            interior,
            ..AtlasOptions::default()
        };
        let atlas = build(&p, &t, &part, &opts)?;
        check_invariants(&atlas, p.len());
        let interior_pixels = atlas
            .occupancy()
            .iter()
            .filter(|o| **o == Occupancy::Interior)
            .count();
        assert_eq!(interior_pixels > 0, interior == Interior::Rasterised);
        assert!(
            atlas.stats().faceless_vertices >= 1,
            "the isolated vertex has no face"
        );
    }
    Ok(())
}

#[test]
fn small_lattice_forces_moves_but_stays_injective() -> Result<(), AtlasError> {
    let (mut p, mut t) = (Vec::new(), Vec::new());
    grid(&mut p, &mut t, 20, [0.0; 3]);
    let opts = AtlasOptions {
        width: 24,
        height: 24,
        ..AtlasOptions::default()
    };
    let atlas = build(&p, &t, &vec![0; p.len()], &opts)?;
    check_invariants(&atlas, p.len());
    Ok(())
}

#[test]
fn one_flattening_lays_out_on_each_size_as_a_build_there() -> Result<(), AtlasError> {
    let (mut p, mut t) = (Vec::new(), Vec::new());
    grid(&mut p, &mut t, 20, [0.0; 3]);
    grid(&mut p, &mut t, 8, [3.0, 0.0, 0.0]);
    let parts = halves(&p);
    let at = |side: u32| AtlasOptions {
        width: side,
        height: side,
        ..AtlasOptions::default()
    };
    let charts = Flattened::new(&p, &t, &parts, &at(24))?;
    let mut fitted = 0;
    for side in [24, 32, 48, 64] {
        let (laid, built) = match (charts.lay_out(side, side), build(&p, &t, &parts, &at(side))) {
            (Ok(laid), Ok(built)) => (laid, built),
            // Charts that do not fit, refused alike.
            (laid, built) => {
                let (laid, built) = (laid.err().map(|e| e.to_string()), built.err());
                assert_eq!(laid, built.map(|e| e.to_string()), "{side}x{side}");
                continue;
            }
        };
        assert_eq!(laid.vertex_pixels(), built.vertex_pixels(), "{side}x{side}");
        assert_eq!(laid.vertex_charts(), built.vertex_charts());
        assert_eq!(laid.charts(), built.charts());
        assert_eq!(laid.occupancy(), built.occupancy());
        // Every figure but the wall time.
        let figures = |a: &Atlas| atlas::AtlasStats {
            build_time: Default::default(),
            ..a.stats().clone()
        };
        assert_eq!(figures(&laid), figures(&built));
        fitted += 1;
    }
    // 24 × 24 is too small for these charts (the size a lattice search starts from), the rest fit.
    assert_eq!(fitted, 3);
    // A size too small for the vertices is refused as a build refuses it.
    let small = charts.lay_out(16, 16).err().map(|e| e.to_string());
    let refused = build(&p, &t, &parts, &at(16)).err().map(|e| e.to_string());
    assert!(small.is_some());
    assert_eq!(small, refused);
    Ok(())
}

#[test]
fn bad_inputs_are_errors() {
    let (mut p, mut t) = (Vec::new(), Vec::new());
    grid(&mut p, &mut t, 3, [0.0; 3]);
    let opts = AtlasOptions::default();
    assert!(matches!(
        build(&p, &t, &[0, 1], &opts),
        Err(AtlasError::PartitionLength { .. })
    ));
    let mut bad = t.clone();
    bad.push([0, 1, 999]);
    assert!(matches!(
        build(&p, &bad, &vec![0; p.len()], &opts),
        Err(AtlasError::VertexOutOfRange { .. })
    ));
    let tiny = AtlasOptions {
        width: 8,
        height: 8,
        ..opts.clone()
    };
    let (mut big, mut big_t) = (Vec::new(), Vec::new());
    grid(&mut big, &mut big_t, 8, [0.0; 3]);
    let err = match build(&big, &big_t, &vec![0; big.len()], &tiny) {
        Ok(_) => String::new(),
        Err(e) => e.to_string(),
    };
    assert!(
        err.contains("81 vertices do not fit a 8×8 lattice"),
        "{err}"
    );
    let odd = AtlasOptions { width: 250, ..opts };
    assert!(matches!(
        build(&p, &t, &vec![0; p.len()], &odd),
        Err(AtlasError::InvalidOptions(_))
    ));
    assert!(sample(&[[300, 0]], 256, &[0.0; 256]).is_err());
}

#[test]
fn empty_mesh_is_an_empty_atlas() -> Result<(), AtlasError> {
    let atlas = build(&[], &[], &[], &AtlasOptions::default())?;
    assert!(atlas.vertex_pixels().is_empty());
    assert_eq!(atlas.stats().charts, 0);
    Ok(())
}

#[test]
fn png_is_written() -> Result<(), Box<dyn std::error::Error>> {
    let (mut p, mut t) = (Vec::new(), Vec::new());
    grid(&mut p, &mut t, 6, [0.0; 3]);
    let atlas = build(&p, &t, &halves(&p), &AtlasOptions::default())?;
    let dir = tempfile::tempdir()?;
    let path = dir.path().join("atlas.png");
    atlas.write_png(&path)?;
    assert!(std::fs::metadata(&path)?.len() > 100);
    Ok(())
}

#[test]
fn forty_one_parts_like_chicken() -> Result<(), AtlasError> {
    let (mut p, mut t) = (Vec::new(), Vec::new());
    for k in 0..41 {
        grid(
            &mut p,
            &mut t,
            2,
            [3.0 * (k % 7) as f32, 3.0 * (k / 7) as f32, 0.0],
        );
    }
    let part: Vec<u32> = (0..p.len() as u32).map(|v| (v / 9) % 20).collect();
    let atlas = build(&p, &t, &part, &AtlasOptions::default())?;
    check_invariants(&atlas, p.len());
    assert!(atlas.stats().seed_pieces >= 41);
    Ok(())
}

#[test]
fn tight_stretch_bound_splits_charts() -> Result<(), AtlasError> {
    // A doubly curved cap: no flattening of it is isometric.
    let (mut p, mut t) = (Vec::new(), Vec::new());
    grid(&mut p, &mut t, 10, [0.0; 3]);
    for q in &mut p {
        let z = q[2] - 1.0;
        q[0] *= 1.0 + 0.4 * z * z;
        q[1] *= 1.0 + 0.4 * z * z;
    }
    let part = vec![0; p.len()];
    let loose = build(&p, &t, &part, &AtlasOptions::default())?;
    let tight = build(
        &p,
        &t,
        &part,
        &AtlasOptions {
            max_stretch: 1.0 + 1e-9,
            ..AtlasOptions::default()
        },
    )?;
    check_invariants(&tight, p.len());
    assert!(tight.stats().split_rounds >= 1);
    assert!(tight.stats().charts >= loose.stats().charts);
    Ok(())
}

/// The skinned figure that ships in the repo's media folder (bind pose).
#[test]
fn shipped_gltf_figure_builds() -> Result<(), Box<dyn std::error::Error>> {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../media/RiggedFigure.glb");
    let (doc, buffers, _) = gltf::import(path)?;
    let (mut p, mut t) = (Vec::new(), Vec::new());
    for mesh in doc.meshes() {
        for prim in mesh.primitives() {
            let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
            let base = p.len() as u32;
            p.extend(reader.read_positions().into_iter().flatten());
            let idx: Vec<u32> = reader
                .read_indices()
                .map(|i| i.into_u32().collect())
                .unwrap_or_default();
            t.extend(
                idx.chunks_exact(3)
                    .map(|c| [base + c[0], base + c[1], base + c[2]]),
            );
        }
    }
    assert!(p.len() > 100);
    // Unwelded glTF vertices share positions: they must still get distinct pixels.
    let part: Vec<u32> = p.iter().map(|q| u32::from(q[1] > 0.0)).collect();
    let atlas = build(&p, &t, &part, &AtlasOptions::default())?;
    check_invariants(&atlas, p.len());
    Ok(())
}
