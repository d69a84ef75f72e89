//! `Decoder`: a stream opened from bytes; frames come out as NumPy arrays.

use crate::arrays;
use crate::errors::IntoPy;
use crate::Animation;
use mcgv_video::mesh::AnimatedMesh;
use mcgv_video::metrics::{compare_sampled, FrameSampling, Measures};
use mcgv_video::{DecodeOptions, Silent};
use numpy::{PyArray2, PyArray3};
use pyo3::exceptions::PyIndexError;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyList};
use std::io::Cursor;
use std::sync::Mutex;

type Inner = mcgv_video::Decoder<Cursor<Vec<u8>>>;

/// Decoder(stream, *, max_bands=None, max_positions=None)
/// --
///
/// A ``.mcgv`` stream opened from its bytes (``bytes``, ``bytearray`` or ``memoryview``; the
/// decoder keeps a copy). Opening reads and checks every part but the coded residuals: a damaged
/// stream raises ``StreamError`` here or when the frames it damaged are decoded.
///
/// ``frame(i)``, ``frames(a, b)`` and ``all()`` return ``float32`` arrays of shape
/// ``(vertices, 3)`` or ``(frames, vertices, 3)``, in the stream's vertex order (the input's
/// unless it was encoded with ``reorder=True``). ``max_bands`` (tdct) decodes a progressive
/// preview; ``max_positions`` refuses streams promising more vertices × frames (default 10⁹).
/// The interpreter's lock is released while decoding.
#[pyclass(module = "mcgv_video", frozen)]
pub struct Decoder {
    inner: Mutex<Inner>,
    header: Py<PyDict>,
    frames: usize,
    vertices: usize,
}

impl Decoder {
    /// Runs `work` on the decoder without the interpreter's lock.
    fn with<T: Send>(
        &self,
        py: Python<'_>,
        work: impl FnOnce(&mut Inner) -> mcgv_video::Result<T> + Send,
    ) -> PyResult<T> {
        py.detach(|| {
            let mut inner = self.inner.lock().map_err(|_| {
                mcgv_video::Error::Usage("the decoder failed in another thread".into())
            })?;
            work(&mut inner)
        })
        .py_err()
    }

    /// `f` as a frame index (negative counts from the end), or an `IndexError`.
    fn index(&self, f: isize) -> PyResult<usize> {
        let i = if f < 0 { f + self.frames as isize } else { f };
        usize::try_from(i)
            .ok()
            .filter(|&i| i < self.frames)
            .ok_or_else(|| {
                PyIndexError::new_err(format!(
                    "frame {f}: the stream has frames 0..{}",
                    self.frames
                ))
            })
    }
}

#[pymethods]
impl Decoder {
    #[new]
    #[pyo3(signature = (stream, *, max_bands=None, max_positions=None))]
    fn new(
        py: Python<'_>,
        stream: &Bound<'_, PyAny>,
        max_bands: Option<usize>,
        max_positions: Option<u64>,
    ) -> PyResult<Self> {
        // bytes, bytearray, memoryview or any other buffer; not what bytes() also takes (an int
        // would make that many zero bytes, an iterable of ints their bytes).
        let bytes: Vec<u8> = match stream.cast::<PyBytes>() {
            Ok(b) => b.as_bytes().to_vec(),
            Err(_) => {
                let builtins = py.import("builtins")?;
                let view = builtins
                    .getattr("memoryview")?
                    .call1((stream,))
                    .map_err(|_| {
                        pyo3::exceptions::PyTypeError::new_err(
                            "stream: expected the bytes of a .mcgv stream (bytes, bytearray or \
                         memoryview)",
                        )
                    })?;
                let copy = builtins.getattr("bytes")?.call1((view,))?;
                copy.cast::<PyBytes>()?.as_bytes().to_vec()
            }
        };
        let options = DecodeOptions {
            max_bands,
            max_positions: max_positions.unwrap_or(mcgv_video::DEFAULT_MAX_POSITIONS),
            ..DecodeOptions::default()
        };
        let inner = py
            .detach(|| Inner::from_reader(Cursor::new(bytes), &options))
            .py_err()?;
        let h = inner.header();
        let header = PyDict::new(py);
        header.set_item("codec", inner.codec().name())?;
        header.set_item("vertices", h.vertices)?;
        header.set_item("frames", h.frames)?;
        header.set_item("triangles", h.triangles)?;
        header.set_item("clusters", h.clusters)?;
        header.set_item("requested_clusters", h.requested_clusters)?;
        header.set_item("quality", h.quality)?;
        header.set_item("affine_precision", f64::from(h.affine_precision) / 16.0)?;
        header.set_item("first_frame_bits", h.first_frame_bits)?;
        header.set_item("reorder", h.reorder)?;
        header.set_item("fps", h.frame_rate)?;
        header.set_item("predictor", h.predictor.name())?;
        header.set_item("segments", inner.segments().len())?;
        header.set_item("bytes", inner.file_len())?;
        Ok(Self {
            frames: h.frames as usize,
            vertices: h.vertices as usize,
            header: header.unbind(),
            inner: Mutex::new(inner),
        })
    }

    /// The stream header as a dict: ``codec``, ``vertices``, ``frames``, ``triangles``,
    /// ``clusters``, ``requested_clusters``, ``quality``, ``affine_precision``,
    /// ``first_frame_bits``, ``reorder``, ``fps``, ``predictor``, ``segments``, ``bytes``.
    #[getter]
    fn header<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.header.bind(py).copy()
    }

    /// Triangles, ``uint32`` of shape ``(triangles, 3)``, indexing the decoded vertices.
    #[getter]
    fn faces<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<u32>>> {
        let triangles = self.with(py, |d| Ok(d.triangles().to_vec()))?;
        arrays::faces_array(py, &triangles)
    }

    /// Texture coordinates of the first set, ``float32`` of shape ``(vertices, 2)``, or ``None``.
    #[getter]
    fn uvs<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyArray2<f32>>>> {
        let set = self.with(py, |d| Ok(d.attributes().texcoords.first().cloned()))?;
        set.map(|uvs| arrays::uvs_array(py, &uvs)).transpose()
    }

    /// The frames of each temporal segment, as ``(start, end)`` pairs.
    fn segments(&self, py: Python<'_>) -> PyResult<Vec<(usize, usize)>> {
        self.with(py, |d| {
            Ok(d.segments().iter().map(|r| (r.start, r.end)).collect())
        })
    }

    /// Bytes each part of the stream takes, as ``(name, bytes)`` pairs in file order.
    fn parts(&self, py: Python<'_>) -> PyResult<Vec<(String, u64)>> {
        self.with(py, |d| Ok(d.part_bytes()))
    }

    /// What the codec stored (of the segment last decoded, the first if none), as a dict:
    /// ``codec``, ``settings`` (by option name), and ``pictures`` or ``bands``.
    fn describe<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let description = self.with(py, |d| {
            if d.describe().is_none() {
                d.seek_segment(0)?;
            }
            Ok(d.describe())
        })?;
        let dict = PyDict::new(py);
        let Some(description) = description else {
            return Ok(dict);
        };
        dict.set_item("codec", description.codec.name())?;
        let settings = PyDict::new(py);
        for (name, value) in description.settings {
            settings.set_item(name, value)?;
        }
        dict.set_item("settings", settings)?;
        if let Some(p) = description.pictures {
            let pictures = PyDict::new(py);
            pictures.set_item("lattice", p.lattice)?;
            pictures.set_item("bit_depth", p.bit_depth)?;
            pictures.set_item("charts", p.charts)?;
            pictures.set_item("packing_efficiency", p.packing_efficiency)?;
            pictures.set_item("padding", p.padding)?;
            pictures.set_item("corrections", PyList::new(py, p.corrections)?)?;
            dict.set_item("pictures", pictures)?;
        }
        if let Some(b) = description.bands {
            let bands = PyDict::new(py);
            bands.set_item("step", b.step)?;
            bands.set_item("lengths", PyList::new(py, b.lengths)?)?;
            bands.set_item("decoded", b.decoded)?;
            dict.set_item("bands", bands)?;
        }
        Ok(dict)
    }

    /// Frame ``i`` decoded alone (reading only what it needs), ``float32`` ``(vertices, 3)``.
    fn frame<'py>(&self, py: Python<'py>, i: isize) -> PyResult<Bound<'py, PyArray2<f32>>> {
        let f = self.index(i)?;
        let frame = self.with(py, |d| d.decode_frame(f))?;
        arrays::frame_array(py, &frame)
    }

    /// Frames ``start`` to ``end - 1``, ``float32`` ``(end - start, vertices, 3)``: the same
    /// values as ``all()[start:end]`` (each segment they fall in is decoded whole).
    fn frames<'py>(
        &self,
        py: Python<'py>,
        start: usize,
        end: usize,
    ) -> PyResult<Bound<'py, PyArray3<f32>>> {
        let flat = self.with(py, |d| {
            Ok(arrays::flatten(&d.decode_frames(start..end, &Silent)?))
        })?;
        arrays::frames_array(py, flat, self.vertices)
    }

    /// Every frame, ``float32`` ``(frames, vertices, 3)``.
    fn all<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray3<f32>>> {
        let frames = self.frames;
        self.frames(py, 0, frames)
    }

    /// Every frame as an ``Animation`` (faces, uvs, materials and fps from the stream).
    fn animation(&self, py: Python<'_>) -> PyResult<Animation> {
        let mesh = self.with(py, |d| d.decode_all())?;
        Ok(Animation { mesh })
    }

    fn __len__(&self) -> usize {
        self.frames
    }

    fn __repr__(&self, py: Python<'_>) -> String {
        let codec = self
            .header
            .bind(py)
            .get_item("codec")
            .ok()
            .flatten()
            .map_or_else(|| "?".into(), |c| c.to_string());
        format!(
            "Decoder({codec}, {} frames, {} vertices)",
            self.frames, self.vertices
        )
    }
}

/// The measures of a stream against its original, as `mcgv-video eval` takes them: decoded in
/// the input's vertex order, with the stream's bpvf, the frames `sampling` says measured in full.
pub fn compare_stream(
    original: &AnimatedMesh,
    bytes: Vec<u8>,
    sampling: FrameSampling,
) -> mcgv_video::Result<Measures> {
    let mut decoder = Inner::from_reader(Cursor::new(bytes), &DecodeOptions::default())?;
    let bits = decoder.file_len() * 8;
    let order = decoder.input_order(original)?;
    let mut decoded = decoder.decode_all()?;
    if let Some(inverse) = &order {
        decoded = decoded.permuted(inverse)?;
    }
    Ok(compare_sampled(original, &decoded, sampling)?.with_bits(bits))
}
