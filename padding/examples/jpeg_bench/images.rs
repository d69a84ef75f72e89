//! Bench inputs: 8-bit grey images with a fixed-pixel mask, grouped into sequences.

use std::path::Path;

/// One geometry image to pad: values on the codec's 0–255 scale, exact at fixed pixels.
pub struct Sample {
    pub width: usize,
    pub height: usize,
    /// Rounded 8-bit values at fixed pixels (the reference the error is measured against); 0 elsewhere.
    pub grey: Vec<f32>,
    pub fixed: Vec<bool>,
}

/// A named set of samples, `per_frame` consecutive samples making one frame (x, y, z images).
pub struct Sequence {
    pub name: String,
    pub samples: Vec<Sample>,
    pub per_frame: usize,
}

impl Sequence {
    pub fn frames(&self) -> f64 {
        self.samples.len() as f64 / self.per_frame as f64
    }

    pub fn fixed_fraction(&self) -> f64 {
        let fixed: usize = self
            .samples
            .iter()
            .map(|s| s.fixed.iter().filter(|&&f| f).count())
            .sum();
        let total: usize = self.samples.iter().map(|s| s.fixed.len()).sum();
        fixed as f64 / total.max(1) as f64
    }
}

impl Sample {
    /// Maps the fixed pixels' values linearly onto 0–255 (their min to 0, max to 255) and rounds,
    /// as an encoder quantising residuals to 8 bits per image does.
    pub fn quantised(width: usize, height: usize, raw: &[f64], fixed: Vec<bool>) -> Sample {
        let (lo, hi) = raw
            .iter()
            .zip(&fixed)
            .filter(|(_, &f)| f)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), (&v, _)| {
                (lo.min(v), hi.max(v))
            });
        let span = if hi > lo { hi - lo } else { 1.0 };
        let grey = raw
            .iter()
            .zip(&fixed)
            .map(|(&v, &f)| {
                if f {
                    ((v - lo) / span * 255.0).round() as f32
                } else {
                    0.0
                }
            })
            .collect();
        Sample {
            width,
            height,
            grey,
            fixed,
        }
    }
}

/// Reads every `NAME.png` (16-bit or 8-bit grey) in `dir` that has a `NAME_mask.png` beside it
/// (nonzero = fixed pixel), in name order, as one sequence of `per_frame` images per frame.
pub fn read_folder(dir: &Path, per_frame: usize) -> Result<Sequence, String> {
    let mut names: Vec<_> = std::fs::read_dir(dir)
        .map_err(|e| format!("{}: {e}", dir.display()))?
        .filter_map(|entry| entry.ok().map(|e| e.path()))
        .filter(|p| {
            p.extension().is_some_and(|e| e == "png")
                && !p
                    .file_stem()
                    .is_some_and(|s| s.to_string_lossy().ends_with("_mask"))
        })
        .collect();
    names.sort();
    let mut samples = Vec::new();
    for path in names {
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let mask_path = path.with_file_name(format!("{stem}_mask.png"));
        if !mask_path.exists() {
            continue;
        }
        let image = image::open(&path)
            .map_err(|e| format!("{}: {e}", path.display()))?
            .to_luma16();
        let mask = image::open(&mask_path)
            .map_err(|e| format!("{}: {e}", mask_path.display()))?
            .to_luma8();
        if image.dimensions() != mask.dimensions() {
            return Err(format!(
                "{}: mask size differs from the image",
                mask_path.display()
            ));
        }
        let (w, h) = (image.width() as usize, image.height() as usize);
        let raw: Vec<f64> = image.pixels().map(|p| f64::from(p.0[0])).collect();
        let fixed: Vec<bool> = mask.pixels().map(|p| p.0[0] != 0).collect();
        samples.push(Sample::quantised(w, h, &raw, fixed));
    }
    if samples.is_empty() {
        return Err(format!("{}: no NAME.png with NAME_mask.png", dir.display()));
    }
    let name = dir
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    Ok(Sequence {
        name,
        samples,
        per_frame,
    })
}

/// Writes a sequence as `NNNN_C.png` (16-bit, fixed pixels only) and `NNNN_C_mask.png`, readable by
/// [`read_folder`], so a folder run can be checked against the synthetic run it came from.
pub fn write_folder(sequence: &Sequence, dir: &Path) -> Result<(), String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    for (k, s) in sequence.samples.iter().enumerate() {
        let stem = format!("{:04}_{}", k / sequence.per_frame, k % sequence.per_frame);
        let (w, h) = (s.width as u32, s.height as u32);
        let values: Vec<u16> = s.grey.iter().map(|&v| (v * 257.0) as u16).collect();
        let mask: Vec<u8> = s.fixed.iter().map(|&f| if f { 255 } else { 0 }).collect();
        let image = image::ImageBuffer::<image::Luma<u16>, _>::from_raw(w, h, values)
            .ok_or("image buffer size")?;
        let mask = image::GrayImage::from_raw(w, h, mask).ok_or("mask buffer size")?;
        image
            .save(dir.join(format!("{stem}.png")))
            .map_err(|e| e.to_string())?;
        mask.save(dir.join(format!("{stem}_mask.png")))
            .map_err(|e| e.to_string())?;
    }
    Ok(())
}
