//! Array conversion shared by the bindings: read-only numpy arrays (any strides)
//! into owned Rust data, with the shape checks that keep user input away from
//! indexing panics, and the error of an output reshape.

use numpy::ndarray::{Array2, ShapeError};
use numpy::{Element, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::PyErr;

use crate::error::Error;

/// `Error::Shape` as a Python `ValueError`.
pub(super) fn shape_err(what: &'static str, expected: impl Into<String>, got: &[usize]) -> PyErr {
    Error::Shape {
        what,
        expected: expected.into(),
        got: format!("{got:?}"),
    }
    .into()
}

/// The error of building an output array from a result of the wrong length
/// (a bug in the binding, reported rather than panicking).
pub(super) fn out_shape_err(e: ShapeError) -> PyErr {
    Error::InvalidArgument {
        what: "output shape",
        reason: e.to_string(),
    }
    .into()
}

/// A 1-d array as a `Vec`; with `len`, its length must be `len`.
pub(super) fn vec1<T: Element + Copy>(
    x: &PyReadonlyArray1<'_, T>,
    what: &'static str,
    len: Option<usize>,
) -> Result<Vec<T>, PyErr> {
    let v = x.as_array();
    match len {
        Some(n) if v.len() != n => Err(shape_err(what, format!("({n},)"), v.shape())),
        _ => Ok(v.iter().copied().collect()),
    }
}

/// A 1-d array of exactly `N` entries.
pub(super) fn array1<T: Element + Copy + Default, const N: usize>(
    x: &PyReadonlyArray1<'_, T>,
    what: &'static str,
) -> Result<[T; N], PyErr> {
    let v = vec1(x, what, Some(N))?;
    let mut out = [T::default(); N];
    out.copy_from_slice(&v);
    Ok(out)
}

/// The rows of a 2-d array with exactly `K` columns; with `rows`, exactly that many rows.
pub(super) fn rows<T: Element + Copy, const K: usize>(
    x: &PyReadonlyArray2<'_, T>,
    what: &'static str,
    rows: Option<usize>,
) -> Result<Vec<[T; K]>, PyErr> {
    let v = x.as_array();
    let ok = v.ncols() == K && rows.is_none_or(|n| v.nrows() == n);
    if !ok {
        let expected = match rows {
            Some(n) => format!("({n}, {K})"),
            None => format!("(n, {K})"),
        };
        return Err(shape_err(what, expected, v.shape()));
    }
    Ok(v.rows()
        .into_iter()
        .map(|r| std::array::from_fn(|k| r[k]))
        .collect())
}

/// Rows of `K` values as an `(n, K)` array: the inverse of [`rows`] for results.
pub(super) fn stack<T: Copy, const K: usize>(
    rows: impl IntoIterator<Item = [T; K]>,
) -> Result<Array2<T>, PyErr> {
    let flat: Vec<T> = rows.into_iter().flatten().collect();
    let n = flat.len() / K.max(1);
    Array2::from_shape_vec((n, K), flat).map_err(out_shape_err)
}
