//! The affine track's stream part (issue 18): levels under the residuals' quality law, coded as
//! trajectories. Round trip within the steps, and damaged parts refused.

use crate::cloth::cloth;
use mcgv_video::motion::{
    segment, AffineTrack, LinearForm, Partition, SegmentOptions, MIN_AFFINE_STEP,
};
use mcgv_video::stream::side_info::{decode_affine, encode_affine};
use mcgv_video::AnimatedMesh;

/// A cloth (every cluster's maps change every frame) and its k-means partition.
fn cloth_and_partition() -> (AnimatedMesh, Partition) {
    let mesh = cloth(16, 24);
    let options = SegmentOptions {
        clusters: 6,
        ..SegmentOptions::default()
    };
    let partition = segment(&mesh, &options).unwrap();
    (mesh, partition)
}

/// Coefficient `c` of a map `[A | b]` in stored form: `A`'s nine numbers in `form`,
/// `t = A·centroid + b`.
fn stored(h: &[f64; 12], centroid: [f64; 3], c: usize, form: LinearForm) -> f64 {
    let row = c / 4;
    match c % 4 {
        3 => h[c] + (0..3).map(|j| h[4 * row + j] * centroid[j]).sum::<f64>(),
        col => {
            let a: [[f64; 3]; 3] = std::array::from_fn(|r| [h[4 * r], h[4 * r + 1], h[4 * r + 2]]);
            form.values(&a).expect("a decomposable map")[3 * row + col]
        }
    }
}

#[test]
fn decoded_maps_are_the_encoders_and_within_half_a_step_of_the_fit() {
    let (mesh, partition) = cloth_and_partition();
    let reference = mesh.frame(0);
    for step in [1e-2, 1e-3, 2.5e-4] {
        let track = AffineTrack::fit(mesh.frames(), reference, &partition, step).unwrap();
        let bytes = encode_affine(&track).unwrap();
        let decoded = decode_affine(&bytes, mesh.frame_count(), &partition, reference).unwrap();
        assert_eq!(decoded, track, "step {step}");
        // Maps are dequantised on request: none past the last frame or cluster, even far past.
        assert!(decoded.frame_maps(mesh.frame_count()).is_empty());
        assert!(decoded.map(usize::MAX, 0).is_none());
        assert!(decoded.map(0, partition.clusters()).is_none());
        assert_eq!(
            decoded.maps().len(),
            mesh.frame_count() * partition.clusters()
        );
        let exact =
            AffineTrack::fit(mesh.frames(), reference, &partition, MIN_AFFINE_STEP).unwrap();
        let geometry = track.geometry();
        for f in 0..mesh.frame_count() {
            for k in 0..partition.clusters() {
                let form = track.quantised().forms[k];
                let steps = geometry.steps(k, f64::from(track.quantised().step), form);
                let (got, want) = (decoded.map(f, k).unwrap(), exact.map(f, k).unwrap());
                let centroid = geometry.centroid(k);
                for (c, quantiser) in steps.iter().enumerate() {
                    let error =
                        (stored(&got, centroid, c, form) - stored(&want, centroid, c, form)).abs();
                    assert!(
                        error <= 0.5 * quantiser * (1.0 + 1e-6) + 1e-9,
                        "step {step}, frame {f}, cluster {k}, coefficient {c}: error {error:e}, \
                         quantiser step {quantiser:e}"
                    );
                }
            }
        }
    }
}

#[test]
fn a_coarser_step_codes_fewer_bytes() {
    let (mesh, partition) = cloth_and_partition();
    let size = |step| {
        let track = AffineTrack::fit(mesh.frames(), mesh.frame(0), &partition, step).unwrap();
        encode_affine(&track).unwrap().len()
    };
    let (fine, coarse) = (size(1e-4), size(1e-3));
    assert!(coarse < fine, "{coarse} bytes at 1e-3, {fine} at 1e-4");
}

#[test]
fn truncated_or_damaged_parts_are_errors() {
    let (mesh, partition) = cloth_and_partition();
    let reference = mesh.frame(0);
    let frames = mesh.frame_count();
    let track = AffineTrack::fit(mesh.frames(), reference, &partition, 1e-3).unwrap();
    let bytes = encode_affine(&track).unwrap();
    for cut in 0..bytes.len() {
        assert!(
            decode_affine(&bytes[..cut], frames, &partition, reference).is_err(),
            "cut at {cut} of {}",
            bytes.len()
        );
    }
    // A forged step: NaN, zero, negative, huge.
    for step in [f32::NAN, 0.0, -1e-3, 1e9] {
        let mut forged = bytes.clone();
        forged[..4].copy_from_slice(&step.to_le_bytes());
        assert!(decode_affine(&forged, frames, &partition, reference).is_err());
    }
    // More frames than the bytes can hold: refused before allocating.
    assert!(decode_affine(&bytes, 1 << 40, &partition, reference).is_err());
    // Flipped bits in the coded levels: an error, never a panic; the end marker catches nearly all.
    let (mut errors, mut trials) = (0, 0);
    for at in (4..bytes.len()).step_by(7) {
        let mut damaged = bytes.clone();
        damaged[at] ^= 0x5A;
        trials += 1;
        match decode_affine(&damaged, frames, &partition, reference) {
            Err(_) => errors += 1,
            // The range coder's last word carries slack: its low bits may go unread.
            Ok(_) if at + 4 >= bytes.len() => {}
            Ok(t) => assert_ne!(t, track, "a flipped byte at {at} changed nothing"),
        }
    }
    assert!(errors * 10 >= trials * 9, "{errors} errors in {trials}");
}

#[test]
fn linear_steps_follow_each_axis_extent_and_move_vertices_as_the_translation_does() {
    // The cloth starts flat in y: every cluster is thin across it, so the middle column of its
    // linear part (what y offsets multiply) is quantised at least as coarse as the other two,
    // and coarser than the finest (the coarsest step is capped).
    let (mesh, partition) = cloth_and_partition();
    let reference = mesh.frame(0);
    let step = 1e-3;
    let track = AffineTrack::fit(mesh.frames(), reference, &partition, step).unwrap();
    let geometry = track.geometry();
    let base = f64::from(track.quantised().step);
    for k in 0..partition.clusters() {
        let steps = geometry.steps(k, base, LinearForm::Entries);
        let spread = geometry.axis_spreads[k];
        assert!(spread[1] < spread[0] && spread[1] < spread[2], "{spread:?}");
        assert!(steps[1] >= steps[0] && steps[1] >= steps[2], "{steps:?}");
        assert!(steps[1] > steps[0].min(steps[2]), "{steps:?}");
        // The rule: a row's three linear steps, weighted by the extents, move the vertices by
        // at most the translation's step (RMS), as the one step of the former rule did.
        for row in 0..3 {
            let moved: f64 = (0..3)
                .map(|j| (steps[4 * row + j] * spread[j]).powi(2))
                .sum();
            assert!(
                moved <= base * base * (1.0 + 1e-9),
                "cluster {k}: {moved:e}"
            );
            assert_eq!(steps[4 * row + 3], base);
        }
    }
    // And the decoded maps move the vertices by about that: RMS within √(2/12) steps (uniform
    // rounding of the translation and of the linear part), with a margin for rounding that is
    // not uniform on few levels.
    let exact = AffineTrack::fit(mesh.frames(), reference, &partition, MIN_AFFINE_STEP).unwrap();
    // Unit coordinates are fractions of the reference's bounding-box diagonal.
    let diagonal = {
        let (lo, hi) = mcgv_video::mesh::bounding_box(reference);
        (0..3)
            .map(|a| f64::from(hi[a] - lo[a]).powi(2))
            .sum::<f64>()
            .sqrt()
    };
    let (mut sum, mut n) = (0.0, 0usize);
    for f in 0..mesh.frame_count() {
        let (got, want) = (
            track.predict(f, reference, &partition),
            exact.predict(f, reference, &partition),
        );
        for (a, b) in got.iter().zip(&want) {
            let d2: f64 = (0..3).map(|i| f64::from(a[i] - b[i]).powi(2)).sum();
            sum += d2 / 3.0 / (diagonal * diagonal);
            n += 1;
        }
    }
    let rms = (sum / n as f64).sqrt();
    assert!(
        rms <= 1.5 * base * (2.0f64 / 12.0).sqrt(),
        "rms {rms:e}, step {base:e}"
    );
    assert!(rms > 0.1 * base, "rms {rms:e}: the maps were quantised");
}

#[test]
fn a_turning_part_is_stored_as_rotation_and_a_stretching_one_as_entries() {
    // Two blocks of 4 × 4 × 4 points: block 0 turns about z by up to 2 radians (all four of its
    // map's x–y entries move; as a rotation one number does), block 1 stretches along x (one
    // entry moves either way: a tie, which keeps the entries).
    let block = |x0: f32| -> Vec<[f32; 3]> {
        (0..64)
            .map(|i| {
                [
                    x0 + 0.1 * (i % 4) as f32,
                    0.1 * (i / 4 % 4) as f32,
                    0.1 * (i / 16) as f32,
                ]
            })
            .collect()
    };
    let rest: Vec<[f32; 3]> = block(0.0).into_iter().chain(block(1.0)).collect();
    let labels: Vec<u32> = (0..128).map(|i| u32::from(i >= 64)).collect();
    let partition = Partition::from_labels(labels, 2).unwrap();
    let frames: Vec<Vec<[f32; 3]>> = (0..30)
        .map(|f| {
            let t = f as f32 / 29.0;
            let (c, s) = ((2.0 * t).cos(), (2.0 * t).sin());
            rest.iter()
                .enumerate()
                .map(|(i, p)| match i < 64 {
                    true => {
                        let (x, y) = (p[0] - 0.15, p[1] - 0.15);
                        [0.15 + c * x - s * y, 0.15 + s * x + c * y, p[2]]
                    }
                    false => [1.0 + (p[0] - 1.0) * (1.0 + t), p[1], p[2]],
                })
                .collect()
        })
        .collect();
    let track = AffineTrack::fit(&frames, &rest, &partition, 1e-4).unwrap();
    assert_eq!(
        track.quantised().forms,
        [LinearForm::RotationStretch, LinearForm::Entries]
    );
    let bytes = encode_affine(&track).unwrap();
    let decoded = decode_affine(&bytes, frames.len(), &partition, &rest).unwrap();
    assert_eq!(decoded, track);
    // Both are predicted to within a few steps (1e-4 of the rest pose's diagonal).
    let diagonal = {
        let (lo, hi) = mcgv_video::mesh::bounding_box(&rest);
        (0..3)
            .map(|a| f64::from(hi[a] - lo[a]).powi(2))
            .sum::<f64>()
            .sqrt()
    };
    for (f, frame) in frames.iter().enumerate() {
        for (got, want) in track.predict(f, &rest, &partition).iter().zip(frame) {
            for a in 0..3 {
                let error = f64::from(got[a] - want[a]).abs() / diagonal;
                assert!(error < 4e-4, "frame {f}: {error:e}");
            }
        }
    }
}

/// A rest pose, its frames, and its clusters.
struct Blocks {
    rest: Vec<[f32; 3]>,
    frames: Vec<Vec<[f32; 3]>>,
    partition: Partition,
}

/// `blocks` blocks of 4 × 4 × 4 points 0.1 apart, in a row along x 0.5 apart, one cluster each.
fn row_of_blocks(blocks: usize) -> (Vec<[f32; 3]>, Partition) {
    let rest: Vec<[f32; 3]> = (0..64 * blocks)
        .map(|i| {
            let p = i % 64;
            let x0 = (i / 64) as f32 * 0.5;
            [
                x0 + 0.1 * (p % 4) as f32,
                0.1 * (p / 4 % 4) as f32,
                0.1 * (p / 16) as f32,
            ]
        })
        .collect();
    let labels: Vec<u32> = (0..64 * blocks).map(|i| (i / 64) as u32).collect();
    let partition = Partition::from_labels(labels, blocks).unwrap();
    (rest, partition)
}

/// Six blocks of 4 × 4 × 4 points in a row, jolted each frame by pseudo-random translations and
/// turns about z: `walks` random walks, block b taking walk b % `walks` (1: all alike, 6: each its
/// own, 2: every other block alike).
fn jolted_blocks(walks: usize) -> Blocks {
    use rand_xoshiro::rand_core::{RngCore, SeedableRng};
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(35);
    let mut uniform = move || (rng.next_u32() >> 8) as f32 / (1u32 << 24) as f32 - 0.5;
    let blocks = 6;
    let (rest, partition) = row_of_blocks(blocks);
    let mut frames = Vec::new();
    let mut poses = vec![[0.0f32; 4]; blocks];
    for _ in 0..40 {
        let jolts: Vec<[f32; 4]> = (0..walks)
            .map(|_| [uniform(), uniform(), uniform(), uniform()])
            .collect();
        for (b, pose) in poses.iter_mut().enumerate() {
            let step = jolts[b % walks];
            for a in 0..4 {
                pose[a] += 0.02 * step[a];
            }
        }
        frames.push(
            rest.iter()
                .enumerate()
                .map(|(i, p)| {
                    let pose = poses[i / 64];
                    let centre = (i / 64) as f32 * 0.5 + 0.15;
                    let (c, s) = (pose[3].cos(), pose[3].sin());
                    let (x, y) = (p[0] - centre, p[1] - 0.15);
                    [
                        centre + c * x - s * y + pose[0],
                        0.15 + s * x + c * y + pose[1],
                        p[2] + pose[2],
                    ]
                })
                .collect(),
        );
    }
    Blocks {
        rest,
        frames,
        partition,
    }
}

/// Bytes of the affine part of `blocks`' fitted track, checked to decode to the same track.
fn coded_size(blocks: Blocks) -> usize {
    let Blocks {
        rest,
        frames,
        partition,
    } = blocks;
    let track = AffineTrack::fit(&frames, &rest, &partition, 1e-4).unwrap();
    let bytes = encode_affine(&track).unwrap();
    let decoded = decode_affine(&bytes, frames.len(), &partition, &rest).unwrap();
    assert_eq!(decoded, track);
    bytes.len()
}

#[test]
fn clusters_jolted_alike_follow_each_other() {
    // Each block's maps are a random walk, which no extrapolation foretells; when every block
    // walks the same way, each but the first adds its neighbour's innovation instead.
    let size = |walks: usize| coded_size(jolted_blocks(walks));
    let (alike, apart) = (size(1), size(6));
    assert!(
        (alike as f64) < 0.5 * apart as f64,
        "alike {alike} bytes, apart {apart}"
    );
}

#[test]
fn a_cluster_follows_a_farther_one_that_moves_as_it_does() {
    // Every other block walks alike: each block's nearest earlier neighbour walks the other way,
    // the one before it the same way, which the block names as its reference (container version
    // 14; with the nearest alone, 772 bytes against six walks' 780, now 336 against 788).
    let size = |walks: usize| coded_size(jolted_blocks(walks));
    let (interleaved, apart) = (size(2), size(6));
    assert!(
        (interleaved as f64) < 0.6 * apart as f64,
        "two interleaved walks {interleaved} bytes, six {apart}"
    );
}

/// `blocks` blocks of 4 × 4 × 4 points in a row along x, swung as one rigid arm about the first
/// block's centre by a pseudo-random walk of turns about z: the farther a block, the farther its
/// centroid moves for the same turn.
fn swung_arm(blocks: usize) -> Blocks {
    use rand_xoshiro::rand_core::{RngCore, SeedableRng};
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(36);
    let (rest, partition) = row_of_blocks(blocks);
    let mut angle = 0.0f32;
    let frames = (0..40)
        .map(|_| {
            angle += 0.05 * ((rng.next_u32() >> 8) as f32 / (1u32 << 24) as f32 - 0.5);
            let (c, s) = (angle.cos(), angle.sin());
            rest.iter()
                .map(|p| {
                    let (x, y) = (p[0] - 0.15, p[1] - 0.15);
                    [0.15 + c * x - s * y, 0.15 + s * x + c * y, p[2]]
                })
                .collect()
        })
        .collect();
    Blocks {
        rest,
        frames,
        partition,
    }
}

#[test]
fn a_swung_arm_follows_its_neighbours_turn_at_its_own_centroid() {
    // Every block turns alike, so its linear part follows its neighbour's; its translation moves
    // by the turn times its own distance from the pivot, which the neighbour's whole map at this
    // block's centroid foretells, and its translation innovation does not.
    let size = |blocks: usize| coded_size(swung_arm(blocks));
    // Six blocks: 176 bytes, one: 60; following the translations' innovations alone, 328.
    let (one, six) = (size(1), size(6));
    assert!(six < 4 * one, "one block {one} bytes, six {six}");
}
