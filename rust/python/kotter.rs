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

/// Kötter's reduction and the uniformization for states `l` of shape (n, 6):
/// a dict of arrays with leading axis n (see `manakov.kotter`).
#[pyfunction(name = "kotter_batch")]
fn kotter_batch_py<'py>(
    py: Python<'py>,
    a: PyReadonlyArray1<'py, f64>,
    l: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let a: [f64; 4] = array1(&a, "a")?;
    let rows = rows::<f64, 6>(&l, "l", None)?;
    let n = rows.len();
    let res: Result<Vec<kotter::KotterState>, Error> =
        py.detach(|| rows.iter().map(|r| kotter::kotter(&a, r)).collect());
    let res = res?;
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
