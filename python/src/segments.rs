//! A long clip's temporal segments, coded anywhere: `FrameSource` reads a clip a run of frames
//! at a time, `SegmentedEncoder` codes segments from one analysis clip and joins them in order
//! (the library's `encoder::SegmentedEncoder`), `CodedSegment`s travel as bytes. The cluster
//! helpers in `mcgv_video/cluster.py` are built on these.

use crate::errors::IntoPy;
use crate::{arrays, on_threads, options, progress, Animation};
use mcgv_video::encoder::{self, CodedSegment};
use mcgv_video::Error;
use numpy::PyArray3;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};
use std::sync::{Mutex, RwLock};

/// analysis_frames(frames, length)
/// --
///
/// The frames of the analysis clip of a clip of ``frames`` frames cut into segments of
/// ``length``: ``length`` frames spread evenly from the first to the last.
#[pyfunction]
pub fn analysis_frames(frames: usize, length: usize) -> Vec<usize> {
    encoder::analysis_frames(frames, length)
}

/// segment_ranges(frames, length)
/// --
///
/// The segments of a clip of ``frames`` frames cut into runs of ``length``, as ``(start, end)``
/// pairs in order (the last one shorter).
#[pyfunction]
pub fn segment_ranges(frames: usize, length: usize) -> Vec<(usize, usize)> {
    encoder::segment_ranges(frames, length)
        .into_iter()
        .map(|r| (r.start, r.end))
        .collect()
}

/// FrameSource(path, clip=None, *, fps=None, base=None, max_positions=None)
/// --
///
/// An animation file read a run of frames at a time (OBJ sequences file by file, PC2 caches by
/// seeking; glTF clips are baked whole): a long clip is never held whole.
#[pyclass(module = "mcgv_video", frozen)]
pub struct FrameSource {
    inner: Mutex<mcgv_video::FrameSource>,
    frames: usize,
    vertices: usize,
}

#[pymethods]
impl FrameSource {
    #[new]
    #[pyo3(signature = (path, clip=None, *, fps=None, base=None, max_positions=None))]
    fn new(
        py: Python<'_>,
        path: std::path::PathBuf,
        clip: Option<&Bound<'_, PyAny>>,
        fps: Option<f64>,
        base: Option<std::path::PathBuf>,
        max_positions: Option<u64>,
    ) -> PyResult<Self> {
        let options = crate::read_options(clip, fps, base, max_positions)?;
        let input = path.display().to_string();
        let inner = py
            .detach(|| mcgv_video::FrameSource::open(&input, &options))
            .py_err()?;
        Ok(Self {
            frames: inner.frame_count(),
            vertices: inner.first().vertex_count(),
            inner: Mutex::new(inner),
        })
    }

    /// Number of frames.
    #[getter]
    fn frame_count(&self) -> usize {
        self.frames
    }

    /// Number of vertices.
    #[getter]
    fn vertex_count(&self) -> usize {
        self.vertices
    }

    /// Positions of frames ``start`` to ``end - 1``, ``float32`` ``(end - start, vertices, 3)``.
    fn read<'py>(
        &self,
        py: Python<'py>,
        start: usize,
        end: usize,
    ) -> PyResult<Bound<'py, PyArray3<f32>>> {
        let flat = self.locked(py, |s| Ok(arrays::flatten(&s.read(start..end)?)))?;
        arrays::frames_array(py, flat, self.vertices)
    }

    /// Frames ``start`` to ``end - 1`` as an ``Animation`` (connectivity, attributes, fps).
    fn clip(&self, py: Python<'_>, start: usize, end: usize) -> PyResult<Animation> {
        let mesh = self.locked(py, |s| s.clip(start..end))?;
        Ok(Animation { mesh })
    }

    /// The analysis clip for segments of ``length`` frames (``analysis_frames``, with the first
    /// frame's connectivity, attributes and fps): what ``SegmentedEncoder.start`` takes.
    fn analysis(&self, py: Python<'_>, length: usize) -> PyResult<Animation> {
        let mesh = self.locked(py, |s| encoder::analysis_clip(s, length))?;
        Ok(Animation { mesh })
    }

    fn __len__(&self) -> usize {
        self.frames
    }
}

impl FrameSource {
    fn locked<T: Send>(
        &self,
        py: Python<'_>,
        work: impl FnOnce(&mut mcgv_video::FrameSource) -> mcgv_video::Result<T> + Send,
    ) -> PyResult<T> {
        py.detach(|| {
            let mut inner = self
                .inner
                .lock()
                .map_err(|_| Error::Usage("the source failed in another thread".into()))?;
            work(&mut inner)
        })
        .py_err()
    }
}

/// An encoding in temporal segments: ``start`` makes every choice on the analysis clip, once;
/// ``analysis()`` ships that analysis as bytes and ``resume`` makes an encoder of them anywhere
/// else; ``code_segment`` codes any segment into bytes; ``add`` takes them back in order and
/// ``finish`` returns the stream — the bytes ``encode`` gives for the whole clip with the same
/// options.
#[pyclass(module = "mcgv_video", frozen)]
pub struct SegmentedEncoder {
    /// Several threads may code segments at once (a shared borrow); `add` and `finish` take it
    /// alone.
    inner: RwLock<Option<encoder::SegmentedEncoder>>,
    threads: Option<usize>,
}

/// The error of an encoder used after `finish`, or after a thread failed inside it.
fn spent() -> Error {
    Error::Usage("the encoder has finished: start another".into())
}

impl SegmentedEncoder {
    /// Runs `work` on the encoder, locked for writing, without the interpreter's lock; errors are
    /// made Python exceptions once the lock is released (making one needs the interpreter).
    fn write<T: Send>(
        &self,
        py: Python<'_>,
        work: impl FnOnce(&mut Option<encoder::SegmentedEncoder>) -> mcgv_video::Result<T> + Send,
    ) -> PyResult<T> {
        py.detach(|| {
            let mut inner = self.inner.write().map_err(|_| spent())?;
            work(&mut inner)
        })
        .py_err()
    }
}

#[pymethods]
impl SegmentedEncoder {
    /// start(analysis, length, *, threads=None, progress=None, **options)
    /// --
    ///
    /// Makes the choices of an encoding in segments of ``length`` frames on ``analysis``, the
    /// clip's analysis clip (``FrameSource.analysis``), with ``encode``'s options.
    #[staticmethod]
    #[pyo3(signature = (analysis, length, *, threads=None, progress=None, **options))]
    fn start(
        py: Python<'_>,
        analysis: &Bound<'_, Animation>,
        length: usize,
        threads: Option<usize>,
        progress: Option<Bound<'_, PyAny>>,
        options: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let opts = options::encode_options("start", options, threads)?;
        let callback = progress::Callback::new(progress)?;
        let mesh = &analysis.get().mesh;
        let started = py.detach(|| {
            on_threads(threads, || {
                encoder::SegmentedEncoder::start(mesh, &opts, length, &callback)
            })
        })?;
        let inner = callback.finish(started)?.py_err()?;
        Ok(Self {
            inner: RwLock::new(Some(inner)),
            threads,
        })
    }

    /// resume(analysis, *, threads=None, **options)
    /// --
    ///
    /// An encoder from ``analysis()``'s bytes and the options the analysis was made with (other
    /// options raise ``UsageError``): it codes, adds and finishes segments as the encoder that
    /// ran ``start`` does, byte for byte, without redoing the analysis.
    #[staticmethod]
    #[pyo3(signature = (analysis, *, threads=None, **options))]
    fn resume(
        py: Python<'_>,
        analysis: &Bound<'_, PyBytes>,
        threads: Option<usize>,
        options: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let opts = options::encode_options("resume", options, threads)?;
        let bytes = analysis.as_bytes().to_vec();
        let inner = py
            .detach(|| encoder::SegmentedEncoder::resume(&bytes, &opts))
            .py_err()?;
        Ok(Self {
            inner: RwLock::new(Some(inner)),
            threads,
        })
    }

    /// The analysis ``start`` made, as bytes (the analysis clip's stream and what its decoder
    /// cannot tell), for ``resume`` on another process or machine.
    fn analysis<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        let bytes = self.write(py, |e| e.as_ref().map(|e| e.analysis()).ok_or_else(spent))?;
        Ok(PyBytes::new(py, &bytes))
    }

    /// Frames added so far.
    #[getter]
    fn frames(&self, py: Python<'_>) -> PyResult<usize> {
        self.write(py, |e| e.as_ref().map(|e| e.frames()).ok_or_else(spent))
    }

    /// Codes the segment of ``positions`` (``float32`` ``(frames, vertices, 3)``, the input's
    /// vertex order) starting at clip frame ``first_frame``; returns its bytes, for ``add``.
    #[pyo3(signature = (first_frame, positions, *, progress=None))]
    fn code_segment<'py>(
        &self,
        py: Python<'py>,
        first_frame: usize,
        positions: &Bound<'py, PyAny>,
        progress: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyBytes>> {
        let frames = arrays::positions("positions", positions)?;
        let callback = progress::Callback::new(progress)?;
        let coded = py.detach(|| {
            on_threads(self.threads, || {
                let inner = self.inner.read().map_err(|_| spent())?;
                let encoder = inner.as_ref().ok_or_else(spent)?;
                encoder
                    .code_segment(first_frame, frames, &callback)
                    .and_then(|s| s.to_bytes())
            })
        })?;
        let bytes = callback.finish(coded)?.py_err()?;
        Ok(PyBytes::new(py, &bytes))
    }

    /// Appends a coded segment (``code_segment``'s bytes); segments must come in order.
    fn add(&self, py: Python<'_>, segment: &Bound<'_, PyBytes>) -> PyResult<()> {
        let bytes = segment.as_bytes().to_vec();
        self.write(py, |e| {
            let encoder = e.as_mut().ok_or_else(spent)?;
            encoder.add(CodedSegment::from_bytes(&bytes)?)
        })
    }

    /// The stream's bytes; the encoder is spent.
    fn finish<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        let bytes = self.write(py, |e| {
            let encoder = e.take().ok_or_else(spent)?;
            Ok(encoder.finish()?.to_bytes())
        })?;
        Ok(PyBytes::new(py, &bytes))
    }
}
