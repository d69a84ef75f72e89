//! NumPy arrays in and out. Every check names the argument it failed on, with the dtype and
//! shape it wanted and got: a Python caller reads which of its arrays is wrong, never a crash.

use mcgv_video::mesh::{Point, Triangle};
use numpy::{
    PyArray1, PyArray2, PyArray3, PyArrayDescrMethods, PyArrayMethods, PyUntypedArray,
    PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;

/// `array`'s dtype and shape, as a message shows them.
fn described(array: &Bound<'_, PyUntypedArray>) -> String {
    let dtype = array
        .dtype()
        .str()
        .map_or_else(|_| "?".into(), |s| s.to_string());
    let shape: Vec<String> = array.shape().iter().map(usize::to_string).collect();
    let shape = match shape.as_slice() {
        [one] => format!("({one},)"),
        _ => format!("({})", shape.join(", ")),
    };
    format!("{dtype} array of shape {shape}")
}

/// `value` as a NumPy array, or a `TypeError` naming `name`.
fn untyped<'a, 'py>(
    name: &str,
    value: &'a Bound<'py, PyAny>,
    wanted: &str,
) -> PyResult<&'a Bound<'py, PyUntypedArray>> {
    value.cast::<PyUntypedArray>().map_err(|_| {
        let got = value
            .get_type()
            .name()
            .map_or_else(|_| "?".into(), |n| n.to_string());
        PyTypeError::new_err(format!("{name}: expected {wanted}, got {got}"))
    })
}

/// Frames of positions from a `float32` array of shape `(frames, vertices, 3)`.
pub fn positions(name: &str, value: &Bound<'_, PyAny>) -> PyResult<Vec<Vec<Point>>> {
    const WANTED: &str = "a numpy float32 array of shape (frames, vertices, 3)";
    let array = untyped(name, value, WANTED)?;
    let Ok(array) = array.cast::<PyArray3<f32>>() else {
        let hint = match array.dtype().is_equiv_to(&numpy::dtype::<f64>(value.py())) {
            true => format!(" (convert with {name}.astype(numpy.float32))"),
            false => String::new(),
        };
        return Err(PyTypeError::new_err(format!(
            "{name}: expected {WANTED}, got a {}{hint}",
            described(array)
        )));
    };
    let [frames, vertices, axes] = [0, 1, 2].map(|i| array.shape()[i]);
    if axes != 3 || frames == 0 || vertices == 0 {
        return Err(PyValueError::new_err(format!(
            "{name}: expected {WANTED} with at least one frame and vertex, got shape \
             ({frames}, {vertices}, {axes})"
        )));
    }
    let readonly = array.readonly();
    let view = readonly.as_array();
    let out = match view.as_slice() {
        // The common case, a C-contiguous array: one pass over its memory.
        Some(flat) => flat
            .chunks_exact(3 * vertices)
            .map(|frame| frame.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect())
            .collect(),
        None => view
            .outer_iter()
            .map(|frame| frame.outer_iter().map(|p| [p[0], p[1], p[2]]).collect())
            .collect(),
    };
    Ok(out)
}

/// Triangles from an integer array of shape `(triangles, 3)` (any integer dtype), every index
/// below `vertices`.
pub fn faces(name: &str, value: &Bound<'_, PyAny>, vertices: usize) -> PyResult<Vec<Triangle>> {
    const WANTED: &str = "an integer numpy array of shape (triangles, 3)";
    let array = untyped(name, value, WANTED)?;
    let kind = array.dtype().kind();
    if !(kind == b'i' || kind == b'u') || array.ndim() != 2 || array.shape()[1] != 3 {
        let error = format!("{name}: expected {WANTED}, got a {}", described(array));
        return Err(match kind == b'i' || kind == b'u' {
            true => PyValueError::new_err(error),
            false => PyTypeError::new_err(error),
        });
    }
    // Any integer dtype, read as int64 (NumPy converts; indices past int64 are refused below).
    let numpy = value.py().import("numpy")?;
    let as_i64 = array.call_method1("astype", (numpy.getattr("int64")?,))?;
    let array = as_i64.cast::<PyArray2<i64>>()?;
    let readonly = array.readonly();
    let mut out = Vec::with_capacity(array.shape()[0]);
    for (t, row) in readonly.as_array().outer_iter().enumerate() {
        let mut triangle = [0u32; 3];
        for (corner, &index) in triangle.iter_mut().zip(row.iter()) {
            *corner = u32::try_from(index)
                .ok()
                .filter(|&i| (i as usize) < vertices)
                .ok_or_else(|| {
                    PyValueError::new_err(format!(
                        "{name}: triangle {t} has vertex index {index}, outside 0..{vertices}"
                    ))
                })?;
        }
        out.push(triangle);
    }
    Ok(out)
}

/// Texture coordinates from a `float32` array of shape `(vertices, 2)`.
pub fn uvs(name: &str, value: &Bound<'_, PyAny>, vertices: usize) -> PyResult<Vec<[f32; 2]>> {
    let wanted = format!("a numpy float32 array of shape ({vertices}, 2): one (u, v) per vertex");
    let array = untyped(name, value, &wanted)?;
    let Ok(typed) = array.cast::<PyArray2<f32>>() else {
        return Err(PyTypeError::new_err(format!(
            "{name}: expected {wanted}, got a {}",
            described(array)
        )));
    };
    if typed.shape() != [vertices, 2] {
        return Err(PyValueError::new_err(format!(
            "{name}: expected {wanted}, got a {}",
            described(array)
        )));
    }
    let readonly = typed.readonly();
    Ok(readonly
        .as_array()
        .outer_iter()
        .map(|uv| [uv[0], uv[1]])
        .collect())
}

/// Frames as a `float32` array of shape `(frames, vertices, 3)`; the frames are flattened
/// before, so NumPy takes the buffer without a copy.
pub fn frames_array<'py>(
    py: Python<'py>,
    flat: Vec<f32>,
    vertices: usize,
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let frames = match vertices {
        0 => 0,
        v => flat.len() / (3 * v),
    };
    PyArray1::from_vec(py, flat).reshape([frames, vertices, 3])
}

/// One frame as a `float32` array of shape `(vertices, 3)`.
pub fn frame_array<'py>(py: Python<'py>, frame: &[Point]) -> PyResult<Bound<'py, PyArray2<f32>>> {
    PyArray1::from_vec(py, frame.iter().flatten().copied().collect()).reshape([frame.len(), 3])
}

/// Frames flattened, x y z of every vertex of frame 0, then frame 1, …
pub fn flatten(frames: &[Vec<Point>]) -> Vec<f32> {
    let mut flat = Vec::with_capacity(frames.iter().map(|f| 3 * f.len()).sum());
    for frame in frames {
        flat.extend(frame.iter().flatten());
    }
    flat
}

/// Triangles as a `uint32` array of shape `(triangles, 3)`.
pub fn faces_array<'py>(
    py: Python<'py>,
    triangles: &[Triangle],
) -> PyResult<Bound<'py, PyArray2<u32>>> {
    let flat: Vec<u32> = triangles.iter().flatten().copied().collect();
    PyArray1::from_vec(py, flat).reshape([triangles.len(), 3])
}

/// Texture coordinates as a `float32` array of shape `(vertices, 2)`.
pub fn uvs_array<'py>(py: Python<'py>, uvs: &[[f32; 2]]) -> PyResult<Bound<'py, PyArray2<f32>>> {
    let flat: Vec<f32> = uvs.iter().flatten().copied().collect();
    PyArray1::from_vec(py, flat).reshape([uvs.len(), 2])
}
