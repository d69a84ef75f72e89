//! A small picture of a partition (like the paper's Figure 3): frame 0 seen from the front,
//! orthographic, z-buffered, flat-shaded, one colour per cluster.
//!
//! Hand-written because it is a few dozen lines; a rendering crate would be far heavier than the job.

use image::{Rgb, RgbImage};
use mcgv_video::mesh::{bounding_box, Point, Triangle};
use mcgv_video::{Error, Result};
use std::path::Path;

const BACKGROUND: Rgb<u8> = Rgb([255, 255, 255]);

/// Writes a `size`×`size` PNG of the mesh seen along −z (x right, y up), each triangle coloured by
/// the cluster of its first vertex and shaded by how much it faces the viewer.
pub fn render_partition_png(
    positions: &[Point],
    triangles: &[Triangle],
    labels: &[u32],
    size: u32,
    path: &Path,
) -> Result<()> {
    if size == 0 {
        return Err(Error::Usage("picture size must be at least 1 pixel".into()));
    }
    if labels.len() != positions.len() {
        return Err(Error::Usage(format!(
            "{} labels for {} vertices",
            labels.len(),
            positions.len()
        )));
    }
    let image = render(positions, triangles, labels, size)?;
    let clusters = labels.iter().max().map_or(0, |&k| k + 1);
    let note = "frame 0 along -z (x right, y up); colour = motion cluster";
    crate::annotate::with_legend(&image, clusters, note)
        .save(path)
        .map_err(|e| Error::io(path, std::io::Error::other(e)))
}

fn render(
    positions: &[Point],
    triangles: &[Triangle],
    labels: &[u32],
    size: u32,
) -> Result<RgbImage> {
    let mut image = RgbImage::from_pixel(size, size, BACKGROUND);
    let mut depth = vec![f32::NEG_INFINITY; (size as usize) * (size as usize)];
    let (lo, hi) = bounding_box(positions);
    let extent = (hi[0] - lo[0]).max(hi[1] - lo[1]);
    let margin = 0.05 * size as f32;
    let scale = if extent > 0.0 {
        (size as f32 - 2.0 * margin) / extent
    } else {
        1.0
    };
    // Centre the drawing; image rows grow downwards, y grows upwards.
    let offset = [
        (size as f32 - (hi[0] - lo[0]) * scale) / 2.0,
        (size as f32 - (hi[1] - lo[1]) * scale) / 2.0,
    ];
    let to_screen = |p: &Point| {
        [
            (p[0] - lo[0]) * scale + offset[0],
            size as f32 - ((p[1] - lo[1]) * scale + offset[1]),
            p[2],
        ]
    };
    for (t, tri) in triangles.iter().enumerate() {
        let corner = |i: usize| {
            positions.get(tri[i] as usize).ok_or_else(|| {
                Error::Mesh(format!(
                    "face {t} refers to vertex {}, but there are {} vertices",
                    tri[i],
                    positions.len()
                ))
            })
        };
        let (a, b, c) = (corner(0)?, corner(1)?, corner(2)?);
        let colour = shade(cluster_colour(labels[tri[0] as usize]), facing(a, b, c));
        let s = [to_screen(a), to_screen(b), to_screen(c)];
        fill_triangle(&mut image, &mut depth, s, colour);
    }
    Ok(image)
}

/// |cos| of the angle between the triangle's normal and the view direction (0 when degenerate).
fn facing(a: &Point, b: &Point, c: &Point) -> f32 {
    let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    let n = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if len > 0.0 {
        (n[2] / len).abs()
    } else {
        0.0
    }
}

/// The cluster's colour, shared with the atlas picture and the legends.
fn cluster_colour(label: u32) -> [f32; 3] {
    crate::annotate::cluster_colour(label).map(|c| c as f32 / 255.0)
}

fn shade(colour: [f32; 3], facing: f32) -> Rgb<u8> {
    let light = 0.35 + 0.65 * facing;
    Rgb(colour.map(|c| (c * light * 255.0).round().clamp(0.0, 255.0) as u8))
}

/// Fills the pixels whose centres fall inside the screen-space triangle and are nearer (larger z)
/// than what is drawn.
fn fill_triangle(image: &mut RgbImage, depth: &mut [f32], s: [[f32; 3]; 3], colour: Rgb<u8>) {
    let edge = |a: [f32; 3], b: [f32; 3], x: f32, y: f32| {
        (b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0])
    };
    let area = edge(s[0], s[1], s[2][0], s[2][1]);
    if area == 0.0 || !area.is_finite() {
        return;
    }
    let (w, h) = (image.width(), image.height());
    let min_x = s
        .iter()
        .map(|p| p[0])
        .fold(f32::INFINITY, f32::min)
        .floor()
        .max(0.0) as u32;
    let max_x = s
        .iter()
        .map(|p| p[0])
        .fold(f32::NEG_INFINITY, f32::max)
        .ceil()
        .min(w as f32 - 1.0);
    let min_y = s
        .iter()
        .map(|p| p[1])
        .fold(f32::INFINITY, f32::min)
        .floor()
        .max(0.0) as u32;
    let max_y = s
        .iter()
        .map(|p| p[1])
        .fold(f32::NEG_INFINITY, f32::max)
        .ceil()
        .min(h as f32 - 1.0);
    if max_x < 0.0 || max_y < 0.0 {
        return;
    }
    for y in min_y..=max_y as u32 {
        for x in min_x..=max_x as u32 {
            let (px, py) = (x as f32 + 0.5, y as f32 + 0.5);
            let w0 = edge(s[1], s[2], px, py) / area;
            let w1 = edge(s[2], s[0], px, py) / area;
            let w2 = 1.0 - w0 - w1;
            if w0 < 0.0 || w1 < 0.0 || w2 < 0.0 {
                continue;
            }
            let z = w0 * s[0][2] + w1 * s[1][2] + w2 * s[2][2];
            let i = (y * w + x) as usize;
            if z > depth[i] {
                depth[i] = z;
                image.put_pixel(x, y, colour);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearer_triangle_wins() {
        let positions = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 1.0],
            [0.0, 1.0, 1.0],
        ];
        let image = render(&positions, &[[0, 1, 2], [3, 4, 5]], &[0, 0, 0, 1, 1, 1], 32).unwrap();
        let front = shade(cluster_colour(1), 1.0);
        assert_eq!(*image.get_pixel(8, 24), front);
        assert_eq!(*image.get_pixel(31, 0), BACKGROUND);
    }

    #[test]
    fn every_cluster_gets_its_colour_and_bad_labels_are_errors() {
        // A 4×4 grid of squares tilted towards the viewer, left half cluster 0, right half 1.
        let positions: Vec<Point> = (0..25)
            .map(|i| [(i % 5) as f32, (i / 5) as f32, 0.3 * (i / 5) as f32])
            .collect();
        let mut triangles = Vec::new();
        for y in 0..4u32 {
            for x in 0..4u32 {
                let a = y * 5 + x;
                triangles.push([a, a + 1, a + 6]);
                triangles.push([a, a + 6, a + 5]);
            }
        }
        let labels: Vec<u32> = (0..25).map(|i| u32::from(i % 5 >= 2)).collect();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("partition.png");
        render_partition_png(&positions, &triangles, &labels, 64, &path).unwrap();
        let image = image::open(&path).unwrap().to_rgb8();
        // The 64×64 drawing, and the legend below it.
        assert!(
            image.width() >= 64 && image.height() > 64,
            "{:?}",
            image.dimensions()
        );
        let mut colours: Vec<[u8; 3]> = image.pixels().map(|p| p.0).collect();
        colours.sort();
        colours.dedup();
        // Background plus two hues.
        assert!(colours.len() >= 3, "{} colours", colours.len());
        assert!(render_partition_png(&positions, &triangles, &labels[1..], 64, &path).is_err());
    }
}
