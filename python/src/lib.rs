//! `mcgv_video._native`: the Python module, a thin layer over the `mcgv-video` library's public
//! API. Arrays cross as NumPy arrays (no Python object per vertex), errors as the exceptions of
//! `mcgv_video.errors`, and the interpreter's lock is released while the library codes, so that
//! other Python threads run meanwhile. The Python-facing documentation is in the docstrings
//! below and in `mcgv_video/__init__.pyi`.

mod arrays;
mod budget;
mod decoder;
mod errors;
mod options;
mod progress;
mod segments;

use errors::IntoPy;
use mcgv_video::mesh::{AnimatedMesh, Attributes, ReadOptions};
use mcgv_video::metrics::{FrameSampling, DEFAULT_RELATIVE_ERROR};
use numpy::{PyArray2, PyArray3};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyTuple};

/// An animated triangle mesh: one connectivity and a position per vertex and frame, with its
/// texture coordinates and frame rate when it has them.
///
/// Made by ``read_animation`` (which keeps everything the file had, materials included, so that
/// ``encode(animation)`` writes the stream the command line writes), ``Decoder.animation()``, or
/// from arrays: ``Animation(positions, faces, fps=None, uvs=None)``.
#[pyclass(module = "mcgv_video", frozen)]
pub struct Animation {
    pub(crate) mesh: AnimatedMesh,
}

#[pymethods]
impl Animation {
    #[new]
    #[pyo3(signature = (positions, faces, *, fps=None, uvs=None))]
    fn new(
        positions: &Bound<'_, PyAny>,
        faces: &Bound<'_, PyAny>,
        fps: Option<f64>,
        uvs: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        Ok(Self {
            mesh: mesh_from_arrays(positions, faces, fps, uvs)?,
        })
    }

    /// Positions, a new ``float32`` array of shape ``(frames, vertices, 3)``.
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray3<f32>>> {
        let flat = py.detach(|| arrays::flatten(self.mesh.frames()));
        arrays::frames_array(py, flat, self.mesh.vertex_count())
    }

    /// Triangles, a ``uint32`` array of shape ``(triangles, 3)`` of vertex indices.
    #[getter]
    fn faces<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<u32>>> {
        arrays::faces_array(py, self.mesh.triangles())
    }

    /// Texture coordinates of the first set, ``float32`` of shape ``(vertices, 2)``, or ``None``.
    #[getter]
    fn uvs<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyArray2<f32>>>> {
        self.mesh
            .attributes()
            .texcoords
            .first()
            .map(|set| arrays::uvs_array(py, set))
            .transpose()
    }

    /// Frames per second, or ``None`` when the source did not say.
    #[getter]
    fn fps(&self) -> Option<f64> {
        self.mesh.frame_rate()
    }

    /// Number of frames.
    #[getter]
    fn frame_count(&self) -> usize {
        self.mesh.frame_count()
    }

    /// Number of vertices.
    #[getter]
    fn vertex_count(&self) -> usize {
        self.mesh.vertex_count()
    }

    /// Material name of each triangle group (empty when the source has none).
    #[getter]
    fn material_names(&self) -> Vec<String> {
        self.mesh.attributes().material_names.clone()
    }

    /// Frames ``start`` to ``end - 1`` as an animation of their own.
    fn clip(&self, start: usize, end: usize) -> PyResult<Self> {
        if start >= end || end > self.mesh.frame_count() {
            return Err(PyValueError::new_err(format!(
                "clip({start}, {end}): the animation has frames 0..{}",
                self.mesh.frame_count()
            )));
        }
        Ok(Self {
            mesh: self.mesh.clip(start..end).py_err()?,
        })
    }

    fn __len__(&self) -> usize {
        self.mesh.frame_count()
    }

    /// Pickling (for multiprocessing, Dask, Ray): every part, attributes included.
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let this = slf.get();
        let attributes = this.mesh.attributes();
        let texcoords = attributes
            .texcoords
            .iter()
            .map(|set| arrays::uvs_array(py, set))
            .collect::<PyResult<Vec<_>>>()?;
        let state = (
            this.positions(py)?,
            this.faces(py)?,
            this.mesh.frame_rate(),
            texcoords,
            attributes.materials.clone(),
            attributes.material_names.clone(),
        )
            .into_pyobject(py)?;
        let rebuild = slf.get_type().getattr("_from_parts")?;
        Ok((rebuild, state))
    }

    /// The inverse of `__reduce__`.
    #[staticmethod]
    #[pyo3(name = "_from_parts")]
    fn from_parts(
        positions: &Bound<'_, PyAny>,
        faces: &Bound<'_, PyAny>,
        fps: Option<f64>,
        texcoords: Vec<Bound<'_, PyAny>>,
        materials: Vec<u32>,
        material_names: Vec<String>,
    ) -> PyResult<Self> {
        let mesh = mesh_from_arrays(positions, faces, fps, None)?;
        let vertices = mesh.vertex_count();
        let attributes = Attributes {
            texcoords: texcoords
                .iter()
                .map(|set| arrays::uvs("texcoords", set, vertices))
                .collect::<PyResult<_>>()?,
            materials,
            material_names,
        };
        Ok(Self {
            mesh: mesh.with_attributes(attributes).py_err()?,
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "Animation({} frames, {} vertices, {} triangles, fps={})",
            self.mesh.frame_count(),
            self.mesh.vertex_count(),
            self.mesh.triangles().len(),
            self.mesh
                .frame_rate()
                .map_or_else(|| "None".into(), |f| f.to_string())
        )
    }
}

/// An animation from NumPy arrays, each checked by its argument's name.
fn mesh_from_arrays(
    positions: &Bound<'_, PyAny>,
    faces: &Bound<'_, PyAny>,
    fps: Option<f64>,
    uvs: Option<&Bound<'_, PyAny>>,
) -> PyResult<AnimatedMesh> {
    let frames = arrays::positions("positions", positions)?;
    let vertices = frames[0].len();
    let triangles = arrays::faces("faces", faces, vertices)?;
    if let Some(f) = fps {
        if !(f.is_finite() && f > 0.0) {
            return Err(PyValueError::new_err(format!(
                "fps: {f}: the frame rate must be a positive number"
            )));
        }
    }
    let mut mesh = AnimatedMesh::new(triangles, frames)
        .py_err()?
        .with_frame_rate(fps);
    if let Some(uvs) = uvs {
        let attributes = Attributes {
            texcoords: vec![arrays::uvs("uvs", uvs, vertices)?],
            ..Attributes::default()
        };
        mesh = mesh.with_attributes(attributes).py_err()?;
    }
    Ok(mesh)
}

/// The animation `encode` and `eval` are given: an ``Animation``, or arrays with their faces.
pub(crate) fn mesh_argument(
    name: &str,
    value: &Bound<'_, PyAny>,
    faces: Option<&Bound<'_, PyAny>>,
    fps: Option<f64>,
    uvs: Option<&Bound<'_, PyAny>>,
) -> PyResult<AnimatedMesh> {
    if let Ok(animation) = value.cast::<Animation>() {
        if faces.is_some() || uvs.is_some() {
            return Err(PyTypeError::new_err(format!(
                "{name} is an Animation, which has its faces and uvs: pass neither"
            )));
        }
        let mesh = animation.get().mesh.clone();
        return Ok(match fps {
            Some(_) => mesh.with_frame_rate(fps),
            None => mesh,
        });
    }
    let faces = faces.ok_or_else(|| {
        PyTypeError::new_err(format!(
            "faces: required when {name} is an array (an integer array of shape (triangles, 3))"
        ))
    })?;
    mesh_from_arrays(value, faces, fps, uvs)
}

/// Runs `work` on a pool of `threads` threads, or on the library's shared pool (as many threads
/// as cores) when `None`.
pub(crate) fn on_threads<T: Send>(
    threads: Option<usize>,
    work: impl FnOnce() -> mcgv_video::Result<T> + Send,
) -> PyResult<mcgv_video::Result<T>> {
    match threads {
        None => Ok(work()),
        Some(0) => Err(errors::option("threads", "0: at least one thread")),
        Some(n) => {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .map_err(|e| errors::option("threads", e.to_string()))?;
            Ok(pool.install(work))
        }
    }
}

/// encode(positions, faces=None, *, codec="tdct", quality=50, fps=None, uvs=None, progress=None, threads=None, **options)
/// --
///
/// Encodes an animation into the bytes of a ``.mcgv`` stream.
///
/// ``positions`` is a ``float32`` array of shape ``(frames, vertices, 3)`` with ``faces`` an
/// integer array of shape ``(triangles, 3)``, or an ``Animation`` (then no ``faces``). ``fps``
/// and ``uvs`` (``float32``, ``(vertices, 2)``) travel in the stream. ``progress(done, total)``
/// is called with frames as the encoder goes; ``threads`` sets how many threads code (default:
/// one per core) and segments coded at once, as the command line's ``--threads``.
///
/// ``options`` are the command line's ``encode`` flags by their field names: ``codec``
/// (``"tdct"``, ``"jpeg"``, ``"mpeg4"``, ``"hevc"``, ``"av1"``), ``quality`` (1..100), ``step``,
/// ``clusters``, ``segmentation`` (``"auto"``, ``"kmeans"``, ``"decimation"``), ``e0``,
/// ``predictor`` (``"auto"``, ``"affine"``, ``"skinning"``), ``weight_bits``,
/// ``affine_precision``, ``first_frame_bits``, ``reorder``, ``uv_bits``, ``segment_frames``
/// (default 128; ``None`` or 0: one segment), and the codecs' own: ``qscale`` (mpeg4), ``qp``
/// (hevc, av1), ``jpeg_quality`` (jpeg), ``gop``, ``bit_depth`` (hevc, av1), ``lattice``
/// (``"auto"``, ``"WxH"`` or ``(w, h)``) and ``padding`` (picture codecs). The same options give
/// the same bytes as ``mcgv-video encode``. The interpreter's lock is released while coding.
#[pyfunction]
#[pyo3(signature = (positions, faces=None, *, fps=None, uvs=None, progress=None, threads=None, **options))]
#[allow(clippy::too_many_arguments)]
fn encode<'py>(
    py: Python<'py>,
    positions: &Bound<'py, PyAny>,
    faces: Option<&Bound<'py, PyAny>>,
    fps: Option<f64>,
    uvs: Option<&Bound<'py, PyAny>>,
    progress: Option<Bound<'py, PyAny>>,
    threads: Option<usize>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyBytes>> {
    let mesh = mesh_argument("positions", positions, faces, fps, uvs)?;
    let opts = options::encode_options("encode", options, threads)?;
    let callback = progress::Callback::new(progress)?;
    let coded = py.detach(|| {
        on_threads(threads, || {
            mcgv_video::encode_with_progress(&mesh, &opts, &callback).map(|e| e.to_bytes())
        })
    })?;
    let bytes = callback.finish(coded)?.py_err()?;
    Ok(PyBytes::new(py, &bytes))
}

/// read_animation(path, clip=None, *, fps=None, base=None, max_positions=None)
/// --
///
/// Reads an animation: a folder or glob of ``.obj`` files, a ``.pc2`` point cache (with its base
/// ``.obj``, ``base`` or the one beside it), or a ``.gltf``/``.glb`` clip (``clip`` by name or
/// index, baked at ``fps``, default the clip's keyframe rate). Returns an ``Animation``.
#[pyfunction]
#[pyo3(signature = (path, clip=None, *, fps=None, base=None, max_positions=None))]
fn read_animation(
    py: Python<'_>,
    path: std::path::PathBuf,
    clip: Option<&Bound<'_, PyAny>>,
    fps: Option<f64>,
    base: Option<std::path::PathBuf>,
    max_positions: Option<u64>,
) -> PyResult<Animation> {
    let options = read_options(clip, fps, base, max_positions)?;
    let input = path.display().to_string();
    let mesh = py
        .detach(|| mcgv_video::read_animation(&input, &options))
        .py_err()?;
    Ok(Animation { mesh })
}

/// The reading options of the keyword arguments (`clip` a name or an index).
pub(crate) fn read_options(
    clip: Option<&Bound<'_, PyAny>>,
    fps: Option<f64>,
    base: Option<std::path::PathBuf>,
    max_positions: Option<u64>,
) -> PyResult<ReadOptions> {
    let clip = match clip {
        None => None,
        Some(c) if c.is_none() => None,
        Some(c) => Some(match c.extract::<usize>() {
            Ok(index) => index.to_string(),
            Err(_) => c.extract::<String>().map_err(|_| {
                PyTypeError::new_err("clip: expected a clip name (str) or index (int)")
            })?,
        }),
    };
    let defaults = ReadOptions::default();
    Ok(ReadOptions {
        fps,
        clip,
        base,
        max_positions: max_positions.unwrap_or(defaults.max_positions),
    })
}

/// eval(original, decoded, *, faces=None, every_frame=False)
/// --
///
/// The error measures of ``decoded`` against ``original`` as a dict: ``rmse``, ``vertex_rmse``,
/// ``kg_error``, ``hausdorff`` (fractions of the original's bounding-box diagonal, KG in percent),
/// ``bpvf`` (when ``decoded`` is a stream), ``frames``, ``vertices`` and ``frame_rmse`` (a
/// ``float64`` array, one per frame), as ``mcgv-video eval`` computes them: the surface RMSE from
/// a sample of the frames measured in full until its standard error is 0.2 % of it (runs of 32
/// frames or more; the others bounded), or from every frame with ``every_frame=True``
/// (``eval --every-frame``). The vertex measures and the Hausdorff distance are exact either way.
///
/// ``original`` is an ``Animation`` or a ``float32`` array ``(frames, vertices, 3)`` with
/// ``faces``; ``decoded`` is an ``Animation``, an array of the original's shape (same faces), or
/// the ``bytes`` of a ``.mcgv`` stream (decoded, put back in the input's vertex order).
#[pyfunction]
#[pyo3(signature = (original, decoded, *, faces=None, every_frame=false))]
fn eval<'py>(
    py: Python<'py>,
    original: &Bound<'py, PyAny>,
    decoded: &Bound<'py, PyAny>,
    faces: Option<&Bound<'py, PyAny>>,
    every_frame: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let original = mesh_argument("original", original, faces, None, None)?;
    let sampling = match every_frame {
        true => FrameSampling::Every,
        false => FrameSampling::Converged {
            relative_error: DEFAULT_RELATIVE_ERROR,
        },
    };
    let measures = if let Ok(bytes) = decoded.cast::<PyBytes>() {
        let bytes = bytes.as_bytes().to_vec();
        py.detach(|| decoder::compare_stream(&original, bytes, sampling))
    } else {
        let decoded = match decoded.cast::<Animation>() {
            Ok(animation) => animation.get().mesh.clone(),
            Err(_) => {
                let faces = arrays::faces_array(py, original.triangles())?;
                mesh_from_arrays(decoded, faces.as_any(), None, None).map_err(|e| {
                    let message = e.to_string().replacen("positions:", "decoded:", 1);
                    match e.is_instance_of::<PyTypeError>(py) {
                        true => PyTypeError::new_err(message),
                        false => PyValueError::new_err(message),
                    }
                })?
            }
        };
        py.detach(|| mcgv_video::metrics::compare_sampled(&original, &decoded, sampling))
    }
    .py_err()?;
    let dict = PyDict::new(py);
    dict.set_item("rmse", measures.rmse)?;
    dict.set_item("vertex_rmse", measures.vertex_rmse)?;
    dict.set_item("kg_error", measures.kg_error)?;
    dict.set_item("hausdorff", measures.hausdorff)?;
    dict.set_item("bpvf", measures.bpvf)?;
    dict.set_item("frames", measures.frames)?;
    dict.set_item("vertices", measures.vertices)?;
    dict.set_item(
        "frame_rmse",
        numpy::PyArray1::from_vec(py, measures.frame_rmse),
    )?;
    Ok(dict)
}

/// The compiled half of the `mcgv_video` package.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Animation>()?;
    m.add_class::<decoder::Decoder>()?;
    m.add_class::<segments::SegmentedEncoder>()?;
    m.add_class::<segments::FrameSource>()?;
    m.add_function(wrap_pyfunction!(encode, m)?)?;
    m.add_function(wrap_pyfunction!(budget::encode_to_budget, m)?)?;
    m.add_function(wrap_pyfunction!(read_animation, m)?)?;
    m.add_function(wrap_pyfunction!(eval, m)?)?;
    m.add_function(wrap_pyfunction!(segments::analysis_frames, m)?)?;
    m.add_function(wrap_pyfunction!(segments::segment_ranges, m)?)?;
    m.add_function(wrap_pyfunction!(codecs, m)?)?;
    Ok(())
}

/// codecs()
/// --
///
/// The codecs this build can code, by name, the default first.
#[pyfunction]
fn codecs() -> Vec<&'static str> {
    let mut all: Vec<mcgv_video::Codec> = mcgv_video::Codec::ALL
        .into_iter()
        .filter(|c| c.available())
        .collect();
    all.sort_by_key(|&c| c != mcgv_video::Codec::default());
    all.into_iter().map(|c| c.name()).collect()
}
