//! Bindings for `crate::kotter`.

use numpy::ndarray::{Array1, Array2, Array3};
use numpy::{Complex64, IntoPyArray, PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArray3};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::arrays::{array1, check_call, out_shape_err, rows, shape_err, stack, vec1};
use super::errors::py_cancel;
use crate::error::Error;
use crate::kotter;
use crate::numeric::alloc::{items_per_check, try_map};

/// Rows of an `(n, K)` input, checked first: `n` rows of `each` bytes of
/// inputs and results must fit the allocation budget.
fn rows_checked<T: numpy::Element + Copy, const K: usize>(
    x: &PyReadonlyArray2<'_, T>,
    what: &'static str,
    n: Option<usize>,
    each: usize,
) -> PyResult<Vec<[T; K]>> {
    check_call(what, x.as_array().nrows(), each)?;
    rows(x, what, n)
}

type C = Complex64;
type LmPair = ([C; 3], [C; 3]);

/// Schottky's l(s) (12) and m(s) (17) on the branch sqrt(s_j4) sqrt(s_kl) = sqrt_g.
#[pyfunction(name = "kotter_schottky")]
fn kotter_schottky_py<'py>(
    py: Python<'py>,
    a: PyReadonlyArray1<'py, f64>,
    l: PyReadonlyArray2<'py, f64>,
    s: PyReadonlyArray1<'py, C>,
    sqrt_g: PyReadonlyArray1<'py, C>,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let a: [f64; 4] = array1(&a, "a")?;
    // l, s, sqrt_g and the two rows of 3 complex results.
    let rows = rows_checked::<f64, 6>(&l, "l", None, 48 + 2 * 16 + 6 * 16 + 6 * 16)?;
    let n = rows.len();
    let s = vec1(&s, "s", Some(n))?;
    let sg = vec1(&sqrt_g, "sqrt_g", Some(n))?;
    let cancel = py_cancel();
    let idx: Vec<usize> = crate::numeric::alloc::try_collect("l", n, 0..n)?;
    let res: Result<Vec<LmPair>, Error> = py.detach(|| {
        crate::error::check_finite("a", &a)?;
        try_map("l", &idx, items_per_check(200.0), &cancel, |&i| {
            crate::error::check_finite("l", &rows[i])?;
            kotter::schottky(&a, &rows[i], s[i], sg[i])
        })
    });
    let res = res?;
    let lv = stack(res.iter().map(|x| x.0))?;
    let mv = stack(res.iter().map(|x| x.1))?;
    Ok((
        lv.into_pyarray(py).into_any(),
        mv.into_pyarray(py).into_any(),
    ))
}

/// The vectors m_b(s) of the Lax matrix M_b(s) (16)-(18) for the top (a, b), states (n, 6).
#[pyfunction(name = "kotter_lax_m")]
fn kotter_lax_m_py<'py>(
    py: Python<'py>,
    a: PyReadonlyArray1<'py, f64>,
    b: PyReadonlyArray1<'py, f64>,
    l: PyReadonlyArray2<'py, f64>,
    s: PyReadonlyArray1<'py, C>,
    sqrt_g: PyReadonlyArray1<'py, C>,
) -> PyResult<Bound<'py, PyAny>> {
    let a: [f64; 4] = array1(&a, "a")?;
    let b: [f64; 4] = array1(&b, "b")?;
    let rows = rows_checked::<f64, 6>(&l, "l", None, 48 + 2 * 16 + 2 * 3 * 16)?;
    let n = rows.len();
    let s = vec1(&s, "s", Some(n))?;
    let sg = vec1(&sqrt_g, "sqrt_g", Some(n))?;
    let cancel = py_cancel();
    let idx: Vec<usize> = crate::numeric::alloc::try_collect("l", n, 0..n)?;
    let res: Result<Vec<[C; 3]>, Error> = py.detach(|| {
        try_map("l", &idx, items_per_check(200.0), &cancel, |&i| {
            kotter::lax_m(&a, &b, &rows[i], s[i], sg[i])
        })
    });
    Ok(stack(res?)?.into_pyarray(py).into_any())
}

/// Coefficients of F(s) (19), monic, highest power first, for integrals h of shape (n, 4).
#[pyfunction(name = "kotter_quartic")]
fn kotter_quartic_py<'py>(
    py: Python<'py>,
    a: PyReadonlyArray1<'py, f64>,
    h: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let a: [f64; 4] = array1(&a, "a")?;
    let rows = rows_checked::<f64, 4>(&h, "h", None, 32 + 2 * 40)?;
    let cancel = py_cancel();
    let res: Result<Vec<[f64; 5]>, Error> = py.detach(|| {
        crate::error::check_finite("a", &a)?;
        try_map("h", &rows, items_per_check(100.0), &cancel, |r| {
            crate::error::check_finite("h", r)?;
            kotter::quartic_f(&a, r)
        })
    });
    Ok(stack(res?)?.into_pyarray(py).into_any())
}

/// Kötter's reduction and the uniformization for states `l` of shape (n, 6):
/// a dict of arrays with leading axis n (see `manakov.kotter`), and `ok`, the
/// rows that succeeded (`kotter::kotter_batch`: with `l0`, every row mapped
/// with the constants of `l0`'s level set; `mask = false`: the first failing
/// row raises, its index in the message; `mask = true`: failing rows are NaN
/// and `ok` false).
#[pyfunction(name = "kotter_batch", signature = (a, l, l0=None, mask=false))]
fn kotter_batch_py<'py>(
    py: Python<'py>,
    a: PyReadonlyArray1<'py, f64>,
    l: PyReadonlyArray2<'py, f64>,
    l0: Option<PyReadonlyArray1<'py, f64>>,
    mask: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let a: [f64; 4] = array1(&a, "a")?;
    // The copy of l and the batch's fields, before either is allocated.
    let rows = rows_checked::<f64, 6>(&l, "l", None, 48 + kotter::ROW_BYTES)?;
    let l0: Option<[f64; 6]> = match l0 {
        Some(v) => Some(array1(&v, "l0")?),
        None => None,
    };
    let cancel = py_cancel();
    let b = py.detach(|| kotter::kotter_batch(&a, &rows, l0.as_ref(), mask, &cancel))?;
    let n = b.n;
    let dict = PyDict::new(py);
    let two = |v: Vec<C>, m: usize| -> PyResult<Bound<'py, PyAny>> {
        Ok(Array2::from_shape_vec((n, m), v)
            .map_err(out_shape_err)?
            .into_pyarray(py)
            .into_any())
    };
    let three = |v: Vec<C>, m: usize, k: usize| -> PyResult<Bound<'py, PyAny>> {
        Ok(Array3::from_shape_vec((n, m, k), v)
            .map_err(out_shape_err)?
            .into_pyarray(py)
            .into_any())
    };
    let one = |v: Vec<C>| Array1::from_vec(v).into_pyarray(py).into_any();
    let h = Array2::from_shape_vec((n, 4), b.h).map_err(out_shape_err)?;
    dict.set_item("h", h.into_pyarray(py))?;
    dict.set_item("s", two(b.s, 4)?)?;
    dict.set_item("sigma", two(b.sigma, 4)?)?;
    dict.set_item("sqrt_fprime", two(b.sqrt_fprime, 4)?)?;
    dict.set_item("l_p", three(b.l_p, 4, 3)?)?;
    dict.set_item("Delta", three(b.delta_det, 3, 3)?)?;
    dict.set_item("xi", two(b.xi, 3)?)?;
    dict.set_item("eta", two(b.eta, 3)?)?;
    dict.set_item("sqrt_d", two(b.sqrt_d, 3)?)?;
    dict.set_item("d", two(b.d, 3)?)?;
    dict.set_item("alpha", two(b.alpha, 3)?)?;
    dict.set_item("beta", two(b.beta, 3)?)?;
    dict.set_item("gamma", two(b.gamma, 3)?)?;
    dict.set_item("delta", two(b.delta, 3)?)?;
    dict.set_item("A", two(b.a_coef, 3)?)?;
    dict.set_item("B", two(b.b_coef, 3)?)?;
    dict.set_item("abgd39", two(b.abgd39, 4)?)?;
    dict.set_item("eps", one(b.eps))?;
    dict.set_item("K", one(b.k))?;
    dict.set_item("P0", one(b.p0))?;
    dict.set_item("g", one(b.g))?;
    dict.set_item("z1", one(b.z1))?;
    dict.set_item("y1", one(b.y1))?;
    dict.set_item("z2", one(b.z2))?;
    dict.set_item("y2", one(b.y2))?;
    dict.set_item("zd", three(b.zd, 2, 5)?)?;
    let br = Array2::from_shape_vec((n, 5), b.branch).map_err(out_shape_err)?;
    dict.set_item("branch", br.into_pyarray(py))?;
    dict.set_item("ok", Array1::from_vec(b.ok).into_pyarray(py))?;
    Ok(dict)
}

/// The inverse map: states (n, 6) from the coefficients of (23), d (26), the points, g and the branch.
#[pyfunction(name = "kotter_from_points", signature = (alpha, beta, gamma, delta, d, z1, y1, z2, y2, g, branch, zd=None))]
#[allow(clippy::too_many_arguments)]
fn kotter_from_points_py<'py>(
    py: Python<'py>,
    alpha: PyReadonlyArray2<'py, C>,
    beta: PyReadonlyArray2<'py, C>,
    gamma: PyReadonlyArray2<'py, C>,
    delta: PyReadonlyArray2<'py, C>,
    d: PyReadonlyArray2<'py, C>,
    z1: PyReadonlyArray1<'py, C>,
    y1: PyReadonlyArray1<'py, C>,
    z2: PyReadonlyArray1<'py, C>,
    y2: PyReadonlyArray1<'py, C>,
    g: PyReadonlyArray1<'py, C>,
    branch: PyReadonlyArray2<'py, i8>,
    zd: Option<PyReadonlyArray3<'py, C>>,
) -> PyResult<Bound<'py, PyAny>> {
    let n = z1.as_array().len();
    // Twenty complex inputs, the branch, the offsets and the state, a row.
    check_call("z1", n, 20 * 16 + 5 + 10 * 16 + 48)?;
    let al = rows::<C, 3>(&alpha, "alpha", Some(n))?;
    let be = rows::<C, 3>(&beta, "beta", Some(n))?;
    let ga = rows::<C, 3>(&gamma, "gamma", Some(n))?;
    let de = rows::<C, 3>(&delta, "delta", Some(n))?;
    let dv = rows::<C, 3>(&d, "d", Some(n))?;
    let z1 = vec1(&z1, "z1", Some(n))?;
    let y1 = vec1(&y1, "y1", Some(n))?;
    let z2 = vec1(&z2, "z2", Some(n))?;
    let y2 = vec1(&y2, "y2", Some(n))?;
    let g = vec1(&g, "g", Some(n))?;
    let br = rows::<i8, 5>(&branch, "branch", Some(n))?;
    let zd: Option<Vec<[[C; 5]; 2]>> = match zd {
        None => None,
        Some(z) => {
            let z = z.as_array();
            if z.shape() != [n, 2, 5] {
                return Err(shape_err("zd", format!("({n}, 2, 5)"), z.shape()));
            }
            Some(crate::numeric::alloc::try_collect(
                "zd",
                n,
                (0..n).map(|i| std::array::from_fn(|p| std::array::from_fn(|j| z[[i, p, j]]))),
            )?)
        }
    };
    let cancel = py_cancel();
    let idx: Vec<usize> = crate::numeric::alloc::try_collect("l", n, 0..n)?;
    let res: Result<Vec<[f64; 6]>, Error> = py.detach(|| {
        try_map("z1", &idx, items_per_check(2000.0), &cancel, |&i| {
            let coef = kotter::Coefficients23 {
                alpha: al[i],
                beta: be[i],
                gamma: ga[i],
                delta: de[i],
            };
            kotter::from_kotter(
                &coef,
                dv[i],
                [z1[i], z2[i]],
                [y1[i], y2[i]],
                zd.as_ref().map(|v| v[i]),
                g[i],
                br[i],
            )
        })
    });
    Ok(stack(res?)?.into_pyarray(py).into_any())
}

/// Adds this module's functions to `manakov._core`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(kotter_schottky_py, m)?)?;
    m.add_function(wrap_pyfunction!(kotter_quartic_py, m)?)?;
    m.add_function(wrap_pyfunction!(kotter_lax_m_py, m)?)?;
    m.add_function(wrap_pyfunction!(kotter_batch_py, m)?)?;
    m.add_function(wrap_pyfunction!(kotter_from_points_py, m)?)?;
    Ok(())
}
