//! The three coordinate images of a frame side by side in one picture (x | y | z), so each frame is one
//! JPEG picture or one MPEG-4 frame: one set of headers per frame instead of three, and one video stream.

use super::plane::Plane;

/// Rounds and clamps three `width × height` images (levels of `depth`-bit samples) into one
/// `3·width × height` plane.
pub fn compose(images: [&[f32]; 3], width: usize, height: usize, depth: u8) -> Plane<u16> {
    let top = super::quantise::max_level(depth);
    let mut data = vec![0u16; 3 * width * height];
    for (a, img) in images.iter().enumerate() {
        for y in 0..height {
            let row = &img[y * width..(y + 1) * width];
            let out = &mut data[y * 3 * width + a * width..y * 3 * width + (a + 1) * width];
            for (o, &v) in out.iter_mut().zip(row) {
                *o = v.round().clamp(0.0, top) as u16;
            }
        }
    }
    Plane {
        width: (3 * width) as u32,
        height: height as u32,
        data,
    }
}

/// The levels at the given lattice pixels of coordinate `axis` of a composed plane.
pub fn sample(plane: &Plane<u16>, axis: usize, width: usize, pixels: &[[u16; 2]]) -> Vec<f32> {
    let stride = plane.width as usize;
    pixels
        .iter()
        .map(|&[u, v]| plane.data[v as usize * stride + axis * width + u as usize] as f32)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One coordinate's image (`axis` 0, 1, 2) cut back out of a composed plane, as `f32` levels.
    pub fn axis_image(plane: &Plane<u16>, axis: usize, width: usize, height: usize) -> Vec<f32> {
        let stride = plane.width as usize;
        let mut out = Vec::with_capacity(width * height);
        for y in 0..height {
            let start = y * stride + axis * width;
            out.extend(plane.data[start..start + width].iter().map(|&v| v as f32));
        }
        out
    }

    #[test]
    fn compose_then_cut_and_sample() {
        let (w, h) = (8, 4);
        let imgs: Vec<Vec<f32>> = (0..3)
            .map(|a| (0..w * h).map(|i| (i * 3 + a * 50) as f32 + 0.4).collect())
            .collect();
        let plane = compose([&imgs[0], &imgs[1], &imgs[2]], w, h, 8);
        assert_eq!((plane.width, plane.height), (24, 4));
        for (a, img) in imgs.iter().enumerate() {
            let cut = axis_image(&plane, a, w, h);
            let want: Vec<f32> = img.iter().map(|v| v.round().min(255.0)).collect();
            assert_eq!(cut, want);
            let s = sample(&plane, a, w, &[[3, 2], [7, 3]]);
            assert_eq!(s, vec![want[2 * w + 3], want[3 * w + 7]]);
        }
    }
}
