//! Segmentation by decimation (skinning paper §3.1) on synthetic animations with a known answer.

use crate::common::{canonical, config, decoder, rand_index, read_media, tube};
use mcgv_video::codec::Codec;
use mcgv_video::encoder::{encode, EncodeOptions, Segmentation};
use mcgv_video::mesh::topology::ManifoldReport;
use mcgv_video::mesh::{Point, Triangle};
use mcgv_video::metrics::compare;
use mcgv_video::motion::{decimate, DecimateOptions, Decimation};
use mcgv_video::{AnimatedMesh, PaddingMethod};

const FRAMES: usize = 10;
const RING_SIZE: usize = 12;

/// Rigid motion of part `k` at time `t` ∈ [0, 1]: part 0 stays, part 1 bends up about the joint at
/// x = 4 and moves along, as a forearm does.
fn rigid(k: usize, t: f32, p: Point) -> Point {
    if k == 0 {
        return p;
    }
    let angle = 0.8 * t;
    let (c, s) = (angle.cos(), angle.sin());
    let (x, y) = (p[0] - 4.0, p[1]);
    [4.0 + c * x - s * y + 0.2 * t, s * x + c * y, p[2]]
}

fn animate(points: &[Point], tris: Vec<Triangle>, part: &[usize]) -> AnimatedMesh {
    crate::common::animate(points, tris, FRAMES, |t, i, p| rigid(part[i], t, p))
}

/// One tube of 41 rings, x in 0..8: x < 4 is part 0, the rest part 1.
fn two_rigid_parts() -> (AnimatedMesh, Vec<usize>) {
    let (mut points, mut tris) = (Vec::new(), Vec::new());
    tube(&mut points, &mut tris, 0.0, 8.0, 41, RING_SIZE);
    let part: Vec<usize> = points.iter().map(|p| usize::from(p[0] >= 4.0)).collect();
    (animate(&points, tris, &part), part)
}

fn run(mesh: &AnimatedMesh, e0: f64) -> Decimation {
    decimate(
        mesh,
        &DecimateOptions {
            e0,
            ..DecimateOptions::default()
        },
    )
    .expect("decimates")
}

#[test]
fn two_rigid_parts_give_two_clusters() {
    let (mesh, part) = two_rigid_parts();
    let d = run(&mesh, 0.003);
    assert_eq!(d.partition.clusters(), 2, "{:?}", d.partition.members());
    assert_eq!(d.components, 1);
    assert!(d.error <= 0.003, "E_l {} above E0", d.error);
    let agreement = rand_index(d.partition.labels(), &part);
    assert!(agreement > 0.97, "Rand index {agreement}");
    // All frames but frame 0 are measured when the mesh is small.
    assert_eq!(d.frames_used, FRAMES - 1);
}

/// A tube bent smoothly (each ring turned by an angle growing with x): no piecewise affine motion
/// fits exactly, so the smaller E0, the more clusters.
fn bent_tube() -> AnimatedMesh {
    let (mut points, mut tris) = (Vec::new(), Vec::new());
    tube(&mut points, &mut tris, 0.0, 8.0, 41, RING_SIZE);
    crate::common::animate(&points, tris, FRAMES, |t, _, p| {
        let angle = 0.15 * t * p[0];
        let (c, s) = (angle.cos(), angle.sin());
        [c * p[0] - s * p[1], s * p[0] + c * p[1], p[2]]
    })
}

#[test]
fn larger_e0_gives_fewer_clusters() {
    let mesh = bent_tube();
    let mut last = usize::MAX;
    let mut counts = Vec::new();
    for e0 in [1e-4, 1e-3, 0.003, 0.03, 0.5] {
        let d = run(&mesh, e0);
        let k = d.partition.clusters();
        assert!(d.error <= e0, "E0 {e0}: E_l {}", d.error);
        assert!(k <= last, "E0 {e0} gave {k} clusters, more than {last}");
        counts.push(k);
        last = k;
    }
    // A tiny threshold needs many pieces for the bend; a huge one merges everything.
    assert!(counts[0] > 4, "{counts:?}");
    assert_eq!(counts.last(), Some(&1), "{counts:?}");
}

#[test]
fn components_are_segmented_on_their_own() {
    // Two tubes moving alike and a lone triangle: three components, so three clusters even when
    // any error is allowed, and the triangle (too small for a determined affine map) is one of them.
    let (mut points, mut tris) = (Vec::new(), Vec::new());
    tube(&mut points, &mut tris, 0.0, 3.0, 7, RING_SIZE);
    tube(&mut points, &mut tris, 4.0, 7.0, 7, RING_SIZE);
    let t = points.len() as u32;
    points.extend([[8.0, 0.0, 0.0], [8.5, 0.0, 0.0], [8.0, 0.5, 0.0]]);
    tris.push([t, t + 1, t + 2]);
    let part = vec![1; points.len()];
    let mesh = animate(&points, tris, &part);
    let d = run(&mesh, 0.9);
    assert_eq!(d.components, 3);
    assert_eq!(d.partition.clusters(), 3);
    let labels = d.partition.labels();
    let tri = labels[t as usize];
    assert!(labels[t as usize..].iter().all(|&l| l == tri));
    assert!(labels[..t as usize].iter().all(|&l| l != tri));
    assert_ne!(labels[0], labels[t as usize - 1]);
}

#[test]
fn non_manifold_input_is_segmented() {
    // The two-part tube plus fins: extra triangles on existing edges (three triangles per edge)
    // whose tips move with their part.
    let (mut points, mut tris) = (Vec::new(), Vec::new());
    tube(&mut points, &mut tris, 0.0, 8.0, 41, RING_SIZE);
    let mut part: Vec<usize> = points.iter().map(|p| usize::from(p[0] >= 4.0)).collect();
    for ring in [5u32, 35] {
        let (a, b) = (ring * RING_SIZE as u32, ring * RING_SIZE as u32 + 1);
        let (pa, pb) = (points[a as usize], points[b as usize]);
        let tip = points.len() as u32;
        points.push([pa[0], 2.0 * pa[1] - pb[1], 2.0 * pa[2] - pb[2] + 0.5]);
        part.push(part[a as usize]);
        tris.push([a, b, tip]);
    }
    let report = ManifoldReport::new(points.len(), &tris);
    assert!(report.non_manifold_edges > 0);
    let mesh = animate(&points, tris, &part);
    let d = run(&mesh, 0.003);
    assert_eq!(d.partition.clusters(), 2);
    assert!(rand_index(d.partition.labels(), &part) > 0.97);
}

#[test]
fn a_triangle_soup_is_welded_at_its_seams() {
    // Every triangle with its own vertices: welding copies that move together makes it one
    // component again, so decimation still finds the two parts.
    let (mut points, mut tris) = (Vec::new(), Vec::new());
    tube(&mut points, &mut tris, 0.0, 8.0, 21, RING_SIZE);
    let soup: Vec<Point> = tris.iter().flatten().map(|&v| points[v as usize]).collect();
    let soup_tris: Vec<Triangle> = (0..tris.len() as u32)
        .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
        .collect();
    let part: Vec<usize> = soup.iter().map(|p| usize::from(p[0] >= 4.0)).collect();
    let mesh = animate(&soup, soup_tris, &part);
    let d = run(&mesh, 0.003);
    assert_eq!(d.components, 1);
    assert_eq!(
        d.partition.clusters(),
        2,
        "{:?} {} {} {}",
        d.partition
            .members()
            .iter()
            .map(Vec::len)
            .collect::<Vec<_>>(),
        d.error,
        d.decimated_error,
        d.decimated_clusters
    );
    assert!(rand_index(d.partition.labels(), &part) > 0.97);
    // The plain collapses (the paper's) leave a band of border vertices paired across the parts in
    // a cluster of its own; border refinement dissolves it without raising the error.
    assert!(d.decimated_clusters > 2, "{}", d.decimated_clusters);
    assert!(d.error <= d.decimated_error);
    let plain = decimate(
        &mesh,
        &DecimateOptions {
            refine_passes: 0,
            ..DecimateOptions::default()
        },
    )
    .expect("decimates");
    assert_eq!(plain.partition.clusters(), d.decimated_clusters);
    assert_eq!(plain.error, d.decimated_error);
}

#[test]
fn still_and_single_frame_animations_collapse_to_their_components() {
    let (mut points, mut tris) = (Vec::new(), Vec::new());
    tube(&mut points, &mut tris, 0.0, 2.0, 5, RING_SIZE);
    let still = AnimatedMesh::new(tris.clone(), vec![points.clone(); 4]).expect("valid");
    let d = run(&still, 1e-6);
    assert_eq!(d.partition.clusters(), 1);
    assert_eq!(d.error, 0.0);
    let single = AnimatedMesh::new(tris, vec![points]).expect("valid");
    let d = run(&single, 1e-6);
    assert_eq!(d.partition.clusters(), 1);
    assert_eq!(d.frames_used, 0);
}

#[test]
fn frames_are_subsampled_past_the_budget() {
    let (mesh, _) = two_rigid_parts();
    let budget = mesh.vertex_count() * 4;
    let d = decimate(
        &mesh,
        &DecimateOptions {
            max_vertex_frames: budget,
            ..DecimateOptions::default()
        },
    )
    .expect("decimates");
    assert_eq!(d.frames_used, 4);
    assert_eq!(d.partition.clusters(), 2);
}

#[test]
fn decimation_is_deterministic() {
    let (mesh, _) = two_rigid_parts();
    let a = run(&mesh, 1e-4);
    let b = run(&mesh, 1e-4);
    assert_eq!(a.partition, b.partition);
    assert_eq!(a.error, b.error);
}

#[test]
fn bad_requests_are_clear_errors() {
    let (mesh, _) = two_rigid_parts();
    for e0 in [0.0, -0.1, f64::NAN, f64::INFINITY] {
        let err = decimate(
            &mesh,
            &DecimateOptions {
                e0,
                ..DecimateOptions::default()
            },
        )
        .expect_err("a bad E0 is refused");
        assert!(err.to_string().contains("E0"), "{err}");
    }
    // More components than the cap allows clusters.
    let (mut points, mut tris) = (Vec::new(), Vec::new());
    for k in 0..3 {
        tube(
            &mut points,
            &mut tris,
            3.0 * k as f32,
            3.0 * k as f32 + 2.0,
            3,
            RING_SIZE,
        );
    }
    let part = vec![0; points.len()];
    let mesh = animate(&points, tris, &part);
    let err = decimate(
        &mesh,
        &DecimateOptions {
            max_clusters: 2,
            ..DecimateOptions::default()
        },
    )
    .expect_err("three components do not fit two clusters");
    assert!(err.to_string().contains("3 connected components"), "{err}");
}

#[test]
fn the_cap_continues_collapsing_past_e0() {
    let mesh = bent_tube();
    let free = run(&mesh, 1e-4);
    assert!(free.partition.clusters() > 2);
    let capped = decimate(
        &mesh,
        &DecimateOptions {
            e0: 1e-4,
            max_clusters: 2,
            ..DecimateOptions::default()
        },
    )
    .expect("decimates");
    assert_eq!(capped.partition.clusters(), 2);
    assert!(capped.error > free.error);
}

/// Encode with decimation, decode, and compare: the stream carries the K decimation found (the
/// two-bone cylinder's two parts), and the decoded animation stays within the error bound.
#[test]
fn decimation_round_trips_through_the_stream() {
    let mesh = read_media("RiggedSimple.glb");
    let opts = EncodeOptions {
        // The paper's padding keeps this debug-build test fast.
        codec: config(Codec::Jpeg, None, Some(PaddingMethod::Cg), None),
        segmentation: Segmentation::Decimation { e0: 0.003 }.into(),
        ..EncodeOptions::default()
    };
    let encoded = encode(&mesh, &opts).expect("encodes");
    let report = encoded.report;
    let k = report.segmentation.clusters;
    assert_eq!(report.segmentation.method, "decimation");
    assert_eq!(report.header.clusters as usize, k);
    assert!(report.segmentation.error.is_some_and(|e| e <= 0.003));
    let bytes = encoded.container.to_bytes();
    let mut decoder = decoder(bytes).expect("stream");
    assert_eq!(decoder.partition().clusters(), k);
    let decoded = decoder.decode_all().expect("decodes");
    assert_eq!(canonical(decoded.triangles()), canonical(mesh.triangles()));
    assert_eq!(decoded.frame_count(), mesh.frame_count());
    let m = compare(&mesh, &decoded).expect("comparable");
    // Measured 1.9e-4 of the diagonal (K = 2: the two bones); the bound is twice that.
    assert_eq!(k, 2);
    assert!(m.rmse < 4e-4, "RMSE {}", m.rmse);
}
