//! Segmentation and piecewise affine prediction on synthetic animations with a known answer.

use crate::common::{animate, rand_index, tube};
use mcgv_video::mesh::{Point, Triangle};
use mcgv_video::motion::{energy, residuals, segment, AffineTrack, Partition, SegmentOptions};
use mcgv_video::AnimatedMesh;

const FRAMES: usize = 12;
const RING_SIZE: usize = 16;

/// Part `k`'s affine map at time `t` ∈ [0, 1]: a rotation about its own axis, a stretch and a shift.
fn part_map(k: usize, t: f32) -> impl Fn(Point) -> Point {
    let angle = t * (0.6 + 0.5 * k as f32) * if k % 2 == 0 { 1.0 } else { -1.0 };
    let stretch = 1.0 + 0.3 * t * (k as f32 - 1.5);
    let shift = [
        0.5 * t * k as f32,
        1.5 * t * (k as f32 * 0.7).sin(),
        -t * k as f32,
    ];
    let axis = k % 3;
    move |p: Point| {
        let (c, s) = (angle.cos(), angle.sin());
        let (i, j) = ((axis + 1) % 3, (axis + 2) % 3);
        let mut q = p;
        q[i] = c * p[i] - s * p[j];
        q[j] = s * p[i] + c * p[j];
        q[axis] *= stretch;
        [q[0] + shift[0], q[1] + shift[1], q[2] + shift[2]]
    }
}

/// An animation whose vertices move exactly by their part's affine map; returns it with the true parts.
fn piecewise_affine(points: Vec<Point>, tris: Vec<Triangle>, part: &[usize]) -> AnimatedMesh {
    animate(&points, tris, FRAMES, |t, i, p| part_map(part[i], t)(p))
}

/// One tube cut into four parts along x.
fn connected_parts() -> (AnimatedMesh, Vec<usize>) {
    let (mut points, mut tris) = (Vec::new(), Vec::new());
    tube(&mut points, &mut tris, 0.0, 8.0, 81, RING_SIZE);
    let part: Vec<usize> = points
        .iter()
        .map(|p| ((p[0] / 2.0) as usize).min(3))
        .collect();
    (piecewise_affine(points, tris, &part), part)
}

/// The tube as a triangle soup: every triangle with its own three vertices, as some exporters
/// write meshes; copies of a vertex move together.
fn tube_soup() -> (AnimatedMesh, Vec<usize>) {
    let (mut points, mut tris) = (Vec::new(), Vec::new());
    tube(&mut points, &mut tris, 0.0, 8.0, 41, RING_SIZE);
    let soup_points: Vec<Point> = tris.iter().flatten().map(|&v| points[v as usize]).collect();
    let soup_tris: Vec<Triangle> = (0..tris.len() as u32)
        .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
        .collect();
    let part: Vec<usize> = soup_points
        .iter()
        .map(|p| ((p[0] / 2.0) as usize).min(3))
        .collect();
    (piecewise_affine(soup_points, soup_tris, &part), part)
}

/// Four separate tubes, one per part.
fn separate_parts() -> (AnimatedMesh, Vec<usize>) {
    let (mut points, mut tris) = (Vec::new(), Vec::new());
    let mut part = Vec::new();
    for k in 0..4 {
        tube(
            &mut points,
            &mut tris,
            2.5 * k as f32,
            2.5 * k as f32 + 2.0,
            9,
            RING_SIZE,
        );
        part.resize(points.len(), k);
    }
    (piecewise_affine(points, tris, &part), part)
}

fn options(clusters: usize) -> SegmentOptions {
    SegmentOptions {
        clusters,
        ..SegmentOptions::default()
    }
}

fn max_residual(mesh: &AnimatedMesh, track: &AffineTrack, partition: &Partition) -> f64 {
    (0..mesh.frame_count())
        .flat_map(|f| {
            let predicted = track.try_predict(f, mesh.frame(0), partition).unwrap();
            residuals(mesh.frame(f), &predicted)
        })
        .map(|d| d.iter().map(|&c| (c as f64).powi(2)).sum::<f64>().sqrt())
        .fold(0.0, f64::max)
}

/// An affine step (fraction of the diagonal) far below the tests' tolerances.
const FINE: f64 = 1e-6;

#[test]
fn separate_parts_are_recovered_and_predicted_to_quantisation_level() {
    let (mesh, truth) = separate_parts();
    let partition = segment(&mesh, &options(4)).unwrap();
    assert_eq!(partition.clusters(), 4);
    assert_eq!(rand_index(partition.labels(), &truth), 1.0);

    let diag = mesh.bbox_diagonal();
    let track = AffineTrack::fit(mesh.frames(), mesh.frame(0), &partition, FINE).unwrap();
    let worst = max_residual(&mesh, &track, &partition);
    assert!(
        worst < 2e-5 * diag,
        "largest residual {worst} vs diagonal {diag}"
    );
    // A coarser step: coarser maps, but still following the motion.
    let coarse = AffineTrack::fit(mesh.frames(), mesh.frame(0), &partition, 1e-2).unwrap();
    let coarse_worst = max_residual(&mesh, &coarse, &partition);
    assert!(
        coarse_worst > worst && coarse_worst < 1e-2 * diag,
        "{coarse_worst}"
    );
}

#[test]
fn connected_parts_are_recovered_up_to_their_seams() {
    let (mesh, truth) = connected_parts();
    let partition = segment(&mesh, &options(4)).unwrap();
    let score = rand_index(partition.labels(), &truth);
    assert!(score > 0.98, "Rand index {score}");

    // With the true parts, the predictor leaves only quantisation noise; the motion is far larger.
    let labels: Vec<u32> = truth.iter().map(|&k| k as u32).collect();
    let exact = Partition::from_labels(labels, 4).unwrap();
    let track = AffineTrack::fit(mesh.frames(), mesh.frame(0), &exact, FINE).unwrap();
    let diag = mesh.bbox_diagonal();
    assert!(max_residual(&mesh, &track, &exact) < 2e-5 * diag);
    let last = mesh.frame(FRAMES - 1);
    let motion: Vec<[f32; 3]> = residuals(last, mesh.frame(0));
    let predicted = track.predict(FRAMES - 1, mesh.frame(0), &exact);
    assert!(energy(&residuals(last, &predicted)) < 1e-9 * energy(&motion));
}

#[test]
fn plain_k_means_recovers_separate_parts_too() {
    let (mesh, truth) = separate_parts();
    let opts = SegmentOptions {
        refine_passes: 0,
        ..options(4)
    };
    let partition = segment(&mesh, &opts).unwrap();
    assert_eq!(rand_index(partition.labels(), &truth), 1.0);
}

/// A tube twisting about its axis, the angle growing along it: smooth motion no few affine maps fit.
fn twisted_tube() -> AnimatedMesh {
    let (mut points, mut tris) = (Vec::new(), Vec::new());
    tube(&mut points, &mut tris, 0.0, 8.0, 41, RING_SIZE);
    animate(&points, tris, FRAMES, |t, _, p| {
        let a = t * 0.4 * p[0] * p[0] / 8.0;
        [
            p[0],
            a.cos() * p[1] - a.sin() * p[2],
            a.sin() * p[1] + a.cos() * p[2],
        ]
    })
}

fn residual_energy(mesh: &AnimatedMesh, partition: &Partition) -> f64 {
    let track = AffineTrack::fit(mesh.frames(), mesh.frame(0), partition, FINE).unwrap();
    (0..mesh.frame_count())
        .map(|f| {
            energy(&residuals(
                mesh.frame(f),
                &track.predict(f, mesh.frame(0), partition),
            ))
        })
        .sum()
}

#[test]
fn border_refinement_lowers_the_residual_energy() {
    let mesh = twisted_tube();
    let plain = SegmentOptions {
        refine_passes: 0,
        ..options(5)
    };
    let plain = residual_energy(&mesh, &segment(&mesh, &plain).unwrap());
    let refined = residual_energy(&mesh, &segment(&mesh, &options(5)).unwrap());
    assert!(refined < plain, "refined {refined} vs plain {plain}");
}

#[test]
fn a_triangle_soup_is_segmented_like_the_welded_mesh() {
    let (mesh, truth) = tube_soup();
    let partition = segment(&mesh, &options(4)).unwrap();
    let score = rand_index(partition.labels(), &truth);
    assert!(score > 0.98, "Rand index {score}");
}

#[test]
fn segmentation_is_deterministic() {
    let (mesh, _) = connected_parts();
    let a = segment(&mesh, &options(6)).unwrap();
    let b = segment(&mesh, &options(6)).unwrap();
    assert_eq!(a, b);
}

#[test]
fn quantised_form_round_trips_and_rejects_corruption() {
    let (mesh, truth) = separate_parts();
    let labels: Vec<u32> = truth.iter().map(|&k| k as u32).collect();
    let partition = Partition::from_labels(labels, 4).unwrap();
    let track = AffineTrack::fit(mesh.frames(), mesh.frame(0), &partition, FINE).unwrap();
    let geometry = track.geometry().clone();
    let again = AffineTrack::from_quantised(track.quantised().clone(), geometry.clone()).unwrap();
    for f in [0, 5, FRAMES - 1] {
        assert_eq!(
            track.predict(f, mesh.frame(0), &partition),
            again.predict(f, mesh.frame(0), &partition)
        );
    }
    let refused = |q: mcgv_video::motion::QuantisedAffine| {
        AffineTrack::from_quantised(q, geometry.clone()).is_err()
    };
    let mut too_big = track.quantised().clone();
    too_big.values[3] = mcgv_video::motion::MAX_AFFINE_LEVEL + 1;
    assert!(refused(too_big));
    let mut short = track.quantised().clone();
    short.values.pop();
    assert!(refused(short));
    for step in [f32::NAN, 0.0, -1.0, f32::INFINITY] {
        let mut bad = track.quantised().clone();
        bad.step = step;
        assert!(refused(bad), "step {step}");
    }
    let mut fewer = geometry.clone();
    fewer.centroids.pop();
    assert!(AffineTrack::from_quantised(track.quantised().clone(), fewer).is_err());
    assert!(track
        .try_predict(FRAMES, mesh.frame(0), &partition)
        .is_err());
    // Unchecked prediction past the end leaves the reference as it is instead of panicking.
    assert_eq!(
        track.predict(FRAMES, mesh.frame(0), &partition),
        mesh.frame(0)
    );
}

fn assert_finite_everywhere(mesh: &AnimatedMesh, clusters: usize) {
    let partition = segment(mesh, &options(clusters)).unwrap();
    assert_eq!(partition.vertex_count(), mesh.vertex_count());
    assert!(partition.clusters() >= 1 && partition.clusters() <= clusters);
    let track = AffineTrack::fit(mesh.frames(), mesh.frame(0), &partition, FINE).unwrap();
    for f in 0..mesh.frame_count() {
        let predicted = track.predict(f, mesh.frame(0), &partition);
        assert!(predicted.iter().flatten().all(|c| c.is_finite()));
    }
}

#[test]
fn degenerate_inputs_give_finite_answers() {
    // A flat grid that slides and shears in its plane, and a moving line of vertices.
    let n = 6u32;
    let grid: Vec<Point> = (0..n * n)
        .map(|i| [(i % n) as f32, (i / n) as f32, 0.0])
        .collect();
    let mut tris = Vec::new();
    for y in 0..n - 1 {
        for x in 0..n - 1 {
            let a = y * n + x;
            tris.push([a, a + 1, a + n + 1]);
            tris.push([a, a + n + 1, a + n]);
        }
    }
    let slide = |p: Point, t: f32| [p[0] + t * p[1], p[1] + t, 0.0];
    let frames = (0..4).map(|f| grid.iter().map(|&p| slide(p, f as f32 * 0.3)).collect());
    assert_finite_everywhere(&AnimatedMesh::new(tris, frames.collect()).unwrap(), 5);

    let line: Vec<Point> = (0..8).map(|i| [i as f32, 0.0, 0.0]).collect();
    let line_tris: Vec<Triangle> = (0..7).map(|i| [i, i + 1, i + 1]).collect();
    let frames = (0..3).map(|f| {
        line.iter()
            .map(|p| [p[0] * (1.0 + f as f32), f as f32, 0.0])
            .collect()
    });
    assert_finite_everywhere(&AnimatedMesh::new(line_tris, frames.collect()).unwrap(), 3);

    // Isolated vertices, more clusters than vertices, a single frame, no motion at all.
    let loose: Vec<Point> = vec![[0.0, 0.0, 0.0], [1.0, 2.0, 3.0], [4.0, 1.0, 0.0]];
    let moved: Vec<Point> = loose.iter().map(|p| [p[0] + 1.0, p[1], -p[2]]).collect();
    assert_finite_everywhere(
        &AnimatedMesh::new(vec![], vec![loose.clone(), moved]).unwrap(),
        20,
    );
    assert_finite_everywhere(&AnimatedMesh::new(vec![], vec![loose.clone()]).unwrap(), 2);
    let (mesh, _) = separate_parts();
    let still =
        AnimatedMesh::new(mesh.triangles().to_vec(), vec![mesh.frame(0).to_vec(); 3]).unwrap();
    let partition = segment(&still, &options(4)).unwrap();
    assert_eq!(partition.clusters(), 1);
}

#[test]
fn small_clusters_are_dissolved() {
    let (mesh, _) = separate_parts();
    // 144 vertices, 60 clusters asked: some would be tiny.
    let partition = segment(&mesh, &options(60)).unwrap();
    let sizes: Vec<usize> = partition.members().iter().map(Vec::len).collect();
    assert!(sizes.iter().all(|&s| s >= 4), "{sizes:?}");
}

#[test]
fn bad_requests_are_errors() {
    let (mesh, truth) = separate_parts();
    assert!(segment(&mesh, &options(0)).is_err());
    let labels: Vec<u32> = truth.iter().map(|&k| k as u32).collect();
    let partition = Partition::from_labels(labels, 4).unwrap();
    assert!(AffineTrack::fit(mesh.frames(), mesh.frame(0), &partition, 0.0).is_err());
    assert!(AffineTrack::fit(mesh.frames(), mesh.frame(0), &partition, f64::NAN).is_err());
    assert!(AffineTrack::fit(mesh.frames(), &mesh.frame(0)[1..], &partition, FINE).is_err());
}

/// Frame 0 of a real mesh shipped with the project (CesiumMan: 138 pieces, flat patches), cut into
/// four slabs along its longest side, each moved by its own map.
#[test]
fn parts_of_a_real_mesh_are_recovered_and_predicted() {
    let figure = mcgv_video::mesh::read_animation(
        concat!(env!("CARGO_MANIFEST_DIR"), "/media/CesiumMan.glb"),
        &mcgv_video::mesh::ReadOptions::default(),
    )
    .unwrap();
    let rest = figure.frame(0).to_vec();
    let (lo, hi) = mcgv_video::mesh::bounding_box(&rest);
    let axis = (0..3)
        .max_by(|&a, &b| (hi[a] - lo[a]).total_cmp(&(hi[b] - lo[b])))
        .unwrap();
    let part: Vec<usize> = rest
        .iter()
        .map(|p| (((p[axis] - lo[axis]) / (hi[axis] - lo[axis]) * 4.0) as usize).min(3))
        .collect();
    let mesh = piecewise_affine(rest, figure.triangles().to_vec(), &part);
    let partition = segment(&mesh, &options(4)).unwrap();
    let score = rand_index(partition.labels(), &part);
    assert!(score > 0.9, "Rand index {score}");
    let labels: Vec<u32> = part.iter().map(|&k| k as u32).collect();
    let exact = Partition::from_labels(labels, 4).unwrap();
    let track = AffineTrack::fit(mesh.frames(), mesh.frame(0), &exact, FINE).unwrap();
    assert!(max_residual(&mesh, &track, &exact) < 2e-5 * mesh.bbox_diagonal());
}
