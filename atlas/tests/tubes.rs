//! Tubes and tori: a cluster that is a band around a tube is an annulus, which needs one cut to
//! become one chart; before the cuts the unwrapper shattered such bands (issue: a skinned snake
//! made 414 charts for 20 clusters). Meshes made in code, small enough to stay fast.

use atlas::{build, AtlasOptions};
use std::f32::consts::TAU;

/// A closed tube (`around` × `rows` quads, a centre vertex capping each end) whose axis follows
/// `axis(t)` for t in 0..1; the cluster of a vertex is its row's band (of `bands`), the caps go
/// with the first and last band.
fn tube(
    around: u32,
    rows: u32,
    bands: u32,
    axis: impl Fn(f32) -> [f32; 3],
) -> (Vec<[f32; 3]>, Vec<[u32; 3]>, Vec<u32>) {
    let (mut p, mut t, mut part) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..rows {
        let s = i as f32 / (rows - 1) as f32;
        let c = axis(s);
        for j in 0..around {
            let a = TAU * j as f32 / around as f32;
            // The ring lies in the plane normal to x; the axes used bend gently, so that is fine.
            p.push([c[0], c[1] + 0.3 * a.cos(), c[2] + 0.3 * a.sin()]);
            part.push(i * bands / rows);
        }
    }
    for i in 0..rows - 1 {
        for j in 0..around {
            let (a, b) = (i * around + j, i * around + (j + 1) % around);
            t.push([a, b, b + around]);
            t.push([a, b + around, a + around]);
        }
    }
    let (first, last) = (rows * around, rows * around + 1);
    for (end, row) in [(0.0, 0), (1.0, rows - 1)] {
        let c = axis(end);
        p.push([c[0] + if row == 0 { -0.2 } else { 0.2 }, c[1], c[2]]);
        part.push(if row == 0 { 0 } else { bands - 1 });
    }
    for j in 0..around {
        let (a, b) = (j, (j + 1) % around);
        t.push([first, b, a]);
        let (a, b) = (
            (rows - 1) * around + j,
            (rows - 1) * around + (j + 1) % around,
        );
        t.push([last, a, b]);
    }
    (p, t, part)
}

/// A torus (`major` × `minor` quads); clusters are `bands` bands around the major circle.
fn torus(major: u32, minor: u32, bands: u32) -> (Vec<[f32; 3]>, Vec<[u32; 3]>, Vec<u32>) {
    let (mut p, mut t, mut part) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..major {
        let u = TAU * i as f32 / major as f32;
        for j in 0..minor {
            let v = TAU * j as f32 / minor as f32;
            let r = 1.0 + 0.3 * v.cos();
            p.push([r * u.cos(), r * u.sin(), 0.3 * v.sin()]);
            part.push(i * bands / major);
        }
    }
    let id = |i: u32, j: u32| (i % major) * minor + j % minor;
    for i in 0..major {
        for j in 0..minor {
            t.push([id(i, j), id(i, j + 1), id(i + 1, j + 1)]);
            t.push([id(i, j), id(i + 1, j + 1), id(i + 1, j)]);
        }
    }
    (p, t, part)
}

fn charts_and_stretch(mesh: &(Vec<[f32; 3]>, Vec<[u32; 3]>, Vec<u32>)) -> (usize, f64) {
    let (p, t, part) = mesh;
    let atlas = build(p, t, part, &AtlasOptions::default()).expect("atlas builds");
    let s = atlas.stats();
    (s.charts, s.max_chart_stretch)
}

#[test]
fn a_closed_tube_gives_at_most_two_charts_per_cluster() {
    let straight = tube(16, 60, 6, |s| [4.0 * s, 0.0, 0.0]);
    let snake = tube(16, 80, 8, |s| {
        [6.0 * s, 0.6 * (TAU * 1.5 * s).sin(), 0.2 * (TAU * s).cos()]
    });
    for (name, mesh, clusters) in [("straight", straight, 6), ("snake", snake, 8)] {
        let (charts, stretch) = charts_and_stretch(&mesh);
        assert!(
            charts <= 2 * clusters,
            "{name}: {charts} charts for {clusters} clusters"
        );
        assert!(stretch <= 1.25, "{name}: chart stretch {stretch}");
    }
}

#[test]
fn torus_bands_and_a_whole_torus_give_few_charts() {
    let (charts, stretch) = charts_and_stretch(&torus(48, 16, 8));
    assert!(charts <= 16, "8 torus bands: {charts} charts");
    assert!(stretch <= 1.25, "torus bands: chart stretch {stretch}");
    // One cluster for the whole torus: genus 1, split and cut, or segmented; a few charts.
    let (charts, _) = charts_and_stretch(&torus(48, 16, 1));
    assert!(charts <= 4, "whole torus: {charts} charts");
}
