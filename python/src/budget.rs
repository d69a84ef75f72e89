//! `encode_to_budget`: the quality whose stream fits a size or an error bound, as
//! `mcgv-video encode --target-size` (and `--target-bpvf`, `--target-error`, `--target-max-error`)
//! finds it, with the search's report.

use crate::errors::{self, IntoPy};
use crate::{mesh_argument, on_threads, options, progress};
use mcgv_video::encoder::{encode_to_budget_with_progress, Budget};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};

/// encode_to_budget(positions, faces=None, *, target_size=None, target_bpvf=None, target_error=None, target_max_error=None, fps=None, uvs=None, progress=None, threads=None, **options)
/// --
///
/// Encodes an animation at the quality whose stream fits a budget; returns ``(stream, report)``.
///
/// Give exactly one budget: ``target_size`` (bytes), ``target_bpvf`` (bits per vertex and
/// frame), ``target_error`` (vertex RMSE over the first frame's bounding-box diagonal, as
/// ``eval``'s ``vertex_rmse``) or ``target_max_error`` (the largest vertex error, same unit).
/// The stream never exceeds the budget and lands within 3 % under it when the quality range
/// allows, in as few full encodes as the search can (usually 2 or 3; ``quality``, default 50,
/// is where it starts). ``report`` is the command line's ``--json`` ``budget`` object: the
/// ``quality`` found (between the integers too), HEVC's and AV1's ``bit_depth``, ``achieved``,
/// ``limit``, ``within_tolerance``, ``encodes``, each encode's ``trials`` and the ``model`` the
/// first encode chose. The other
/// arguments are ``encode``'s (no ``step``: the search chooses it); the same options give the
/// same bytes as ``mcgv-video encode --target-*``.
#[pyfunction]
#[pyo3(signature = (positions, faces=None, *, target_size=None, target_bpvf=None, target_error=None, target_max_error=None, fps=None, uvs=None, progress=None, threads=None, **options))]
#[allow(clippy::too_many_arguments)]
pub fn encode_to_budget<'py>(
    py: Python<'py>,
    positions: &Bound<'py, PyAny>,
    faces: Option<&Bound<'py, PyAny>>,
    target_size: Option<u64>,
    target_bpvf: Option<f64>,
    target_error: Option<f64>,
    target_max_error: Option<f64>,
    fps: Option<f64>,
    uvs: Option<&Bound<'py, PyAny>>,
    progress: Option<Bound<'py, PyAny>>,
    threads: Option<usize>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<(Bound<'py, PyBytes>, Bound<'py, PyAny>)> {
    let targets = (target_size, target_bpvf, target_error, target_max_error);
    let budget = budget_of(targets)?;
    let mesh = mesh_argument("positions", positions, faces, fps, uvs)?;
    let opts = options::encode_options("encode_to_budget", options, threads)?;
    let callback = progress::Callback::new(progress)?;
    let found = py.detach(|| {
        on_threads(threads, || {
            encode_to_budget_with_progress(&mesh, &opts, budget, &callback).and_then(|found| {
                let report = serde_json::to_string(&found.search)
                    .map_err(|e| mcgv_video::Error::Usage(e.to_string()))?;
                Ok((found.encoded.to_bytes(), report))
            })
        })
    })?;
    let (bytes, report) = callback.finish(found)?.py_err()?;
    // The report as the command line prints it, parsed by Python's own JSON reader.
    let report = py.import("json")?.call_method1("loads", (report,))?;
    Ok((PyBytes::new(py, &bytes), report))
}

/// The one budget given.
fn budget_of(targets: (Option<u64>, Option<f64>, Option<f64>, Option<f64>)) -> PyResult<Budget> {
    let given = [
        targets.0.map(Budget::Bytes),
        targets.1.map(Budget::Bpvf),
        targets.2.map(Budget::VertexRmse),
        targets.3.map(Budget::MaxVertexError),
    ];
    let mut given = given.into_iter().flatten();
    match (given.next(), given.next()) {
        (Some(budget), None) => Ok(budget),
        (None, _) => Err(errors::option(
            "target_size",
            "encode_to_budget needs a budget: target_size, target_bpvf, target_error or \
             target_max_error",
        )),
        (Some(_), Some(_)) => Err(errors::option(
            "target_size",
            "one budget at a time: target_size, target_bpvf, target_error or target_max_error",
        )),
    }
}
