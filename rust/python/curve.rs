//! Bindings for `crate::curve`.
//!
//! The curve is passed as `d = (d1, d2, d3)`, a complex array of length 3,
//! and validated on every call (cheap); batches are 1-D (or `(n, k)`) arrays
//! that the Python layer has broadcast and flattened.

use numpy::ndarray::{Array1, Array2, Array3};
use numpy::{
    Complex64, IntoPyArray, PyArray1, PyArray2, PyArray3, PyReadonlyArray1, PyReadonlyArray2,
};
use pyo3::prelude::*;

use super::arrays::{array1, check_call, out_shape_err, rows, vec1};
use super::errors::py_cancel;
use crate::curve::{CurvePoint, KotterCurve};
use crate::error::Error;
use crate::numeric::alloc::{items_per_check, try_vec};

/// An `(n, k)` array of zeros (the default), allocated fallibly.
fn zeros2<T: Clone + Default>(what: &'static str, n: usize, k: usize) -> PyResult<Array2<T>> {
    Array2::from_shape_vec((n, k), try_vec(what, n * k, T::default())?).map_err(out_shape_err)
}

/// Points between two checks for Ctrl-C in the maps below (~10 µs a point).
fn every() -> usize {
    items_per_check(1e4)
}

type C = Complex64;

fn curve_of(d: &PyReadonlyArray1<'_, C>) -> PyResult<KotterCurve> {
    let [d1, d2, d3]: [C; 3] = array1(d, "d")?;
    Ok(KotterCurve::new(d1, d2, d3)?)
}

/// The two points of row `i` with their offsets `zd = (zd1, zd2)` (a row of 10).
fn points_with_offsets(z1: C, y1: C, z2: C, y2: C, zd: &[C; 10]) -> (CurvePoint, CurvePoint) {
    let p1 = CurvePoint {
        z: z1,
        y: y1,
        zd: std::array::from_fn(|j| zd[j]),
    };
    let p2 = CurvePoint {
        z: z2,
        y: y2,
        zd: std::array::from_fn(|j| zd[5 + j]),
    };
    (p1, p2)
}

/// `(d0, …, d4)` of the curve (8) with the given `(d1, d2, d3)`, validated.
#[pyfunction(name = "curve_branch_points")]
fn curve_branch_points_py<'py>(
    py: Python<'py>,
    d: PyReadonlyArray1<'py, C>,
) -> PyResult<Bound<'py, PyArray1<C>>> {
    let k = curve_of(&d)?;
    Ok(Array1::from(k.branch_points().to_vec()).into_pyarray(py))
}

/// `(c_1, c_2, c_3)`, `(c̃_1, c̃_2, c̃_3)` (33) and `κ = Π_m (d_m − d_4)` (as a
/// length-1 array).
#[pyfunction(name = "curve_constants")]
#[allow(clippy::type_complexity)]
fn curve_constants_py<'py>(
    py: Python<'py>,
    d: PyReadonlyArray1<'py, C>,
) -> PyResult<(
    Bound<'py, PyArray1<C>>,
    Bound<'py, PyArray1<C>>,
    Bound<'py, PyArray1<C>>,
)> {
    let k = curve_of(&d)?;
    Ok((
        Array1::from(k.c().to_vec()).into_pyarray(py),
        Array1::from(k.c_tilde().to_vec()).into_pyarray(py),
        Array1::from(vec![k.kappa()]).into_pyarray(py),
    ))
}

/// `R(x)` and the canonical sheet `y(x)` at each `x`.
#[pyfunction(name = "curve_eval")]
#[allow(clippy::type_complexity)]
fn curve_eval_py<'py>(
    py: Python<'py>,
    d: PyReadonlyArray1<'py, C>,
    x: PyReadonlyArray1<'py, C>,
) -> PyResult<(Bound<'py, PyArray1<C>>, Bound<'py, PyArray1<C>>)> {
    let k = curve_of(&d)?;
    check_call("x", x.as_array().len(), 3 * 16)?;
    let xs = vec1(&x, "x", None)?;
    if let Some(index) = xs
        .iter()
        .position(|v| !(v.re.is_finite() && v.im.is_finite()))
    {
        return Err(Error::NonFinite { what: "x", index }.into());
    }
    let cancel = py_cancel();
    let ry = py.detach(|| {
        crate::numeric::alloc::try_map("x", &xs, items_per_check(100.0), &cancel, |&x| {
            Ok([k.r(x), k.y(x)])
        })
    })?;
    let (r, y): (Vec<C>, Vec<C>) = ry.iter().map(|v| (v[0], v[1])).unzip();
    Ok((
        Array1::from(r).into_pyarray(py),
        Array1::from(y).into_pyarray(py),
    ))
}

/// The Wurzelfunktionen (27)–(28) of `n` point pairs: `P (n, 5)`, `Pjk (n, 5, 5)`.
/// With `zd` (`(n, 10)`: `z1 − d_j` then `z2 − d_j`) the roots come from the
/// offsets ([`KotterCurve::wurzel_points`]).
#[pyfunction(name = "curve_wurzel")]
#[pyo3(signature = (d, z1, y1, z2, y2, eps=None, zd=None))]
#[allow(clippy::type_complexity, clippy::too_many_arguments)]
fn curve_wurzel_py<'py>(
    py: Python<'py>,
    d: PyReadonlyArray1<'py, C>,
    z1: PyReadonlyArray1<'py, C>,
    y1: PyReadonlyArray1<'py, C>,
    z2: PyReadonlyArray1<'py, C>,
    y2: PyReadonlyArray1<'py, C>,
    eps: Option<PyReadonlyArray2<'py, i8>>,
    zd: Option<PyReadonlyArray2<'py, C>>,
) -> PyResult<(Bound<'py, PyArray2<C>>, Bound<'py, PyArray3<C>>)> {
    let k = curve_of(&d)?;
    let n = z1.as_array().len();
    // Four points, eps, the offsets, P and Pjk a row.
    check_call("z1", n, 4 * 16 + 5 + 10 * 16 + 30 * 16)?;
    let (z1, y1) = (vec1(&z1, "z1", Some(n))?, vec1(&y1, "y1", Some(n))?);
    let (z2, y2) = (vec1(&z2, "z2", Some(n))?, vec1(&y2, "y2", Some(n))?);
    let eps: Option<Vec<[i8; 5]>> = eps.map(|e| rows(&e, "eps", Some(n))).transpose()?;
    let zd: Option<Vec<[C; 10]>> = zd.map(|z| rows(&z, "zd", Some(n))).transpose()?;
    let mut p = zeros2::<C>("P", n, 5)?;
    let pjk_flat = try_vec("Pjk", n * 25, C::default())?;
    let mut pjk = Array3::from_shape_vec((n, 5, 5), pjk_flat).map_err(out_shape_err)?;
    let cancel = py_cancel();
    let out = py.detach(|| -> Result<(Array2<C>, Array3<C>), Error> {
        for i in 0..n {
            if i % every() == 0 {
                cancel.check()?;
            }
            let e = eps.as_ref().map(|e| e[i]);
            let w = match &zd {
                None => k.wurzel(z1[i], y1[i], z2[i], y2[i], e)?,
                Some(zd) => {
                    let (p1, p2) = points_with_offsets(z1[i], y1[i], z2[i], y2[i], &zd[i]);
                    k.wurzel_points(&p1, &p2, e)?
                }
            };
            for j in 0..5 {
                p[[i, j]] = w.p[j];
                for m in 0..5 {
                    pjk[[i, j, m]] = w.pjk[j][m];
                }
            }
        }
        Ok((p, pjk))
    })?;
    Ok((out.0.into_pyarray(py), out.1.into_pyarray(py)))
}

/// Kötter's `ξ, η` (37) of `n` point pairs with factors `g`: two `(n, 3)` arrays.
/// With `zd` (`(n, 10)`) the roots come from the offsets
/// ([`KotterCurve::xi_eta_points`]).
#[pyfunction(name = "curve_xi_eta")]
#[pyo3(signature = (d, z1, y1, z2, y2, g, eps=None, sqrt_c=None, zd=None))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn curve_xi_eta_py<'py>(
    py: Python<'py>,
    d: PyReadonlyArray1<'py, C>,
    z1: PyReadonlyArray1<'py, C>,
    y1: PyReadonlyArray1<'py, C>,
    z2: PyReadonlyArray1<'py, C>,
    y2: PyReadonlyArray1<'py, C>,
    g: PyReadonlyArray1<'py, C>,
    eps: Option<PyReadonlyArray2<'py, i8>>,
    sqrt_c: Option<PyReadonlyArray1<'py, C>>,
    zd: Option<PyReadonlyArray2<'py, C>>,
) -> PyResult<(Bound<'py, PyArray2<C>>, Bound<'py, PyArray2<C>>)> {
    let k = curve_of(&d)?;
    let n = z1.as_array().len();
    // Four points, g, eps, the offsets, xi and eta a row.
    check_call("z1", n, 5 * 16 + 5 + 10 * 16 + 6 * 16)?;
    let (z1, y1) = (vec1(&z1, "z1", Some(n))?, vec1(&y1, "y1", Some(n))?);
    let (z2, y2) = (vec1(&z2, "z2", Some(n))?, vec1(&y2, "y2", Some(n))?);
    let g = vec1(&g, "g", Some(n))?;
    let eps: Option<Vec<[i8; 5]>> = eps.map(|e| rows(&e, "eps", Some(n))).transpose()?;
    let zd: Option<Vec<[C; 10]>> = zd.map(|z| rows(&z, "zd", Some(n))).transpose()?;
    let sqrt_c: Option<[C; 3]> = sqrt_c.map(|s| array1(&s, "sqrt_c")).transpose()?;
    let mut xi = zeros2::<C>("xi", n, 3)?;
    let mut eta = zeros2::<C>("eta", n, 3)?;
    let cancel = py_cancel();
    let out = py.detach(|| -> Result<(Array2<C>, Array2<C>), Error> {
        for i in 0..n {
            if i % every() == 0 {
                cancel.check()?;
            }
            let e = eps.as_ref().map(|e| e[i]);
            let (x, h) = match &zd {
                None => k.xi_eta(z1[i], y1[i], z2[i], y2[i], g[i], e, sqrt_c)?,
                Some(zd) => {
                    let (p1, p2) = points_with_offsets(z1[i], y1[i], z2[i], y2[i], &zd[i]);
                    k.xi_eta_points(&p1, &p2, g[i], e, sqrt_c)?
                }
            };
            for j in 0..3 {
                xi[[i, j]] = x[j];
                eta[[i, j]] = h[j];
            }
        }
        Ok((xi, eta))
    })?;
    Ok((out.0.into_pyarray(py), out.1.into_pyarray(py)))
}

/// The inverse of (37) for `n` rows of `(ξ, η)`: the columns `z1, y1, z2, y2, g`
/// `(n, 5)`, `eps` `(n, 5)`, `residual` `(n,)` and the offsets `zd` `(n, 10)`
/// (`z1 − d_j` then `z2 − d_j`, full relative accuracy).
#[pyfunction(name = "curve_points_from_xi_eta")]
#[pyo3(signature = (d, xi, eta, sqrt_c=None, g_ref=None, rtol=1e-8))]
#[allow(clippy::type_complexity)]
fn curve_points_from_xi_eta_py<'py>(
    py: Python<'py>,
    d: PyReadonlyArray1<'py, C>,
    xi: PyReadonlyArray2<'py, C>,
    eta: PyReadonlyArray2<'py, C>,
    sqrt_c: Option<PyReadonlyArray1<'py, C>>,
    g_ref: Option<PyReadonlyArray1<'py, C>>,
    rtol: f64,
) -> PyResult<(
    Bound<'py, PyArray2<C>>,
    Bound<'py, PyArray2<i8>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray2<C>>,
)> {
    let k = curve_of(&d)?;
    let n = xi.as_array().shape()[0];
    // xi, eta, g_ref, the points, eps, the residual and the offsets a row.
    check_call("xi", n, 7 * 16 + 5 * 16 + 5 + 8 + 10 * 16)?;
    let xi: Vec<[C; 3]> = rows(&xi, "xi", Some(n))?;
    let eta: Vec<[C; 3]> = rows(&eta, "eta", Some(n))?;
    let g_ref = g_ref.map(|g| vec1(&g, "g_ref", Some(n))).transpose()?;
    let sqrt_c: Option<[C; 3]> = sqrt_c.map(|s| array1(&s, "sqrt_c")).transpose()?;
    type Out = (Array2<C>, Array2<i8>, Array1<f64>, Array2<C>);
    // Columns: z1, y1, z2, y2, g.
    let mut pts = zeros2::<C>("points", n, 5)?;
    let mut eps = zeros2::<i8>("eps", n, 5)?;
    let mut res = Array1::from(try_vec("residual", n, 0.0)?);
    let mut zd = zeros2::<C>("zd", n, 10)?;
    let cancel = py_cancel();
    let out = py.detach(|| -> Result<Out, Error> {
        for i in 0..n {
            if i % every() == 0 {
                cancel.check()?;
            }
            let gr = g_ref.as_ref().map(|g| g[i]);
            let b = k.points_from_xi_eta(xi[i], eta[i], sqrt_c, gr, rtol)?;
            for (j, v) in [b.z1, b.y1, b.z2, b.y2, b.g].into_iter().enumerate() {
                pts[[i, j]] = v;
            }
            for j in 0..5 {
                eps[[i, j]] = b.eps[j];
            }
            res[i] = b.residual;
            for j in 0..5 {
                zd[[i, j]] = b.zd1[j];
                zd[[i, 5 + j]] = b.zd2[j];
            }
        }
        Ok((pts, eps, res, zd))
    })?;
    Ok((
        out.0.into_pyarray(py),
        out.1.into_pyarray(py),
        out.2.into_pyarray(py),
        out.3.into_pyarray(py),
    ))
}

/// Adds this module's functions to `manakov._core`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(curve_branch_points_py, m)?)?;
    m.add_function(wrap_pyfunction!(curve_constants_py, m)?)?;
    m.add_function(wrap_pyfunction!(curve_eval_py, m)?)?;
    m.add_function(wrap_pyfunction!(curve_wurzel_py, m)?)?;
    m.add_function(wrap_pyfunction!(curve_xi_eta_py, m)?)?;
    m.add_function(wrap_pyfunction!(curve_points_from_xi_eta_py, m)?)?;
    Ok(())
}
