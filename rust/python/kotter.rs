//! Bindings for `crate::kotter`.

use numpy::ndarray::{Array1, Array2, Array3};
use numpy::{Complex64, IntoPyArray, PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArray3};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::arrays::{array1, out_shape_err, rows, shape_err, stack, vec1};
use crate::error::Error;
use crate::kotter;

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
    let rows = rows::<f64, 6>(&l, "l", None)?;
    let n = rows.len();
    let s = vec1(&s, "s", Some(n))?;
    let sg = vec1(&sqrt_g, "sqrt_g", Some(n))?;
    let res: Result<Vec<LmPair>, Error> = py.detach(|| {
        crate::error::check_finite("a", &a)?;
        rows.iter()
            .zip(s.iter().zip(sg.iter()))
            .map(|(r, (&si, &gi))| {
                crate::error::check_finite("l", r)?;
                kotter::schottky(&a, r, si, gi)
            })
            .collect()
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
    let rows = rows::<f64, 6>(&l, "l", None)?;
    let n = rows.len();
    let s = vec1(&s, "s", Some(n))?;
    let sg = vec1(&sqrt_g, "sqrt_g", Some(n))?;
    let res: Result<Vec<[C; 3]>, Error> = py.detach(|| {
        rows.iter()
            .zip(s.iter().zip(sg.iter()))
            .map(|(r, (&si, &gi))| kotter::lax_m(&a, &b, r, si, gi))
            .collect()
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
    let rows = rows::<f64, 4>(&h, "h", None)?;
    let res: Result<Vec<[f64; 5]>, Error> = py.detach(|| {
        crate::error::check_finite("a", &a)?;
        rows.iter()
            .map(|r| {
                crate::error::check_finite("h", r)?;
                kotter::quartic_f(&a, r)
            })
            .collect()
    });
    Ok(stack(res?)?.into_pyarray(py).into_any())
}

/// A state whose every field is NaN (the rows that failed, with `errors="mask"`).
fn nan_state() -> PyResult<kotter::KotterState> {
    let n = C::new(f64::NAN, f64::NAN);
    let constants = kotter::KotterConstants {
        a: [f64::NAN; 4],
        h: [f64::NAN; 4],
        s: [n; 4],
        sigma: [n; 4],
        sqrt_fprime: [n; 4],
        u: [[n; 3]; 4],
        v: [[n; 3]; 4],
        u_lo: [[n; 3]; 4],
        v_lo: [[n; 3]; 4],
        delta_det: [[n; 3]; 3],
        sqrt_d: [n; 3],
        d: [n; 3],
        d_lo: [n; 3],
        alpha: [n; 3],
        beta: [n; 3],
        gamma: [n; 3],
        delta: [n; 3],
        a_coef: [n; 3],
        b_coef: [n; 3],
        abgd39: [n; 4],
        eps: n,
        k: n,
    };
    // any regular curve: the rows' curves are rebuilt from their (NaN) d_j in Python
    let curve =
        crate::curve::KotterCurve::new(C::new(1.0, 1.0), C::new(2.0, 1.0), C::new(3.0, 1.0))?;
    Ok(kotter::KotterState {
        constants,
        l_p: [[n; 3]; 4],
        xi: [n; 3],
        eta: [n; 3],
        curve,
        p0: n,
        points: crate::curve::WurzelPoints {
            z1: n,
            y1: n,
            z2: n,
            y2: n,
            g: n,
            eps: [0; 5],
            residual: f64::NAN,
            zd1: [n; 5],
            zd2: [n; 5],
        },
    })
}

/// Kötter's reduction and the uniformization for states `l` of shape (n, 6):
/// a dict of arrays with leading axis n (see `manakov.kotter`), and `ok`, the
/// rows that succeeded. With `l0`, every row is mapped with the constants of
/// `l0`'s level set (`kotter::kotter_along`); otherwise each row with its own
/// (`kotter::kotter`). `mask = false`: the first failing row raises, its
/// index in the message; `mask = true`: failing rows are NaN and `ok` false.
#[pyfunction(name = "kotter_batch", signature = (a, l, l0=None, mask=false))]
fn kotter_batch_py<'py>(
    py: Python<'py>,
    a: PyReadonlyArray1<'py, f64>,
    l: PyReadonlyArray2<'py, f64>,
    l0: Option<PyReadonlyArray1<'py, f64>>,
    mask: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let a: [f64; 4] = array1(&a, "a")?;
    let rows = rows::<f64, 6>(&l, "l", None)?;
    let l0: Option<[f64; 6]> = match l0 {
        Some(v) => Some(array1(&v, "l0")?),
        None => None,
    };
    let n = rows.len();
    let all: Result<Vec<Result<kotter::KotterState, Error>>, Error> = py.detach(|| match l0 {
        Some(l0) => {
            let constants = kotter::kotter_constants(&a, &l0)?;
            Ok(kotter::kotter_along(&constants, &rows))
        }
        None => Ok(rows.iter().map(|r| kotter::kotter(&a, r)).collect()),
    });
    let all = all?;
    let mut ok = Vec::with_capacity(n);
    let mut res = Vec::with_capacity(n);
    for (i, r) in all.into_iter().enumerate() {
        match r {
            Ok(st) => {
                ok.push(true);
                res.push(st);
            }
            Err(e) if mask => {
                let _ = e;
                ok.push(false);
                res.push(nan_state()?);
            }
            Err(e) => {
                let err: PyErr = e.into();
                if n == 1 {
                    return Err(err);
                }
                let msg = format!("row {i} of {n}: {}", err.value(py));
                return Err(PyErr::from_type(err.get_type(py), msg));
            }
        }
    }
    let dict = PyDict::new(py);
    let c2 = |f: &dyn Fn(&kotter::KotterState) -> Vec<C>, m: usize| -> PyResult<Array2<C>> {
        let v: Vec<C> = res.iter().flat_map(f).collect();
        Array2::from_shape_vec((n, m), v).map_err(out_shape_err)
    };
    let c1 = |f: &dyn Fn(&kotter::KotterState) -> C| -> Array1<C> { res.iter().map(f).collect() };
    let k = |st: &kotter::KotterState| st.constants.clone();
    dict.set_item("h", {
        let v: Vec<f64> = res.iter().flat_map(|st| st.constants.h).collect();
        Array2::from_shape_vec((n, 4), v)
            .map_err(out_shape_err)?
            .into_pyarray(py)
    })?;
    dict.set_item("s", c2(&|st| k(st).s.to_vec(), 4)?.into_pyarray(py))?;
    dict.set_item("sigma", c2(&|st| k(st).sigma.to_vec(), 4)?.into_pyarray(py))?;
    dict.set_item(
        "sqrt_fprime",
        c2(&|st| k(st).sqrt_fprime.to_vec(), 4)?.into_pyarray(py),
    )?;
    let lp: Vec<C> = res.iter().flat_map(|st| st.l_p.concat()).collect();
    dict.set_item(
        "l_p",
        Array3::from_shape_vec((n, 4, 3), lp)
            .map_err(out_shape_err)?
            .into_pyarray(py),
    )?;
    let dd: Vec<C> = res
        .iter()
        .flat_map(|st| st.constants.delta_det.concat())
        .collect();
    dict.set_item(
        "Delta",
        Array3::from_shape_vec((n, 3, 3), dd)
            .map_err(out_shape_err)?
            .into_pyarray(py),
    )?;
    dict.set_item("xi", c2(&|st| st.xi.to_vec(), 3)?.into_pyarray(py))?;
    dict.set_item("eta", c2(&|st| st.eta.to_vec(), 3)?.into_pyarray(py))?;
    dict.set_item(
        "sqrt_d",
        c2(&|st| k(st).sqrt_d.to_vec(), 3)?.into_pyarray(py),
    )?;
    dict.set_item("d", c2(&|st| k(st).d.to_vec(), 3)?.into_pyarray(py))?;
    dict.set_item("alpha", c2(&|st| k(st).alpha.to_vec(), 3)?.into_pyarray(py))?;
    dict.set_item("beta", c2(&|st| k(st).beta.to_vec(), 3)?.into_pyarray(py))?;
    dict.set_item("gamma", c2(&|st| k(st).gamma.to_vec(), 3)?.into_pyarray(py))?;
    dict.set_item("delta", c2(&|st| k(st).delta.to_vec(), 3)?.into_pyarray(py))?;
    dict.set_item("A", c2(&|st| k(st).a_coef.to_vec(), 3)?.into_pyarray(py))?;
    dict.set_item("B", c2(&|st| k(st).b_coef.to_vec(), 3)?.into_pyarray(py))?;
    dict.set_item(
        "abgd39",
        c2(&|st| k(st).abgd39.to_vec(), 4)?.into_pyarray(py),
    )?;
    dict.set_item("eps", c1(&|st| st.constants.eps).into_pyarray(py))?;
    dict.set_item("K", c1(&|st| st.constants.k).into_pyarray(py))?;
    dict.set_item("P0", c1(&|st| st.p0).into_pyarray(py))?;
    dict.set_item("g", c1(&|st| st.points.g).into_pyarray(py))?;
    dict.set_item("z1", c1(&|st| st.points.z1).into_pyarray(py))?;
    dict.set_item("y1", c1(&|st| st.points.y1).into_pyarray(py))?;
    dict.set_item("z2", c1(&|st| st.points.z2).into_pyarray(py))?;
    dict.set_item("y2", c1(&|st| st.points.y2).into_pyarray(py))?;
    let zd: Vec<C> = res
        .iter()
        .flat_map(|st| [st.points.zd1, st.points.zd2].concat())
        .collect();
    dict.set_item(
        "zd",
        Array3::from_shape_vec((n, 2, 5), zd)
            .map_err(out_shape_err)?
            .into_pyarray(py),
    )?;
    let br: Vec<i8> = res.iter().flat_map(|st| st.points.eps).collect();
    dict.set_item(
        "branch",
        Array2::from_shape_vec((n, 5), br)
            .map_err(out_shape_err)?
            .into_pyarray(py),
    )?;
    dict.set_item("ok", Array1::from_vec(ok).into_pyarray(py))?;
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
            Some(
                (0..n)
                    .map(|i| std::array::from_fn(|p| std::array::from_fn(|j| z[[i, p, j]])))
                    .collect(),
            )
        }
    };
    let res: Result<Vec<[f64; 6]>, Error> = py.detach(|| {
        (0..n)
            .map(|i| {
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
            .collect()
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
