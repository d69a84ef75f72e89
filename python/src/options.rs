//! Keyword arguments → [`EncodeOptions`]: each keyword is the field (or the codec option) of the
//! same name, as the command line's flags are; the codec's own options go through
//! [`CodecConfig`]'s accessors, so an option the chosen codec has not is an `InvalidOptionError`
//! naming the codecs that have it.

use crate::errors::option;
use mcgv_video::codec::PictureOptions;
use mcgv_video::encoder::Segmentation;
use mcgv_video::{
    Codec, CodecConfig, EncodeOptions, Lattice, PaddingMethod, PredictorChoice, PredictorKind,
    SegmentationChoice,
};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};

/// The keyword arguments `encode` passes on to [`encode_options`].
pub const KEYWORDS: [&str; 20] = [
    "codec",
    "quality",
    "step",
    "affine_precision",
    "clusters",
    "segmentation",
    "e0",
    "predictor",
    "weight_bits",
    "first_frame_bits",
    "reorder",
    "uv_bits",
    "segment_frames",
    "qscale",
    "qp",
    "jpeg_quality",
    "gop",
    "bit_depth",
    "lattice",
    "padding",
];

/// The keyword arguments, read one by one; a keyword nobody read is an error at the end.
struct Keywords<'py> {
    dict: Option<Bound<'py, PyDict>>,
    function: &'static str,
}

impl<'py> Keywords<'py> {
    /// The value of keyword `name`, unless absent or `None`.
    fn get(&self, name: &str) -> PyResult<Option<Bound<'py, PyAny>>> {
        let Some(dict) = &self.dict else {
            return Ok(None);
        };
        Ok(dict.get_item(name)?.filter(|v| !v.is_none()))
    }

    /// Keyword `name` as a `T`, or a `TypeError` naming it and the type wanted.
    fn typed<T>(&self, name: &'static str, wanted: &str) -> PyResult<Option<T>>
    where
        T: for<'a> FromPyObject<'a, 'py>,
    {
        match self.get(name)? {
            None => Ok(None),
            Some(v) => v.extract::<T>().map(Some).map_err(|_| {
                let got = v
                    .get_type()
                    .name()
                    .map_or_else(|_| "?".into(), |n| n.to_string());
                PyTypeError::new_err(format!("{name}: expected {wanted}, got {got}"))
            }),
        }
    }

    /// Keyword `name` as an integer that fits a `T`, else an `InvalidOptionError`.
    fn int<T: TryFrom<i64>>(&self, name: &'static str) -> PyResult<Option<T>> {
        let Some(v) = self.typed::<i64>(name, "an int")? else {
            return Ok(None);
        };
        T::try_from(v)
            .map(Some)
            .map_err(|_| option(name, format!("{v} is out of range")))
    }

    fn float(&self, name: &'static str) -> PyResult<Option<f64>> {
        self.typed::<f64>(name, "a float")
    }

    fn string(&self, name: &'static str) -> PyResult<Option<String>> {
        self.typed::<String>(name, "a str")
    }

    /// Every keyword must be one of `known`.
    fn check_known(&self, known: &[&str]) -> PyResult<()> {
        let Some(dict) = &self.dict else {
            return Ok(());
        };
        for key in dict.keys() {
            let key = key.cast::<PyString>()?.to_string();
            if !known.contains(&key.as_str()) {
                return Err(PyTypeError::new_err(format!(
                    "{}() got an unexpected keyword argument '{key}'",
                    self.function
                )));
            }
        }
        Ok(())
    }
}

/// The encoder options of `kwargs` (every other field at its default, as the command line's),
/// `threads` coding that many segments at once as `--threads` does.
pub fn encode_options(
    function: &'static str,
    kwargs: Option<&Bound<'_, PyDict>>,
    threads: Option<usize>,
) -> PyResult<EncodeOptions> {
    let k = Keywords {
        dict: kwargs.cloned(),
        function,
    };
    k.check_known(&KEYWORDS)?;
    let defaults = EncodeOptions::default();
    let codec = match k.string("codec")? {
        None => Codec::default(),
        Some(name) => Codec::from_name(&name).ok_or_else(|| {
            let names: Vec<&str> = Codec::ALL.iter().map(|c| c.name()).collect();
            option(
                "codec",
                format!("{name}: unknown codec; one of {}", names.join(", ")),
            )
        })?,
    };
    let clusters = k.int::<usize>("clusters")?;
    let e0 = k.float("e0")?;
    let segmentation = segmentation_choice(&k, clusters, e0)?;
    let predictor = predictor_choice(&k)?;
    let segment_frames = match k.dict.as_ref().map(|d| d.get_item("segment_frames")) {
        None | Some(Ok(None)) => defaults.segment_frames,
        // None, as the command line's 0, never cuts the clip.
        Some(Ok(Some(v))) if v.is_none() => None,
        Some(Ok(Some(_))) => match k.int::<usize>("segment_frames")? {
            Some(0) => None,
            n => n,
        },
        Some(Err(e)) => return Err(e),
    };
    Ok(EncodeOptions {
        codec: codec_config(&k, codec)?,
        quality: k.int::<u8>("quality")?.unwrap_or(defaults.quality),
        step: k.float("step")?,
        affine_precision: k.float("affine_precision")?,
        clusters: clusters.unwrap_or(defaults.clusters),
        segmentation,
        predictor,
        weight_bits: k.int::<u8>("weight_bits")?.unwrap_or(defaults.weight_bits),
        first_frame_bits: k.int::<u8>("first_frame_bits")?,
        reorder: k.typed::<bool>("reorder", "a bool")?.unwrap_or(false),
        uv_bits: k.int::<u8>("uv_bits")?.unwrap_or(defaults.uv_bits),
        segment_frames,
        parallel_segments: threads.unwrap_or(defaults.parallel_segments),
        fine_quality: None,
    })
}

/// The segmentation of `k` (`auto` when not given), checked against the `clusters` and `e0`
/// given.
fn segmentation_choice(
    k: &Keywords<'_>,
    clusters: Option<usize>,
    e0: Option<f64>,
) -> PyResult<SegmentationChoice> {
    let choice = match k.string("segmentation")?.as_deref().unwrap_or("auto") {
        "auto" => SegmentationChoice::Auto {
            e0: e0.unwrap_or(mcgv_video::encoder::DEFAULT_E0),
        },
        "kmeans" => {
            if e0.is_some() {
                return Err(option(
                    "e0",
                    "applies to segmentation decimation (or auto) only",
                ));
            }
            SegmentationChoice::Fixed(Segmentation::KMeans)
        }
        "decimation" => {
            if clusters.is_some() {
                return Err(option(
                    "clusters",
                    "applies to segmentation kmeans (or auto) only: decimation finds K from e0",
                ));
            }
            SegmentationChoice::Fixed(Segmentation::Decimation {
                e0: e0.unwrap_or(mcgv_video::encoder::DEFAULT_E0),
            })
        }
        other => {
            return Err(option(
                "segmentation",
                format!("{other}: one of auto, kmeans, decimation"),
            ))
        }
    };
    Ok(choice)
}

/// The predictor of `k` (`auto` when not given).
fn predictor_choice(k: &Keywords<'_>) -> PyResult<PredictorChoice> {
    let choice = match k.string("predictor")?.as_deref().unwrap_or("auto") {
        "auto" => PredictorChoice::Auto,
        "affine" => PredictorChoice::Fixed(PredictorKind::Affine),
        "skinning" => PredictorChoice::Fixed(PredictorKind::Skinning),
        other => {
            return Err(option(
                "predictor",
                format!("{other}: one of auto, affine, skinning"),
            ))
        }
    };
    Ok(choice)
}

/// The codec's configuration with the codec options of `k` set.
fn codec_config(k: &Keywords<'_>, codec: Codec) -> PyResult<CodecConfig> {
    let mut config = CodecConfig::from(codec);
    for name in ["qscale", "qp", "jpeg_quality"] {
        let Some(value) = k.int::<u8>(name)? else {
            continue;
        };
        let has = |c: &mut CodecConfig| matches!(c.quantiser_mut(), Some((n, _)) if n == name);
        match config.quantiser_mut() {
            Some((n, q)) if n == name => *q = Some(value),
            _ => return Err(not_for(name, codec, has)),
        }
    }
    if let Some(gop) = k.int::<usize>("gop")? {
        match config.gop_mut() {
            Some(g) => *g = gop,
            None => return Err(not_for("gop", codec, |c| c.gop_mut().is_some())),
        }
    }
    let bit_depth = match k.get("bit_depth")? {
        Some(v) if v.extract::<String>().is_ok_and(|s| s == "auto") => None,
        Some(_) => k.int::<u8>("bit_depth")?,
        None => None,
    };
    if let Some(bits) = bit_depth {
        match config.bit_depth_mut() {
            Some(d) => *d = Some(bits),
            None => return Err(not_for("bit_depth", codec, |c| c.bit_depth_mut().is_some())),
        }
    }
    let lattice = lattice(k)?;
    let padding = match k.string("padding")? {
        Some(name) => Some(
            name.parse::<PaddingMethod>()
                .map_err(|e| option("padding", format!("{name}: {e}")))?,
        ),
        None => None,
    };
    let pictures = |c: &mut CodecConfig| c.pictures_mut().is_some();
    match config.pictures_mut() {
        Some(p) => *p = PictureOptions { lattice, padding },
        None if padding.is_some() => return Err(not_for("padding", codec, pictures)),
        None if lattice != Lattice::Auto => return Err(not_for("lattice", codec, pictures)),
        None => {}
    }
    Ok(config)
}

/// `lattice`: `"auto"`, `"WIDTHxHEIGHT"` or a `(width, height)` pair.
fn lattice(k: &Keywords<'_>) -> PyResult<Lattice> {
    let Some(value) = k.get("lattice")? else {
        return Ok(Lattice::Auto);
    };
    let bad = || {
        option(
            "lattice",
            "expected \"auto\", \"WIDTHxHEIGHT\" or a (width, height) pair, e.g. (256, 256)",
        )
    };
    if let Ok((w, h)) = value.extract::<(i64, i64)>() {
        return match (u16::try_from(w), u16::try_from(h)) {
            (Ok(w), Ok(h)) => Ok(Lattice::Fixed(w, h)),
            _ => Err(bad()),
        };
    }
    let text = value.extract::<String>().map_err(|_| bad())?;
    if text.trim().eq_ignore_ascii_case("auto") {
        return Ok(Lattice::Auto);
    }
    let (w, h) = text.split_once(['x', 'X']).ok_or_else(bad)?;
    Ok(Lattice::Fixed(
        w.trim().parse().map_err(|_| bad())?,
        h.trim().parse().map_err(|_| bad())?,
    ))
}

/// An option the codec has not, naming the codecs that have it.
fn not_for(name: &'static str, codec: Codec, has: impl Fn(&mut CodecConfig) -> bool) -> PyErr {
    let takers: Vec<&str> = Codec::ALL
        .into_iter()
        .filter(|c| has(&mut c.default_config()))
        .map(Codec::name)
        .collect();
    option(
        name,
        format!(
            "applies to the {} codec only, not {}",
            takers.join(" and "),
            codec.name()
        ),
    )
}
