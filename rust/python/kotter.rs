//! Bindings for `crate::kotter`.

use numpy::ndarray::{Array1, Array2, Array3};
use numpy::{Complex64, IntoPyArray, PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArray3};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::error::Error;
use crate::kotter;

type C = Complex64;
type LmPair = ([C; 3], [C; 3]);

fn shape_err(what: &'static str, expected: &str, got: &[usize]) -> PyErr {
    Error::Shape {
        what,
        expected: expected.to_string(),
        got: format!("{got:?}"),
    }
    .into()
}

fn read_a(a: &PyReadonlyArray1<'_, f64>) -> PyResult<[f64; 4]> {
    let a = a.as_array();
    if a.len() != 4 {
        return Err(shape_err("a", "(4,)", a.shape()));
    }
    Ok([a[0], a[1], a[2], a[3]])
}

fn read_rows<const N: usize>(
    what: &'static str,
    x: &PyReadonlyArray2<'_, f64>,
) -> PyResult<Vec<[f64; N]>> {
    let x = x.as_array();
    if x.ncols() != N {
        return Err(shape_err(what, &format!("(n, {N})"), x.shape()));
    }
    Ok(x.rows()
        .into_iter()
        .map(|r| std::array::from_fn(|i| r[i]))
        .collect())
}

fn read_crows<const N: usize>(
    what: &'static str,
    x: &PyReadonlyArray2<'_, C>,
    n: usize,
) -> PyResult<Vec<[C; N]>> {
    let x = x.as_array();
    if x.ncols() != N || x.nrows() != n {
        return Err(shape_err(what, &format!("({n}, {N})"), x.shape()));
    }
    Ok(x.rows()
        .into_iter()
        .map(|r| std::array::from_fn(|i| r[i]))
        .collect())
}

fn read_c1(what: &'static str, x: &PyReadonlyArray1<'_, C>, n: usize) -> PyResult<Vec<C>> {
    let x = x.as_array();
    if x.len() != n {
        return Err(shape_err(what, &format!("({n},)"), x.shape()));
    }
    Ok(x.iter().copied().collect())
}

/// The integrals (h0, h1, h2, h3) (6)-(7) with the complementary-pair H2, H3, for states `l` of shape (n, 6).
#[pyfunction(name = "kotter_integrals")]
fn kotter_integrals_py<'py>(
    py: Python<'py>,
    a: PyReadonlyArray1<'py, f64>,
    l: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let a = read_a(&a)?;
    let rows = read_rows::<6>("l", &l)?;
    let n = rows.len();
    let out: Vec<f64> = py.detach(|| rows.iter().flat_map(|r| kotter::integrals(&a, r)).collect());
    let arr = Array2::from_shape_vec((n, 4), out).map_err(|e| shape_err_msg(e.to_string()))?;
    Ok(arr.into_pyarray(py).into_any())
}

fn shape_err_msg(msg: String) -> PyErr {
    Error::InvalidArgument {
        what: "array shape",
        reason: msg,
    }
    .into()
}

/// Schottky's l(s) (12) and m(s) (17) on the branch sqrt(s_j4) sqrt(s_kl) = sqrt_g.
#[pyfunction(name = "kotter_schottky")]
fn kotter_schottky_py<'py>(
    py: Python<'py>,
    a: PyReadonlyArray1<'py, f64>,
    l: PyReadonlyArray2<'py, f64>,
    s: PyReadonlyArray1<'py, C>,
    sqrt_g: PyReadonlyArray1<'py, C>,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let a = read_a(&a)?;
    let rows = read_rows::<6>("l", &l)?;
    let n = rows.len();
    let s = read_c1("s", &s, n)?;
    let sg = read_c1("sqrt_g", &sqrt_g, n)?;
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
    let lv: Vec<C> = res.iter().flat_map(|x| x.0).collect();
    let mv: Vec<C> = res.iter().flat_map(|x| x.1).collect();
    let lv = Array2::from_shape_vec((n, 3), lv).map_err(|e| shape_err_msg(e.to_string()))?;
    let mv = Array2::from_shape_vec((n, 3), mv).map_err(|e| shape_err_msg(e.to_string()))?;
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
    let a = read_a(&a)?;
    let b = {
        let b = b.as_array();
        if b.len() != 4 {
            return Err(shape_err("b", "(4,)", b.shape()));
        }
        [b[0], b[1], b[2], b[3]]
    };
    let rows = read_rows::<6>("l", &l)?;
    let n = rows.len();
    let s = read_c1("s", &s, n)?;
    let sg = read_c1("sqrt_g", &sqrt_g, n)?;
    let res: Result<Vec<[C; 3]>, Error> = py.detach(|| {
        rows.iter()
            .zip(s.iter().zip(sg.iter()))
            .map(|(r, (&si, &gi))| kotter::lax_m(&a, &b, r, si, gi))
            .collect()
    });
    let out: Vec<C> = res?.into_iter().flatten().collect();
    let arr = Array2::from_shape_vec((n, 3), out).map_err(|e| shape_err_msg(e.to_string()))?;
    Ok(arr.into_pyarray(py).into_any())
}

/// Coefficients of F(s) (19), monic, highest power first, for integrals h of shape (n, 4).
#[pyfunction(name = "kotter_quartic")]
fn kotter_quartic_py<'py>(
    py: Python<'py>,
    a: PyReadonlyArray1<'py, f64>,
    h: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let a = read_a(&a)?;
    let rows = read_rows::<4>("h", &h)?;
    let n = rows.len();
    let res: Result<Vec<[f64; 5]>, Error> = py.detach(|| {
        crate::error::check_finite("a", &a)?;
        rows.iter()
            .map(|r| {
                crate::error::check_finite("h", r)?;
                kotter::quartic_f(&a, r)
            })
            .collect()
    });
    let out: Vec<f64> = res?.into_iter().flatten().collect();
    let arr = Array2::from_shape_vec((n, 5), out).map_err(|e| shape_err_msg(e.to_string()))?;
    Ok(arr.into_pyarray(py).into_any())
}

/// Kötter's reduction and the uniformization for states `l` of shape (n, 6):
/// a dict of arrays with leading axis n (see `manakov.kotter`).
#[pyfunction(name = "kotter_batch")]
fn kotter_batch_py<'py>(
    py: Python<'py>,
    a: PyReadonlyArray1<'py, f64>,
    l: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let a = read_a(&a)?;
    let rows = read_rows::<6>("l", &l)?;
    let n = rows.len();
    let res: Result<Vec<kotter::KotterState>, Error> =
        py.detach(|| rows.iter().map(|r| kotter::kotter(&a, r)).collect());
    let res = res?;
    let dict = PyDict::new(py);
    let c2 = |f: &dyn Fn(&kotter::KotterState) -> Vec<C>, m: usize| -> PyResult<Array2<C>> {
        let v: Vec<C> = res.iter().flat_map(f).collect();
        Array2::from_shape_vec((n, m), v).map_err(|e| shape_err_msg(e.to_string()))
    };
    let c1 = |f: &dyn Fn(&kotter::KotterState) -> C| -> Array1<C> { res.iter().map(f).collect() };
    let k = |st: &kotter::KotterState| st.constants.clone();
    dict.set_item("h", {
        let v: Vec<f64> = res.iter().flat_map(|st| st.constants.h).collect();
        Array2::from_shape_vec((n, 4), v)
            .map_err(|e| shape_err_msg(e.to_string()))?
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
            .map_err(|e| shape_err_msg(e.to_string()))?
            .into_pyarray(py),
    )?;
    let dd: Vec<C> = res
        .iter()
        .flat_map(|st| st.constants.delta_det.concat())
        .collect();
    dict.set_item(
        "Delta",
        Array3::from_shape_vec((n, 3, 3), dd)
            .map_err(|e| shape_err_msg(e.to_string()))?
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
            .map_err(|e| shape_err_msg(e.to_string()))?
            .into_pyarray(py),
    )?;
    let br: Vec<i8> = res.iter().flat_map(|st| st.points.eps).collect();
    dict.set_item(
        "branch",
        Array2::from_shape_vec((n, 5), br)
            .map_err(|e| shape_err_msg(e.to_string()))?
            .into_pyarray(py),
    )?;
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
    let al = read_crows::<3>("alpha", &alpha, n)?;
    let be = read_crows::<3>("beta", &beta, n)?;
    let ga = read_crows::<3>("gamma", &gamma, n)?;
    let de = read_crows::<3>("delta", &delta, n)?;
    let dv = read_crows::<3>("d", &d, n)?;
    let z1 = read_c1("z1", &z1, n)?;
    let y1 = read_c1("y1", &y1, n)?;
    let z2 = read_c1("z2", &z2, n)?;
    let y2 = read_c1("y2", &y2, n)?;
    let g = read_c1("g", &g, n)?;
    let br = {
        let b = branch.as_array();
        if b.ncols() != 5 || b.nrows() != n {
            return Err(shape_err("branch", &format!("({n}, 5)"), b.shape()));
        }
        b.rows()
            .into_iter()
            .map(|r| std::array::from_fn(|i| r[i]))
            .collect::<Vec<[i8; 5]>>()
    };
    let zd: Option<Vec<[[C; 5]; 2]>> = match zd {
        None => None,
        Some(z) => {
            let z = z.as_array();
            if z.shape() != [n, 2, 5] {
                return Err(shape_err("zd", &format!("({n}, 2, 5)"), z.shape()));
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
    let out: Vec<f64> = res?.into_iter().flatten().collect();
    let arr = Array2::from_shape_vec((n, 6), out).map_err(|e| shape_err_msg(e.to_string()))?;
    Ok(arr.into_pyarray(py).into_any())
}

/// Adds this module's functions to `manakov._core`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(kotter_integrals_py, m)?)?;
    m.add_function(wrap_pyfunction!(kotter_schottky_py, m)?)?;
    m.add_function(wrap_pyfunction!(kotter_quartic_py, m)?)?;
    m.add_function(wrap_pyfunction!(kotter_lax_m_py, m)?)?;
    m.add_function(wrap_pyfunction!(kotter_batch_py, m)?)?;
    m.add_function(wrap_pyfunction!(kotter_from_points_py, m)?)?;
    Ok(())
}
