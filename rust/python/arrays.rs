//! Array conversion shared by the bindings: read-only numpy arrays (any strides)
//! into owned Rust data, with the shape checks that keep user input away from
//! indexing panics, and the error of an output reshape.
//!
//! Every copy here is sized by the user's array, so it goes through the
//! checked allocation of `crate::numeric::alloc` (an error naming the size,
//! never an abort); [`check_call`] checks a whole call's arrays before the
//! first copy.

use numpy::ndarray::{Array2, ShapeError};
use numpy::{Element, IntoPyArray, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::PyErr;

use super::errors::py_cancel;
use crate::error::Error;
use crate::numeric::alloc::{check_size, items_per_check, try_collect, try_map_rows, try_vec};
use crate::numeric::cancel::Cancel;

/// Checks, before any copy or work, that `count` items (states, points,
/// samples) of a call fit the allocation budget when each needs `bytes_each`
/// bytes of input copies and results together.
pub(super) fn check_call(what: &'static str, count: usize, bytes_each: usize) -> Result<(), PyErr> {
    check_size(what, count, bytes_each)?;
    Ok(())
}

/// Copies a read-only 2-d array (any strides) into a row-major Vec with its shape.
pub(super) fn vec2<T: Element + Copy>(
    x: &PyReadonlyArray2<'_, T>,
    what: &'static str,
) -> Result<(Vec<T>, usize, usize), PyErr> {
    let v = x.as_array();
    let (r, c) = v.dim();
    Ok((try_collect(what, v.len(), v.iter().copied())?, r, c))
}

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

/// `l(t_k)`, `(N, 6)`, of a flat array of times by a core batch `eval`
/// (`Solution::l_batch`, `Motion::l_batch`), with the GIL released and Ctrl-C
/// polled; the times and the six components at each are checked against the
/// allocation budget before anything is copied.
pub(super) fn l_of_times<'py>(
    py: Python<'py>,
    t: PyReadonlyArray1<'_, f64>,
    eval: impl Fn(&[f64], &mut [f64], &Cancel) -> crate::error::Result<()> + Send + Sync,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    check_call("t", t.as_array().len(), 7 * std::mem::size_of::<f64>())?;
    let t = vec1(&t, "t", None)?;
    let n = t.len();
    let out = py.detach(|| -> crate::error::Result<Vec<f64>> {
        let mut out = try_vec("l(t)", 6 * n, 0.0)?;
        eval(&t, &mut out, &py_cancel())?;
        Ok(out)
    })?;
    Ok(Array2::from_shape_vec((n, 6), out)
        .map_err(out_shape_err)?
        .into_pyarray(py))
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
        _ => Ok(try_collect(what, v.len(), v.iter().copied())?),
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
    let out = try_collect(
        what,
        v.nrows(),
        v.rows().into_iter().map(|r| std::array::from_fn(|k| r[k])),
    )?;
    Ok(out)
}

/// Rows of `K` values as an `(n, K)` array: the inverse of [`rows`] for results.
pub(super) fn stack<T: Copy, const K: usize, I>(rows: I) -> Result<Array2<T>, PyErr>
where
    I: IntoIterator<Item = [T; K]>,
    I::IntoIter: ExactSizeIterator,
{
    let rows = rows.into_iter();
    let n = rows.len();
    let flat: Vec<T> = try_collect("result", n.saturating_mul(K), rows.flatten())?;
    Array2::from_shape_vec((n, K), flat).map_err(out_shape_err)
}

/// The rows of `l` `(N, m)` mapped by `f` to rows of `k` values, `(N, k)`, with
/// the GIL released: the call's size is checked before the copy of `l`
/// (`m` inputs and `k` results a row), the output allocated fallibly, and
/// Ctrl-C polled about every millisecond of work (`cost_ns`, the cost of one
/// row, sets how many rows that is). The caller has checked `m`.
pub(super) fn map_rows<'py, U>(
    py: Python<'py>,
    l: &PyReadonlyArray2<'py, f64>,
    what: &'static str,
    k: usize,
    cost_ns: f64,
    f: impl Fn(&[f64], &mut [U]) -> crate::error::Result<()> + Sync,
) -> PyResult<Bound<'py, PyArray2<U>>>
where
    U: Element + Clone + Default + Send,
{
    let (rows, m) = l.as_array().dim();
    let each = m * std::mem::size_of::<f64>() + k * std::mem::size_of::<U>();
    check_call(what, rows, each)?;
    let (lv, _, _) = vec2(l, what)?;
    let cancel = py_cancel();
    let every = items_per_check(cost_ns);
    let out = py.detach(|| try_map_rows(what, &lv, m, k, every, &cancel, |x, o| f(x, o)))?;
    Ok(Array2::from_shape_vec((rows, k), out)
        .map_err(out_shape_err)?
        .into_pyarray(py))
}
